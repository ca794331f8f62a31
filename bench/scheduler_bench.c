/* bench/scheduler_bench.c — load balance of the heterogeneous scheduler.
 *
 * Two devices, A and B, render the same scene alone and together:
 *   with a CUDA device:    A = cpu:(T-1) (4-wide BVH), B = cuda:0;
 *   without (CI machines): A = cpu:(T-1),              B = gpu-fallback:1 (binary BVH kernel on
 *                          one host thread, staged like a GPU) — the split `--devices auto`
 *                          makes, T being the cores.
 * Every run shades on all T cores (one core budget shared with the CPU devices).  For each scene
 * and device set it prints, as medians of --runs renders:
 *   samples/s          paths finished per second of the whole render;
 *   trace Mrays/s      rays traced per second of the render's tracing phases (the time the render
 *                      thread waits for the scheduler): what the devices deliver together;
 *   efficiency         A+B ÷ (A alone + B alone), of the trace Mrays/s (the load balance: ideal
 *                      1.0) and of samples/s (which also carries the shading, the same CPU work
 *                      in every set, so it is below 1 whenever shading takes time);
 *   idle               per device, the share of the tracing phases it spent without a chunk
 *                      (1 - its busy time ÷ the tracing phases' time);
 *   share              per device, its share of the rays in A+B.
 * Then a sweep on the first scene: A+B at fixed chunk sizes and 1 or 2 waves in flight against
 * the defaults (adaptive chunks, auto waves).  With 2 waves the render thread waits only for the
 * tracing that shading did not hide, so its trace rate is no device throughput: those rows give
 * samples/s only.  Images are checked: A, B and A+B must agree bit
 * for bit (the fallback) or to float rounding (a GPU; printed).
 *
 *   scheduler_bench [--quick] [--runs N] [--size N] [--spp N] [--scene NAME]... [--models DIR]
 *                   [--csv FILE]
 *   NAME: a built-in scene, or cornell-mesh:FILE (FILE under the models folder) */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_render.h"
#include "core/alloc.h"
#include "machine.h"

#define MAX_SCENES  8
#define MAX_RUNS    15
#define MAX_CONFIGS 10

enum { SET_A, SET_B, SET_AB, N_SETS };
static const char *const set_names[N_SETS] = {"A alone", "B alone", "A+B"};

typedef struct config {
    int set;
    uint32_t chunk; /* 0: adaptive */
    uint32_t waves; /* 0: auto */
} config;

typedef struct measure {
    double sps, trace_mrays; /* medians */
    double run_mrays[MAX_RUNS];
    double idle[2], share[2];
    double seconds;
} measure;

typedef struct bench {
    int threads, have_gpu, runs;
    uint32_t size, spp;
    float *ref; /* A alone's image of the current scene */
    double max_diff;
    int mismatch;
} bench;

static int make_device(const bench *b, int which, rs_cores *cores, rs_device **out)
{
    if (which == 0) {
        rs_cpu_device_opts o;
        memset(&o, 0, sizeof o);
        o.threads = b->threads > 1 ? b->threads - 1 : 1;
        o.cores = cores;
        return rs_cpu_device_create_opts(&o, out) == RS_OK;
    }
    if (b->have_gpu)
        return rs_gpu_device_create(0, out) == RS_OK;
    return rs_gpu_fallback_create(1, 0, cores, out) == RS_OK;
}

