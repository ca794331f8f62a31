/* bench/traversal_bench.c — the CPU traversal kernels' speed, and Intel Embree's on the same rays.
 *
 * For each scene (bench/bench_scene.h; by default the teapot+bunny Cornell box, the bunny, the
 * dragon and the living room, lit by its sky through the windows, from the shared models) it builds our BVH (binned SAH by default, --bvh) and traces the
 * three ray sets, primary, diffuse-bounce and shadow, with both queries, closest hit and any hit,
 * with our kernels: the binary traversal every device shares (rs_bvh_closest / rs_bvh_occluded,
 * what the CUDA kernels and the GPU fallback run), the 4-wide SSE traversal (accel/bvh4.h) and the
 * 8-wide AVX2 one (accel/bvh8.h; where the CPU has AVX2), on one thread, and the CPU device's
 * kernel (the widest of them) on all threads too (an OpenMP loop, dynamic chunks of 256 rays).
 * Each figure is Mrays/s, the median of --runs runs, the kernels' runs taken in turn.  Our kernels
 * must give the same answers bit for bit (same prim, same t); the run fails otherwise.
 *
 * Built with Embree 3 (libembree-dev; optional, found by CMake), the same program puts the same
 * primitives in an Embree scene (triangles, quads, spheres as RTC_GEOMETRY_TYPE_SPHERE_POINT;
 * build quality MEDIUM, the default) and traces the same rays with rtcIntersect1 / rtcOccluded1
 * in the same loops, prints our widest kernel's ratio to Embree, and checks that both find the
 * same answers: the same occlusion, and the same closest primitive or a hit at the same distance
 * (relative 1e-4: a tie between neighbours).  A disagreement on more than 0.1% of any set (and
 * more than 16 rays: --quick's 64x64 Cornell box has 8 primary rays that graze its walls' edges,
 * hit by one test and missed by the other, Embree's watertight pair of triangles against our
 * parallelogram) fails the run.
 *
 *   traversal_bench [--quick] [--scene SPEC]... [--models DIR] [--bvh NAME] [--size W]
 *                   [--secondary N] [--runs N] [--threads N] [--no-embree] [--csv FILE]
 *                   [--rays FILE] [--batch-walk packets|single]
 *   --quick: builtin:cornell, 64x64 primary and 4096 secondary rays, one run (the smoke test).
 *   --rays FILE: instead of the three sets above, a render's own rays, recorded with
 *   RS_RECORD_RAYS=FILE (cpu/cpu_paths.c) from a render of the one --scene given: its first
 *   W x W camera rays and first --secondary bounce and shadow rays, in the render's order.
 *   --batch-walk: what the "8-wide batch" column runs over each chunk of CHUNK rays: the packet
 *   walk (rs_bvh8_trace_packets, the default) or the single-ray walk (rs_bvh8_trace), the two
 *   the CPU device's waves choose between (the "8-wide" column calls rs_bvh8_closest and
 *   rs_bvh8_occluded ray by ray, whose setup a batch makes eight rays at a time). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "accel/bvh4.h"
#include "accel/bvh8.h"
#include "bench_scene.h"
#include "core/parallel.h"
#include "machine.h"
#include "streams/batch.h"

#ifdef RS_HAVE_EMBREE
#  include <embree3/rtcore.h>
#endif

#define MAX_RUNS   15
#define MAX_SCENES 8
#define CHUNK      256

enum { Q_CLOSEST = 0, Q_ANY = 1 };
enum { ENGINE_BIN = 0, ENGINE_BVH4 = 1, ENGINE_BVH8 = 2, ENGINE_PK = 3, ENGINE_EMBREE = 4, N_ENGINES = 5 };

/* Answers of one engine on one set: the closest hit's prim and t, or occlusion. */
typedef struct answers {
    uint32_t *prim;
    float *t;
    uint8_t *occluded;
} answers;

typedef struct settings {
    const char *bvh_name;
    rs_bvh_builder builder;
    uint32_t size, n_secondary;
    int runs, threads, embree;
    FILE *csv;
    const char *rays; /* --rays: a render's recorded rays instead of the three made-up sets */
    int batch_walk;   /* --batch-walk: what the batch column runs (BATCH_*) */
} settings;

/* The batch column's walk over a batch of rays (rs_bvh8_trace_packets, rs_bvh8_trace), the two
 * the CPU device's waves choose between. */
enum { BATCH_PACKETS = 0, BATCH_SINGLE, BATCH_N };
static const char *const BATCH_NAME[BATCH_N] = {"packets", "single"};

/* ---- a render's own rays (--rays FILE, recorded with RS_RECORD_RAYS: cpu/cpu_paths.c) ------ */

