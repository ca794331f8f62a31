/* bench/mpi_bench.c — distributed rendering on one machine: `raystream render` as one process and
 * under `mpirun -n N` for N = 1, 2, 4 (each rank on one thread, --threads 1, so N ranks want N
 * cores; beyond the machine's cores they are oversubscribed), interleaved rounds, medians.
 *
 * The one process is pinned to one core, as mpirun binds each rank to one (--bind-to core, its
 * default up to 2 ranks), so that both run the cache-sized waves of a process confined to one
 * core (scheduler/render.h).  For each configuration: the render's samples/s (the stats' render seconds, from the first
 * pass handed out to the last film added) and end to end (the whole command, start-up of every
 * rank and MPI included), the speed-up over the one-process run of the same round, the
 * efficiency per core used (speed-up / min(N, cores)), the passes rank 0 rendered itself, the
 * film bytes and control messages that reached rank 0, and the CPU seconds of the messaging
 * threads (which must not spin).  Every image is checked against the one-process image bit for
 * bit first.  Last, what the film reduction needs at 4K: the bytes a rank sends.
 *
 *   mpi_bench [--quick] [--runs N] [--scene NAME] [--width N] [--height N] [--spp N]
 *             [--ranks LIST]     (default 1,2,4)
 * Skips (exit 0, saying why) where raystream was built without MPI or mpirun is missing. */
#define _GNU_SOURCE /* sched_setaffinity */
#include <errno.h>
#include <sched.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "machine.h"

#ifndef RS_BINARY_DIR
#  define RS_BINARY_DIR "."
#endif

#define MAX_CFG  6
#define MAX_RUNS 15

static const char *prog = "mpi_bench";
static char tmp_dir[256];
static char binary[1024];

typedef struct cfg {
    int ranks; /* 0: one process without mpirun */
    double render_s[MAX_RUNS], wall_s[MAX_RUNS], ratio[MAX_RUNS];
    double rank0_passes, passes, film_bytes, messages, comm_cpu;
} cfg;

/* Runs argv (NULL-terminated), output to /dev/null, pinned to the last core if `pin` (as
 * mpirun binds a rank to a core); the exit code, -1 if it did not end well. */
static int run_quiet(char *const argv[], int pin)
{
    int status;
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        int null = open("/dev/null", O_WRONLY);
        cpu_set_t all, one;
        int c;
        if (pin && sched_getaffinity(0, sizeof all, &all) == 0) {
            CPU_ZERO(&one);
            for (c = CPU_SETSIZE - 1; c >= 0; --c)
                if (CPU_ISSET(c, &all)) {
                    CPU_SET(c, &one);
                    break;
                }
            sched_setaffinity(0, sizeof one, &one);
        }
        if (null >= 0) {
            dup2(null, 1);
            dup2(null, 2);
        }
        execvp(argv[0], argv);
        _exit(127);
    }
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    char *s;
    long n;
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = (char *)malloc((size_t)n + 1);
    if (s && fread(s, 1, (size_t)n, f) != (size_t)n) {
        free(s);
        s = NULL;
    }
    if (s)
        s[n] = 0;
    fclose(f);
    return s;
}

/* the number after "key": (after `after`, if given), 0 if absent */
static double json_num(const char *text, const char *after, const char *key)
{
    char pat[64];
    const char *s = after ? strstr(text, after) : text;
    if (!s)
        return 0;
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    s = strstr(s, pat);
    return s ? atof(s + strlen(pat)) : 0;
}

/* the sum of every "key": in the text after `after` */
static double json_sum(const char *text, const char *after, const char *key)
{
    char pat[64];
    const char *s = strstr(text, after);
    double t = 0;
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    while (s && (s = strstr(s, pat)) != NULL) {
        s += strlen(pat);
        t += atof(s);
    }
    return t;
}

typedef struct run_result {
    double render_s, wall_s;
    double rank0_passes, passes, film_bytes, messages, comm_cpu;
    float *rgb;
    uint32_t w, h;
} run_result;

