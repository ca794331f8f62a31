/* bench/bvh_bench.c — the BVH builders compared (the thesis's §6.4 and Table 6.5, plus binned SAH
 * and LBVH): build time, tree quality (SAH cost, nodes, depth) and closest-hit traversal speed.
 *
 * Scenes (bench/bench_scene.h; --scene SPEC, repeatable): by default a soup of 100000 random
 * triangles and, when the shared models exist, the teapot+bunny Cornell box of the thesis
 * (builtin:cornell-bunny-teapot) and the largest model, the dragon (dragon/dragon_100k.ply, read
 * by the real mesh importer).  Two ray sets per scene, the same for every builder: primary
 * (camera rays, scanline order) and diffuse (cosine bounce rays from the primary hits).
 *
 * Validates first: the median builder's closest hits equal brute force on a subset of each ray
 * set, and then every builder's hits equal the median builder's (same t, bit for bit, and the
 * same triangle or an exact tie) on every 8th ray.  Then prints the machine, the settings and per
 * scene one table: build time (median of the runs, with 1 thread and with all threads), SAH cost
 * (C_trav = C_isect = 1, rs_bvh_sah_cost), nodes, depth, and Mrays/s of closest-hit queries (the
 * median of the runs, 1 thread and all threads; all threads use an OpenMP loop with dynamic
 * chunks of 256 rays), with the ratios to the median builder measured in the same run.
 *
 *   bvh_bench [--quick] [--scene SPEC]... [--models DIR] [--size W] [--diffuse N] [--runs N]
 *             [--max-leaf N] [--bvh NAME,NAME,...] [--csv FILE]
 *   --quick: a 3000-triangle soup, 64x64 primary rays, one run (the test suite's smoke test). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "core/parallel.h"
#include "machine.h"
#include "bvh_count.h"
#include "bench_scene.h"

#define MAX_VARIANTS 64
#define MAX_RUNS     15

typedef struct ray_set {
    const char *name;
    rs_ray *rays;
    rs_hit *hits; /* scratch answers */
    uint32_t n;
} ray_set;

typedef struct row {
    rs_bvh_builder b;
    double build1, buildn, sah;
    uint32_t nodes, depth, leaves, fallback;
    double mrays[2][2];                 /* [primary, diffuse][1 thread, all threads] */
    double box_tests[2], prim_tests[2]; /* per ray, primary / diffuse (counting pass) */
} row;

/* ---- measuring ----------------------------------------------------------------------------- */

static rs_bvh *build_timed(const rs_geom *g, const rs_bvh_builder *b, uint32_t max_leaf,
                           int threads, int runs, double *median_s)
{
    double t[MAX_RUNS];
    rs_bvh *bvh = NULL;
    int k;
    for (k = 0; k < runs; ++k) {
        rs_bvh_build_opts o;
        double t0;
        memset(&o, 0, sizeof o);
        o.max_leaf = max_leaf;
        o.builder = *b;
        o.threads = (uint32_t)threads;
        rs_bvh_destroy(bvh);
        bvh = NULL;
        t0 = rs_now_s();
        if (rs_bvh_build(g, &o, &bvh) != RS_OK) {
            fprintf(stderr, "bvh_bench: %s\n", rs_error_message());
            return NULL;
        }
        t[k] = rs_now_s() - t0;
    }
    *median_s = rs_bench_median(t, runs);
    return bvh;
}

/* Closest hits of every ray into s->hits; returns the seconds taken. */
static double trace(const rs_bvh *bvh, const rs_geom *g, ray_set *s, int threads)
{
    rs_bvh_view v = rs_bvh_view_of(bvh);
    double t0 = rs_now_s();
    long i, n = (long)s->n;
    if (threads == 1) {
        for (i = 0; i < n; ++i)
            rs_bvh_closest(&v, g, s->rays[i], &s->hits[i]);
    } else {
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
        for (i = 0; i < n; ++i)
            rs_bvh_closest(&v, g, s->rays[i], &s->hits[i]);
    }
    return rs_now_s() - t0;
}

static double mrays(const rs_bvh *bvh, const rs_geom *g, ray_set *s, int threads, int runs)
{
    double t[MAX_RUNS];
    int k;
    for (k = 0; k < runs; ++k)
        t[k] = trace(bvh, g, s, threads);
    return (double)s->n / rs_bench_median(t, runs) / 1e6;
}

