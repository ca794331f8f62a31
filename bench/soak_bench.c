/* bench/soak_bench.c — soak: random scenes, device sets, chunk and wave sizes, injected faults
 * and bad inputs for a bounded time (issue 15 item 5).
 *
 * Each round, from one seeded random stream (so a failure is replayed by --seed alone):
 *   - a random scene (spheres, moving spheres, quads, triangles with and without UVs, boxes;
 *     every material and procedural texture type; sky or flat background; depth of field and
 *     a shutter) written as a JSON scene file to a private temporary folder and read back
 *     through rs_scene_load_json, the reader `raystream render FILE.json` uses;
 *   - random settings (size, spp, max depth, seed, sampling, sampler), the same for every
 *     render of the round;
 *   - the reference: the stream engine on `cpu` (one thread, adaptive chunks, automatic waves);
 *   - a render on a random device set — cpu, cpu:2, cpu + gpu, gpu, the megakernel on cpu or on
 *     gpu (gpu: the CUDA device's host fallback, gpu/gpu_fallback.c) — with random chunk size,
 *     wave size and waves in flight, and, on two devices, often a fault injected into one of
 *     them (scheduler/fault.c, what RS_FAULT does: it fails after N chunks); on one device
 *     sometimes too, where the render must then fail with RS_ERR_DEVICE_LOST, not hang;
 *   - bad inputs made from the round's scene: cut short, trailing content, a duplicate key, a
 *     number out of range, an undefined material, an unknown key, a non-finite number; each
 *     must be refused with one line naming the file.  Random byte flips as well, which may be
 *     accepted or refused (again with one line), never crash.
 * Every render's image must be the reference's bit for bit (a documented promise: the image
 * depends only on the seed and the settings), every path done and every ray answered, and no
 * pixel NaN or Inf.  It prints the machine, the settings and:
 *   renders, faults survived, bad inputs refused, samples lost, images differing, NaN/Inf
 * and exits 1 when samples were lost, an image differs, a pixel is NaN/Inf, a bad input was
 * accepted or anything failed that must not.
 *
 *   soak_bench [--quick] [--seconds N] [--seed N]
 *   --quick: 3 s (the test suite's smoke test, soak_bench_quick); default 60 s, seed 1 */
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "accel/bvh8.h"
#include "core/alloc.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "machine.h"
#include "scenes/scene_json.h"
#include "scheduler/fault.h"
#include "scheduler/render.h"

#define PROG     "soak_bench"
#define MAX_TEXT (64u << 10)

/* ---- the random stream ------------------------------------------------------------------- */

static uint64_t g_rng;