/* Fills sets[] from the recording at `path`: its camera rays (closest-hit queries of bounce 0,
 * at most w x w), bounce rays (closest-hit queries of later bounces) and shadow rays (any-hit
 * queries), each the first of its kind in the render's order, at most n of each.  0 with a
 * message where the file cannot be read or is not a recording. */
static int recorded_rays(const char *path, uint32_t w, uint32_t n, bs_rays sets[BS_N_SETS])
{
    FILE *f = fopen(path, "rb");
    char magic[8];
    unsigned char rec[36];
    uint32_t cap[BS_N_SETS], k;
    int ok = 0;
    memset(sets, 0, BS_N_SETS * sizeof sets[0]);
    sets[BS_PRIMARY].name = "camera (recorded)";
    sets[BS_DIFFUSE].name = "bounce (recorded)";
    sets[BS_SHADOW].name = "shadow (recorded)";
    cap[BS_PRIMARY] = w * w;
    cap[BS_DIFFUSE] = cap[BS_SHADOW] = n;
    if (!f) {
        fprintf(stderr, "traversal_bench: --rays %s: cannot open it\n", path);
        return 0;
    }
    if (fread(magic, 1, 8, f) != 8 || memcmp(magic, "RSRAYS01", 8) != 0) {
        fprintf(stderr, "traversal_bench: --rays %s: not a ray recording (RS_RECORD_RAYS)\n",
                path);
        goto out;
    }
    for (k = 0; k < BS_N_SETS; ++k)
        if (!(sets[k].rays = (rs_ray *)malloc((size_t)cap[k] * sizeof(rs_ray)))) {
            fprintf(stderr, "traversal_bench: out of memory for the rays\n");
            goto out;
        }
    while (fread(rec, sizeof rec, 1, f) == 1) {
        float v[8];
        rs_ray *r;
        k = rec[32] ? BS_SHADOW : rec[33] ? BS_DIFFUSE : BS_PRIMARY;
        if (sets[k].n == cap[k])
            continue;
        memcpy(v, rec, sizeof v);
        r = &sets[k].rays[sets[k].n++];
        r->o = rs_v3(v[0], v[1], v[2]);
        r->d = rs_v3(v[3], v[4], v[5]);
        r->tmin = v[6];
        r->tmax = v[7];
        r->time = 0.0f;
    }
    if (sets[BS_PRIMARY].n == 0 || sets[BS_DIFFUSE].n == 0 || sets[BS_SHADOW].n == 0) {
        fprintf(stderr, "traversal_bench: --rays %s: no %s rays in it\n", path,
                sets[BS_PRIMARY].n == 0 ? "camera" : sets[BS_DIFFUSE].n == 0 ? "bounce" : "shadow");
        goto out;
    }
    ok = 1;
out:
    fclose(f);
    if (!ok)
        bs_rays_free(sets, BS_N_SETS);
    return ok;
}

/* ---- our kernel ---------------------------------------------------------------------------- */

typedef struct ours_ctx {
    rs_bvh_view v;
    const rs_bvh4 *b4;
    const rs_bvh8 *b8;
    const rs_geom *g;
    const bs_rays *sets;             /* the packet walk's rays: sets[k] as a stream, batch[k] */
    rs_trace_batch batch[BS_N_SETS];
    int batch_walk;
} ours_ctx;

/* Our kernel `e` (ENGINE_BIN, _BVH4, _BVH8) over the set. */
static double trace_ours(const ours_ctx *c, int e, const bs_rays *s, int q, int threads,
                         answers *a)
{
    double t0 = rs_now_s();
    (void)threads; /* read only by the OpenMP clauses (compiled out under ThreadSanitizer) */
    long i, n = (long)s->n;
    if (q == Q_CLOSEST) {
#pragma omp parallel for schedule(dynamic, CHUNK) num_threads(threads)
        for (i = 0; i < n; ++i) {
            rs_hit h;
            if (e == ENGINE_BVH8)
                rs_bvh8_closest(c->b8, c->g, s->rays[i], &h);
            else if (e == ENGINE_BVH4)
                rs_bvh4_closest(c->b4, c->g, s->rays[i], &h);
            else
                rs_bvh_closest(&c->v, c->g, s->rays[i], &h);
            a->prim[i] = h.prim;
            a->t[i] = h.t;
        }
    } else {
#pragma omp parallel for schedule(dynamic, CHUNK) num_threads(threads)
        for (i = 0; i < n; ++i)
            a->occluded[i] = (uint8_t)(e == ENGINE_BVH8   ? rs_bvh8_occluded(c->b8, c->g, s->rays[i])
                                       : e == ENGINE_BVH4 ? rs_bvh4_occluded(c->b4, c->g, s->rays[i])
                                                          : rs_bvh_occluded(&c->v, c->g, s->rays[i]));
    }
    return rs_now_s() - t0;
}

