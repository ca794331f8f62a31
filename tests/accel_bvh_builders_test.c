/* tests/accel_bvh_builders_test.c — every BVH builder of accel/bvh.h: median, the thesis's 27
 * axis/partition/comparator combinations, binned SAH (2, 8, 16 and 32 bins) and LBVH.
 *
 * What is checked, for every variant:
 *   - structure: node 0 is the root, children adjacent and after their parent, every node
 *     reached once, each prim exactly once in prim_ids, leaves hold 1 .. max_leaf prims, each
 *     node's box is exactly the union of its children's (a leaf's: of its prims' boxes), the
 *     recorded depth, leaf count and fullest leaf are right, depth < RS_BVH_STACK (64), and the
 *     halving builders (median, grid) stay within ceil(log2(n)) + 1;
 *   - traversal equals brute force: closest hit (prim, t bit for bit, u, v) and occlusion for
 *     10^5 random rays over a fixed-seed soup of 300 spheres (half of them moving, rays at
 *     random times), 200 quads and 2000 triangles with max_leaf 4, and the first 10^4 of them
 *     with max_leaf 1 and 8;
 *   - the SAH cost (rs_bvh_sah_cost, C_trav = C_isect = 1) of the binned-SAH trees is below the
 *     median builder's on the soup and on a clustered distribution (and on the bunny);
 *   - determinism: 1, 2 and 4 OpenMP threads build the same tree, bit for bit, over 150000
 *     triangles (large enough for the tasks and the chunked passes);
 *   - edge cases: 0, 1, 2, 3 and 5 prims; 1000 prims with identical centroids; an input on
 *     which SAH would nest deeper than the traversal stack (the depth guard must act);
 *     allocation failure at every allocation of the build (RS_ERR_NOMEM, *out NULL, a message;
 *     leaks are caught by the sanitizer build);
 *   - names: every variant's name parses back to it; bad names are RS_ERR_ARG; a zeroed, NULL,
 *     "median" and "largest-nth-centroid" build all give the same tree.
 * If the shared models exist (../shared/models, or $RS_MODELS_DIR) every variant is also built
 * over the Stanford bunny's 69451 triangles and checked on 2000 rays against brute force;
 * otherwise that test prints why and passes. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "accel/bvh4.h"
#include "accel/morton.h"
#include "core/alloc.h"

#include "test_mesh.h"
#include "test_rand.h"

#define T_INF FLT_MAX
#define SOUP  40.0f

/* ---- variants ------------------------------------------------------------------------------ */

#define N_EXTRA_SAH 3
#define N_VARIANTS  (RS_BVH_N_VARIANTS + N_EXTRA_SAH)

static rs_bvh_builder g_variants[N_VARIANTS];

static int variants_init(void)
{
    static const uint32_t extra_bins[N_EXTRA_SAH] = {2, 8, 32};
    uint32_t i, n = rs_bvh_builder_variants(g_variants, RS_BVH_N_VARIANTS);
    if (n != RS_BVH_N_VARIANTS)
        return -1;
    for (i = 0; i < N_EXTRA_SAH; ++i) {
        memset(&g_variants[n + i], 0, sizeof g_variants[0]);
        g_variants[n + i].method = RS_BVH_SAH;
        g_variants[n + i].bins = extra_bins[i];
    }
    return 0;
}

static const char *vname(const rs_bvh_builder *b)
{
    static char buf[64];
    return rs_bvh_builder_name(b, buf, sizeof buf);
}

/* ---- scenes -------------------------------------------------------------------------------- */

typedef struct soup {
    rs_sphere *spheres;
    rs_vec3 *motion;
    rs_quad *quads;
    rs_tri *tris;
    rs_geom g;
} soup;

static void soup_alloc(soup *s, uint32_t ns, uint32_t nq, uint32_t nt)
{
    s->spheres = (rs_sphere *)calloc(ns ? ns : 1, sizeof *s->spheres);
    s->motion = (rs_vec3 *)calloc(ns ? ns : 1, sizeof *s->motion);
    s->quads = (rs_quad *)calloc(nq ? nq : 1, sizeof *s->quads);
    s->tris = (rs_tri *)calloc(nt ? nt : 1, sizeof *s->tris);
    assert_true(s->spheres && s->motion && s->quads && s->tris);
    memset(&s->g, 0, sizeof s->g);
    s->g.spheres = s->spheres;
    s->g.quads = s->quads;
    s->g.tris = s->tris;
    s->g.n_spheres = ns;
    s->g.n_quads = nq;
    s->g.n_tris = nt;
}

static void soup_free(soup *s)
{
    free(s->spheres);
    free(s->motion);
    free(s->quads);
    free(s->tris);
}

static rs_tri random_tri(uint64_t *seed, rs_vec3 c, double lo, double hi)
{
    rs_tri t;
    t.v0 = rs_v3_madd(c, rnd_unit(seed), rnd_range(seed, lo, hi));
    t.v1 = rs_v3_madd(c, rnd_unit(seed), rnd_range(seed, lo, hi));
    t.v2 = rs_v3_madd(c, rnd_unit(seed), rnd_range(seed, lo, hi));
    return t;
}

/* The mixed soup: spheres of radius 0.2 .. 3, every other one moving up to 3 units during the
 * shutter [0, 1]; quads with edges 0.5 .. 6, every fourth axis-aligned; triangles up to 4 from
 * their centre, every eighth in an axis plane. */