/* One render of `scene` with configuration `c`; fills the per-run figures. */
static int render_once(bench *b, const rs_scene *scene, const rs_bvh *bvh, const config *c,
                       double *sps, double *mrays, double idle[2], double share[2], double *secs,
                       float *rgb)
{
    rs_geom g = rs_scene_geom(scene);
    rs_device *devs[2] = {NULL, NULL};
    int n = c->set == SET_AB ? 2 : 1, i, ok = 0;
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rs_sched_config cfg;
    rs_cores cores;
    rs_cores_init(&cores, b->threads);
    if (c->set == SET_AB) {
        if (!make_device(b, 0, &cores, &devs[0]) || !make_device(b, 1, &cores, &devs[1]))
            goto out;
    } else if (!make_device(b, c->set == SET_A ? 0 : 1, &cores, &devs[0])) {
        goto out;
    }
    for (i = 0; i < n; ++i)
        if (rs_device_upload(devs[i], &g, bvh) != RS_OK)
            goto out;
    memset(&cfg, 0, sizeof cfg);
    cfg.chunk_size = c->chunk;
    memset(&st, 0, sizeof st);
    st.width = st.height = b->size;
    st.spp = b->spp;
    st.max_depth = 50;
    st.seed = 1;
    st.sampling = RS_SAMPLING_MIS;
    st.threads = b->threads;
    st.cores = &cores;
    st.waves_in_flight = c->waves;
    if (rs_sched_create(devs, n, &cfg, &sched) != RS_OK ||
        rs_film_create(b->size, b->size, &film) != RS_OK ||
        rs_render(scene, sched, &st, NULL, film, &stats) != RS_OK)
        goto out;
    *sps = (double)stats.paths_total / stats.seconds;
    *mrays = 1e-6 * (double)(stats.rays_closest + stats.rays_shadow) / stats.wait_s;
    *secs = stats.seconds;
    for (i = 0; i < 2; ++i)
        idle[i] = share[i] = 0.0;
    for (i = 0; i < n; ++i) {
        rs_device_stats ds;
        int alive;
        rs_sched_device_stats(sched, i, &ds, &alive);
        idle[i] = stats.wait_s > 0.0 ? 1.0 - ds.busy_s / stats.wait_s : 0.0;
        if (idle[i] < 0.0)
            idle[i] = 0.0;
        share[i] = (double)ds.rays / (double)(stats.rays_closest + stats.rays_shadow);
    }
    if (rgb)
        rs_film_resolve(film, rgb);
    ok = 1;
out:
    if (!ok)
        fprintf(stderr, "scheduler_bench: %s\n", rs_error_message());
    rs_sched_destroy(sched);
    for (i = 0; i < n; ++i)
        rs_device_destroy(devs[i]);
    rs_film_destroy(film);
    return ok;
}

/* Renders each of the n configurations b->runs times, interleaved (run 1 of every configuration,
 * then run 2, ...) so that a drift of the machine's speed touches them all alike; fills their
 * medians and per-run trace rates.  The first run's images are compared with the scene's
 * reference (A alone's, which the first configuration sets when it is A with the defaults). */
static int measure_configs(bench *b, const rs_scene *scene, const rs_bvh *bvh, const config *cs,
                           int n, measure *ms)
{
    double sps[MAX_CONFIGS][MAX_RUNS], idle[MAX_CONFIGS][2][MAX_RUNS],
        share[MAX_CONFIGS][2][MAX_RUNS], secs[MAX_CONFIGS][MAX_RUNS], tmp[MAX_RUNS];
    size_t nf = (size_t)b->size * b->size * 3, k;
    float *img = (float *)malloc(nf * sizeof *img);
    int r, i, c;
    for (r = 0; r < b->runs; ++r)
        for (c = 0; c < n; ++c) {
            double id[2], sh[2];
            if (!render_once(b, scene, bvh, &cs[c], &sps[c][r], &ms[c].run_mrays[r], id, sh,
                             &secs[c][r], r == 0 ? img : NULL)) {
                free(img);
                return 0;
            }
            for (i = 0; i < 2; ++i) {
                idle[c][i][r] = id[i];
                share[c][i][r] = sh[i];
            }
            if (r > 0)
                continue;
            if (cs[c].set == SET_A && cs[c].chunk == 0 && cs[c].waves == 0) {
                memcpy(b->ref, img, nf * sizeof *img);
            } else {
                for (k = 0; k < nf; ++k) {
                    double d = fabs((double)img[k] - b->ref[k]);
                    b->max_diff = d > b->max_diff ? d : b->max_diff;
                    b->mismatch |= img[k] != b->ref[k];
                }
            }
        }
    free(img);
    for (c = 0; c < n; ++c) {
        measure *m = &ms[c];
        m->sps = rs_bench_median(sps[c], b->runs);
        memcpy(tmp, m->run_mrays, (size_t)b->runs * sizeof *tmp);
        m->trace_mrays = rs_bench_median(tmp, b->runs);
        m->seconds = rs_bench_median(secs[c], b->runs);
        for (i = 0; i < 2; ++i) {
            m->idle[i] = rs_bench_median(idle[c][i], b->runs);
            m->share[i] = rs_bench_median(share[c][i], b->runs);
        }
    }
    return 1;
}

/* The load-balance efficiency of `ab` against the alone runs, run by run (runs are interleaved,
 * so run r of each set saw the same machine), and its median. */