/* ---- Embree -------------------------------------------------------------------------------- */

#ifdef RS_HAVE_EMBREE
typedef struct embree_scene {
    RTCDevice dev;
    RTCScene scene;
    uint32_t base[3]; /* global prim number of each geometry's first primitive */
} embree_scene;

static void embree_free(embree_scene *e)
{
    if (e->scene)
        rtcReleaseScene(e->scene);
    if (e->dev)
        rtcReleaseDevice(e->dev);
    memset(e, 0, sizeof *e);
}

/* One geometry of `n` primitives with `nv` vertices each; fills vertices (and for meshes an
 * index buffer 0, 1, 2, ...); attached with id `id`. */
static int embree_add(embree_scene *e, const rs_geom *g, enum RTCGeometryType type, uint32_t id,
                      uint32_t n)
{
    RTCGeometry geo;
    uint32_t i, k;
    if (n == 0)
        return 1;
    geo = rtcNewGeometry(e->dev, type);
    if (!geo)
        return 0;
    if (type == RTC_GEOMETRY_TYPE_SPHERE_POINT) {
        float *v = (float *)rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0,
                                                    RTC_FORMAT_FLOAT4, 4 * sizeof(float), n);
        if (!v)
            goto fail;
        for (i = 0; i < n; ++i) {
            v[4 * i + 0] = g->spheres[i].center.x;
            v[4 * i + 1] = g->spheres[i].center.y;
            v[4 * i + 2] = g->spheres[i].center.z;
            v[4 * i + 3] = g->spheres[i].radius;
        }
    } else {
        uint32_t nv = type == RTC_GEOMETRY_TYPE_QUAD ? 4 : 3;
        float *v = (float *)rtcSetNewGeometryBuffer(geo, RTC_BUFFER_TYPE_VERTEX, 0,
                                                    RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv * n);
        uint32_t *ix = (uint32_t *)rtcSetNewGeometryBuffer(
            geo, RTC_BUFFER_TYPE_INDEX, 0, nv == 4 ? RTC_FORMAT_UINT4 : RTC_FORMAT_UINT3,
            nv * sizeof(uint32_t), n);
        if (!v || !ix)
            goto fail;
        for (i = 0; i < n; ++i) {
            rs_vec3 p[4];
            if (nv == 4) {
                const rs_quad *q = &g->quads[i];
                p[0] = q->q;
                p[1] = rs_v3_add(q->q, q->u);
                p[2] = rs_v3_add(p[1], q->v);
                p[3] = rs_v3_add(q->q, q->v);
            } else {
                p[0] = g->tris[i].v0;
                p[1] = g->tris[i].v1;
                p[2] = g->tris[i].v2;
            }
            for (k = 0; k < nv; ++k) {
                v[3 * (nv * i + k) + 0] = p[k].x;
                v[3 * (nv * i + k) + 1] = p[k].y;
                v[3 * (nv * i + k) + 2] = p[k].z;
                ix[nv * i + k] = nv * i + k;
            }
        }
    }
    rtcCommitGeometry(geo);
    rtcAttachGeometryByID(e->scene, geo, id);
    rtcReleaseGeometry(geo);
    return 1;
fail:
    rtcReleaseGeometry(geo);
    return 0;
}

static int embree_build(embree_scene *e, const rs_geom *g)
{
    memset(e, 0, sizeof *e);
    e->dev = rtcNewDevice(NULL);
    if (!e->dev)
        return 0;
    e->scene = rtcNewScene(e->dev);
    if (!e->scene) {
        embree_free(e);
        return 0;
    }
    e->base[0] = 0;
    e->base[1] = g->n_spheres;
    e->base[2] = g->n_spheres + g->n_quads;
    if (!embree_add(e, g, RTC_GEOMETRY_TYPE_SPHERE_POINT, 0, g->n_spheres) ||
        !embree_add(e, g, RTC_GEOMETRY_TYPE_QUAD, 1, g->n_quads) ||
        !embree_add(e, g, RTC_GEOMETRY_TYPE_TRIANGLE, 2, g->n_tris)) {
        embree_free(e);
        return 0;
    }
    rtcCommitScene(e->scene);
    return rtcGetDeviceError(e->dev) == RTC_ERROR_NONE;
}

static void embree_ray(const rs_ray *r, struct RTCRay *e)
{
    e->org_x = r->o.x;
    e->org_y = r->o.y;
    e->org_z = r->o.z;
    e->dir_x = r->d.x;
    e->dir_y = r->d.y;
    e->dir_z = r->d.z;
    e->tnear = r->tmin;
    e->tfar = r->tmax;
    e->time = 0.0f;
    e->mask = 0xffffffffu;
    e->id = 0;
    e->flags = 0;
}

