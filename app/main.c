/* app/main.c — the `raystream` command: reads the options, picks the command and runs it.
 *
 *   render   app/render_cmd.c (its steps: app/render_run.h; under mpirun app/dist_glue.c)
 *   export   app/scene_load.c
 *   scenes, --version, --help   here
 *
 * The program ends only by returning from main: the exit status is the command's (RS_EXIT_*,
 * app/options.h).  The stop signals are app/signals.c's. */
#include <signal.h>
#include <stdio.h>

#include "app/dist_glue.h"
#include "app/render_run.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "gpu/gpu_device.h"
#include "scenes/builtin.h"

static int cmd_version(void)
{
    const char *why = "";
    int n;
    printf("raystream %s\n", RS_VERSION);
    if (rs_gpu_compiled()) {
        n = rs_gpu_count(&why);
        if (n > 0)
            printf("  CUDA:        yes (%d device%s)\n", n, n == 1 ? "" : "s");
        else
            printf("  CUDA:        yes, built in; no usable device (%s)\n", why);
    } else {
        printf("  CUDA:        no (built without the CUDA toolkit)\n");
    }
    if (RS_HAVE_OPENMP)
        printf("  OpenMP:      yes, %d threads available\n", rs_default_threads());
    else
        printf("  OpenMP:      no (compiled out for ThreadSanitizer); %d cores\n", rs_cpu_count());
    printf("  OpenImageIO: %s\n", rs_image_library_version());
    if (rs_dist_built())
        printf("  MPI:         yes (mpirun -n N raystream render ...; docs/distributed.md)\n");
    else
        printf("  MPI:         no (built without MPI: RS_MPI, libopenmpi-dev)\n");
    return RS_EXIT_OK;
}

static int cmd_scenes(void)
{
    int i;
    const char *name, *desc;
    for (i = 0; (name = rs_builtin_name(i, &desc)) != NULL; ++i)
        printf("builtin:%-12s %s\n", name, desc);
    return RS_EXIT_OK;
}

int main(int argc, char **argv)
{
    rs_cli_options o;
    int rc;
    /* A reader that goes away (`raystream render ... 2>&1 | head -1`) must not kill the render:
     * writes to stdout or stderr then fail with EPIPE, which nothing here treats as fatal. */
    signal(SIGPIPE, SIG_IGN);
    /* under mpirun every rank parses the same line: only rank 0 tells what is wrong */
    rc = rs_mpi_parse_options(argc, argv, &o);
    if (rc != RS_EXIT_OK)
        return rc;
    switch (o.command) {
    case RS_CMD_HELP: rs_cli_print_help(o.scene); return RS_EXIT_OK;
    case RS_CMD_VERSION: return cmd_version();
    case RS_CMD_SCENES: return cmd_scenes();
    case RS_CMD_RENDER: return rs_cmd_render(&o, &argc, &argv);
    case RS_CMD_EXPORT: return rs_cmd_export(&o);
    }
    return RS_EXIT_OK;
}