static void soup_random(soup *s, uint64_t seed)
{
    uint32_t i;
    soup_alloc(s, 300, 200, 2000);
    s->g.sphere_motion = s->motion;
    s->g.time0 = 0.0f;
    s->g.time1 = 1.0f;
    for (i = 0; i < s->g.n_spheres; ++i) {
        s->spheres[i].center = rnd_box(&seed, SOUP);
        s->spheres[i].radius = rnd_range(&seed, 0.2, 3.0);
        if (i % 2)
            s->motion[i] = rnd_box(&seed, 1.5f);
    }
    for (i = 0; i < s->g.n_quads; ++i) {
        rs_vec3 q = rnd_box(&seed, SOUP), u, v;
        if (i % 4 == 0) {
            int axis = (int)(i / 4 % 3);
            float a = rnd_range(&seed, 0.5, 6.0), b = rnd_range(&seed, 0.5, 6.0);
            u = axis == 0 ? rs_v3(0, a, 0) : rs_v3(a, 0, 0);
            v = axis == 2 ? rs_v3(0, b, 0) : rs_v3(0, 0, b);
        } else {
            u = rs_v3_scale(rnd_unit(&seed), rnd_range(&seed, 0.5, 6.0));
            v = rs_v3_scale(rnd_unit(&seed), rnd_range(&seed, 0.5, 6.0));
        }
        s->quads[i] = rs_quad_make(q, u, v);
    }
    for (i = 0; i < s->g.n_tris; ++i) {
        s->tris[i] = random_tri(&seed, rnd_box(&seed, SOUP), 0.3, 4.0);
        if (i % 8 == 0) {
            s->tris[i].v1.y = s->tris[i].v0.y;
            s->tris[i].v2.y = s->tris[i].v0.y;
        }
    }
}

/* A clustered distribution: 3000 small triangles in 12 tight clusters of different sizes, 40
 * large ones spread over the whole box, and 40 spheres. */
static void soup_clustered(soup *s, uint64_t seed)
{
    rs_vec3 centre[12];
    float size[12];
    uint32_t i;
    soup_alloc(s, 40, 0, 3040);
    for (i = 0; i < 12; ++i) {
        centre[i] = rnd_box(&seed, 100.0f);
        size[i] = rnd_range(&seed, 0.5, 6.0);
    }
    for (i = 0; i < 3000; ++i) {
        uint32_t k = i % 12;
        rs_vec3 c = rs_v3_add(centre[k], rnd_box(&seed, size[k]));
        s->tris[i] = random_tri(&seed, c, 0.05, 0.4);
    }
    for (; i < 3040; ++i)
        s->tris[i] = random_tri(&seed, rnd_box(&seed, 100.0f), 5.0, 30.0);
    for (i = 0; i < 40; ++i) {
        s->spheres[i].center = rnd_box(&seed, 100.0f);
        s->spheres[i].radius = rnd_range(&seed, 0.5, 4.0);
    }
}

/* A triangle-only soup of n triangles (the determinism test). */
static void soup_tris(soup *s, uint32_t n, uint64_t seed)
{
    uint32_t i;
    soup_alloc(s, 0, 0, n);
    for (i = 0; i < n; ++i)
        s->tris[i] = random_tri(&seed, rnd_box(&seed, 100.0f), 0.1, 1.5);
}

/* ---- rays and brute force ------------------------------------------------------------------ */

/* A random ray around a scene of half-size `h`: the origin inside the box or in one three times
 * as wide; the direction random or aimed at a point of the box, one in eight with zero
 * components; tmin > 0 for one in eight, tmax cut short for one in four; a random time. */
static rs_ray random_ray(uint64_t *s, long i, rs_vec3 centre, float h)
{
    rs_vec3 o = rs_v3_add(centre, (i & 1) ? rnd_box(s, 1.1f * h) : rnd_box(s, 3.0f * h)), d;
    float tmin = 0.0f, tmax = T_INF;
    rs_ray r;
    if (i % 3 == 0)
        d = rs_v3_sub(rs_v3_add(centre, rnd_box(s, h)), o);
    else
        d = rs_v3_scale(rnd_unit(s), rnd_range(s, 0.5, 2.0));
    if (i % 8 == 5) {
        d.x = 0.0f;
        if (i % 16 == 5)
            d.z = -0.0f;
        if (rs_v3_is_zero(d))
            d.y = 1.0f;
    }
    if (i % 8 == 2)
        tmin = rnd_range(s, 0.0, 0.5 * h);
    if (i % 4 == 3)
        tmax = rnd_range(s, 0.0, h);
    r = mk_ray(o, d, tmin, tmax);
    r.time = (float)rnd01(s);
    return r;
}

/* Rays and their brute-force answers, computed once and shared by every variant. */
typedef struct ray_set {
    rs_ray *rays;
    rs_hit *ref;
    int *ref_hit;
    long n;
} ray_set;

static void ray_set_make(ray_set *rs, const rs_geom *g, long n, uint64_t seed, rs_vec3 c, float h)
{
    long i;
    rs->n = n;
    rs->rays = (rs_ray *)malloc((size_t)n * sizeof *rs->rays);
    rs->ref = (rs_hit *)malloc((size_t)n * sizeof *rs->ref);
    rs->ref_hit = (int *)malloc((size_t)n * sizeof *rs->ref_hit);
    assert_true(rs->rays && rs->ref && rs->ref_hit);
    for (i = 0; i < n; ++i)
        rs->rays[i] = random_ray(&seed, i, c, h);
#pragma omp parallel for schedule(dynamic, 64)
    for (i = 0; i < n; ++i)
        rs->ref_hit[i] = brute_closest(g, &rs->rays[i], &rs->ref[i]);
}