static double trace_embree(const embree_scene *e, const bs_rays *s, int q, int threads, answers *a)
{
    double t0 = rs_now_s();
    long i, n = (long)s->n;
    if (q == Q_CLOSEST) {
#  pragma omp parallel for schedule(dynamic, CHUNK) num_threads(threads)
        for (i = 0; i < n; ++i) {
            struct RTCIntersectContext ctx;
            struct RTCRayHit rh;
            rtcInitIntersectContext(&ctx);
            embree_ray(&s->rays[i], &rh.ray);
            rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
            rtcIntersect1(e->scene, &ctx, &rh);
            a->prim[i] = rh.hit.geomID == RTC_INVALID_GEOMETRY_ID
                             ? RS_NO_HIT
                             : e->base[rh.hit.geomID] + rh.hit.primID;
            a->t[i] = rh.ray.tfar;
        }
    } else {
#  pragma omp parallel for schedule(dynamic, CHUNK) num_threads(threads)
        for (i = 0; i < n; ++i) {
            struct RTCIntersectContext ctx;
            struct RTCRay r;
            rtcInitIntersectContext(&ctx);
            embree_ray(&s->rays[i], &r);
            rtcOccluded1(e->scene, &ctx, &r);
            a->occluded[i] = r.tfar < 0.0f;
        }
    }
    return rs_now_s() - t0;
}
#endif

/* ---- one scene ----------------------------------------------------------------------------- */

static int answers_alloc(answers *a, uint32_t n)
{
    size_t m = n ? n : 1;
    a->prim = (uint32_t *)malloc(m * sizeof *a->prim);
    a->t = (float *)malloc(m * sizeof *a->t);
    a->occluded = (uint8_t *)malloc(m);
    return a->prim && a->t && a->occluded;
}

static void answers_free(answers *a)
{
    free(a->prim);
    free(a->t);
    free(a->occluded);
}

/* How many of the n answers differ (see the top of the file). */
static uint32_t disagreements(const answers *x, const answers *y, uint32_t n, int q)
{
    uint32_t i, bad = 0;
    for (i = 0; i < n; ++i) {
        if (q == Q_ANY) {
            bad += x->occluded[i] != y->occluded[i];
        } else if ((x->prim[i] == RS_NO_HIT) != (y->prim[i] == RS_NO_HIT)) {
            ++bad;
        } else if (x->prim[i] != RS_NO_HIT && x->prim[i] != y->prim[i]) {
            bad += fabsf(x->t[i] - y->t[i]) > 1e-4f * fmaxf(1.0f, fabsf(x->t[i]));
        }
    }
    return bad;
}

typedef double (*trace_fn)(const void *ctx, const bs_rays *s, int q, int threads, answers *a);

static double run_bin(const void *ctx, const bs_rays *s, int q, int threads, answers *a)
{
    return trace_ours((const ours_ctx *)ctx, ENGINE_BIN, s, q, threads, a);
}

static double run_bvh4(const void *ctx, const bs_rays *s, int q, int threads, answers *a)
{
    return trace_ours((const ours_ctx *)ctx, ENGINE_BVH4, s, q, threads, a);
}

static double run_bvh8(const void *ctx, const bs_rays *s, int q, int threads, answers *a)
{
    return trace_ours((const ours_ctx *)ctx, ENGINE_BVH8, s, q, threads, a);
}

/* The 8-wide tree's batch walk over the set, from its stream copy, in chunks of CHUNK rays: the
 * packet walk (rs_bvh8_trace_packets: eight neighbouring rays at a time) or, with --batch-walk
 * single, rs_bvh8_trace, as the CPU device's waves run them. */
static double run_pk(const void *ctx, const bs_rays *s, int q, int threads, answers *a)
{
    const ours_ctx *c = (const ours_ctx *)ctx;
    rs_trace_batch b = c->batch[s - c->sets];
    long i, n = ((long)s->n + CHUNK - 1) / CHUNK;
    double t0 = rs_now_s(), dt;
    (void)threads;
    b.kind = q == Q_CLOSEST ? RS_TRACE_CLOSEST : RS_TRACE_OCCLUDED;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (i = 0; i < n; ++i) {
        uint32_t b0 = (uint32_t)i * CHUNK;
        uint32_t b1 = s->n - b0 < CHUNK ? s->n : b0 + CHUNK;
        if (c->batch_walk == BATCH_SINGLE)
            rs_bvh8_trace(c->b8, c->g, &b, b0, b1);
        else
            rs_bvh8_trace_packets(c->b8, c->g, &b, b0, b1);
    }
    dt = rs_now_s() - t0;
    for (i = 0; i < (long)s->n; ++i) {
        if (q == Q_CLOSEST) {
            a->prim[i] = b.hits.prim[i];
            a->t[i] = b.hits.t[i];
        } else {
            a->occluded[i] = b.occluded[i];
        }
    }
    return dt;
}

