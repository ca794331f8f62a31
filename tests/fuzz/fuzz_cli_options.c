/* tests/fuzz/fuzz_cli_options.c — libFuzzer harness for the command-line parser.
 *
 * The bytes are split into arguments at NUL and newline bytes (a last newline ends the last
 * argument; each argument is its own allocation, so a read past one is seen) and given to
 * rs_cli_parse after argv[0].  It must return 0 or the usage exit status 2 (after its one line),
 * and a render it accepts must be within the documented ranges; never a crash or a sanitizer
 * report.  Built with -DRS_FUZZ=ON (scripts/fuzz.sh). */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "app/options.h"
#include "fuzz_util.h"

#define MAX_ARGS 64

static void broken(const char *what) { fz_broken("rs_cli_parse accepted options with %s", what); }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *argv[MAX_ARGS + 2];
    int argc = 1, rc, i;
    size_t start = 0, k;
    rs_cli_options o;
    argv[0] = strdup("raystream");
    for (k = 0; k <= size && argc <= MAX_ARGS; ++k) {
        if (k == size && start == size && size > 0)
            break; /* the input ended with a separator */
        if (k == size || data[k] == '\0' || data[k] == '\n') {
            char *a = (char *)malloc(k - start + 1);
            if (!a)
                abort();
            memcpy(a, data + start, k - start);
            a[k - start] = '\0';
            argv[argc++] = a;
            start = k + 1;
        }
    }
    argv[argc] = NULL;
    rc = rs_cli_parse(argc, argv, &o);
    if (rc != RS_EXIT_OK && rc != RS_EXIT_USAGE)
        broken("an exit status other than 0 or 2");
    if (rc == RS_EXIT_OK && o.command == RS_CMD_RENDER) {
        if (!o.scene || !*o.scene)
            broken("no scene");
        if (o.spp < 1 || o.spp > (1u << 20) || o.max_depth < 1 || o.max_depth > 10000)
            broken("spp or max depth out of range");
        if (o.width > 32768 || o.height > 32768 || o.threads < 0 || o.threads > 1024)
            broken("a size or thread count out of range");
        if (o.n_devices < 0 || o.n_devices > RS_MAX_DEVICES || (!o.devices_auto && !o.n_devices))
            broken("a bad device list");
        if (o.waves > 4 || o.chunk_size > (1u << 26) || o.wave_paths > (1u << 26))
            broken("waves, chunk or wave size out of range");
        if (!(o.ckpt_every_s > 0 && o.ckpt_every_s <= 1e9) ||
            !(o.time_limit_s >= 0 && o.time_limit_s <= 1e9) ||
            !(o.mpi_timeout_s >= 0 && o.mpi_timeout_s <= 1e9))
            broken("a time out of range");
        if (o.mpi_pass_spp > (1u << 24))
            broken("--mpi-pass out of range");
        if (o.megakernel && !o.devices_auto && o.n_devices > 1)
            broken("the megakernel on several devices");
        if (o.bvh_width != 0 && o.bvh_width != 2 && o.bvh_width != 4 && o.bvh_width != 8)
            broken("a bad --bvh-width");
    }
    for (i = 0; i < argc; ++i)
        free(argv[i]);
    return 0;
}
