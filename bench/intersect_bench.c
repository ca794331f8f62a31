/* bench/intersect_bench.c — ray/primitive intersection tests per second for each algorithm of
 * core/intersect.h (the thesis's Tables 6.3 and 6.4 and Fig. 6.3, §6.3): ray/sphere algebraic
 * and geometric, ray/triangle Möller–Trumbore, Snyder–Barr and watertight, ray/box slab,
 * branchless, williams, kensler and swap.
 *
 * Inputs are generated before timing, in arrays of structures (AoS): per family a pool of n rays
 * and n primitives (rs_ray 36 B and rs_sphere 16 B / rs_tri 36 B; box rays {o, inv_d, tmin, tmax}
 * 32 B and rs_aabb 24 B), about 200 KB a family at the default n = 4096, so they stay in L2 and
 * the loop measures the test, not memory.  The rays come from a sphere of radius 8 and aim at
 * random points of the cube [-1, 1]^3, around which the primitives lie (centres in
 * [-0.8, 0.8]^3; sphere radii 0.3-0.8, triangle vertices 0.8-1.6 from a centre, box half-sizes
 * 0.1-0.7), which gives hit rates of 10% to 30%.  Two orders of the same tests (see loop_fn):
 * "incoherent", every test a new ray, and "ray-major", one ray against 64 primitives in turn as
 * in a traversal; branches that depend on the ray alone are unpredictable in the first and
 * predictable in the second, which decides the ranking of the box tests.
 * Each timed loop inlines one algorithm (no dispatch) and adds the t of every hit into a
 * checksum that is printed, so no work can be optimised away.  One thread.
 *
 * Validates first, in each order: every algorithm against its family's first (the default) on
 * the same 64 n tests, test by test: hit or miss the same, except at most 2 + 1 in 10^5 (rays
 * within float rounding of an edge or a silhouette); t within a relative 1e-4 of the default's,
 * except at most 1 hit in 10^3, and none beyond 1e-2 (grazing a sphere, t's float error grows
 * like the square root of the discriminant's; tests/core_isect_variants_test.c checks every
 * variant against a double reference with a band for that).  The timed runs' hit counts are
 * then checked against the default's the same way.  Then prints the machine, the settings, and
 * per order and algorithm the median of the runs, Mtests/s, the ratio to the family's first
 * algorithm measured in the same run, hits and the checksum.
 *
 *   intersect_bench [--quick] [--runs N] [--n N] [--tests N] [--csv FILE]
 *   --n: pool size (a power of two, default 4096); --tests: tests per run per algorithm and
 *   order (default 2^24, rounded up to whole passes); --runs (default 5); --csv FILE also
 *   writes the table as CSV; --quick: n = 256, 2^16 tests, 1 run (the test suite's smoke
 *   test). */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/intersect.h"
#include "machine.h"

/* ---- inputs -------------------------------------------------------------------------------- */

/* splitmix64 (Steele, Lea & Flood 2014), as tests/test_rand.h */
static uint64_t rng_next(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}
static float rng_range(uint64_t *s, double lo, double hi)
{
    return (float)(lo + (hi - lo) * ((double)(rng_next(s) >> 11) * 0x1.0p-53));
}
static rs_vec3 rng_box(uint64_t *s, float h)
{
    float x = rng_range(s, -h, h), y = rng_range(s, -h, h), z = rng_range(s, -h, h);
    return rs_v3(x, y, z);
}
static rs_vec3 rng_unit(uint64_t *s)
{
    double z = 2.0 * rng_range(s, 0.0, 1.0) - 1.0, phi = 6.283185307179586 * rng_range(s, 0, 1);
    double r = sqrt(fmax(0.0, 1.0 - z * z));
    return rs_v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
}

typedef struct box_ray {
    rs_vec3 o, inv_d;
    float tmin, tmax;
} box_ray;