/* The sets as streams for run_pk; 0 when out of memory. */
static int pk_batches(ours_ctx *c, const bs_rays *sets)
{
    int k;
    uint32_t i;
    c->sets = sets;
    for (k = 0; k < BS_N_SETS; ++k) {
        rs_trace_batch *b = &c->batch[k];
        if (rs_ray_soa_init(&b->rays, sets[k].n ? sets[k].n : 1) != RS_OK ||
            rs_hit_soa_init(&b->hits, sets[k].n ? sets[k].n : 1) != RS_OK ||
            !(b->occluded = (uint8_t *)malloc(sets[k].n ? sets[k].n : 1)))
            return 0;
        for (i = 0; i < sets[k].n; ++i)
            rs_ray_soa_set(&b->rays, i, &sets[k].rays[i], i);
        b->count = sets[k].n;
    }
    return 1;
}

static void pk_batches_free(ours_ctx *c)
{
    int k;
    for (k = 0; k < BS_N_SETS; ++k) {
        rs_ray_soa_free(&c->batch[k].rays);
        rs_hit_soa_free(&c->batch[k].hits);
        free(c->batch[k].occluded);
    }
    memset(c->batch, 0, sizeof c->batch);
}

/* The same answers bit for bit: 0, else the index of the first difference + 1. */
static uint32_t first_difference(const answers *x, const answers *y, uint32_t n, int q)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (q == Q_ANY ? x->occluded[i] != y->occluded[i]
                       : x->prim[i] != y->prim[i] || memcmp(&x->t[i], &y->t[i], sizeof(float)))
            return i + 1;
    return 0;
}

#ifdef RS_HAVE_EMBREE
static double run_embree(const void *ctx, const bs_rays *s, int q, int threads, answers *a)
{
    return trace_embree((const embree_scene *)ctx, s, q, threads, a);
}
#endif

/* Mrays/s of each engine e with on[e] set: the median of `runs` runs, the engines' runs taken in
 * turn (run 1 of each, then run 2 of each, ...) so that drift of the machine's speed is shared.
 * Each engine's answers of its last run are left in a[e]. */
static void mrays(trace_fn const *f, const void *const *ctx, const int *on, const bs_rays *s, int q,
                  int threads, int runs, answers *a, double *out)
{
    double t[N_ENGINES][MAX_RUNS];
    int k, e;
    for (k = 0; k < runs; ++k)
        for (e = 0; e < N_ENGINES; ++e)
            if (on[e])
                t[e][k] = f[e](ctx[e], s, q, threads, &a[e]);
    for (e = 0; e < N_ENGINES; ++e)
        out[e] = on[e] ? (double)s->n / rs_bench_median(t[e], runs) / 1e6 : 0.0;
}

static int bench_scene(const bs_scene *sc, const void *ctx)
{
    const settings *st = (const settings *)ctx;
    static const char *const QNAME[2] = {"closest", "any"};
    static const char *const ENAME[4] = {"binary", "4-wide", "8-wide", "8-wide batch"};
    bs_rays sets[BS_N_SETS];
    rs_bvh_build_opts bo;
    rs_bvh *bvh = NULL;
    rs_bvh4 *bvh4 = NULL;
    rs_bvh8 *bvh8 = NULL;
    ours_ctx ours;
    answers ans[N_ENGINES];
    trace_fn fns[N_ENGINES] = {run_bin, run_bvh4, run_bvh8, run_pk, NULL};
    const void *ctxs[N_ENGINES];
    int on1[N_ENGINES] = {1, 1, 0, 0, 0}, onn[N_ENGINES] = {0, 0, 0, 0, 0};
    double m[BS_N_SETS][2][N_ENGINES][2]; /* [set][query][engine][1 thread, all threads] */
    uint32_t bad[BS_N_SETS][2], hits[BS_N_SETS][2];
    double build_s, embree_build_s = 0.0;
    int k, q, e, best, embree = 0, ok = 0;
#ifdef RS_HAVE_EMBREE
    embree_scene es;
    memset(&es, 0, sizeof es);
    fns[ENGINE_EMBREE] = run_embree;
#endif
    memset(ans, 0, sizeof ans);
    memset(&ours, 0, sizeof ours);
    memset(bad, 0, sizeof bad);
    memset(m, 0, sizeof m);
    if (st->rays ? !recorded_rays(st->rays, st->size, st->n_secondary, sets)
                 : !bs_make_rays(sc, st->size, st->n_secondary, sets))
        return 0;
    memset(&bo, 0, sizeof bo);
    bo.builder = st->builder;
    /* as the CLI builds it for the CPU device */
    bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, &sc->g);
    build_s = rs_now_s();
    if (rs_bvh_build(&sc->g, &bo, &bvh) != RS_OK) {
        fprintf(stderr, "traversal_bench: %s: %s\n", sc->label, rs_error_message());
        goto out;
    }
    build_s = rs_now_s() - build_s;
    if (rs_bvh4_build(bvh, &sc->g, &bvh4) != RS_OK || rs_bvh8_build(bvh, &sc->g, &bvh8) != RS_OK) {
        fprintf(stderr, "traversal_bench: %s: %s\n", sc->label, rs_error_message());
        goto out;
    }
    ours.v = rs_bvh_view_of(bvh);
    ours.b4 = bvh4;
    ours.b8 = bvh8;
    ours.g = &sc->g;
    ours.batch_walk = st->batch_walk;
    on1[ENGINE_BVH8] = on1[ENGINE_PK] = rs_bvh8_supported();
    if (on1[ENGINE_PK] && !pk_batches(&ours, sets)) {
        fprintf(stderr, "traversal_bench: out of memory\n");
        goto out;
    }
    best = on1[ENGINE_BVH8] ? ENGINE_BVH8 : ENGINE_BVH4; /* what the CPU device runs */
    onn[best] = 1;
    for (e = 0; e < N_ENGINES; ++e)
        ctxs[e] = &ours;