static uint64_t rnd(void)
{
    /* splitmix64 (Steele, Lea, Flood 2014) */
    uint64_t z = (g_rng += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* A whole number in [lo, hi]. */
static int rnd_int(int lo, int hi) { return lo + (int)(rnd() % (uint64_t)(hi - lo + 1)); }

/* A number in [lo, hi), on a grid of 1/1024 so that it prints exactly. */
static double rnd_num(double lo, double hi)
{
    return lo + (hi - lo) * (double)(rnd() % 1024) / 1024.0;
}

/* ---- scene files --------------------------------------------------------------------------- */

typedef struct text {
    char buf[MAX_TEXT];
    size_t len;
} text;

static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    int n;
    va_start(ap, fmt);
    n = vsnprintf(t->buf + t->len, sizeof t->buf - t->len, fmt, ap);
    va_end(ap);
    if (n > 0)
        t->len += (size_t)n < sizeof t->buf - t->len ? (size_t)n : sizeof t->buf - t->len - 1;
}

static void put_vec(text *t, double lo, double hi)
{
    put(t, "[%.10g, %.10g, %.10g]", rnd_num(lo, hi), rnd_num(lo, hi), rnd_num(lo, hi));
}

/* The ways generate() makes a scene file that must be refused. */
enum {
    BAD_NONE,
    BAD_RADIUS,    /* a sphere of radius -1 */
    BAD_ALBEDO,    /* a reflectance of 5 */
    BAD_MATERIAL,  /* an object naming a material that is not defined */
    BAD_KEY,       /* an unknown key */
    BAD_INFINITE,  /* 1e999, which cJSON reads as inf */
    BAD_CUT,       /* the file cut short */
    BAD_TRAILING,  /* content after the JSON value */
    BAD_DUPLICATE, /* "objects" twice */
    BAD_KINDS
};

static const char *const bad_names[BAD_KINDS] = {"",      "radius", "albedo",   "material", "key",
                                                 "1e999", "cut",    "trailing", "duplicate"};

static const char *const mat_types[] = {"lambertian", "diffuse_uniform", "disney_diffuse", "phong",
                                        "metal",      "dielectric",      "light"};
#define N_MAT_TYPES 7

/* A random scene as JSON text, valid unless `bad` says otherwise. */
static void generate(text *t, int bad)
{
    int n_tex = rnd_int(0, 3), n_mat = rnd_int(1, 6), n_obj = rnd_int(1, 14), i;
    double fx = rnd_num(-6, 6), fz = rnd_num(3, 9);
    t->len = 0;
    put(t, "{\n  \"camera\": {\"from\": [%.10g, %.10g, %.10g], \"at\": [0, 0, 0], \"vfov\": %.10g",
        fx, rnd_num(-2, 4), fz, rnd_num(20, 90));
    if (rnd() % 4 == 0)
        put(t, ", \"aperture\": %.10g, \"focus_distance\": %.10g", rnd_num(0, 0.3), rnd_num(1, 10));
    if (rnd() % 3 == 0)
        put(t, ", \"shutter\": [0, %.10g]", rnd_num(0, 1));
    put(t, "},\n");
    if (rnd() % 2)
        put(t, "  \"background\": [%.10g, %.10g, %.10g],\n", rnd_num(0, 1), rnd_num(0, 1),
            rnd_num(0, 1));
    else
        put(t, "  \"background\": {\"horizon\": [1, 1, 1], \"zenith\": [%.10g, %.10g, 1]},\n",
            rnd_num(0, 1), rnd_num(0, 1));
    put(t, "  \"textures\": {");
    for (i = 0; i < n_tex; ++i) {
        int k = rnd_int(0, 2);
        put(t, "%s\n    \"t%d\": ", i ? "," : "", i);
        if (k == 0) {
            put(t, "{\"type\": \"solid\", \"color\": ");
            put_vec(t, 0, 1);
            put(t, "}");
        } else {
            put(t, "{\"type\": \"%s\", \"a\": ", k == 1 ? "checker" : "stripes");
            put_vec(t, 0, 1);
            put(t, ", \"b\": ");
            put_vec(t, 0, 1);
            put(t, ", \"scale\": %.10g}", rnd_num(0.5, 20));
        }
    }
    put(t, "},\n  \"materials\": {");
    for (i = 0; i < n_mat; ++i) {
        const char *type = mat_types[i == 0 ? N_MAT_TYPES - 1 : rnd_int(0, N_MAT_TYPES - 1)];
        put(t, "%s\n    \"m%d\": {\"type\": \"%s\"", i ? "," : "", i, type);
        if (strcmp(type, "light") == 0) {
            put(t, ", \"emission\": ");
            put_vec(t, 0, 8);
            if (rnd() % 2)
                put(t, ", \"two_sided\": true");
        } else if (strcmp(type, "dielectric") == 0) {
            put(t, ", \"ior\": %.10g, \"tint\": ", rnd_num(1.0, 2.5));
            put_vec(t, 0.5, 1);
        } else if (strcmp(type, "metal") == 0) {
            put(t, ", \"albedo\": ");
            put_vec(t, 0, 1);
            put(t, ", \"fuzz\": %.10g", rnd_num(0, 1));
        } else {
            const char *key = strcmp(type, "phong") == 0 ? "kd" : "albedo";
            if (n_tex && rnd() % 2) {
                put(t, ", \"texture\": \"t%d\"", rnd_int(0, n_tex - 1));
            } else if (bad == BAD_ALBEDO) {
                put(t, ", \"%s\": [0.5, 5, 0.5]", key);
                bad = BAD_NONE; /* placed */
            } else {
                put(t, ", \"%s\": ", key);
                put_vec(t, 0, 0.5);
            }
            if (strcmp(type, "phong") == 0)
                put(t, ", \"ks\": [0.3, 0.3, 0.3], \"exponent\": %.10g", rnd_num(1, 200));
            if (strcmp(type, "disney_diffuse") == 0)
                put(t, ", \"roughness\": %.10g", rnd_num(0, 1));
            if (rnd() % 5 == 0)
                put(t, ", \"importance_sampling\": false");
        }
        put(t, "}");
    }
    if (bad == BAD_ALBEDO) /* every material took a texture: one more */
        put(t, ",\n    \"bad\": {\"type\": \"metal\", \"albedo\": [5, 5, 5]}");
    put(t, "},\n  \"objects\": [");
    for (i = 0; i < n_obj; ++i) {
        int k = rnd_int(0, 4), m = rnd_int(0, n_mat - 1);
        put(t, "%s\n    {", i ? "," : "");
        if (k == 0) {
            put(t, "\"type\": \"sphere\", \"center\": ");
            put_vec(t, -3, 3);
            put(t, ", \"radius\": %.10g", bad == BAD_RADIUS ? -1.0 : rnd_num(0.05, 1.5));
            if (bad == BAD_RADIUS)
                bad = BAD_NONE;
            if (rnd() % 3 == 0) {
                put(t, ", \"moving_to\": ");
                put_vec(t, -3, 3);
            }
        } else if (k == 1) {
            put(t, "\"type\": \"quad\", \"q\": ");
            put_vec(t, -4, 4);
            put(t, ", \"u\": [%.10g, 0, %.10g], \"v\": [0, %.10g, %.10g]", rnd_num(0.1, 4),
                rnd_num(-1, 1), rnd_num(0.1, 4), rnd_num(-1, 1));
        } else if (k == 2 || k == 3) {
            put(t,
                "\"type\": \"triangle\", \"vertices\": [[%.10g, %.10g, %.10g], "
                "[%.10g, %.10g, %.10g], [%.10g, %.10g, %.10g]]",
                rnd_num(-3, -0.5), rnd_num(-3, -0.5), rnd_num(-1, 1), rnd_num(0.5, 3),
                rnd_num(-3, -0.5), rnd_num(-1, 1), rnd_num(-1, 1), rnd_num(0.5, 3), rnd_num(-1, 1));
            if (k == 3)
                put(t, ", \"uv\": [0, 0, 1, 0, 0.5, 1]");
        } else {
            put(t,
                "\"type\": \"box\", \"min\": [%.10g, %.10g, %.10g], \"max\": "
                "[%.10g, %.10g, %.10g], \"rotate_y\": %.10g, \"translate\": ",
                rnd_num(-2, 0), rnd_num(-2, 0), rnd_num(-2, 0), rnd_num(0.1, 2), rnd_num(0.1, 2),
                rnd_num(0.1, 2), rnd_num(-180, 180));
            put_vec(t, -2, 2);
        }
        if (bad == BAD_KEY) {
            put(t, ", \"colour\": 1");
            bad = BAD_NONE;
        } else if (bad == BAD_INFINITE) {
            put(t, ", \"radius\": 1e999");
            bad = BAD_NONE;
        }
        put(t, ", \"material\": \"%s%d\"}", bad == BAD_MATERIAL ? "x" : "m", m);
        if (bad == BAD_MATERIAL)
            bad = BAD_NONE;
    }
    if (bad == BAD_RADIUS) /* no sphere was drawn: one more */
        put(t, ",\n    {\"type\": \"sphere\", \"center\": [0, 0, 0], \"radius\": -1, "
               "\"material\": \"m0\"}");
    put(t, "\n  ]");
    if (bad == BAD_DUPLICATE)
        put(t, ",\n  \"objects\": []");
    put(t, "\n}\n");
    if (bad == BAD_TRAILING)
        put(t, "%s", rnd() % 2 ? "{}\n" : "x");
    if (bad == BAD_CUT) /* anywhere before the closing brace */
        t->len = (size_t)rnd_int(0, (int)t->len - 3);
}

/* ---- the soak --------------------------------------------------------------------------- */

enum { SET_CPU, SET_CPU2, SET_CPU_GPU, SET_GPU, SET_MK_CPU, SET_MK_GPU, N_SETS };
static const char *const set_names[N_SETS] = {"cpu", "cpu:2",          "cpu,gpu",
                                              "gpu", "megakernel cpu", "megakernel gpu"};

typedef struct tally {
    long rounds, renders, per_set[N_SETS];
    long faults_injected, faults_survived, total_loss_reported;
    long bad_inputs, bad_refused, bad_accepted, per_bad[BAD_KINDS];
    long mutated, mutated_accepted, mutated_refused;
    uint64_t samples_lost, rays_unanswered;
    long images_differing, nonfinite, failures;
} tally;

static void failure(tally *ty, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, PROG ": FAIL: ");
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
    va_end(ap);
    ty->failures++;
}