typedef struct inputs {
    int n;
    rs_ray *rays;   /* shared by spheres and triangles */
    rs_wt_ray *wt;  /* the rays' watertight setup, for the "precomputed" row */
    box_ray *brays; /* the same rays with reciprocal directions */
    rs_sphere *spheres;
    rs_tri *tris;
    rs_aabb *boxes;
} inputs;

static int inputs_make(inputs *in, int n, uint64_t seed)
{
    uint64_t s = seed;
    int i;
    memset(in, 0, sizeof *in);
    in->n = n;
    in->rays = (rs_ray *)malloc((size_t)n * sizeof *in->rays);
    in->wt = (rs_wt_ray *)malloc((size_t)n * sizeof *in->wt);
    in->brays = (box_ray *)malloc((size_t)n * sizeof *in->brays);
    in->spheres = (rs_sphere *)malloc((size_t)n * sizeof *in->spheres);
    in->tris = (rs_tri *)malloc((size_t)n * sizeof *in->tris);
    in->boxes = (rs_aabb *)malloc((size_t)n * sizeof *in->boxes);
    if (!in->rays || !in->wt || !in->brays || !in->spheres || !in->tris || !in->boxes)
        return 0;
    for (i = 0; i < n; ++i) {
        rs_vec3 o = rs_v3_scale(rng_unit(&s), 8.0f), target = rng_box(&s, 1.0f), c, h;
        rs_ray *r = &in->rays[i];
        float k = rng_range(&s, 0.5, 2.0);
        r->o = o;
        r->d = rs_v3_scale(rs_v3_sub(target, o), k);
        r->tmin = 0.0f;
        r->tmax = FLT_MAX;
        r->time = 0.0f;
        in->wt[i] = rs_wt_ray_make(r);
        in->brays[i].o = r->o;
        in->brays[i].inv_d = rs_v3(1.0f / r->d.x, 1.0f / r->d.y, 1.0f / r->d.z);
        in->brays[i].tmin = r->tmin;
        in->brays[i].tmax = r->tmax;
        in->spheres[i].center = rng_box(&s, 0.8f);
        in->spheres[i].radius = rng_range(&s, 0.3, 0.8);
        c = rng_box(&s, 0.8f);
        in->tris[i].v0 = rs_v3_madd(c, rng_unit(&s), rng_range(&s, 0.8, 1.6));
        in->tris[i].v1 = rs_v3_madd(c, rng_unit(&s), rng_range(&s, 0.8, 1.6));
        in->tris[i].v2 = rs_v3_madd(c, rng_unit(&s), rng_range(&s, 0.8, 1.6));
        c = rng_box(&s, 0.8f);
        h = rs_v3(rng_range(&s, 0.1, 0.7), rng_range(&s, 0.1, 0.7), rng_range(&s, 0.1, 0.7));
        in->boxes[i].lo = rs_v3_sub(c, h);
        in->boxes[i].hi = rs_v3_add(c, h);
    }
    return 1;
}

static void inputs_free(inputs *in)
{
    free(in->rays);
    free(in->wt);
    free(in->brays);
    free(in->spheres);
    free(in->tris);
    free(in->boxes);
}

/* ---- the timed loops, one per algorithm and order ------------------------------------------ */

typedef struct loop_out {
    uint64_t hits;
    double checksum; /* sum of the hits' t */
} loop_out;

/* Runs `passes` passes; when rec_hit / rec_t are given, also records each test's answer (the
 * validation run; t is 0 for a miss).
 *   incoherent  pass p: ray i against primitive (i + p) mod n, i = 0..n-1 (n tests a pass);
 *   ray-major   pass p: ray i against primitives (i + BLOCK p + k) mod n, k = 0..BLOCK-1,
 *               one ray after the other (n BLOCK tests a pass), as a ray meets box after box in
 *               a BVH traversal or triangle after triangle in a leaf: branches on the ray (the
 *               sign of a direction component) repeat, and the compiler may hoist the per-ray
 *               part of a test out of the inner loop.
 * Both meet every (ray, primitive) pair once in n passes (incoherent) or n / BLOCK (ray-major),
 * so the default 2^24 = n^2 tests a run test each pair exactly once. */