#ifdef RS_HAVE_EMBREE
    ctxs[ENGINE_EMBREE] = &es;
    if (st->embree) {
        if (sc->g.sphere_motion) {
            printf("\n(Embree left out on %s: it has moving spheres)\n", sc->label);
        } else {
            embree_build_s = rs_now_s();
            if (!embree_build(&es, &sc->g)) {
                fprintf(stderr, "traversal_bench: %s: Embree could not build the scene\n",
                        sc->label);
                goto out;
            }
            embree_build_s = rs_now_s() - embree_build_s;
            embree = 1;
            on1[ENGINE_EMBREE] = onn[ENGINE_EMBREE] = 1;
        }
    }
#endif
    {
        uint32_t most = 0;
        for (k = 0; k < BS_N_SETS; ++k)
            most = sets[k].n > most ? sets[k].n : most;
        for (e = 0; e < N_ENGINES; ++e)
            if (!answers_alloc(&ans[e], most)) {
                fprintf(stderr, "traversal_bench: out of memory\n");
                goto out;
            }
    }

    for (k = 0; k < BS_N_SETS; ++k)
        for (q = 0; q < 2; ++q) {
            double r1[N_ENGINES], rn[N_ENGINES];
            mrays(fns, ctxs, on1, &sets[k], q, 1, st->runs, ans, r1);
            mrays(fns, ctxs, onn, &sets[k], q, st->threads, st->runs, ans, rn);
            for (e = 0; e < N_ENGINES; ++e) {
                m[k][q][e][0] = r1[e];
                m[k][q][e][1] = rn[e];
            }
            {
                uint32_t i, h = 0;
                for (i = 0; i < sets[k].n; ++i)
                    h += q == Q_ANY ? ans[0].occluded[i] : ans[0].prim[i] != RS_NO_HIT;
                hits[k][q] = h;
            }
            for (e = ENGINE_BVH4; e <= ENGINE_PK; ++e) {
                uint32_t d = on1[e] ? first_difference(&ans[ENGINE_BIN], &ans[e], sets[k].n, q) : 0;
                if (d) {
                    fprintf(stderr,
                            "traversal_bench: %s: the binary and %s kernels answer %s ray %u "
                            "(%s) differently\n",
                            sc->label, ENAME[e], sets[k].name, d - 1, QNAME[q]);
                    goto out;
                }
            }
            if (embree) {
                bad[k][q] = disagreements(&ans[best], &ans[ENGINE_EMBREE], sets[k].n, q);
                if (bad[k][q] > (sets[k].n / 1000 > 16 ? sets[k].n / 1000 : 16)) {
                    fprintf(stderr,
                            "traversal_bench: %s: Embree and raystream disagree on %u of %u %s "
                            "rays (%s)\n",
                            sc->label, bad[k][q], sets[k].n, sets[k].name, QNAME[q]);
                    goto out;
                }
            }
        }

    if (st->rays)
        printf("\n### %s: %u primitives; a render's rays from %s: %u camera, %u bounce and %u "
               "shadow rays\n\n",
               sc->label, rs_geom_prim_count(&sc->g), st->rays, sets[0].n, sets[1].n, sets[2].n);
    else
        printf("\n### %s: %u primitives; %u primary rays (%ux%u), %u diffuse and %u shadow rays\n\n",
               sc->label, rs_geom_prim_count(&sc->g), sets[0].n, st->size, st->size, sets[1].n,
               sets[2].n);
    printf("BVH %s: %u nodes, SAH cost %.2f, built in %.1f ms; 4-wide: %u nodes, depth %u; 8-wide: "
           "%u nodes, depth %u (binary %u)",
           st->bvh_name, bvh->n_nodes, rs_bvh_sah_cost(bvh), 1e3 * build_s, bvh4->n_nodes,
           bvh4->depth, bvh8->n_nodes, bvh8->depth, bvh->depth);
    if (bvh8->n_tri8)
        printf(", %u triangle blocks of 8 (%.2f triangles a block)", bvh8->n_tri8,
               (double)sc->g.n_tris / bvh8->n_tri8);
    if (embree)
        printf("; Embree scene committed in %.1f ms", 1e3 * embree_build_s);
    if (!on1[ENGINE_BVH8])
        printf("; this CPU has no AVX2: the 8-wide kernel is left out");
    printf("\n\n");
    printf("| rays | query | hit %% | binary Mrays/s 1 thr | 4-wide 1 thr | 8-wide 1 thr | 8-wide "
           "batch (%s) 1 thr | %s %d thr | %s vs binary 1 thr",
           BATCH_NAME[st->batch_walk], ENAME[best], st->threads, ENAME[best]);
    if (embree)
        printf(" | Embree 1 thr | Embree %d thr | ours/Embree 1 thr | ours/Embree %d thr | "
               "answers differ",
               st->threads, st->threads);
    printf(" |\n|---|---|---:|---:|---:|---:|---:|---:|---:|%s\n",
           embree ? "---:|---:|---:|---:|---:|" : "");
    for (k = 0; k < BS_N_SETS; ++k)
        for (q = 0; q < 2; ++q) {
            double hp = sets[k].n ? 100.0 * hits[k][q] / sets[k].n : 0.0;
            printf("| %s | %s | %.1f | %.2f | %.2f | %.2f | %.2f | %.2f | %.2fx", sets[k].name,
                   QNAME[q], hp, m[k][q][ENGINE_BIN][0], m[k][q][ENGINE_BVH4][0],
                   m[k][q][ENGINE_BVH8][0], m[k][q][ENGINE_PK][0], m[k][q][best][1],
                   m[k][q][best][0] / m[k][q][ENGINE_BIN][0]);
            if (embree)
                printf(" | %.2f | %.2f | %.2fx | %.2fx | %u", m[k][q][ENGINE_EMBREE][0],
                       m[k][q][ENGINE_EMBREE][1],
                       m[k][q][best][0] / m[k][q][ENGINE_EMBREE][0],
                       m[k][q][best][1] / m[k][q][ENGINE_EMBREE][1], bad[k][q]);
            printf(" |\n");
            if (st->csv)
                fprintf(st->csv, "%s,%s,%s,%s,%u,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u\n",
                        sc->label, st->bvh_name, sets[k].name, QNAME[q], sets[k].n,
                        m[k][q][ENGINE_BIN][0], m[k][q][ENGINE_BVH4][0], m[k][q][ENGINE_BVH8][0],
                        m[k][q][ENGINE_PK][0], m[k][q][best][1],
                        m[k][q][ENGINE_EMBREE][0], m[k][q][ENGINE_EMBREE][1], bad[k][q]);
        }
    ok = 1;