static void ray_set_free(ray_set *rs)
{
    free(rs->rays);
    free(rs->ref);
    free(rs->ref_hit);
}

/* Checks the first n rays of `rs` against the tree and its 4-wide collapse (the CPU device's
 * kernel); returns the hit count.  The answer must be brute force's bit for bit: the same
 * routines compute t, u, v, and every kernel breaks ties by the lowest prim (rs_hit_better). */
static long check_rays(const rs_bvh *bvh, const rs_geom *g, const ray_set *rs, long n,
                       const char *what)
{
    rs_bvh_view view = rs_bvh_view_of(bvh);
    rs_bvh4 *b4 = NULL;
    long i, hits = 0;
    if (rs_bvh4_build(bvh, g, &b4) != RS_OK)
        fail_msg("%s: rs_bvh4_build: %s", what, rs_error_message());
    if (n > rs->n)
        n = rs->n;
    for (i = 0; i < n; ++i) {
        const rs_ray *r = &rs->rays[i];
        const rs_hit *ref = &rs->ref[i];
        int want = rs->ref_hit[i], k;
        hits += want;
        for (k = 0; k < 2; ++k) {
            rs_hit h;
            int got = k ? rs_bvh4_closest(b4, g, *r, &h) : rs_bvh_closest(&view, g, *r, &h);
            int occ = k ? rs_bvh4_occluded(b4, g, *r) : rs_bvh_occluded(&view, g, *r);
            if (got != want || h.prim != ref->prim ||
                (got && (h.t != ref->t || h.u != ref->u || h.v != ref->v)))
                fail_msg("%s ray %ld (%s kernel): bvh %s prim %u t %.9g, brute force %s prim %u "
                         "t %.9g (o %g %g %g d %g %g %g t %g..%g time %g)",
                         what, i, k ? "4-wide" : "binary", got ? "hit" : "miss", h.prim, h.t,
                         want ? "hit" : "miss", ref->prim, ref->t, r->o.x, r->o.y, r->o.z, r->d.x,
                         r->d.y, r->d.z, r->tmin, r->tmax, r->time);
            if (occ != want)
                fail_msg("%s ray %ld (%s kernel): occluded %d, brute force %d", what, i,
                         k ? "4-wide" : "binary", occ, want);
        }
    }
    rs_bvh4_destroy(b4);
    return hits;
}

/* ---- structure ----------------------------------------------------------------------------- */

static int box_equal(rs_vec3 alo, rs_vec3 ahi, rs_vec3 blo, rs_vec3 bhi)
{
    return alo.x == blo.x && alo.y == blo.y && alo.z == blo.z && ahi.x == bhi.x && ahi.y == bhi.y &&
           ahi.z == bhi.z;
}

static uint32_t ceil_log2(uint32_t n)
{
    uint32_t k = 0;
    while ((1ull << k) < n)
        ++k;
    return k;
}