typedef loop_out (*loop_fn)(const inputs *in, int passes, unsigned char *rec_hit, float *rec_t);

#define BLOCK 64

#define RECORD(idx, h, t)                                                                          \
  if (rec_hit) {                                                                                   \
    rec_hit[idx] = (unsigned char)(h);                                                             \
    rec_t[idx] = (h) ? (t) : 0.0f;                                                                 \
  }

/* One test of ray `i` against primitive `j` of the pool, as the statement BODY: it declares
 * `float t` and `int h`.  PRIM(j) and RAY(i) pick the arrays. */
#define DEFINE_LOOPS(name, BODY)                                                                   \
  static loop_out name##_inc(const inputs *in, int passes, unsigned char *rec_hit, float *rec_t)   \
  {                                                                                                \
    loop_out out = {0, 0.0};                                                                       \
    int p, i, mask = in->n - 1;                                                                    \
    for (p = 0; p < passes; ++p)                                                                   \
      for (i = 0; i < in->n; ++i) {                                                                \
        int j = (i + p) & mask;                                                                    \
        BODY if (h)                                                                                \
        {                                                                                          \
          ++out.hits;                                                                              \
          out.checksum += t;                                                                       \
        }                                                                                          \
        RECORD((size_t)p *(size_t)in->n + (size_t)i, h, t)                                         \
      }                                                                                            \
    return out;                                                                                    \
  }                                                                                                \
  static loop_out name##_rm(const inputs *in, int passes, unsigned char *rec_hit, float *rec_t)    \
  {                                                                                                \
    loop_out out = {0, 0.0};                                                                       \
    int p, i, k, mask = in->n - 1;                                                                 \
    for (p = 0; p < passes; ++p)                                                                   \
      for (i = 0; i < in->n; ++i) {                                                                \
        float acc = 0.0f;                                                                          \
        for (k = 0; k < BLOCK; ++k) {                                                              \
          int j = (i + p * BLOCK + k) & mask;                                                      \
          BODY if (h)                                                                              \
          {                                                                                        \
            ++out.hits;                                                                            \
            acc += t;                                                                              \
          }                                                                                        \
          RECORD(((size_t)p * (size_t)in->n + (size_t)i) * BLOCK + (size_t)k, h, t)                \
        }                                                                                          \
        out.checksum += acc;                                                                       \
      }                                                                                            \
    return out;                                                                                    \
  }

#define SPHERE_TEST(call)                                                                          \
  const rs_sphere *sp = &in->spheres[j];                                                           \
  const rs_ray *r = &in->rays[i];                                                                  \
  float t = 0.0f;                                                                                  \
  int h = call;

#define TRI_TEST(call)                                                                             \
  const rs_tri *tr = &in->tris[j];                                                                 \
  const rs_ray *r = &in->rays[i];                                                                  \
  const rs_wt_ray *w = &in->wt[i];                                                                 \
  float t = 0.0f, u, v;                                                                            \
  int h = call;                                                                                    \
  (void)r;                                                                                         \
  (void)w;

#define BOX_TEST(fn)                                                                               \
  const rs_aabb *b = &in->boxes[j];                                                                \
  const box_ray *r = &in->brays[i];                                                                \
  float t = 0.0f;                                                                                  \
  int h = fn(b, r->o, r->inv_d, r->tmin, r->tmax, &t);