/* Same answer: the same t bit for bit, and the same prim or an exact tie. */
static int same_hit(const rs_geom *g, const rs_ray *r, const rs_hit *a, const rs_hit *b)
{
    float t, u, v;
    if (a->prim == RS_NO_HIT || b->prim == RS_NO_HIT)
        return a->prim == b->prim;
    if (a->t != b->t)
        return 0;
    return a->prim == b->prim || (rs_geom_intersect(g, a->prim, r, &t, &u, &v) && t == b->t);
}

/* ---- one scene ----------------------------------------------------------------------------- */

typedef struct settings {
    const rs_bvh_builder *variants;
    int n_variants, runs, threads;
    uint32_t max_leaf, size, n_diffuse, brute_rays;
    int progress; /* a line on stderr per builder */
    FILE *csv;
} settings;

static int bench_scene(const bs_scene *sc, const void *ctx)
{
    const settings *st = (const settings *)ctx;
    const char *scene = sc->label;
    rs_geom g = sc->g;
    uint32_t nt = rs_geom_prim_count(&g);
    bs_rays made[BS_N_SETS];
    ray_set sets[2];
    rs_hit *ref[2] = {NULL, NULL};
    row rows[MAX_VARIANTS];
    rs_bvh *median_bvh = NULL;
    int v, k, ok = 0, median_row = -1;
    uint32_t i;
    long hits[2] = {0, 0};
    char name[64];
    memset(sets, 0, sizeof sets);
    if (!bs_make_rays(sc, st->size, st->n_diffuse, made))
        return 0;
    free(made[BS_SHADOW].rays);
    for (k = 0; k < 2; ++k) {
        sets[k].name = made[k].name;
        sets[k].rays = made[k].rays;
        sets[k].n = made[k].n;
        sets[k].hits = (rs_hit *)malloc((size_t)(made[k].n ? made[k].n : 1) * sizeof(rs_hit));
        if (!sets[k].hits) {
            fprintf(stderr, "bvh_bench: out of memory for rays\n");
            goto out;
        }
    }
    /* the reference: the median builder, checked against brute force on a subset */
    {
        rs_bvh_builder med;
        double dummy;
        memset(&med, 0, sizeof med);
        median_bvh = build_timed(&g, &med, st->max_leaf, 1, 1, &dummy);
        if (!median_bvh)
            goto out;
    }
    for (k = 0; k < 2; ++k) {
        uint32_t step = sets[k].n / st->brute_rays ? sets[k].n / st->brute_rays : 1;
        ref[k] = (rs_hit *)malloc((size_t)sets[k].n * sizeof *ref[k]);
        if (!ref[k])
            goto out;
        trace(median_bvh, &g, &sets[k], st->threads);
        memcpy(ref[k], sets[k].hits, (size_t)sets[k].n * sizeof *ref[k]);
        for (i = 0; i < sets[k].n; ++i)
            hits[k] += ref[k][i].prim != RS_NO_HIT;
        for (i = 0; i < sets[k].n; i += step) {
            rs_hit h;
            brute_closest(&g, &sets[k].rays[i], &h);
            if (!same_hit(&g, &sets[k].rays[i], &h, &ref[k][i])) {
                fprintf(stderr,
                        "bvh_bench: %s: median BVH disagrees with brute force on %s ray %u\n",
                        scene, sets[k].name, i);
                goto out;
            }
        }
    }

    for (v = 0; v < st->n_variants; ++v) {
        row *r = &rows[v];
        rs_bvh *bvh, *b1;
        r->b = st->variants[v];
        rs_bvh_builder_name(&r->b, name, sizeof name);
        if (r->b.method == RS_BVH_MEDIAN)
            median_row = v;
        b1 = build_timed(&g, &r->b, st->max_leaf, 1, st->runs, &r->build1);
        bvh = build_timed(&g, &r->b, st->max_leaf, st->threads, st->runs, &r->buildn);
        if (!b1 || !bvh)
            goto out;
        if (b1->n_nodes != bvh->n_nodes ||
            memcmp(b1->nodes, bvh->nodes, (size_t)b1->n_nodes * sizeof *b1->nodes) != 0) {
            fprintf(stderr, "bvh_bench: %s: %s builds another tree with %d threads\n", scene, name,
                    st->threads);
            goto out;
        }
        rs_bvh_destroy(b1);
        r->sah = rs_bvh_sah_cost(bvh);
        r->nodes = bvh->n_nodes;
        r->depth = bvh->depth;
        r->leaves = bvh->n_leaves;
        r->fallback = bvh->n_fallback;
        /* validate against the median builder before timing */
        for (k = 0; k < 2; ++k) {
            trace(bvh, &g, &sets[k], st->threads);
            for (i = 0; i < sets[k].n; i += 8)
                if (!same_hit(&g, &sets[k].rays[i], &sets[k].hits[i], &ref[k][i])) {
                    fprintf(stderr,
                            "bvh_bench: %s: %s disagrees with the median BVH on %s ray %u\n", scene,
                            name, sets[k].name, i);
                    rs_bvh_destroy(bvh);
                    goto out;
                }
            rs_bench_count_closest(bvh, &g, sets[k].rays, sets[k].n, &r->box_tests[k],
                                   &r->prim_tests[k]);
            r->mrays[k][0] = mrays(bvh, &g, &sets[k], 1, st->runs);
            r->mrays[k][1] = mrays(bvh, &g, &sets[k], st->threads, st->runs);
        }
        rs_bvh_destroy(bvh);
        if (st->progress)
            fprintf(stderr, "  %s: %s done\n", scene, name);
    }

    printf("\n### %s: %u primitives; %u primary rays (%ux%u), %u diffuse rays; %.1f%% / %.1f%% "
           "hit\n\n",
           scene, nt, sets[0].n, st->size, st->size, sets[1].n, 100.0 * hits[0] / sets[0].n,
           sets[1].n ? 100.0 * hits[1] / sets[1].n : 0.0);
    printf("| builder | build ms 1 thr | build ms %d thr | build vs median | SAH cost | SAH vs "
           "median | nodes | depth | primary Mrays/s 1 thr | primary %d thr | diffuse 1 thr | "
           "diffuse %d thr | primary vs median | diffuse vs median | box+prim tests/ray primary | "
           "diffuse |\n",
           st->threads, st->threads, st->threads);
    printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (v = 0; v < st->n_variants; ++v) {
        const row *r = &rows[v], *m = median_row >= 0 ? &rows[median_row] : &rows[0];
        rs_bvh_builder_name(&r->b, name, sizeof name);
        printf("| %s | %.2f | %.2f | %.2fx | %.2f | %.3f | %u | %u | %.2f | %.2f | %.2f | %.2f | "
               "%.2fx | %.2fx | %.1f + %.1f | %.1f + %.1f |\n",
               name, 1e3 * r->build1, 1e3 * r->buildn, r->build1 / m->build1, r->sah,
               r->sah / m->sah, r->nodes, r->depth, r->mrays[0][0], r->mrays[0][1], r->mrays[1][0],
               r->mrays[1][1], r->mrays[0][1] / m->mrays[0][1], r->mrays[1][1] / m->mrays[1][1],
               r->box_tests[0], r->prim_tests[0], r->box_tests[1], r->prim_tests[1]);
        if (st->csv)
            fprintf(st->csv, "%s,%u,%s,%u,%.6f,%.6f,%.4f,%u,%u,%u,%u,%.4f,%.4f,%.4f,%.4f\n", scene,
                    nt, name, st->max_leaf, r->build1, r->buildn, r->sah, r->nodes, r->depth,
                    r->leaves, r->fallback, r->mrays[0][0], r->mrays[0][1], r->mrays[1][0],
                    r->mrays[1][1]);
    }
    ok = 1;
out:
    rs_bvh_destroy(median_bvh);
    free(ref[0]);
    free(ref[1]);
    for (k = 0; k < 2; ++k) {
        free(sets[k].rays);
        free(sets[k].hits);
    }
    return ok;
}