static void check_structure(const rs_bvh *b, const rs_geom *g, uint32_t max_leaf, const char *what)
{
    uint32_t n = rs_geom_prim_count(g), i, max_depth = 0, n_leaves = 0, fullest = 0;
    uint32_t *seen_prim = (uint32_t *)calloc(n ? n : 1, sizeof *seen_prim);
    uint32_t *seen_slot = (uint32_t *)calloc(n ? n : 1, sizeof *seen_slot);
    uint32_t *seen_node = (uint32_t *)calloc(b->n_nodes ? b->n_nodes : 1, sizeof *seen_node);
    uint32_t stack[2 * RS_BVH_STACK + 2], depth_of[2 * RS_BVH_STACK + 2], sp = 0;
    assert_true(seen_prim && seen_slot && seen_node);
    assert_int_equal(b->n_prims, n);
    if (n == 0) {
        assert_int_equal(b->n_nodes, 0);
        goto done;
    }
    if (!(b->n_nodes >= 1 && b->n_nodes <= 2 * n - 1))
        fail_msg("%s: %u nodes for %u prims", what, b->n_nodes, n);
    stack[sp] = 0;
    depth_of[sp++] = 1;
    while (sp > 0) {
        uint32_t node = stack[--sp], depth = depth_of[sp];
        const rs_bvh_node *nd = &b->nodes[node];
        if (seen_node[node]++)
            fail_msg("%s: node %u is reached twice", what, node);
        if (depth >= RS_BVH_STACK)
            fail_msg("%s: node %u at depth %u, traversal's stack holds %d", what, node, depth,
                     RS_BVH_STACK);
        if (depth > max_depth)
            max_depth = depth;
        if (nd->count == 0) {
            uint32_t l = nd->left_first;
            const rs_bvh_node *cl, *cr;
            if (!(l > node && l + 1 < b->n_nodes))
                fail_msg("%s: node %u: children %u, %u out of range (%u nodes)", what, node, l,
                         l + 1, b->n_nodes);
            cl = &b->nodes[l];
            cr = &b->nodes[l + 1];
            if (!box_equal(nd->lo, nd->hi, rs_v3_min(cl->lo, cr->lo), rs_v3_max(cl->hi, cr->hi)))
                fail_msg("%s: node %u's box is not the union of its children's", what, node);
            for (i = 0; i < 2; ++i) {
                stack[sp] = l + i;
                depth_of[sp++] = depth + 1;
            }
        } else {
            rs_aabb u;
            /* set from the first prim below; zeroed so that the compiler's flow analysis, which
             * cannot see that a leaf holds at least one, does not warn */
            u.lo = u.hi = rs_v3_splat(0.0f);
            ++n_leaves;
            if (nd->count > fullest)
                fullest = nd->count;
            if (nd->count > max_leaf)
                fail_msg("%s: leaf %u holds %u prims, max_leaf %u", what, node, nd->count,
                         max_leaf);
            if (!(nd->left_first <= n && nd->count <= n - nd->left_first))
                fail_msg("%s: leaf %u: range [%u, +%u) outside prim_ids[%u]", what, node,
                         nd->left_first, nd->count, n);
            for (i = nd->left_first; i < nd->left_first + nd->count; ++i) {
                uint32_t prim = b->prim_ids[i];
                rs_aabb pb;
                if (seen_slot[i]++)
                    fail_msg("%s: prim_ids[%u] belongs to two leaves", what, i);
                if (prim >= n)
                    fail_msg("%s: prim_ids[%u] = %u, only %u prims", what, i, prim, n);
                pb = rs_geom_prim_bounds(g, prim);
                if (i == nd->left_first) {
                    u = pb;
                } else {
                    u.lo = rs_v3_min(u.lo, pb.lo);
                    u.hi = rs_v3_max(u.hi, pb.hi);
                }
            }
            if (!box_equal(nd->lo, nd->hi, u.lo, u.hi))
                fail_msg("%s: leaf %u's box is not the union of its prims' boxes", what, node);
        }
    }
    for (i = 0; i < b->n_nodes; ++i)
        if (seen_node[i] != 1)
            fail_msg("%s: node %u is reached %u times", what, i, seen_node[i]);
    for (i = 0; i < n; ++i) {
        if (seen_slot[i] != 1)
            fail_msg("%s: prim_ids[%u] is in %u leaves", what, i, seen_slot[i]);
        seen_prim[b->prim_ids[i]]++;
    }
    for (i = 0; i < n; ++i)
        if (seen_prim[i] != 1)
            fail_msg("%s: prim %u appears %u times in prim_ids", what, i, seen_prim[i]);
    if (b->n_nodes != 2 * n_leaves - 1 || b->n_leaves != n_leaves)
        fail_msg("%s: %u nodes, %u leaves (recorded %u)", what, b->n_nodes, n_leaves, b->n_leaves);
    if (max_depth != b->depth)
        fail_msg("%s: measured depth %u, recorded %u", what, max_depth, b->depth);
    if (fullest != b->max_leaf_count)
        fail_msg("%s: fullest leaf %u, recorded %u", what, fullest, b->max_leaf_count);
    if ((b->builder.method == RS_BVH_MEDIAN || b->builder.method == RS_BVH_GRID) &&
        max_depth > ceil_log2(n) + 1)
        fail_msg("%s: depth %u over ceil(log2(%u)) + 1 for a halving builder", what, max_depth, n);
done:
    free(seen_prim);
    free(seen_slot);
    free(seen_node);
}

static rs_bvh *build_with(const rs_geom *g, const rs_bvh_builder *bld, uint32_t max_leaf,
                          uint32_t threads)
{
    rs_bvh_build_opts o;
    rs_bvh *b = NULL;
    rs_status st;
    memset(&o, 0, sizeof o);
    o.max_leaf = max_leaf;
    o.builder = *bld;
    o.threads = threads;
    st = rs_bvh_build(g, &o, &b);
    if (st != RS_OK)
        fail_msg("%s: rs_bvh_build failed: %d (%s)", vname(bld), (int)st, rs_error_message());
    assert_non_null(b);
    return b;
}

static int same_tree(const rs_bvh *a, const rs_bvh *b)
{
    return a->n_nodes == b->n_nodes && a->n_prims == b->n_prims && a->depth == b->depth &&
           a->n_leaves == b->n_leaves && a->max_leaf_count == b->max_leaf_count &&
           a->n_fallback == b->n_fallback &&
           memcmp(a->nodes, b->nodes, (size_t)a->n_nodes * sizeof *a->nodes) == 0 &&
           memcmp(a->prim_ids, b->prim_ids, (size_t)a->n_prims * sizeof *a->prim_ids) == 0;
}

/* ---- tests --------------------------------------------------------------------------------- */