typedef struct job {
    int set;
    int threads;
    uint32_t chunk, wave, waves;
    int fault_dev; /* -1: none */
    int fault_after;
} job;

/* Renders `scene` with job `j`; the image into rgb.  Returns the render's status; *retired is
 * set when the faulty device was retired, *lost to paths not done plus rays not answered. */
static rs_status render(const rs_scene *scene, const rs_geom *g, const rs_bvh *bvh,
                        const rs_render_settings *base, const job *j, float *rgb, int *retired,
                        uint64_t *lost, uint64_t *unanswered)
{
    rs_device *devs[2] = {NULL, NULL};
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st = *base;
    rs_render_stats stats;
    rs_sched_config cfg;
    rs_status rs = RS_OK;
    int n = j->set == SET_CPU_GPU ? 2 : 1, i;
    memset(&stats, 0, sizeof stats);
    *retired = 0;
    *lost = *unanswered = 0;
    st.threads = j->threads;
    st.wave_paths = j->wave;
    st.waves_in_flight = j->waves;
    for (i = 0; i < n && rs == RS_OK; ++i) {
        int gpu = j->set == SET_GPU || j->set == SET_MK_GPU || (j->set == SET_CPU_GPU && i == 1);
        rs = gpu ? rs_gpu_fallback_create(j->threads, 0, NULL, &devs[i])
                 : rs_cpu_device_create(j->set == SET_CPU2 ? 2 : j->threads, "cpu", &devs[i]);
        if (rs == RS_OK && j->fault_dev == i)
            rs = rs_fault_wrap(&devs[i], j->fault_after);
        if (rs == RS_OK)
            rs = rs_device_upload(devs[i], g, bvh);
    }
    if (rs == RS_OK)
        rs = rs_film_create(st.width, st.height, &film);
    if (rs == RS_OK && (j->set == SET_MK_CPU || j->set == SET_MK_GPU)) {
        rs = rs_render_passes(scene, devs[0], &st, NULL, film, &stats);
    } else if (rs == RS_OK) {
        memset(&cfg, 0, sizeof cfg);
        cfg.chunk_size = j->chunk;
        rs = rs_sched_create(devs, n, &cfg, &sched);
        if (rs == RS_OK)
            rs = rs_render(scene, sched, &st, NULL, film, &stats);
        if (rs == RS_OK) {
            uint64_t sub, ans;
            rs_sched_totals(sched, &sub, &ans);
            *unanswered = sub - ans;
            if (j->fault_dev >= 0) {
                rs_device_stats ds;
                int alive = 1;
                rs_sched_device_stats(sched, j->fault_dev, &ds, &alive);
                *retired = !alive;
            }
        }
    }
    if (rs == RS_OK) {
        *lost = stats.paths_total - stats.paths_done;
        rs_film_resolve(film, rgb);
    }
    rs_sched_destroy(sched);
    for (i = 0; i < n; ++i)
        rs_device_destroy(devs[i]);
    rs_film_destroy(film);
    return rs;
}