DEFINE_LOOPS(loop_sphere_algebraic, SPHERE_TEST(rs_isect_sphere(sp, r, &t)))
DEFINE_LOOPS(loop_sphere_geometric, SPHERE_TEST(rs_isect_sphere_geometric(sp, r, &t)))
DEFINE_LOOPS(loop_tri_moller, TRI_TEST(rs_isect_tri(tr, r, &t, &u, &v)))
DEFINE_LOOPS(loop_tri_snyder_barr, TRI_TEST(rs_isect_tri_snyder_barr(tr, r, &t, &u, &v)))
DEFINE_LOOPS(loop_tri_watertight, TRI_TEST(rs_isect_tri_watertight(tr, r, &t, &u, &v)))
DEFINE_LOOPS(loop_tri_watertight_pre, TRI_TEST(rs_isect_tri_watertight_pre(tr, w, &t, &u, &v)))
DEFINE_LOOPS(loop_aabb_slab, BOX_TEST(rs_isect_aabb))
DEFINE_LOOPS(loop_aabb_branchless, BOX_TEST(rs_isect_aabb_branchless))
DEFINE_LOOPS(loop_aabb_williams, BOX_TEST(rs_isect_aabb_williams))
DEFINE_LOOPS(loop_aabb_kensler, BOX_TEST(rs_isect_aabb_kensler))
DEFINE_LOOPS(loop_aabb_swap, BOX_TEST(rs_isect_aabb_swap))

typedef struct algo {
    const char *family; /* the first algorithm of a family is its baseline */
    const char *name;
    loop_fn inc, rm;
} algo;

#define ALGO(family, name, fn)                                                                     \
  {                                                                                                \
    family, name, fn##_inc, fn##_rm                                                                \
  }

/* Names as rs_isect_*_algo_name prints them; "watertight-pre" is the watertight test with the
 * per-ray setup (rs_wt_ray_make) done once per ray outside the loop, as the paper intends. */
static const algo ALGOS[] = {
    ALGO("sphere", "algebraic", loop_sphere_algebraic),
    ALGO("sphere", "geometric", loop_sphere_geometric),
    ALGO("triangle", "moller", loop_tri_moller),
    ALGO("triangle", "snyder-barr", loop_tri_snyder_barr),
    ALGO("triangle", "watertight", loop_tri_watertight),
    ALGO("triangle", "watertight-pre", loop_tri_watertight_pre),
    ALGO("box", "slab", loop_aabb_slab),
    ALGO("box", "branchless", loop_aabb_branchless),
    ALGO("box", "williams", loop_aabb_williams),
    ALGO("box", "kensler", loop_aabb_kensler),
    ALGO("box", "swap", loop_aabb_swap),
};
#define N_ALGOS ((int)(sizeof ALGOS / sizeof ALGOS[0]))

/* ---- measuring ----------------------------------------------------------------------------- */

typedef struct result {
    double median_s;
    loop_out out;
} result;

static const char *const ORDER_NAMES[2] = {"incoherent", "ray-major"};

static loop_fn order_fn(const algo *a, int order) { return order ? a->rm : a->inc; }

static int family_start(int a) { return a == 0 || strcmp(ALGOS[a].family, ALGOS[a - 1].family); }

/* Checks every algorithm test by test against its family's first on `vpasses` passes of
 * `order`; prints one line each.  Returns 0 when one disagrees beyond the stated tolerance. */