static double efficiency(const bench *b, const measure *a, const measure *bb, const measure *ab)
{
    double e[MAX_RUNS];
    int r;
    for (r = 0; r < b->runs; ++r)
        e[r] = ab->run_mrays[r] / (a->run_mrays[r] + bb->run_mrays[r]);
    return rs_bench_median(e, b->runs);
}

int main(int argc, char **argv)
{
    const char *scenes[MAX_SCENES], *models = NULL, *csv = NULL;
    int n_scenes = 0, quick = 0, i, s, k, failed = 0;
    bench b;
    FILE *csv_f = NULL;
    const char *why = "";
    char a_name[64], b_name[64];

    memset(&b, 0, sizeof b);
    b.runs = 5;
    b.size = 200;
    b.spp = 16;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            b.runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            b.size = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--spp") == 0 && i + 1 < argc) {
            b.spp = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc && n_scenes < MAX_SCENES) {
            scenes[n_scenes++] = argv[++i];
        } else if (strcmp(argv[i], "--models") == 0 && i + 1 < argc) {
            models = argv[++i];
        } else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            csv = argv[++i];
        } else {
            fprintf(stderr, "usage: scheduler_bench [--quick] [--runs N] [--size N] [--spp N] "
                            "[--scene NAME]... [--models DIR] [--csv FILE]\n");
            return 2;
        }
    }
    if (quick) {
        b.runs = 1;
        b.size = 32;
        b.spp = 2;
        if (n_scenes == 0)
            scenes[n_scenes++] = "cornell";
    }
    if (n_scenes == 0) {
        scenes[n_scenes++] = "cornell";
        scenes[n_scenes++] = "rtiow-final";
        scenes[n_scenes++] = "cornell-mesh:dragon/dragon_100k.ply";
    }
    if (b.runs < 1 || b.runs > MAX_RUNS || b.size < 1 || b.spp < 1) {
        fprintf(stderr, "scheduler_bench: runs must be 1..%d, size and spp >= 1\n", MAX_RUNS);
        return 2;
    }
    b.threads = rs_cpu_count();
    b.have_gpu = rs_gpu_count(&why) > 0;
    b.ref = (float *)malloc((size_t)b.size * b.size * 3 * sizeof *b.ref);
    snprintf(a_name, sizeof a_name, "cpu:%d", b.threads > 1 ? b.threads - 1 : 1);
    snprintf(b_name, sizeof b_name, "%s", b.have_gpu ? "cuda:0" : "gpu-fallback:1");
    if (csv) {
        csv_f = rs_bench_csv_open("scheduler_bench", csv,
                                  "scene,set,chunk,waves,samples_per_s,trace_mrays_per_s,"
                                  "seconds,idle_a,idle_b,share_a,share_b\n");
        if (!csv_f)
            return 1;
    }

    rs_bench_print_machine(stdout);
    printf("settings: %ux%u, %u spp, max depth 50, MIS, %d shading threads, median of %d; "
           "A = %s, B = %s%s\n\n",
           b.size, b.size, b.spp, b.threads, b.runs, a_name, b_name,
           b.have_gpu ? "" : " (no CUDA device: the fallback)");

    for (s = 0; s < n_scenes; ++s) {
        rs_scene *scene = NULL;
        rs_bvh *bvh = NULL;
        rs_geom g;
        measure m[N_SETS];
        double eff_t, eff_s;
        int loaded = br_load_scene("scheduler_bench", scenes[s], models, 1, &scene, &g, &bvh);
        if (loaded < 0)
            return 1;
        if (loaded == 0)
            continue;
        b.max_diff = 0.0;
        b.mismatch = 0;
        printf("scene %s (%u primitives, SAH BVH)\n", scenes[s], rs_geom_prim_count(&g));
        printf("  %-8s %-22s %12s %14s %9s %9s %8s %8s\n", "set", "devices", "samples/s",
               "trace Mrays/s", "idle A", "idle B", "share A", "share B");
        {
            config cs[N_SETS] = {{SET_A, 0, 0}, {SET_B, 0, 0}, {SET_AB, 0, 0}};
            if (!measure_configs(&b, scene, bvh, cs, N_SETS, m))
                failed = 1;
        }
        for (k = 0; k < N_SETS && !failed; ++k) {
            char devs[96];
            snprintf(devs, sizeof devs, "%s", k == SET_A ? a_name : k == SET_B ? b_name : "both");
            printf("  %-8s %-22s %12.0f %14.2f %8.1f%% %8.1f%% %7.1f%% %7.1f%%\n", set_names[k],
                   devs, m[k].sps, m[k].trace_mrays, 100.0 * m[k].idle[0],
                   k == SET_AB ? 100.0 * m[k].idle[1] : 0.0, 100.0 * m[k].share[0],
                   100.0 * m[k].share[1]);
            if (csv_f)
                fprintf(csv_f, "%s,%s,auto,auto,%.1f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", scenes[s],
                        set_names[k], m[k].sps, m[k].trace_mrays, m[k].seconds, m[k].idle[0],
                        m[k].idle[1], m[k].share[0], m[k].share[1]);
        }
        if (failed) {
            rs_bvh_destroy(bvh);
            rs_scene_destroy(scene);
            break;
        }
        eff_t = efficiency(&b, &m[SET_A], &m[SET_B], &m[SET_AB]);
        eff_s = m[SET_AB].sps / (m[SET_A].sps + m[SET_B].sps);
        printf("  load-balance efficiency (trace Mrays/s): %.3f   samples/s: %.3f   "
               "A+B vs A alone: %.2fx\n",
               eff_t, eff_s, m[SET_AB].sps / m[SET_A].sps);
        printf("  images: %s\n\n",
               !b.mismatch ? "A, B and A+B bit-identical"
                           : (b.have_gpu ? "differ by float rounding (GPU)" : "DIFFER"));
        if (b.have_gpu && b.mismatch)
            printf("  max abs pixel difference: %.3g\n\n", b.max_diff);
        if (b.mismatch && !b.have_gpu)
            failed = 1;

        /* the sweep, on the first scene only */
        if (s == 0 && !failed) {
            static const uint32_t chunks[] = {0, 1024, 16384, 262144};
            static const uint32_t waves[] = {1, 2};
            size_t ci, wi;
            printf("  sweep, A+B: chunk size x waves in flight (defaults: adaptive, auto = %s)\n",
                   b.have_gpu ? "2" : "1");
            printf("  %-10s %6s %12s %11s %14s %11s %9s %9s\n", "chunk", "waves", "samples/s",
                   "vs row 1", "trace Mrays/s", "efficiency", "idle A", "idle B");
            /* A and B alone again, interleaved with the sweep, so that each row's efficiency
             * pairs runs made side by side */
            config sw[MAX_CONFIGS] = {{SET_A, 0, 0}, {SET_B, 0, 0}};
            measure wm[MAX_CONFIGS];
            int n_sw = 2, j;
            for (ci = 0; ci < sizeof chunks / sizeof chunks[0]; ++ci)
                for (wi = 0; wi < sizeof waves / sizeof waves[0]; ++wi)
                    if (!(quick && ci > 1)) {
                        sw[n_sw].set = SET_AB;
                        sw[n_sw].chunk = chunks[ci];
                        sw[n_sw++].waves = waves[wi];
                    }
            if (!measure_configs(&b, scene, bvh, sw, n_sw, wm))
                failed = 1;
            for (j = 2; j < n_sw && !failed; ++j) {
                const measure *w = &wm[j];
                char cs[16], eff[16];
                snprintf(cs, sizeof cs, "%u", sw[j].chunk);
                /* with 2 waves the render thread waits only for what shading did not hide: its
                 * "trace" rate is no device throughput, so no efficiency */
                snprintf(eff, sizeof eff, "%.3f", efficiency(&b, &wm[0], &wm[1], w));
                printf("  %-10s %6u %12.0f %10.2fx %14.2f %11s %8.1f%% %8.1f%%\n",
                       sw[j].chunk ? cs : "adaptive", sw[j].waves, w->sps, w->sps / wm[2].sps,
                       w->trace_mrays, sw[j].waves == 1 ? eff : "-", 100.0 * w->idle[0],
                       100.0 * w->idle[1]);
                if (csv_f)
                    fprintf(csv_f, "%s,sweep,%s,%u,%.1f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f\n", scenes[s],
                            sw[j].chunk ? cs : "auto", sw[j].waves, w->sps, w->trace_mrays,
                            w->seconds, w->idle[0], w->idle[1], w->share[0], w->share[1]);
            }
            if (b.mismatch && !b.have_gpu)
                failed = 1;
            printf("  sweep images: %s\n\n", b.mismatch ? "DIFFER" : "bit-identical to A alone");
        }
        rs_bvh_destroy(bvh);
        rs_scene_destroy(scene);
    }
    if (csv_f)
        fclose(csv_f);
    free(b.ref);
    return failed ? 1 : 0;
}