static long count_nonfinite(const float *rgb, size_t n)
{
    long bad = 0;
    size_t i;
    for (i = 0; i < n; ++i)
        bad += !isfinite(rgb[i]);
    return bad;
}

static void write_text(const char *path, const char *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(data, 1, len, f) != len || fclose(f) != 0) {
        fprintf(stderr, PROG ": cannot write %s\n", path);
        exit(1);
    }
}

/* A refused file's message: one line naming the file. */
static int refused_well(const char *path)
{
    const char *msg = rs_error_message();
    return *msg && !strchr(msg, '\n') && strstr(msg, path);
}

/* The round's bad inputs: one made invalid by generate(), and random byte flips. */
static void bad_inputs(tally *ty, const char *dir, const text *good)
{
    static text t;
    char path[600];
    rs_scene *s = NULL;
    rs_status st;
    int bad = rnd_int(1, BAD_KINDS - 1), k;
    snprintf(path, sizeof path, "%s/bad.json", dir);
    generate(&t, bad);
    write_text(path, t.buf, t.len);
    rs_error_clear();
    st = rs_scene_load_json(path, &s);
    ty->bad_inputs++;
    ty->per_bad[bad]++;
    if (st == RS_OK) {
        ty->bad_accepted++;
        failure(ty, "a scene file with a bad %s was accepted (%s)", bad_names[bad], path);
        rs_scene_destroy(s);
    } else if (!refused_well(path)) {
        failure(ty, "a bad %s was refused without one line naming the file: '%s'", bad_names[bad],
                rs_error_message());
    } else {
        ty->bad_refused++;
    }
    rs_error_clear();

    /* byte flips: either outcome, but an error is one line naming the file */
    memcpy(t.buf, good->buf, good->len);
    t.len = good->len;
    for (k = rnd_int(1, 8); k > 0; --k)
        t.buf[rnd() % t.len] = (char)(rnd() & 0xff);
    write_text(path, t.buf, t.len);
    s = NULL;
    st = rs_scene_load_json(path, &s);
    ty->mutated++;
    if (st == RS_OK) {
        ty->mutated_accepted++;
        rs_scene_destroy(s);
    } else if (!refused_well(path)) {
        failure(ty, "a mutated scene was refused without one line naming the file: '%s'",
                rs_error_message());
    } else {
        ty->mutated_refused++;
    }
    rs_error_clear();
    unlink(path);
}