out:
#ifdef RS_HAVE_EMBREE
    embree_free(&es);
#endif
    for (e = 0; e < N_ENGINES; ++e)
        answers_free(&ans[e]);
    pk_batches_free(&ours);
    rs_bvh8_destroy(bvh8);
    rs_bvh4_destroy(bvh4);
    rs_bvh_destroy(bvh);
    bs_rays_free(sets, BS_N_SETS);
    return ok;
}

/* ---- main ---------------------------------------------------------------------------------- */

int main(int argc, char **argv)
{
    settings st;
    const char *models = NULL, *csv = NULL, *scenes[MAX_SCENES];
    char paths[3][4200];
    int quick = 0, i, ok = 1, n_scenes = 0;

    memset(&st, 0, sizeof st);
    st.bvh_name = "sah";
    st.size = 512;
    st.n_secondary = 262144;
    st.runs = 5;
    st.threads = rs_default_threads();
    st.embree = 1;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc && n_scenes < MAX_SCENES) {
            scenes[n_scenes++] = argv[++i];
        } else if (strcmp(argv[i], "--models") == 0 && i + 1 < argc) {
            models = argv[++i];
        } else if (strcmp(argv[i], "--bvh") == 0 && i + 1 < argc) {
            st.bvh_name = argv[++i];
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            st.size = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--secondary") == 0 && i + 1 < argc) {
            st.n_secondary = (uint32_t)atol(argv[++i]);
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            st.runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            st.threads = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--no-embree") == 0) {
            st.embree = 0;
        } else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            csv = argv[++i];
        } else if (strcmp(argv[i], "--rays") == 0 && i + 1 < argc) {
            st.rays = argv[++i];
        } else if (strcmp(argv[i], "--batch-walk") == 0 && i + 1 < argc) {
            const char *w = argv[++i];
            for (st.batch_walk = 0; st.batch_walk < BATCH_N; ++st.batch_walk)
                if (strcmp(w, BATCH_NAME[st.batch_walk]) == 0)
                    break;
            if (st.batch_walk == BATCH_N) {
                fprintf(stderr, "traversal_bench: --batch-walk %s: packets or single\n", w);
                return 2;
            }
        } else {
            fprintf(stderr,
                    "usage: traversal_bench [--quick] [--scene soup:N|builtin:NAME|FILE]... "
                    "[--models DIR] [--bvh NAME] [--size W] [--secondary N] [--runs N] "
                    "[--threads N] [--no-embree] [--csv FILE] [--rays FILE] "
                    "[--batch-walk packets|single]\n");
            return 2;
        }
    }
    if (quick) {
        st.size = 64;
        st.n_secondary = 4096;
        st.runs = 1;
        if (n_scenes == 0)
            scenes[n_scenes++] = "builtin:cornell";
    }
    if (st.size < 1 || st.n_secondary < 1 || st.runs < 1 || st.runs > MAX_RUNS || st.threads < 1) {
        fprintf(stderr, "traversal_bench: size, secondary, threads must be >= 1, runs 1..%d\n",
                MAX_RUNS);
        return 2;
    }
    if (st.rays && n_scenes != 1) {
        fprintf(stderr, "traversal_bench: --rays goes with the one --scene it was recorded in\n");
        return 2;
    }
    if (rs_bvh_builder_parse(st.bvh_name, &st.builder) != RS_OK) {
        fprintf(stderr, "traversal_bench: --bvh: %s\n", rs_error_message());
        return 2;
    }
    if (csv) {
        st.csv = rs_bench_csv_open("traversal_bench", csv,
                                   "scene,bvh,rays,query,n,binary_mrays_1thr,bvh4_mrays_1thr,"
                                   "bvh8_mrays_1thr,bvh8_packets_mrays_1thr,"
                                   "cpu_kernel_mrays_nthr,embree_mrays_1thr,"
                                   "embree_mrays_nthr,answers_differ\n");
        if (!st.csv)
            return 1;
    }

    rs_bench_print_machine(stdout);