static int render_once(int ranks, const char *scene, uint32_t w, uint32_t h, uint32_t spp,
                       run_result *out)
{
    char ws[16], hs[16], ss[16], ns[16], img[300], json[300];
    char *argv[40];
    int k = 0, rc;
    double t0;
    char *text;
    memset(out, 0, sizeof *out);
    snprintf(ws, sizeof ws, "%u", w);
    snprintf(hs, sizeof hs, "%u", h);
    snprintf(ss, sizeof ss, "%u", spp);
    snprintf(ns, sizeof ns, "%d", ranks);
    snprintf(img, sizeof img, "%s/img-%d.%s", tmp_dir, ranks, br_float_ext());
    snprintf(json, sizeof json, "%s/stats-%d.json", tmp_dir, ranks);
    if (ranks > 0) {
        argv[k++] = (char *)"mpirun";
        argv[k++] = (char *)"-n";
        argv[k++] = ns;
        argv[k++] = (char *)"--oversubscribe";
        if (geteuid() == 0)
            argv[k++] = (char *)"--allow-run-as-root";
    }
    argv[k++] = binary;
    argv[k++] = (char *)"render";
    argv[k++] = (char *)scene;
    argv[k++] = (char *)"--width";
    argv[k++] = ws;
    argv[k++] = (char *)"--height";
    argv[k++] = hs;
    argv[k++] = (char *)"--spp";
    argv[k++] = ss;
    argv[k++] = (char *)"--threads";
    argv[k++] = (char *)"1";
    argv[k++] = (char *)"-q";
    argv[k++] = (char *)"-o";
    argv[k++] = img;
    argv[k++] = (char *)"--stats-json";
    argv[k++] = json;
    argv[k] = NULL;
    t0 = rs_now_s();
    rc = run_quiet(argv, ranks == 0);
    out->wall_s = rs_now_s() - t0;
    if (rc != 0) {
        fprintf(stderr, "%s: %s render with %d ranks failed (exit %d)\n", prog, scene, ranks, rc);
        return 0;
    }
    text = slurp(json);
    if (!text)
        return 0;
    out->render_s = json_num(text, NULL, "seconds");
    if (ranks > 0) {
        out->passes = json_num(text, "\"mpi\"", "passes");
        out->rank0_passes = json_num(text, "\"rank\": 0", "passes");
        out->film_bytes = json_num(text, "\"mpi\"", "bytes_received");
        out->messages = json_num(text, "\"mpi\"", "messages");
        out->comm_cpu = json_sum(text, "\"per_rank\"", "comm_cpu_s");
    }
    free(text);
    if (rs_image_read(img, &out->w, &out->h, &out->rgb) != RS_OK) {
        fprintf(stderr, "%s: cannot read back %s\n", prog, img);
        return 0;
    }
    return 1;
}

static int has_mpi(void)
{
    char cmd[1200];
    FILE *p;
    char line[256];
    int yes = 0;
    snprintf(cmd, sizeof cmd, "'%s' --version 2>/dev/null", binary);
    p = popen(cmd, "r");
    while (p && fgets(line, sizeof line, p))
        yes |= strstr(line, "MPI:         yes") != NULL;
    if (p)
        pclose(p);
    if (!yes) {
        printf("%s: skipped: %s was built without MPI\n", prog, binary);
        return 0;
    }
    if (system("mpirun --version >/dev/null 2>&1") != 0) {
        printf("%s: skipped: mpirun is not on PATH (apt-get install openmpi-bin)\n", prog);
        return 0;
    }
    return 1;
}

