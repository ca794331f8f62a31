/* bench/machine.h — the machine line every benchmark table starts with: CPU model, cores,
 * GPU, compiler and build flags.  Benchmark-only helper. */
#ifndef RS_BENCH_MACHINE_H
#define RS_BENCH_MACHINE_H

#include <stdio.h>
#include <string.h>

#include "core/parallel.h"
#include "gpu/gpu_device.h"

#ifndef RS_BUILD_FLAGS
#  define RS_BUILD_FLAGS "?"
#endif

static inline void rs_bench_cpu_model(char *buf, size_t n)
{
    FILE *f = fopen("/proc/cpuinfo", "r");
    char line[512];
    snprintf(buf, n, "unknown CPU");
    if (!f)
        return;
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "model name", 10) == 0) {
            char *colon = strchr(line, ':');
            if (colon) {
                colon += 2;
                colon[strcspn(colon, "\n")] = '\0';
                snprintf(buf, n, "%s", colon);
            }
            break;
        }
    }
    fclose(f);
}

static inline void rs_bench_print_machine(FILE *out)
{
    char cpu[256];
    const char *why = "";
    int ngpu = rs_gpu_count(&why);
    rs_bench_cpu_model(cpu, sizeof cpu);
    fprintf(out, "machine: %s, %d cores; GPU: ", cpu, rs_cpu_count());
    if (ngpu > 0) {
        rs_device *d;
        if (rs_gpu_device_create(0, &d) == RS_OK) {
            fprintf(out, "%s", d->name);
            rs_device_destroy(d);
        }
        if (ngpu > 1)
            fprintf(out, " (+%d more)", ngpu - 1);
    } else {
        fprintf(out, "none (%s)", why);
    }
    fprintf(out, "\ncompiler: gcc %s; flags: %s\n", __VERSION__, RS_BUILD_FLAGS);
}

#endif