static int validate(const inputs *in, int order, int vpasses, size_t vtests,
                    unsigned char *base_hit, float *base_t, unsigned char *hit, float *tv)
{
    int a, base = 0, ok = 1;
    for (a = 0; a < N_ALGOS; ++a) {
        size_t j, hits = 0, hit_diff = 0, t_diff = 0, allowed = 2 + vtests / 100000;
        double max_rel = 0.0;
        if (family_start(a)) {
            base = a;
            order_fn(&ALGOS[a], order)(in, vpasses, base_hit, base_t);
            continue;
        }
        order_fn(&ALGOS[a], order)(in, vpasses, hit, tv);
        for (j = 0; j < vtests; ++j) {
            if (hit[j] != base_hit[j]) {
                ++hit_diff;
            } else if (hit[j]) {
                double rel;
                ++hits;
                rel = fabs((double)tv[j] - base_t[j]) / fabs((double)base_t[j]);
                if (rel > max_rel)
                    max_rel = rel;
                if (!(rel <= 1e-4))
                    ++t_diff;
            }
        }
        printf("validated %s: %s %s against %s: %zu tests, %zu hit/miss differ, %zu of %zu "
               "common hits' t beyond 1e-4, max relative t difference %.2g\n",
               ORDER_NAMES[order], ALGOS[a].family, ALGOS[a].name, ALGOS[base].name, vtests,
               hit_diff, t_diff, hits, max_rel);
        if (hit_diff > allowed || t_diff > hits / 1000 || !(max_rel <= 1e-2)) {
            fprintf(stderr,
                    "intersect_bench: %s %s disagrees with %s: %zu hit/miss (at most %zu allowed), "
                    "%zu t beyond 1e-4 (at most %zu), max relative t difference %.3g (at most "
                    "1e-2)\n",
                    ALGOS[a].family, ALGOS[a].name, ALGOS[base].name, hit_diff, allowed, t_diff,
                    hits / 1000, max_rel);
            ok = 0;
        }
    }
    return ok;
}

