/* bench/machine.h — what every benchmark shares: the machine line its tables start with (CPU
 * model, cores, GPU, compiler and build flags), a monotonic clock and the median of runs.
 * Benchmark-only helper. */
#ifndef RS_BENCH_MACHINE_H
#define RS_BENCH_MACHINE_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/clock.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "gpu/gpu_device.h"

#ifndef RS_BUILD_FLAGS
#  define RS_BUILD_FLAGS "?"
#endif

/* The float image format this build writes: .exr, or .pfm in the PFM-only build (no
 * OpenImageIO: RS_DEPS=OPTIONAL, a bare GPU machine's). */
static inline const char *br_float_ext(void)
{
    return strncmp(rs_image_library_version(), "none", 4) == 0 ? "pfm" : "exr";
}

/* A benchmark that renders scene files it writes: in a build that reads none (RS_DEPS=OPTIONAL
 * without cJSON; bench/CMakeLists.txt defines RS_NO_SCENE_FILES) it says so and exits 77, which
 * CTest and bench/run-all count as skipped. */
#ifdef RS_NO_SCENE_FILES
#  define BR_SKIP_NO_SCENE_FILES(prog)                                                         \
      do {                                                                                     \
          printf("%s: skipped: this build has no cJSON and reads no scene files\n", (prog));  \
          return 77;                                                                           \
      } while (0)
#else
#  define BR_SKIP_NO_SCENE_FILES(prog) (void)(prog)
#endif

static inline int rs_bench_cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The median of v[n] (sorts v). */
static inline double rs_bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof v[0], rs_bench_cmp_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* Opens `path` for a benchmark's CSV and writes `header` (a line with its newline); NULL after
 * printing "PROG: cannot write PATH". */
static inline FILE *rs_bench_csv_open(const char *prog, const char *path, const char *header)
{
    FILE *f = fopen(path, "w");
    if (!f) {
        fprintf(stderr, "%s: cannot write %s\n", prog, path);
        return NULL;
    }
    fputs(header, f);
    return f;
}

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