static void test_names(void **state)
{
    static const char *const bad[] = {"",
                                      "foo",
                                      "Median",
                                      "sah:",
                                      "sah:1",
                                      "sah:33",
                                      "sah:16x",
                                      "sah:-4",
                                      "sah16",
                                      "random-sort",
                                      "random-sort-",
                                      "random-sort-centroid-x",
                                      "rotational--max",
                                      "largest-nth-middle",
                                      "diagonal-nth-centroid",
                                      "random-quick-min"};
    rs_bvh_builder b;
    rs_geom g;
    rs_bvh *out = (rs_bvh *)(uintptr_t)1;
    rs_bvh_build_opts o;
    char buf[64];
    size_t i;
    (void)state;
    for (i = 0; i < N_VARIANTS; ++i) {
        const char *name = rs_bvh_builder_name(&g_variants[i], buf, sizeof buf);
        assert_int_equal(rs_bvh_builder_check(&g_variants[i]), RS_OK);
        if (rs_bvh_builder_parse(name, &b) != RS_OK)
            fail_msg("'%s' does not parse: %s", name, rs_error_message());
        if (memcmp(&b, &g_variants[i], sizeof b) != 0)
            fail_msg("'%s' parses to another builder", name);
    }
    assert_int_equal(rs_bvh_builder_parse("sah", &b), RS_OK);
    assert_int_equal(b.method, RS_BVH_SAH);
    assert_int_equal(b.bins, RS_BVH_SAH_BINS_DEFAULT);
    assert_int_equal(rs_bvh_builder_parse("rotational-partial-max", &b), RS_OK);
    assert_true(b.method == RS_BVH_GRID && b.axis == RS_BVH_AXIS_ROTATIONAL &&
                b.partition == RS_BVH_PART_PARTIAL && b.key == RS_BVH_KEY_MAX);
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rs_error_clear();
        if (rs_bvh_builder_parse(bad[i], &b) != RS_ERR_ARG)
            fail_msg("'%s' parsed", bad[i]);
        assert_true(rs_error_message()[0] != '\0');
    }
    rs_error_clear();
    assert_int_equal(rs_bvh_builder_parse(NULL, &b), RS_ERR_ARG);
    /* invalid builders are refused by the build itself */
    memset(&g, 0, sizeof g);
    memset(&o, 0, sizeof o);
    o.builder.method = 9;
    rs_error_clear();
    assert_int_equal(rs_bvh_build(&g, &o, &out), RS_ERR_ARG);
    assert_null(out);
    assert_true(strstr(rs_error_message(), "method") != NULL);
    o.builder.method = RS_BVH_SAH;
    o.builder.bins = 33;
    out = (rs_bvh *)(uintptr_t)1;
    assert_int_equal(rs_bvh_build(&g, &o, &out), RS_ERR_ARG);
    assert_null(out);
    o.builder.method = RS_BVH_GRID;
    o.builder.bins = 0;
    o.builder.key = 3;
    assert_int_equal(rs_bvh_build(&g, &o, &out), RS_ERR_ARG);
    rs_error_clear();
    assert_string_equal(rs_bvh_builder_name(&o.builder, buf, sizeof buf), "?");
}

static void test_median_is_default(void **state)
{
    soup s;
    rs_bvh *a = NULL, *b, *c, *d;
    rs_bvh_build_opts o;
    rs_bvh_builder bl;
    (void)state;
    soup_random(&s, 0x5eed);
    assert_int_equal(rs_bvh_build(&s.g, NULL, &a), RS_OK);
    memset(&o, 0, sizeof o);
    assert_int_equal(rs_bvh_build(&s.g, &o, &b), RS_OK);
    assert_int_equal(rs_bvh_builder_parse("median", &bl), RS_OK);
    c = build_with(&s.g, &bl, 4, 0);
    assert_int_equal(rs_bvh_builder_parse("largest-nth-centroid", &bl), RS_OK);
    d = build_with(&s.g, &bl, 4, 0);
    assert_true(same_tree(a, b));
    assert_true(same_tree(a, c));
    assert_true(same_tree(a, d));
    /* fields the method does not read are ignored, and rs_bvh.builder has them zeroed */
    rs_bvh_destroy(d);
    memset(&bl, 0, sizeof bl);
    bl.axis = 1;
    bl.bins = 9;
    d = build_with(&s.g, &bl, 4, 0);
    assert_true(same_tree(a, d));
    assert_true(d->builder.axis == 0 && d->builder.bins == 0);
    rs_bvh_destroy(d);
    assert_int_equal(rs_bvh_builder_parse("sah", &bl), RS_OK);
    bl.bins = 0;
    d = build_with(&s.g, &bl, 4, 0);
    assert_int_equal(d->builder.bins, RS_BVH_SAH_BINS_DEFAULT);
    assert_int_equal(a->builder.method, RS_BVH_MEDIAN);
    assert_int_equal(a->n_fallback, 0);
    rs_bvh_destroy(a);
    rs_bvh_destroy(b);
    rs_bvh_destroy(c);
    rs_bvh_destroy(d);
    soup_free(&s);
}

static void test_variants_vs_brute_force(void **state)
{
    enum { N_RAYS = 100000, N_SMALL = 10000 };
    static const uint32_t other_leaf[] = {1, 8};
    soup s;
    ray_set rs;
    size_t v, k;
    long hits = 0;
    (void)state;
    soup_random(&s, 0x5eed);
    ray_set_make(&rs, &s.g, N_RAYS, 0xbeef, rs_v3(0, 0, 0), SOUP);
    for (v = 0; v < N_VARIANTS; ++v) {
        char what[96];
        rs_bvh *b = build_with(&s.g, &g_variants[v], 4, 0);
        snprintf(what, sizeof what, "%s max_leaf 4", vname(&g_variants[v]));
        check_structure(b, &s.g, 4, what);
        hits = check_rays(b, &s.g, &rs, N_RAYS, what);
        print_message("%-26s %5u nodes depth %2u leaves<=%u fallback %u SAH %.2f\n",
                      vname(&g_variants[v]), b->n_nodes, b->depth, b->max_leaf_count, b->n_fallback,
                      rs_bvh_sah_cost(b));
        rs_bvh_destroy(b);
        for (k = 0; k < 2; ++k) {
            b = build_with(&s.g, &g_variants[v], other_leaf[k], 0);
            snprintf(what, sizeof what, "%s max_leaf %u", vname(&g_variants[v]), other_leaf[k]);
            check_structure(b, &s.g, other_leaf[k], what);
            check_rays(b, &s.g, &rs, N_SMALL, what);
            rs_bvh_destroy(b);
        }
    }
    print_message("%d rays, %ld hit\n", N_RAYS, hits);
    assert_true(hits > N_RAYS / 5 && hits < N_RAYS - N_RAYS / 5);
    ray_set_free(&rs);
    soup_free(&s);
}