/* One round: a scene, its reference render, one render on a random job, the bad inputs. */
static void round_once(tally *ty, const char *dir)
{
    static text t;
    char path[600];
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_bvh_build_opts bo;
    rs_render_settings st;
    rs_geom g;
    float *ref = NULL, *img = NULL;
    size_t nf;
    job j, refj;
    int retired;
    uint64_t lost, unanswered;
    rs_status rs;

    ty->rounds++;
    generate(&t, BAD_NONE);
    snprintf(path, sizeof path, "%s/scene-%ld.json", dir, ty->rounds);
    write_text(path, t.buf, t.len);
    rs_error_clear();
    if (rs_scene_load_json(path, &scene) != RS_OK) {
        failure(ty, "a generated scene was refused: %s", rs_error_message());
        rs_error_clear();
        goto out;
    }
    g = rs_scene_geom(scene);
    memset(&bo, 0, sizeof bo);
    bo.builder.method = RS_BVH_SAH;
    /* leaves sized to the CPU's wide tree's blocks, as the CLI builds for a CPU-only set (every
     * tree gives the same hits, so the GPU-fallback sets may share it) */
    bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, &g);
    if (rs_bvh_build(&g, &bo, &bvh) != RS_OK) {
        failure(ty, "%s: BVH: %s", path, rs_error_message());
        goto out;
    }
    memset(&st, 0, sizeof st);
    st.width = (uint32_t)rnd_int(8, 40);
    st.height = (uint32_t)rnd_int(8, 40);
    st.spp = (uint32_t)rnd_int(1, 4);
    st.max_depth = (uint32_t)rnd_int(1, 12);
    st.seed = rnd();
    st.sampling = (rs_sampling)rnd_int(0, 3);
    st.sampler = (rs_sampler)rnd_int(0, RS_SAMPLER_ZSOBOL);
    nf = (size_t)st.width * st.height * 3;
    ref = (float *)rs_alloc(nf, sizeof *ref);
    img = (float *)rs_alloc(nf, sizeof *img);
    if (!ref || !img) {
        failure(ty, "out of memory");
        goto out;
    }

    memset(&refj, 0, sizeof refj);
    refj.set = SET_CPU;
    refj.threads = 1;
    refj.fault_dev = -1;
    rs = render(scene, &g, bvh, &st, &refj, ref, &retired, &lost, &unanswered);
    if (rs != RS_OK) {
        failure(ty, "%s: the reference render failed: %s", path, rs_error_message());
        goto out;
    }
    ty->renders++;
    ty->per_set[SET_CPU]++;
    ty->nonfinite += count_nonfinite(ref, nf);

    memset(&j, 0, sizeof j);
    j.set = rnd_int(0, N_SETS - 1);
    j.threads = rnd_int(1, 2);
    j.chunk = rnd() % 3 ? 0u : (uint32_t)rnd_int(1, 8192);
    j.wave = rnd() % 3 ? 0u : (uint32_t)rnd_int(1, 20000);
    j.waves = (uint32_t)rnd_int(0, 4);
    j.fault_dev = -1;
    if (j.set == SET_CPU_GPU && rnd() % 4 != 0) {
        j.fault_dev = rnd_int(0, 1);
        j.fault_after = rnd_int(0, 6);
    } else if ((j.set == SET_CPU || j.set == SET_CPU2 || j.set == SET_GPU) && rnd() % 8 == 0) {
        j.fault_dev = 0; /* the only device: the render must fail, not hang */
        j.fault_after = rnd_int(0, 2);
    }
    ty->faults_injected += j.fault_dev >= 0;
    rs = render(scene, &g, bvh, &st, &j, img, &retired, &lost, &unanswered);
    if (rs == RS_ERR_DEVICE_LOST && j.fault_dev >= 0 && j.set != SET_CPU_GPU) {
        ty->total_loss_reported++; /* every device failed: reported, nothing hung */
    } else if (rs != RS_OK) {
        failure(ty, "%s on %s (chunk %u, wave %u, waves %u, fault %d after %d): %s", path,
                set_names[j.set], j.chunk, j.wave, j.waves, j.fault_dev, j.fault_after,
                rs_error_message());
    } else {
        ty->renders++;
        ty->per_set[j.set]++;
        ty->samples_lost += lost;
        ty->rays_unanswered += unanswered;
        ty->nonfinite += count_nonfinite(img, nf);
        if (memcmp(img, ref, nf * sizeof *img) != 0) {
            ty->images_differing++;
            failure(ty,
                    "%s on %s (chunk %u, wave %u, waves %u, fault %d after %d; %ux%u, %u "
                    "spp, seed %llu): the image differs from cpu's",
                    path, set_names[j.set], j.chunk, j.wave, j.waves, j.fault_dev, j.fault_after,
                    st.width, st.height, st.spp, (unsigned long long)st.seed);
        } else if (j.fault_dev >= 0 && retired) {
            ty->faults_survived++;
        }
    }
    rs_error_clear();
    bad_inputs(ty, dir, &t);