int main(int argc, char **argv)
{
    const char *csv = NULL;
    int n = 4096, runs = 5, quick = 0, i, a, k, o;
    long long tests = 1LL << 24;
    int passes[2];
    long long ntests[2];
    size_t vsize;
    unsigned char *base_hit, *hit;
    float *base_t, *tv;
    inputs in;
    result res[2][N_ALGOS];
    FILE *csv_f = NULL;

    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--n") == 0 && i + 1 < argc) {
            n = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--tests") == 0 && i + 1 < argc) {
            tests = atoll(argv[++i]);
        } else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            csv = argv[++i];
        } else {
            fprintf(stderr, "usage: intersect_bench [--quick] [--runs N] [--n N] [--tests N] "
                            "[--csv FILE]\n");
            return 2;
        }
    }
    if (quick) {
        n = 256;
        tests = 1LL << 16;
        runs = 1;
    }
    if (n < 2 || (n & (n - 1)) != 0 || n > (1 << 20) || runs < 1 || runs > 64 || tests < 1 ||
        tests > (1LL << 40)) {
        fprintf(stderr, "intersect_bench: --n must be a power of two in [2, 2^20], --runs in "
                        "[1, 64], --tests in [1, 2^40]\n");
        return 2;
    }
    for (o = 0; o < 2; ++o) {
        long long per_pass = (long long)n * (o ? BLOCK : 1);
        passes[o] = (int)((tests + per_pass - 1) / per_pass);
        ntests[o] = (long long)passes[o] * per_pass;
    }
    /* validation: 64 incoherent passes, or 1 ray-major pass: 64 n tests either way */
    vsize = (size_t)n * 64;
    if (!inputs_make(&in, n, 1)) {
        fprintf(stderr, "intersect_bench: out of memory\n");
        return 1;
    }
    base_hit = (unsigned char *)malloc(vsize);
    hit = (unsigned char *)malloc(vsize);
    base_t = (float *)malloc(vsize * sizeof *base_t);
    tv = (float *)malloc(vsize * sizeof *tv);
    if (!base_hit || !hit || !base_t || !tv) {
        fprintf(stderr, "intersect_bench: out of memory\n");
        return 1;
    }

    for (o = 0; o < 2; ++o) {
        int vpasses = o ? 1 : (passes[0] < 64 ? passes[0] : 64), base = 0;
        size_t vtests = (size_t)vpasses * (size_t)n * (o ? BLOCK : 1);
        if (!validate(&in, o, vpasses, vtests, base_hit, base_t, hit, tv))
            return 1;
        /* time: the median of `runs` runs */
        for (a = 0; a < N_ALGOS; ++a) {
            double secs[64];
            for (k = 0; k < runs; ++k) {
                double t0 = rs_now_s();
                res[o][a].out = order_fn(&ALGOS[a], o)(&in, passes[o], NULL, NULL);
                secs[k] = rs_now_s() - t0;
            }
            res[o][a].median_s = rs_bench_median(secs, runs);
        }
        /* the timed runs' hit counts against the baseline's (same inputs) */
        for (a = 0; a < N_ALGOS; ++a) {
            long long diff;
            if (family_start(a))
                base = a;
            diff = (long long)res[o][a].out.hits - (long long)res[o][base].out.hits;
            if (llabs(diff) > 2 + ntests[o] / 100000) {
                fprintf(stderr, "intersect_bench: %s %s: %llu hits in the timed runs, %s %llu\n",
                        ALGOS[a].family, ALGOS[a].name, (unsigned long long)res[o][a].out.hits,
                        ALGOS[base].name, (unsigned long long)res[o][base].out.hits);
                return 1;
            }
        }
    }

    printf("\n");
    rs_bench_print_machine(stdout);
    printf("settings: 1 thread; per family %d rays and %d primitives, AoS (rs_ray 36 B, rs_sphere "
           "16 B, rs_tri 36 B; box rays {o, inv_d, tmin, tmax} 32 B, rs_aabb 24 B); median of %d "
           "run%s; seed 1\n",
           n, n, runs, runs == 1 ? "" : "s");
    printf("  incoherent: a run = %lld tests, ray i against primitive (i + p) mod %d in pass p\n",
           ntests[0], n);
    printf("  ray-major:  a run = %lld tests, each ray against %d consecutive primitives in turn "
           "(as in a traversal): ray i against (i + %d p + k) mod %d in pass p\n",
           ntests[1], BLOCK, BLOCK, n);
    if (csv) {
        csv_f = fopen(csv, "w");
        if (!csv_f) {
            fprintf(stderr, "intersect_bench: cannot write %s\n", csv);
            return 1;
        }
        fprintf(csv_f, "order,family,algorithm,tests,median_s,mtests_per_s,ratio,hits,checksum\n");
    }
    for (o = 0; o < 2; ++o) {
        int base = 0;
        printf("\n%s\n\n", ORDER_NAMES[o]);
        printf("| family | algorithm | median ms | Mtests/s | ns/test | vs baseline | hits | hit "
               "rate | checksum |\n");
        printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
        for (a = 0; a < N_ALGOS; ++a) {
            double nt = (double)ntests[o], mts = nt / res[o][a].median_s / 1e6, ratio;
            if (family_start(a))
                base = a;
            ratio = res[o][base].median_s / res[o][a].median_s;
            printf("| %s | %s | %.1f | %.1f | %.2f | %.2fx | %llu | %.1f%% | %.7g |\n",
                   ALGOS[a].family, ALGOS[a].name, 1e3 * res[o][a].median_s, mts,
                   1e9 * res[o][a].median_s / nt, ratio, (unsigned long long)res[o][a].out.hits,
                   100.0 * (double)res[o][a].out.hits / nt, res[o][a].out.checksum);
            if (csv_f)
                fprintf(csv_f, "%s,%s,%s,%lld,%.6f,%.3f,%.4f,%llu,%.9g\n", ORDER_NAMES[o],
                        ALGOS[a].family, ALGOS[a].name, ntests[o], res[o][a].median_s, mts, ratio,
                        (unsigned long long)res[o][a].out.hits, res[o][a].out.checksum);
        }
    }
    printf("\nvs baseline: the family's first row's median time / this row's (> 1: faster); "
           "checksum: the sum of the hits' t\n");
    if (csv_f)
        fclose(csv_f);
    free(base_hit);
    free(hit);
    free(base_t);
    free(tv);
    inputs_free(&in);
    return 0;
}