/* SAH cost of every variant on `g`; SAH builders with 8+ bins must beat the median builder. */
static void compare_costs(const rs_geom *g, const char *scene)
{
    double median = 0.0;
    size_t v;
    print_message("%s: SAH cost (C_trav = C_isect = 1), max_leaf 4\n", scene);
    for (v = 0; v < N_VARIANTS; ++v) {
        rs_bvh *b = build_with(g, &g_variants[v], 4, 0);
        double cost = rs_bvh_sah_cost(b);
        if (g_variants[v].method == RS_BVH_MEDIAN)
            median = cost;
        print_message("  %-26s %8.2f (%.3fx median)\n", vname(&g_variants[v]), cost,
                      median > 0 ? cost / median : 0.0);
        assert_true(cost > 0.0 && isfinite(cost));
        if (g_variants[v].method == RS_BVH_SAH && g_variants[v].bins >= 8 && !(cost < median))
            fail_msg("%s: %s has SAH cost %.3f, not below the median builder's %.3f", scene,
                     vname(&g_variants[v]), cost, median);
        rs_bvh_destroy(b);
    }
}

static void test_sah_cost(void **state)
{
    soup s, t;
    rs_bvh *one;
    rs_bvh_builder med;
    (void)state;
    soup_random(&s, 0x5eed);
    compare_costs(&s.g, "soup");
    soup_clustered(&t, 0xc1u);
    compare_costs(&t.g, "clustered");
    /* the cost of a one-leaf tree is its primitive count; an empty tree costs 0 */
    memset(&med, 0, sizeof med);
    t.g.n_tris = 3;
    t.g.n_spheres = 0;
    one = build_with(&t.g, &med, 4, 0);
    assert_int_equal(one->n_nodes, 1);
    assert_true(fabs(rs_bvh_sah_cost(one) - 3.0 * RS_BVH_COST_ISECT) < 1e-12);
    rs_bvh_destroy(one);
    assert_true(rs_bvh_sah_cost(NULL) == 0.0);
    soup_free(&s);
    soup_free(&t);
}

static void test_thread_determinism(void **state)
{
    static const uint32_t threads[] = {2, 4};
    soup s;
    size_t v, k;
    (void)state;
    soup_tris(&s, 150000, 0xd37);
    for (v = 0; v < N_VARIANTS; ++v) {
        rs_bvh *one = build_with(&s.g, &g_variants[v], 4, 1);
        if (g_variants[v].method == RS_BVH_LBVH)
            check_structure(one, &s.g, 4, "lbvh 150000 tris");
        for (k = 0; k < 2; ++k) {
            rs_bvh *b = build_with(&s.g, &g_variants[v], 4, threads[k]);
            if (!same_tree(one, b))
                fail_msg("%s: %u threads build another tree than 1 thread", vname(&g_variants[v]),
                         threads[k]);
            rs_bvh_destroy(b);
        }
        rs_bvh_destroy(one);
    }
    soup_free(&s);
}

static void test_small_counts(void **state)
{
    static const uint32_t counts[] = {0, 1, 2, 3, 5};
    size_t v, k;
    uint32_t ml;
    (void)state;
    for (k = 0; k < sizeof counts / sizeof counts[0]; ++k) {
        uint32_t n = counts[k], ns = (n + 2) / 3, nq = (n + 1) / 3, nt = n / 3;
        uint64_t seed = 0x51 + n;
        soup s;
        ray_set rs;
        uint32_t i;
        soup_alloc(&s, ns, nq, nt);
        for (i = 0; i < ns; ++i) {
            s.spheres[i].center = rnd_box(&seed, 3.0f);
            s.spheres[i].radius = rnd_range(&seed, 0.3, 1.0);
        }
        for (i = 0; i < nq; ++i)
            s.quads[i] =
                rs_quad_make(rnd_box(&seed, 3.0f), rs_v3(1.5f, 0, 0.2f), rs_v3(0, 1.5f, 0));
        for (i = 0; i < nt; ++i)
            s.tris[i] = random_tri(&seed, rnd_box(&seed, 3.0f), 0.5, 2.0);
        ray_set_make(&rs, &s.g, 2000, 0x99 + n, rs_v3(0, 0, 0), 4.0f);
        for (v = 0; v < N_VARIANTS; ++v)
            for (ml = 1; ml <= 4; ml *= 4) {
                char what[96];
                rs_bvh *b = build_with(&s.g, &g_variants[v], ml, 0);
                snprintf(what, sizeof what, "%s, %u prims, max_leaf %u", vname(&g_variants[v]), n,
                         ml);
                check_structure(b, &s.g, ml, what);
                if (n == 0)
                    assert_int_equal(b->n_nodes, 0);
                if (n == 1 || (n >= 1 && n <= ml && g_variants[v].method != RS_BVH_SAH))
                    assert_int_equal(b->n_nodes, 1); /* SAH may split below max_leaf */
                if (n == 2 && ml == 1)
                    assert_int_equal(b->n_nodes, 3);
                check_rays(b, &s.g, &rs, rs.n, what);
                rs_bvh_destroy(b);
            }
        ray_set_free(&rs);
        soup_free(&s);
    }
}