out:
    rs_error_clear();
    rs_free(ref);
    rs_free(img);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    unlink(path);
}

int main(int argc, char **argv)
{
    double seconds = 60.0, t0;
    uint64_t seed = 1;
    char dir[512];
    const char *tmp = getenv("TMPDIR");
    tally ty;
    int i, ok;
    BR_SKIP_NO_SCENE_FILES(argv[0]);
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            seconds = 3.0;
        } else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
            seconds = atof(argv[++i]);
            if (!(seconds > 0 && seconds <= 86400)) {
                fprintf(stderr, PROG ": --seconds must be in (0, 86400]\n");
                return 2;
            }
        } else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) {
            seed = strtoull(argv[++i], NULL, 10);
        } else {
            fprintf(stderr, "usage: " PROG " [--quick] [--seconds N] [--seed N]\n");
            return 2;
        }
    }
    snprintf(dir, sizeof dir, "%s/rs-soak-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(dir)) {
        fprintf(stderr, PROG ": cannot make a folder in %s\n", tmp && *tmp ? tmp : "/tmp");
        return 1;
    }
    g_rng = seed;
    memset(&ty, 0, sizeof ty);

    rs_bench_print_machine(stdout);
    printf("settings: %.0f s, seed %llu; scenes of 1-14 random objects (every material and "
           "texture type), 8-40 px, 1-4 spp, depth 1-12, every sampling and sampler; device sets "
           "cpu, cpu:2, cpu,gpu, gpu, megakernel cpu, megakernel gpu (gpu: the CUDA device's host "
           "fallback); chunk, wave size and waves in flight random; faults after 0-6 chunks\n",
           seconds, (unsigned long long)seed);
    fflush(stdout);
    t0 = rs_now_s();
    while (rs_now_s() - t0 < seconds)
        round_once(&ty, dir);
    rmdir(dir);

    printf("rounds: %ld in %.1f s; renders: %ld (", ty.rounds, rs_now_s() - t0, ty.renders);
    for (i = 0; i < N_SETS; ++i)
        printf("%s%s %ld", i ? ", " : "", set_names[i], ty.per_set[i]);
    printf(")\n");
    printf("faults injected: %ld; survived (device retired, image unchanged): %ld; every device "
           "lost, reported: %ld; not reached (the render needed fewer chunks): %ld\n",
           ty.faults_injected, ty.faults_survived, ty.total_loss_reported,
           ty.faults_injected - ty.faults_survived - ty.total_loss_reported);
    printf("bad inputs refused: %ld of %ld (", ty.bad_refused, ty.bad_inputs);
    for (i = 1; i < BAD_KINDS; ++i)
        printf("%s%s %ld", i > 1 ? ", " : "", bad_names[i], ty.per_bad[i]);
    printf("); byte-flipped files: %ld accepted, %ld refused with one line\n", ty.mutated_accepted,
           ty.mutated_refused);
    printf("samples lost: %llu; rays unanswered: %llu; images differing from cpu: %ld; NaN/Inf "
           "pixels: %ld; failures: %ld\n",
           (unsigned long long)ty.samples_lost, (unsigned long long)ty.rays_unanswered,
           ty.images_differing, ty.nonfinite, ty.failures);
    ok = ty.samples_lost == 0 && ty.rays_unanswered == 0 && ty.images_differing == 0 &&
         ty.nonfinite == 0 && ty.failures == 0 && ty.bad_accepted == 0 && ty.renders > 0;
    printf("soak: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