int main(int argc, char **argv)
{
    const char *scene = "builtin:cornell";
    uint32_t w = 256, h = 256, spp = 64;
    int runs = 5, quick = 0, i, j, n_cfg = 0, cores = rs_cpu_count(), ok = 1;
    cfg c[MAX_CFG];
    char ranks_list[64] = "1,2,4", *tok, *save = NULL;
    run_result ref;
    memset(c, 0, sizeof c);
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (i + 1 < argc && strcmp(argv[i], "--runs") == 0) {
            runs = atoi(argv[++i]);
        } else if (i + 1 < argc && strcmp(argv[i], "--scene") == 0) {
            scene = argv[++i];
        } else if (i + 1 < argc && strcmp(argv[i], "--width") == 0) {
            w = (uint32_t)atoi(argv[++i]);
        } else if (i + 1 < argc && strcmp(argv[i], "--height") == 0) {
            h = (uint32_t)atoi(argv[++i]);
        } else if (i + 1 < argc && strcmp(argv[i], "--spp") == 0) {
            spp = (uint32_t)atoi(argv[++i]);
        } else if (i + 1 < argc && strcmp(argv[i], "--ranks") == 0) {
            snprintf(ranks_list, sizeof ranks_list, "%s", argv[++i]);
        } else {
            fprintf(stderr,
                    "usage: %s [--quick] [--runs N] [--scene NAME] [--width N] [--height N] "
                    "[--spp N] [--ranks LIST]\n",
                    prog);
            return 2;
        }
    }
    if (quick) {
        runs = 1;
        w = h = 48;
        spp = 8;
        snprintf(ranks_list, sizeof ranks_list, "2");
    }
    if (runs < 1 || runs > MAX_RUNS || w < 1 || h < 1 || spp < 1) {
        fprintf(stderr, "%s: --runs 1..%d, sizes and --spp >= 1\n", prog, MAX_RUNS);
        return 2;
    }
    snprintf(binary, sizeof binary, "%s/raystream", RS_BINARY_DIR);
    {
        /* an address-sanitized raystream traces Open MPI's leaks to its libraries, which it
         * suppresses (app/distributed.c), only with full unwinding; other builds ignore it */
        const char *asan = getenv("ASAN_OPTIONS");
        char opts[512];
        snprintf(opts, sizeof opts, "%s%sfast_unwind_on_malloc=0", asan ? asan : "",
                 asan && *asan ? ":" : "");
        setenv("ASAN_OPTIONS", opts, 1);
    }
    if (!has_mpi())
        return 0;
    snprintf(tmp_dir, sizeof tmp_dir, "/tmp/mpi_bench-XXXXXX");
    if (!mkdtemp(tmp_dir)) {
        fprintf(stderr, "%s: mkdtemp: %s\n", prog, strerror(errno));
        return 1;
    }
    c[n_cfg++].ranks = 0;
    for (tok = strtok_r(ranks_list, ",", &save); tok && n_cfg < MAX_CFG;
         tok = strtok_r(NULL, ",", &save))
        if (atoi(tok) > 0)
            c[n_cfg++].ranks = atoi(tok);

    rs_bench_print_machine(stdout);
    printf("settings: %s %ux%u, %u spp, stream engine, --threads 1 per rank; %d interleaved "
           "round%s (medians); Open MPI mpirun --oversubscribe on this one machine\n",
           scene, w, h, spp, runs, runs == 1 ? "" : "s");

    /* the one-process image; every other must be it bit for bit */
    if (!render_once(0, scene, w, h, spp, &ref))
        return 1;
    for (i = 0; i < runs && ok; ++i) {
        double base = 0;
        for (j = 0; j < n_cfg && ok; ++j) {
            int k = (j + i) % n_cfg; /* rotate the order: the machine drifts */
            run_result rr;
            if (!render_once(c[k].ranks, scene, w, h, spp, &rr)) {
                ok = 0;
                break;
            }
            if (rr.w != ref.w || rr.h != ref.h ||
                memcmp(rr.rgb, ref.rgb, (size_t)ref.w * ref.h * 3 * sizeof(float)) != 0) {
                fprintf(stderr, "%s: %d ranks: the image is not the one-process image\n", prog,
                        c[k].ranks);
                ok = 0;
            }
            rs_free(rr.rgb);
            c[k].render_s[i] = rr.render_s;
            c[k].wall_s[i] = rr.wall_s;
            c[k].rank0_passes = rr.rank0_passes;
            c[k].passes = rr.passes;
            c[k].film_bytes = rr.film_bytes;
            c[k].messages = rr.messages;
            c[k].comm_cpu = rr.comm_cpu;
        }
        for (j = 0; j < n_cfg; ++j)
            if (c[j].ranks == 0)
                base = c[j].render_s[i];
        for (j = 0; j < n_cfg; ++j)
            c[j].ratio[i] = c[j].render_s[i] > 0 ? base / c[j].render_s[i] : 0;
    }
    rs_free(ref.rgb);
    if (!ok)
        return 1;
    printf("images: every run equals the one-process image bit for bit\n\n");
    printf("| run | cores used | render s | Msamples/s | speed-up | per core | end to end s | "
           "passes (rank 0) | film bytes to rank 0 | messages | messaging CPU s |\n");
    printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
    for (j = 0; j < n_cfg; ++j) {
        double rs = rs_bench_median(c[j].render_s, runs);
        double ws = rs_bench_median(c[j].wall_s, runs);
        double up = rs_bench_median(c[j].ratio, runs);
        int used = c[j].ranks == 0 ? 1 : (c[j].ranks < cores ? c[j].ranks : cores);
        char name[32];
        if (c[j].ranks == 0)
            snprintf(name, sizeof name, "one process");
        else
            snprintf(name, sizeof name, "mpirun -n %d", c[j].ranks);
        printf("| %s | %d | %.3f | %.3f | %.2fx | %.2f | %.3f | ", name, used, rs,
               (double)w * h * spp / rs / 1e6, up, up / used, ws);
        if (c[j].ranks == 0)
            printf("- | - | - | - |\n");
        else
            printf("%.0f (%.0f) | %.0f | %.0f | %.3f |\n", c[j].passes, c[j].rank0_passes,
                   c[j].film_bytes, c[j].messages, c[j].comm_cpu);
    }
    /* what a 4K frame's reduction sends: each rank but 0 its film once, sums as int64 when
     * they fit (3 x 8 bytes a pixel) plus the counts (4), else int128 (3 x 16 + 4) */
    printf("\nfilm reduction at 3840x2160: %.0f MB per rank sending int64 sums (28 B a pixel), "
           "%.0f MB with int128 sums (52 B a pixel); over 10 Gb/s that is %.2f s (%.2f s) per "
           "rank, received one rank after another by rank 0\n",
           3840.0 * 2160 * 28 / 1e6, 3840.0 * 2160 * 52 / 1e6, 3840.0 * 2160 * 28 * 8 / 10e9,
           3840.0 * 2160 * 52 * 8 / 10e9);
    {
        char cmd[400];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
        if (system(cmd) != 0)
            fprintf(stderr, "%s: could not remove %s\n", prog, tmp_dir);
    }
    return 0;
}