#ifdef RS_HAVE_EMBREE
    if (st.embree)
        printf("Embree %s: rtcIntersect1 / rtcOccluded1, build quality medium\n",
               RTC_VERSION_STRING);
    else
        printf("Embree: left out (--no-embree)\n");
#else
    printf("Embree: not built in (install libembree-dev and re-run CMake to compare)\n");
#endif
    printf("settings: our BVH %s (leaves of at most %u, SAH leaf cost in blocks of as many, "
           "where the primitives pack: what the CLI builds for this CPU); median of %d run%s; %d threads in the "
           "multi-threaded columns (OpenMP, dynamic chunks of %d rays)\n",
           st.bvh_name, rs_bvh8_supported() ? 8 : 4, st.runs, st.runs == 1 ? "" : "s", st.threads, CHUNK);

    if (n_scenes == 0) {
        const char *dir = bs_models_dir(models);
        if (dir) {
            scenes[n_scenes++] = "builtin:cornell-bunny-teapot";
            snprintf(paths[0], sizeof paths[0], "%s/bunny/bun_zipper.ply", dir);
            scenes[n_scenes++] = paths[0];
            snprintf(paths[1], sizeof paths[1], "%s/dragon/dragon_100k.ply", dir);
            scenes[n_scenes++] = paths[1];
            /* a real interior: the rays an architectural scene's paths trace (issue 40) */
            snprintf(paths[2], sizeof paths[2], "%s/living-room/living-room.raystream.json", dir);
            scenes[n_scenes++] = paths[2];
        } else {
            printf("\n(no shared models folder at %s: the Cornell box and a soup instead)\n",
                   rs_builtin_models_dir(models));
            scenes[n_scenes++] = "builtin:cornell";
            scenes[n_scenes++] = "soup:100000";
        }
    }
    ok = bs_for_each(scenes, n_scenes, models, bench_scene, &st);
    if (st.csv)
        fclose(st.csv);
    return ok ? 0 : 1;
}