static void test_identical_centroids(void **state)
{
    /* 400 spheres, 300 quads and 300 triangles all centred on (1, 2, 3) (the construction of
     * accel_bvh_test.c): no heuristic can separate them by position */
    soup s;
    rs_vec3 c = rs_v3(1, 2, 3);
    ray_set rs;
    uint32_t i, ml;
    size_t v;
    (void)state;
    soup_alloc(&s, 400, 300, 300);
    fill_identical_centroids(s.spheres, s.g.n_spheres, s.quads, s.g.n_quads, s.tris, s.g.n_tris, c);
    for (i = 0; i < rs_geom_prim_count(&s.g); ++i) {
        rs_aabb b = rs_geom_prim_bounds(&s.g, i);
        rs_vec3 m = rs_v3_scale(rs_v3_add(b.lo, b.hi), 0.5f);
        assert_true(m.x == c.x && m.y == c.y && m.z == c.z);
    }
    ray_set_make(&rs, &s.g, 3000, 0xce27, c, 8.0f);
    for (v = 0; v < N_VARIANTS; ++v)
        for (ml = 1; ml <= 4; ml *= 4) {
            char what[96];
            rs_bvh *b = build_with(&s.g, &g_variants[v], ml, 0);
            snprintf(what, sizeof what, "%s identical centroids max_leaf %u", vname(&g_variants[v]),
                     ml);
            check_structure(b, &s.g, ml, what);
            /* halving by position in the range: as shallow as the median builder */
            if (b->depth > ceil_log2(rs_geom_prim_count(&s.g)) + 1)
                fail_msg("%s: depth %u", what, b->depth);
            check_rays(b, &s.g, &rs, rs.n, what);
            rs_bvh_destroy(b);
        }
    ray_set_free(&rs);
    soup_free(&s);
}

/* The lbvh_sort hook (how the GPU sorts the Morton codes: gpu/cuda_lbvh.cu) as its contract
 * states it, by a qsort of (code, id): the tree must be the host LBVH's, bit for bit.  A hook
 * that fails makes the build fail with its error, and nothing leaks (ASan). */
typedef struct code_id {
    uint32_t code, id;
} code_id;

static int code_id_cmp(const void *a, const void *b)
{
    const code_id *x = (const code_id *)a, *y = (const code_id *)b;
    if (x->code != y->code)
        return x->code < y->code ? -1 : 1;
    return x->id < y->id ? -1 : x->id > y->id;
}

static rs_status reference_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                                const float scale[3], uint32_t *ids, uint32_t *codes)
{
    code_id *p = (code_id *)malloc((n ? n : 1) * sizeof *p);
    uint32_t i;
    ++*(int *)user;
    for (i = 0; i < n; ++i) {
        p[i].code = rs_morton3(centroid[i], lo, scale);
        p[i].id = i;
    }
    qsort(p, n, sizeof *p, code_id_cmp);
    for (i = 0; i < n; ++i) {
        codes[i] = p[i].code;
        ids[i] = p[i].id;
    }
    free(p);
    return RS_OK;
}

static rs_status failing_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                              const float scale[3], uint32_t *ids, uint32_t *codes)
{
    (void)user, (void)centroid, (void)n, (void)lo, (void)scale, (void)ids, (void)codes;
    return rs_error_set(RS_ERR_CUDA, "injected sort failure");
}

static void test_lbvh_sort_hook(void **state)
{
    soup s[3];
    int k, calls = 0;
    (void)state;
    soup_random(&s[0], 0x1b5);
    soup_clustered(&s[1], 0x1b6);
    soup_alloc(&s[2], 40, 30, 30);
    fill_identical_centroids(s[2].spheres, s[2].g.n_spheres, s[2].quads, s[2].g.n_quads, s[2].tris,
                             s[2].g.n_tris, rs_v3(1, 2, 3));
    for (k = 0; k < 3; ++k) {
        rs_bvh_build_opts o;
        rs_bvh *host, *hooked = NULL;
        memset(&o, 0, sizeof o);
        o.builder.method = RS_BVH_LBVH;
        host = build_with(&s[k].g, &o.builder, 4, 0);
        o.lbvh_sort = reference_sort;
        o.lbvh_sort_user = &calls;
        assert_int_equal(rs_bvh_build(&s[k].g, &o, &hooked), RS_OK);
        assert_true(same_tree(host, hooked));
        rs_bvh_destroy(hooked);
        o.lbvh_sort = failing_sort;
        rs_error_clear();
        assert_int_equal(rs_bvh_build(&s[k].g, &o, &hooked), RS_ERR_CUDA);
        assert_null(hooked);
        assert_non_null(strstr(rs_error_message(), "injected sort failure"));
        rs_error_clear();
        rs_bvh_destroy(host);
        soup_free(&s[k]);
    }
    assert_int_equal(calls, 3);
}

static void test_depth_bound(void **state)
{
    /* Spheres on the three axes at 40^0 .. 40^23 (72 of them).  In any range, the farthest
     * sphere on an axis is more than 32 times as far out as every other, so (with up to 32 bins)
     * all the others fall into the first bin and every SAH plane cuts off one sphere: without
     * the depth guard the SAH tree is a chain about 72 deep.  Every builder must stay below the
     * traversal stack and stay exact (the far spheres are out of float range for the ray test,
     * which then misses them in brute force and in the BVH alike; the near ones are hit). */
    enum { PER_AXIS = 24 };
    soup s;
    ray_set rs;
    uint32_t i;
    size_t v;
    (void)state;
    soup_alloc(&s, 3 * PER_AXIS, 0, 0);
    for (i = 0; i < 3 * PER_AXIS; ++i) {
        float x = (float)pow(40.0, (double)(i / 3));
        s.spheres[i].center = rs_v3(i % 3 == 0 ? x : 0, i % 3 == 1 ? x : 0, i % 3 == 2 ? x : 0);
        s.spheres[i].radius = 0.25f;
    }
    ray_set_make(&rs, &s.g, 4000, 0xdee9, rs_v3(0, 0, 0), 30.0f);
    for (v = 0; v < N_VARIANTS; ++v) {
        char what[96];
        rs_bvh *b = build_with(&s.g, &g_variants[v], 1, 0);
        snprintf(what, sizeof what, "%s geometric spheres", vname(&g_variants[v]));
        check_structure(b, &s.g, 1, what);
        check_rays(b, &s.g, &rs, rs.n, what);
        if (g_variants[v].method == RS_BVH_SAH) {
            print_message("%s: depth %u, %u splits overridden by the depth guard\n",
                          vname(&g_variants[v]), b->depth, b->n_fallback);
            /* the guard acted (else this input does not test it) and kept the bound */
            assert_true(b->n_fallback > 0);
            assert_true(b->depth <= RS_BVH_MAX_DEPTH && b->depth > 40);
        }
        rs_bvh_destroy(b);
    }
    ray_set_free(&rs);
    soup_free(&s);
}