/* ---- main ---------------------------------------------------------------------------------- */

static int parse_list(const char *list, rs_bvh_builder *out, int cap)
{
    char buf[1024], *tok;
    int n = 0;
    snprintf(buf, sizeof buf, "%s", list);
    for (tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (n == cap || rs_bvh_builder_parse(tok, &out[n]) != RS_OK) {
            fprintf(stderr, "bvh_bench: %s\n", rs_error_message());
            return -1;
        }
        ++n;
    }
    return n;
}

#define MAX_SCENES 8

int main(int argc, char **argv)
{
    rs_bvh_builder variants[MAX_VARIANTS];
    settings st;
    const char *csv = NULL, *list = NULL, *models = NULL, *scenes[MAX_SCENES];
    char dragon[4200];
    int quick = 0, i, ok = 1, have_median = 0, n_scenes = 0;

    memset(&st, 0, sizeof st);
    st.runs = 3;
    st.threads = rs_default_threads();
    st.max_leaf = 4;
    st.size = 512;
    st.n_diffuse = 262144;
    st.brute_rays = 256;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            quick = 1;
        } else if (strcmp(argv[i], "--scene") == 0 && i + 1 < argc && n_scenes < MAX_SCENES) {
            scenes[n_scenes++] = argv[++i];
        } else if (strcmp(argv[i], "--models") == 0 && i + 1 < argc) {
            models = argv[++i];
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            st.size = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--diffuse") == 0 && i + 1 < argc) {
            st.n_diffuse = (uint32_t)atol(argv[++i]);
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            st.runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--max-leaf") == 0 && i + 1 < argc) {
            st.max_leaf = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--bvh") == 0 && i + 1 < argc) {
            list = argv[++i];
        } else if (strcmp(argv[i], "--csv") == 0 && i + 1 < argc) {
            csv = argv[++i];
        } else {
            fprintf(stderr, "usage: bvh_bench [--quick] [--scene soup:N|builtin:NAME|FILE]... "
                            "[--models DIR] [--size W] [--diffuse N] [--runs N] [--max-leaf N] "
                            "[--bvh NAME,...] [--csv FILE]\n");
            return 2;
        }
    }
    st.progress = !quick;
    if (quick) {
        st.size = 64;
        st.n_diffuse = 4096;
        st.runs = 1;
        st.brute_rays = 64;
        if (n_scenes == 0)
            scenes[n_scenes++] = "soup:3000";
    }
    if (st.size < 1 || st.n_diffuse < 1 || st.runs < 1 || st.runs > MAX_RUNS || st.max_leaf < 1) {
        fprintf(stderr, "bvh_bench: size, diffuse, max-leaf must be >= 1, runs 1..%d\n", MAX_RUNS);
        return 2;
    }
    /* the builders: the given list, or every standard variant plus SAH with 8 and 32 bins; the
     * median builder is always measured (it is the baseline of the ratios) */
    if (list) {
        st.n_variants = parse_list(list, variants, MAX_VARIANTS - 1);
        if (st.n_variants < 0)
            return 2;
    } else {
        st.n_variants = (int)rs_bvh_builder_variants(variants, MAX_VARIANTS);
        rs_bvh_builder_parse("sah:8", &variants[st.n_variants++]);
        rs_bvh_builder_parse("sah:32", &variants[st.n_variants++]);
    }
    for (i = 0; i < st.n_variants; ++i)
        have_median |= variants[i].method == RS_BVH_MEDIAN;
    if (!have_median) {
        memmove(&variants[1], &variants[0], (size_t)st.n_variants * sizeof variants[0]);
        memset(&variants[0], 0, sizeof variants[0]);
        st.n_variants++;
    }
    st.variants = variants;
    if (csv) {
        st.csv = rs_bench_csv_open("bvh_bench", csv,
                                   "scene,primitives,builder,max_leaf,build_s_1thr,build_s_nthr,"
                                   "sah_cost,nodes,depth,leaves,fallback,primary_mrays_1thr,"
                                   "primary_mrays_nthr,diffuse_mrays_1thr,diffuse_mrays_nthr\n");
        if (!st.csv)
            return 1;
    }

    rs_bench_print_machine(stdout);
    printf("settings: max_leaf %u; %d builders; median of %d run%s; %d threads for the "
           "\"all threads\" columns; SAH cost with C_trav = C_isect = 1 normalised by the root's "
           "area\n",
           st.max_leaf, st.n_variants, st.runs, st.runs == 1 ? "" : "s", st.threads);

    if (n_scenes == 0) {
        const char *dir = bs_models_dir(models);
        scenes[n_scenes++] = "soup:100000";
        if (dir) {
            scenes[n_scenes++] = "builtin:cornell-bunny-teapot";
            snprintf(dragon, sizeof dragon, "%s/dragon/dragon_100k.ply", dir);
            scenes[n_scenes++] = dragon;
        } else {
            printf("\n(the model scenes are skipped: no shared models folder at %s)\n",
                   rs_builtin_models_dir(models));
        }
    }
    ok = bs_for_each(scenes, n_scenes, models, bench_scene, &st);
    if (st.csv)
        fclose(st.csv);
    return ok ? 0 : 1;
}