static void test_out_of_memory(void **state)
{
    soup s;
    size_t v;
    (void)state;
    soup_random(&s, 0x5eed);
    for (v = 0; v < N_VARIANTS; ++v) {
        rs_bvh_build_opts o;
        long k;
        int succeeded = 0;
        memset(&o, 0, sizeof o);
        o.builder = g_variants[v];
        for (k = 0; k < 64 && !succeeded; ++k) {
            rs_bvh *b = (rs_bvh *)(uintptr_t)1;
            rs_status st;
            rs_error_clear();
            rs_alloc_fail_after(k);
            st = rs_bvh_build(&s.g, &o, &b);
            rs_alloc_fail_after(-1);
            if (st == RS_OK) {
                check_structure(b, &s.g, 4, vname(&g_variants[v]));
                rs_bvh_destroy(b);
                succeeded = 1;
            } else {
                if (st != RS_ERR_NOMEM || b != NULL || rs_error_message()[0] == '\0')
                    fail_msg("%s: allocation %ld failing gave status %d, out %p, message '%s'",
                             vname(&g_variants[v]), k, (int)st, (void *)b, rs_error_message());
            }
        }
        if (!succeeded || k < 3)
            fail_msg("%s: %ld allocations, succeeded %d", vname(&g_variants[v]), k, succeeded);
    }
    rs_error_clear();
    soup_free(&s);
}

static void test_bunny(void **state)
{
    const char *why = "", *dir = test_models_dir(&why);
    char path[4200];
    test_mesh m;
    rs_geom g;
    ray_set rs;
    rs_aabb box;
    double median = 0.0;
    uint32_t i;
    size_t v;
    (void)state;
    if (!dir) {
        print_message("bunny: skipped: %s\n", why);
        return;
    }
    snprintf(path, sizeof path, "%s/bunny/bun_zipper.ply", dir);
    if (!test_mesh_load(path, &m)) {
        snprintf(path, sizeof path, "%s/bunny/stanford-bunny.obj", dir);
        if (!test_mesh_load(path, &m)) {
            print_message("bunny: skipped: neither bun_zipper.ply nor stanford-bunny.obj "
                          "could be read in %s/bunny\n",
                          dir);
            return;
        }
    }
    assert_int_equal(m.n_tris, 69451);
    memset(&g, 0, sizeof g);
    g.tris = m.tris;
    g.n_tris = m.n_tris;
    box = rs_geom_prim_bounds(&g, 0);
    for (i = 1; i < m.n_tris; ++i) {
        rs_aabb b = rs_geom_prim_bounds(&g, i);
        box.lo = rs_v3_min(box.lo, b.lo);
        box.hi = rs_v3_max(box.hi, b.hi);
    }
    ray_set_make(&rs, &g, 2000, 0xb0, rs_v3_scale(rs_v3_add(box.lo, box.hi), 0.5f),
                 0.5f * rs_v3_max_comp(rs_v3_sub(box.hi, box.lo)));
    print_message("bunny (%s): %u triangles\n", path, m.n_tris);
    for (v = 0; v < N_VARIANTS; ++v) {
        rs_bvh *b = build_with(&g, &g_variants[v], 4, 0);
        double cost = rs_bvh_sah_cost(b);
        char what[96];
        snprintf(what, sizeof what, "%s bunny", vname(&g_variants[v]));
        check_structure(b, &g, 4, what);
        check_rays(b, &g, &rs, rs.n, what);
        if (g_variants[v].method == RS_BVH_MEDIAN)
            median = cost;
        print_message("  %-26s %6u nodes depth %2u SAH %7.2f (%.3fx median)\n",
                      vname(&g_variants[v]), b->n_nodes, b->depth, cost, cost / median);
        if (g_variants[v].method == RS_BVH_SAH && g_variants[v].bins >= 8 && !(cost < median))
            fail_msg("bunny: %s SAH cost %.3f not below the median's %.3f", vname(&g_variants[v]),
                     cost, median);
        rs_bvh_destroy(b);
    }
    ray_set_free(&rs);
    test_mesh_free(&m);
}

static int setup(void **state)
{
    (void)state;
    return variants_init();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_median_is_default),
        cmocka_unit_test(test_variants_vs_brute_force),
        cmocka_unit_test(test_sah_cost),
        cmocka_unit_test(test_thread_determinism),
        cmocka_unit_test(test_small_counts),
        cmocka_unit_test(test_identical_centroids),
        cmocka_unit_test(test_depth_bound),
        cmocka_unit_test(test_lbvh_sort_hook),
        cmocka_unit_test(test_out_of_memory),
        cmocka_unit_test(test_bunny),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
