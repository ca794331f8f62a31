/* tests/accel_bvh_test.c — accel/bvh.h and accel/bvh4.h: rs_bvh_build, the binary traversal
 * (rs_bvh_closest, rs_bvh_occluded) and the 4-wide one the CPU device runs (rs_bvh4_*).
 *
 * What is checked:
 *   - traversal equals brute force: over a fixed-seed soup of 2000 triangles, 300 spheres and
 *     200 quads (global numbering of core/geom.h: spheres, quads, triangles), 10^5 random rays
 *     (origins inside and outside the soup, random and axis-aligned directions, some with tmin
 *     or tmax limited) give the same closest prim, t, u and v as looping rs_geom_intersect over
 *     every primitive, for trees with max_leaf 1, 4 and 8, with both kernels, bit for bit: the
 *     same routines compute t, and ties go to the lowest prim number in every kernel as in the
 *     brute-force loop (rs_hit_better).  The 4-wide kernel packs leaves of triangles and tests
 *     four at once; a soup of triangles alone (every leaf packed) and one with the watertight
 *     test (none packed) are checked too.  Occlusion equals "brute force found a hit in
 *     (tmin, tmax)";
 *   - structure: every prim id appears exactly once in prim_ids; the leaves' ranges partition
 *     prim_ids; every node is reachable exactly once; each node's bounds contain its children's
 *     and its primitives' bounds (rs_geom_prim_bounds); each interior node separates its
 *     children's centroids along some axis; leaves hold 1 .. max_leaf prims; depth is the
 *     recorded depth and at most ceil(log2(n)) + 2; n_nodes = 2 leaves - 1 <= 2n - 1;
 *   - edge cases: no primitives (no nodes, every ray misses), one primitive of each kind, all
 *     centroids identical (the build ends and traversal stays exact), rays with NaN or Inf
 *     components (return within a time limit, with a valid answer), an axis-aligned ray lying
 *     in the scene's bounding plane, and allocation failure during the build and the collapse
 *     to 4-wide nodes. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "accel/bvh.h"
#include "accel/bvh4.h"
#include "accel/bvh8.h"
#include "core/alloc.h"
#include "streams/batch.h"
#include "scenes/scene.h"

#include "test_rand.h"

#define T_INF FLT_MAX

/* ---- helpers ------------------------------------------------------------------------------- */

/* A scene the tests own: arrays plus the rs_geom view of them. */
typedef struct soup {
    rs_sphere *spheres;
    rs_quad *quads;
    rs_tri *tris;
    rs_geom g;
} soup;

static void soup_alloc(soup *s, uint32_t ns, uint32_t nq, uint32_t nt)
{
    s->spheres = (rs_sphere *)calloc(ns ? ns : 1, sizeof *s->spheres);
    s->quads = (rs_quad *)calloc(nq ? nq : 1, sizeof *s->quads);
    s->tris = (rs_tri *)calloc(nt ? nt : 1, sizeof *s->tris);
    assert_non_null(s->spheres);
    assert_non_null(s->quads);
    assert_non_null(s->tris);
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
    free(s->quads);
    free(s->tris);
}

/* Soup extent: centres in [-SOUP, SOUP]^3. */
#define SOUP 40.0f

/* The random soup: spheres of radius 0.2 .. 3; quads with random edges 0.5 .. 6 long, every
 * fourth one axis-aligned (zero-thickness bounds); triangles with vertices up to 4 from their
 * centre, every eighth one in an axis plane. */
static void soup_random(soup *s, uint64_t seed)
{
    uint32_t i;
    soup_alloc(s, 300, 200, 2000);
    for (i = 0; i < s->g.n_spheres; ++i) {
        s->spheres[i].center = rnd_box(&seed, SOUP);
        s->spheres[i].radius = rnd_range(&seed, 0.2, 3.0);
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
        rs_vec3 c = rnd_box(&seed, SOUP);
        rs_tri *t = &s->tris[i];
        t->v0 = rs_v3_madd(c, rnd_unit(&seed), rnd_range(&seed, 0.3, 4.0));
        t->v1 = rs_v3_madd(c, rnd_unit(&seed), rnd_range(&seed, 0.3, 4.0));
        t->v2 = rs_v3_madd(c, rnd_unit(&seed), rnd_range(&seed, 0.3, 4.0));
        if (i % 8 == 0) {
            t->v1.y = t->v0.y;
            t->v2.y = t->v0.y;
        }
    }
}

/* Brute force: every primitive with the full interval; the strictly smallest t wins, so the
 * lowest-numbered prim wins ties.  Returns 1 on a hit. */
static rs_bvh *build(const rs_geom *g, uint32_t max_leaf)
{
    rs_bvh_build_opts o = {0};
    rs_bvh *b = NULL;
    rs_status st;
    o.max_leaf = max_leaf;
    st = rs_bvh_build(g, max_leaf ? &o : NULL, &b);
    if (st != RS_OK)
        fail_msg("rs_bvh_build failed: %d (%s)", (int)st, rs_error_message());
    assert_non_null(b);
    return b;
}

/* The binned SAH tree with leaf costs counted in blocks of `block` (what the CLI builds for the
 * CPU's wide trees with blocks of 4 or 8: rs_bvh_wide_leaf_size). */
static rs_bvh *build_sah_blocks(const rs_geom *g, uint32_t max_leaf, uint32_t block)
{
    rs_bvh_build_opts o = {0};
    rs_bvh *b = NULL;
    rs_status st;
    o.max_leaf = max_leaf;
    o.builder.method = RS_BVH_SAH;
    o.leaf_block = block;
    st = rs_bvh_build(g, &o, &b);
    if (st != RS_OK)
        fail_msg("rs_bvh_build (sah, blocks of %u) failed: %d (%s)", block, (int)st,
                 rs_error_message());
    assert_non_null(b);
    return b;
}

static void describe_ray(char *buf, size_t n, const rs_ray *r)
{
    snprintf(buf, n, "o (%.9g %.9g %.9g) d (%.9g %.9g %.9g) t (%.9g, %.9g)", r->o.x, r->o.y, r->o.z,
             r->d.x, r->d.y, r->d.z, r->tmin, r->tmax);
}

/* The wide trees of a binary tree, what the CPU device runs: the 4-wide one and the 8-wide one
 * (built anywhere; its AVX2 traversal is tested where the CPU has AVX2). */
typedef struct wide {
    rs_bvh4 *b4;
    rs_bvh8 *b8;
} wide;

/* The wide trees of `b`, or a test failure. */
static wide collapse(const rs_bvh *b, const rs_geom *g)
{
    wide w = {NULL, NULL};
    rs_status st = rs_bvh4_build(b, g, &w.b4);
    if (st != RS_OK)
        fail_msg("rs_bvh4_build failed: %d (%s)", (int)st, rs_error_message());
    st = rs_bvh8_build(b, g, &w.b8);
    if (st != RS_OK)
        fail_msg("rs_bvh8_build failed: %d (%s)", (int)st, rs_error_message());
    assert_non_null(w.b4);
    assert_non_null(w.b8);
    /* the same leaves, packed the same way (spheres in the 8-wide tree only) */
    assert_true(w.b8->n_packed >= w.b4->n_packed);
    assert_true((w.b8->n_tri8 == 0) == (w.b4->n_tri4 == 0) && w.b8->n_tri8 <= w.b4->n_tri4);
    assert_true((w.b8->n_quad8 == 0) == (w.b4->n_quad4 == 0) && w.b8->n_quad8 <= w.b4->n_quad4);
    return w;
}

static void wide_free(wide *w)
{
    rs_bvh4_destroy(w->b4);
    rs_bvh8_destroy(w->b8);
    w->b4 = NULL;
    w->b8 = NULL;
}

/* Wide kernels to test: the 4-wide one (0) and, with AVX2, the 8-wide one (1). */
static int n_wide_kernels(void)
{
    static int said = 0;
    if (!rs_bvh8_supported() && !said++)
        print_message("this CPU has no AVX2: the 8-wide traversal is not tested\n");
    return rs_bvh8_supported() ? 2 : 1;
}

static const char *wide_name(int k) { return k ? "8-wide" : "4-wide"; }

static int wide_closest(const wide *w, int k, const rs_geom *g, rs_ray r, rs_hit *h)
{
    return k ? rs_bvh8_closest(w->b8, g, r, h) : rs_bvh4_closest(w->b4, g, r, h);
}

static int wide_occluded(const wide *w, int k, const rs_geom *g, rs_ray r)
{
    return k ? rs_bvh8_occluded(w->b8, g, r) : rs_bvh4_occluded(w->b4, g, r);
}

/* Compares the queries of the binary tree and, if w is not NULL, of the wide ones against the
 * brute-force answer for ray r: the same hit bit for bit, and the same occlusion. */
static void expect_same_hit(const rs_bvh *bvh, const wide *w, const rs_geom *g, const rs_ray *r,
                            const rs_hit *ref, int ref_hit, const char *what, long index)
{
    static const char *const kernel[3] = {"binary", "4-wide", "8-wide"};
    rs_bvh_view view = rs_bvh_view_of(bvh);
    int k;
    for (k = 0; k < (w ? 1 + n_wide_kernels() : 1); ++k) {
        rs_hit h;
        int got = k ? wide_closest(w, k - 1, g, *r, &h) : rs_bvh_closest(&view, g, *r, &h);
        int occ = k ? wide_occluded(w, k - 1, g, *r) : rs_bvh_occluded(&view, g, *r);
        char ray[256];
        if (got != ref_hit || h.prim != ref->prim ||
            (got && (h.t != ref->t || h.u != ref->u || h.v != ref->v))) {
            describe_ray(ray, sizeof ray, r);
            fail_msg("%s ray %ld: %s bvh %s prim %u t %.9g (u %.9g v %.9g), brute force %s prim "
                     "%u t %.9g (u %.9g v %.9g); %s",
                     what, index, kernel[k], got ? "hit" : "miss", h.prim, h.t, h.u, h.v,
                     ref_hit ? "hit" : "miss", ref->prim, ref->t, ref->u, ref->v, ray);
        }
        if (occ != ref_hit) {
            describe_ray(ray, sizeof ray, r);
            fail_msg("%s ray %ld: %s occluded %d, brute force %s; %s", what, index, kernel[k], occ,
                     ref_hit ? "hit" : "miss", ray);
        }
    }
}

/* ---- structure ----------------------------------------------------------------------------- */

static int box_contains(rs_vec3 olo, rs_vec3 ohi, rs_vec3 ilo, rs_vec3 ihi)
{
    return olo.x <= ilo.x && olo.y <= ilo.y && olo.z <= ilo.z && ohi.x >= ihi.x && ohi.y >= ihi.y &&
           ohi.z >= ihi.z;
}

static uint32_t ceil_log2(uint32_t n)
{
    uint32_t k = 0;
    while ((1ull << k) < n)
        ++k;
    return k;
}

/* Centroid range of the primitives under `node` (the builder's centroid: the middle of
 * rs_geom_prim_bounds), and a check that every interior node separates its children's
 * centroids along some axis: a split by position, whatever the split rule.  Recursion depth is
 * the tree depth, checked separately. */
static void centroid_range(const rs_bvh *b, const rs_geom *g, uint32_t node, rs_vec3 *lo,
                           rs_vec3 *hi)
{
    const rs_bvh_node *nd = &b->nodes[node];
    uint32_t i;
    if (nd->count > 0) {
        for (i = nd->left_first; i < nd->left_first + nd->count; ++i) {
            rs_aabb pb = rs_geom_prim_bounds(g, b->prim_ids[i]);
            rs_vec3 c = rs_v3_scale(rs_v3_add(pb.lo, pb.hi), 0.5f);
            *lo = i == nd->left_first ? c : rs_v3_min(*lo, c);
            *hi = i == nd->left_first ? c : rs_v3_max(*hi, c);
        }
        return;
    }
    {
        rs_vec3 llo, lhi, rlo, rhi;
        int axis, separated = 0;
        centroid_range(b, g, nd->left_first, &llo, &lhi);
        centroid_range(b, g, nd->left_first + 1, &rlo, &rhi);
        for (axis = 0; axis < 3; ++axis)
            if (rs_v3_get(lhi, axis) <= rs_v3_get(rlo, axis) ||
                rs_v3_get(rhi, axis) <= rs_v3_get(llo, axis))
                separated = 1;
        if (!separated)
            fail_msg("node %u: its children's centroids overlap on every axis", node);
        *lo = rs_v3_min(llo, rlo);
        *hi = rs_v3_max(lhi, rhi);
    }
}

/* Walks the tree from the root with an explicit stack and checks every structural invariant. */
static void check_structure(const rs_bvh *b, const rs_geom *g, uint32_t max_leaf)
{
    uint32_t n = rs_geom_prim_count(g), i, max_depth = 0, n_leaves = 0, limit;
    uint32_t *seen_prim = (uint32_t *)calloc(n ? n : 1, sizeof *seen_prim);
    uint32_t *seen_slot = (uint32_t *)calloc(n ? n : 1, sizeof *seen_slot);
    uint32_t *seen_node = (uint32_t *)calloc(b->n_nodes ? b->n_nodes : 1, sizeof *seen_node);
    uint32_t stack[2 * RS_BVH_STACK], depth_of[2 * RS_BVH_STACK], sp = 0;
    assert_non_null(seen_prim);
    assert_non_null(seen_slot);
    assert_non_null(seen_node);
    assert_int_equal(b->n_prims, n);
    if (n == 0) {
        assert_int_equal(b->n_nodes, 0);
        goto done;
    }
    assert_true(b->n_nodes >= 1 && b->n_nodes <= 2 * n - 1);
    stack[sp] = 0;
    depth_of[sp++] = 1;
    while (sp > 0) {
        uint32_t node = stack[--sp], depth = depth_of[sp];
        const rs_bvh_node *nd = &b->nodes[node];
        assert_true(node < b->n_nodes);
        if (seen_node[node]++)
            fail_msg("node %u is reached twice", node);
        if (depth > max_depth)
            max_depth = depth;
        assert_true(nd->lo.x <= nd->hi.x && nd->lo.y <= nd->hi.y && nd->lo.z <= nd->hi.z);
        if (nd->count == 0) {
            uint32_t l = nd->left_first;
            if (!(l > node && l + 1 < b->n_nodes))
                fail_msg("node %u: children %u, %u out of range (%u nodes)", node, l, l + 1,
                         b->n_nodes);
            for (i = 0; i < 2; ++i) {
                const rs_bvh_node *c = &b->nodes[l + i];
                if (!box_contains(nd->lo, nd->hi, c->lo, c->hi))
                    fail_msg("node %u does not contain its child %u", node, l + i);
                assert_true(sp < 2 * RS_BVH_STACK);
                stack[sp] = l + i;
                depth_of[sp++] = depth + 1;
            }
        } else {
            ++n_leaves;
            if (nd->count > max_leaf)
                fail_msg("leaf %u holds %u prims, max_leaf %u", node, nd->count, max_leaf);
            if (!(nd->left_first <= n && nd->count <= n - nd->left_first))
                fail_msg("leaf %u: range [%u, +%u) outside prim_ids[%u]", node, nd->left_first,
                         nd->count, n);
            for (i = nd->left_first; i < nd->left_first + nd->count; ++i) {
                uint32_t prim = b->prim_ids[i];
                rs_aabb pb;
                if (seen_slot[i]++)
                    fail_msg("prim_ids[%u] belongs to two leaves", i);
                if (prim >= n)
                    fail_msg("prim_ids[%u] = %u, only %u prims", i, prim, n);
                pb = rs_geom_prim_bounds(g, prim);
                if (!box_contains(nd->lo, nd->hi, pb.lo, pb.hi))
                    fail_msg("leaf %u does not contain the bounds of prim %u", node, prim);
            }
        }
    }
    for (i = 0; i < b->n_nodes; ++i)
        if (seen_node[i] != 1)
            fail_msg("node %u is reached %u times", i, seen_node[i]);
    for (i = 0; i < n; ++i) {
        if (seen_slot[i] != 1)
            fail_msg("prim_ids[%u] is in %u leaves", i, seen_slot[i]);
        seen_prim[b->prim_ids[i]]++;
    }
    for (i = 0; i < n; ++i)
        if (seen_prim[i] != 1)
            fail_msg("prim %u appears %u times in prim_ids", i, seen_prim[i]);
    /* a binary tree: nodes = 2 leaves - 1 */
    assert_int_equal(b->n_nodes, 2 * n_leaves - 1);
    if (max_depth != b->depth)
        fail_msg("measured depth %u, recorded %u", max_depth, b->depth);
    {
        rs_vec3 clo, chi;
        centroid_range(b, g, 0, &clo, &chi);
    }
    limit = ceil_log2(n) + 2;
    if (max_depth > limit)
        fail_msg("depth %u over ceil(log2(%u)) + 2 = %u (max_leaf %u)", max_depth, n, limit,
                 max_leaf);
done:
    free(seen_prim);
    free(seen_slot);
    free(seen_node);
}

static void test_structure(void **state)
{
    static const uint32_t leaf_sizes[] = {1, 4, 8, 0};
    soup s;
    size_t i;
    (void)state;
    soup_random(&s, 0x5eed);
    for (i = 0; i < sizeof leaf_sizes / sizeof leaf_sizes[0]; ++i) {
        rs_bvh *b = build(&s.g, leaf_sizes[i]);
        print_message("max_leaf %u: %u nodes, depth %u\n", leaf_sizes[i], b->n_nodes, b->depth);
        check_structure(b, &s.g, leaf_sizes[i] ? leaf_sizes[i] : 4);
        rs_bvh_destroy(b);
    }
    soup_free(&s);
    rs_bvh_destroy(NULL);
}

/* ---- traversal against brute force --------------------------------------------------------- */

/* A random ray for the soup: the origin inside the soup's box half the time, in a box three
 * times as wide otherwise; the direction random, aimed at a random point of the soup, or (one
 * in eight) with one or two components exactly zero; tmin > 0 for one in eight and tmax cut
 * short for one in four. */
static rs_ray soup_ray(uint64_t *s, long i)
{
    rs_vec3 o = (i & 1) ? rnd_box(s, SOUP + 4.0f) : rnd_box(s, 3.0f * SOUP), d;
    float tmin = 0.0f, tmax = T_INF;
    if (i % 3 == 0)
        d = rs_v3_sub(rnd_box(s, SOUP), o);
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
        tmin = rnd_range(s, 0.0, 20.0);
    if (i % 4 == 3)
        tmax = rnd_range(s, 0.0, 40.0);
    return mk_ray(o, d, tmin, tmax);
}

/* A height field of triangles on an n x n grid of cells, two per cell, sharing their edges and
 * vertices exactly: rays aimed at its vertices cross several triangles at one point, where
 * two of them can report the very same t (a tie the kernels must break the same way). */
static void soup_grid(soup *s, uint32_t n, uint64_t seed)
{
    uint32_t x, y;
    float *h = (float *)malloc((size_t)(n + 1) * (n + 1) * sizeof *h);
    assert_non_null(h);
    for (x = 0; x < (n + 1) * (n + 1); ++x)
        h[x] = rnd_range(&seed, -2.0, 2.0);
    soup_alloc(s, 0, 0, 2 * n * n);
    for (y = 0; y < n; ++y)
        for (x = 0; x < n; ++x) {
            rs_vec3 a = rs_v3((float)x, h[y * (n + 1) + x], (float)y);
            rs_vec3 b = rs_v3((float)x + 1, h[y * (n + 1) + x + 1], (float)y);
            rs_vec3 c = rs_v3((float)x, h[(y + 1) * (n + 1) + x], (float)y + 1);
            rs_vec3 d = rs_v3((float)x + 1, h[(y + 1) * (n + 1) + x + 1], (float)y + 1);
            rs_tri *t = &s->tris[2 * (y * n + x)];
            t[0].v0 = a, t[0].v1 = b, t[0].v2 = c;
            t[1].v0 = b, t[1].v1 = d, t[1].v2 = c;
        }
    free(h);
}

/* Rays from above the grid aimed at one of its vertices, or at a random point. */
static rs_ray grid_ray(uint64_t *s, long i, uint32_t n, const soup *g)
{
    rs_vec3 o =
        rs_v3(rnd_range(s, -5.0, n + 5.0), rnd_range(s, 5.0, 30.0), rnd_range(s, -5.0, n + 5.0));
    rs_vec3 target;
    if (i % 4 != 3) {
        const rs_tri *t = &g->tris[(uint32_t)(rnd01(s) * g->g.n_tris)];
        target = i % 4 == 0 ? t->v0 : (i % 4 == 1 ? t->v1 : t->v2);
    } else {
        target = rs_v3(rnd_range(s, 0.0, n), 0.0f, rnd_range(s, 0.0, n));
    }
    return mk_ray(o, rs_v3_sub(target, o), 0.0f, T_INF);
}

/* How many primitives other than ref->prim hit r at exactly ref->t. */
static int brute_ties(const rs_geom *g, const rs_ray *r, const rs_hit *ref)
{
    uint32_t i, n = rs_geom_prim_count(g);
    int ties = 0;
    for (i = 0; i < n; ++i) {
        float t, u, v;
        ties += i != ref->prim && rs_geom_intersect(g, i, r, &t, &u, &v) && t == ref->t;
    }
    return ties;
}

/* n rays (from the soup's generator, or the grid's when grid > 0) against brute force, for median
 * trees with max_leaf 1, 4 and 8 and the SAH tree with leaf costs in blocks of 8 (max_leaf 8), and
 * every kernel.  Returns the hits; *ties counts the rays whose
 * closest t several primitives share. */
static long check_vs_brute_force(const soup *s, const char *name, long n, uint32_t grid, long *ties)
{
    static const uint32_t leaf_sizes[] = {1, 4, 8, 8};
    rs_bvh *trees[4];
    wide wides[4];
    uint64_t rs = 0xbeef;
    long i, hits = 0;
    size_t k;
    *ties = 0;
    for (k = 0; k < 4; ++k) {
        trees[k] = k < 3 ? build(&s->g, leaf_sizes[k])
                         : build_sah_blocks(&s->g, leaf_sizes[k], 8);
        wides[k] = collapse(trees[k], &s->g);
    }
    for (i = 0; i < n; ++i) {
        rs_ray r = grid ? grid_ray(&rs, i, grid, s) : soup_ray(&rs, i);
        rs_hit ref;
        int ref_hit = brute_closest(&s->g, &r, &ref);
        hits += ref_hit;
        if (ref_hit && grid)
            *ties += brute_ties(&s->g, &r, &ref) > 0;
        for (k = 0; k < 4; ++k) {
            char what[64];
            snprintf(what, sizeof what, "%s, %s max_leaf %u", name, k < 3 ? "median" : "sah blocks",
                     leaf_sizes[k]);
            expect_same_hit(trees[k], &wides[k], &s->g, &r, &ref, ref_hit, what, i);
        }
    }
    for (k = 0; k < 4; ++k) {
        wide_free(&wides[k]);
        rs_bvh_destroy(trees[k]);
    }
    return hits;
}

static void test_random_rays_vs_brute_force(void **state)
{
    enum { N_RAYS = 100000 };
    soup s;
    long hits, ties;
    (void)state;
    soup_random(&s, 0x5eed);
    hits = check_vs_brute_force(&s, "soup", N_RAYS, 0, &ties);
    print_message("soup: %d rays, %ld hit\n", N_RAYS, hits);
    /* both outcomes well represented, or the comparison says little */
    assert_true(hits > N_RAYS / 5 && hits < N_RAYS - N_RAYS / 5);
    /* the same soup with the watertight triangle test: the wide trees pack no triangles then */
    s.g.tri_algo = RS_ISECT_TRI_WATERTIGHT;
    hits = check_vs_brute_force(&s, "soup, watertight", N_RAYS / 4, 0, &ties);
    assert_true(hits > N_RAYS / 20);
    {
        /* its parallelograms alone: every wide leaf a quad4 block */
        soup q = s;
        rs_bvh *b;
        wide w;
        q.g.n_spheres = 0;
        q.g.n_tris = 0;
        b = build(&q.g, 4);
        w = collapse(b, &q.g);
#ifdef RS_BVH4_SSE
        assert_int_equal(w.b4->n_packed, b->n_leaves);
        assert_true(w.b4->n_quad4 >= (q.g.n_quads + 3) / 4 && w.b4->n_tri4 == 0);
#endif
        wide_free(&w);
        rs_bvh_destroy(b);
        hits = check_vs_brute_force(&q, "parallelograms", N_RAYS / 4, 0, &ties);
        print_message("parallelograms: %d rays, %ld hit\n", N_RAYS / 4, hits);
        assert_true(hits > N_RAYS / 100);
    }
    {
        /* its spheres alone: every 8-wide leaf a sphere8 block (the 4-wide tree packs none) */
        soup q = s;
        rs_bvh *b;
        wide w;
        q.g.n_quads = 0;
        q.g.n_tris = 0;
        b = build(&q.g, 8);
        w = collapse(b, &q.g);
#ifdef RS_BVH4_SSE
        assert_int_equal(w.b8->n_packed, b->n_leaves);
        assert_true(w.b8->n_sphere8 >= (q.g.n_spheres + 7) / 8 && w.b4->n_packed == 0);
#endif
        wide_free(&w);
        rs_bvh_destroy(b);
        hits = check_vs_brute_force(&q, "spheres", N_RAYS / 4, 0, &ties);
        print_message("spheres: %d rays, %ld hit\n", N_RAYS / 4, hits);
        assert_true(hits > N_RAYS / 100);
    }
    soup_free(&s);
}

static void test_shared_vertices_vs_brute_force(void **state)
{
    enum { N_RAYS = 40000, GRID = 24 };
    soup s;
    long hits, ties;
    rs_bvh *b;
    wide w;
    (void)state;
    soup_grid(&s, GRID, 0x9e1d);
    /* a triangles-only scene: with Möller-Trumbore every wide leaf is packed */
    b = build(&s.g, 4);
    w = collapse(b, &s.g);
#ifdef RS_BVH4_SSE
    assert_true(w.b4->n_packed > 0);
    assert_true(w.b4->n_tri4 >= (s.g.n_tris + 3) / 4);
#endif
    wide_free(&w);
    rs_bvh_destroy(b);
    hits = check_vs_brute_force(&s, "grid", N_RAYS, GRID, &ties);
    print_message("grid: %d rays, %ld hit, %ld at a t that several triangles share\n", N_RAYS, hits,
                  ties);
    assert_true(hits > N_RAYS * 3 / 4);
    /* the tie rule was exercised */
    assert_true(ties > 100);
    soup_free(&s);
}

/* ---- packets: eight rays walked together (rs_bvh8_trace_packets) ---------------------------- */

enum { PK_RAYS = 6003 }; /* not a multiple of eight: the last packet is short */

/* Ray i of the packet test.  Groups of eight in three kinds: a shared origin and nearly the same
 * direction (a row of camera rays: the packet stays together), a shared origin and any direction
 * (a diffuse bounce: it parts), or nothing shared; over a grid (grid > 0) the first kind aims at
 * neighbouring vertices, where several triangles share the closest t.  Some lanes have a zero
 * direction component (walked alone), a tmin > 0 or a short tmax. */
static rs_ray packet_ray(uint64_t *s, long i, const soup *sp, uint32_t grid, float extent,
                         rs_vec3 *o, rs_vec3 *d0)
{
    long lane = i % 8, kind = (i / 8) % 3;
    rs_vec3 d;
    float tmin = 0.0f, tmax = T_INF;
    if (lane == 0) {
        *o = grid ? rs_v3(rnd_range(s, 0.0, grid), rnd_range(s, 3.0, 20.0), rnd_range(s, 0.0, grid))
                  : rnd_box(s, 1.5f * extent);
        *d0 = rs_v3_sub(rnd_box(s, 0.5f * extent), *o);
    }
    if (kind == 0 && grid) {
        const rs_tri *t = &sp->tris[((uint32_t)(*o).x * 2u * grid + (uint32_t)(*o).z * 2u +
                                     (uint32_t)lane) %
                                    sp->g.n_tris];
        d = rs_v3_sub(lane & 1 ? t->v1 : t->v0, *o);
    } else if (kind == 0) {
        d = rs_v3_add(*d0, rnd_box(s, 0.02f * rs_v3_length(*d0)));
    } else if (kind == 1) {
        d = rnd_unit(s);
    } else {
        *o = rnd_box(s, 1.5f * extent);
        d = rs_v3_sub(rnd_box(s, extent), *o);
    }
    if (i % 29 == 7) {
        d.x = 0.0f;
        if (rs_v3_is_zero(d))
            d.y = 1.0f;
    }
    if (i % 13 == 4)
        tmin = rnd_range(s, 0.0, extent);
    if (i % 11 == 3)
        tmax = rnd_range(s, 0.0, 2.0 * extent);
    return mk_ray(*o, d, tmin, tmax);
}

/* rs_bvh8_trace_packets against rs_bvh8_trace, and rs_bvh8_trace (which makes eight rays' 1 / d
 * at once) against rs_bvh8_closest and rs_bvh8_occluded ray by ray (checked against brute force
 * above): the same closest hit, bit for bit, and the same occlusion, for rays cut into packets
 * from offset 0 and from offset 3.  Returns the rays that hit. */
static long expect_packets_match(const rs_bvh8 *b8, const rs_geom *g, const soup *sp,
                                 uint32_t grid, float extent, const char *what)
{
    rs_trace_batch one, pk;
    rs_vec3 o = rs_v3(0, 0, 0), d0 = rs_v3(0, 0, 1);
    uint64_t rs = 0x9ac7e75;
    uint32_t i, from;
    long hits = 0;
    memset(&one, 0, sizeof one);
    memset(&pk, 0, sizeof pk);
    assert_int_equal(rs_ray_soa_init(&one.rays, PK_RAYS), RS_OK);
    assert_int_equal(rs_hit_soa_init(&one.hits, PK_RAYS), RS_OK);
    assert_int_equal(rs_hit_soa_init(&pk.hits, PK_RAYS), RS_OK);
    one.occluded = (uint8_t *)calloc(PK_RAYS, 1);
    pk.occluded = (uint8_t *)calloc(PK_RAYS, 1);
    assert_non_null(one.occluded);
    assert_non_null(pk.occluded);
    for (i = 0; i < PK_RAYS; ++i) {
        rs_ray r = packet_ray(&rs, i, sp, grid, extent, &o, &d0);
        rs_ray_soa_set(&one.rays, i, &r, i);
    }
    one.count = pk.count = PK_RAYS;
    pk.rays = one.rays;
    for (from = 0; from <= 3; from += 3) {
        one.kind = pk.kind = RS_TRACE_CLOSEST;
        rs_bvh8_trace(b8, g, &one, from, PK_RAYS);
        rs_bvh8_trace_packets(b8, g, &pk, from, PK_RAYS);
        one.kind = pk.kind = RS_TRACE_OCCLUDED;
        rs_bvh8_trace(b8, g, &one, from, PK_RAYS);
        rs_bvh8_trace_packets(b8, g, &pk, from, PK_RAYS);
        for (i = from; i < PK_RAYS; ++i) {
            rs_hit a = rs_hit_soa_get(&one.hits, i), b = rs_hit_soa_get(&pk.hits, i);
            if (memcmp(&a, &b, sizeof a) != 0 || one.occluded[i] != pk.occluded[i]) {
                char ray[256];
                rs_ray r = rs_ray_soa_get(&one.rays, i);
                describe_ray(ray, sizeof ray, &r);
                fail_msg("%s, ray %u (packets from %u): packets prim %u t %.9g u %.9g v %.9g "
                         "occluded %d, alone prim %u t %.9g u %.9g v %.9g occluded %d; %s",
                         what, i, from, b.prim, b.t, b.u, b.v, pk.occluded[i], a.prim, a.t, a.u,
                         a.v, one.occluded[i], ray);
            }
            hits += from == 0 && a.prim != RS_NO_HIT;
            {
                rs_hit c;
                rs_ray r = rs_ray_soa_get(&one.rays, i);
                rs_bvh8_closest(b8, g, r, &c);
                if (memcmp(&a, &c, sizeof a) != 0 || one.occluded[i] != rs_bvh8_occluded(b8, g, r))
                    fail_msg("%s, ray %u (from %u): rs_bvh8_trace prim %u t %.9g occluded %d, "
                             "rs_bvh8_closest prim %u t %.9g, rs_bvh8_occluded %d",
                             what, i, from, a.prim, a.t, one.occluded[i], c.prim, c.t,
                             rs_bvh8_occluded(b8, g, r));
            }
        }
    }
    free(one.occluded);
    free(pk.occluded);
    rs_ray_soa_free(&one.rays);
    rs_hit_soa_free(&one.hits);
    rs_hit_soa_free(&pk.hits);
    return hits;
}

/* The packet walk on each kind of leaf: triangles, parallelograms and spheres packed in blocks,
 * all three mixed, the watertight test's unpacked leaves, and a grid whose rays meet vertices
 * (ties broken by primitive number whatever the order of the visit). */
static void test_packets_match_single(void **state)
{
    soup s, q;
    long hits;
    int k;
    (void)state;
    if (!rs_bvh8_supported()) {
        print_message("this CPU has no AVX2: the 8-wide packets are not tested\n");
        return;
    }
    soup_random(&s, 0x9acc);
    for (k = 0; k < 5; ++k) {
        static const char *const name[5] = {"mixed soup", "triangles", "parallelograms",
                                            "spheres", "watertight triangles"};
        rs_bvh *b;
        rs_bvh8 *b8 = NULL;
        q = s;
        if (k == 1 || k == 4)
            q.g.n_spheres = q.g.n_quads = 0;
        if (k == 2)
            q.g.n_spheres = q.g.n_tris = 0;
        if (k == 3)
            q.g.n_quads = q.g.n_tris = 0;
        if (k == 4)
            q.g.tri_algo = RS_ISECT_TRI_WATERTIGHT;
        b = build_sah_blocks(&q.g, 8, 8);
        assert_int_equal(rs_bvh8_build(b, &q.g, &b8), RS_OK);
        assert_true(k == 4 ? b8->n_packed == 0 : b8->n_packed > 0);
        hits = expect_packets_match(b8, &q.g, &q, 0, SOUP, name[k]);
        print_message("packets, %s: %d rays, %ld hit\n", name[k], PK_RAYS, hits);
        assert_true(hits > PK_RAYS / 20 && hits < PK_RAYS - PK_RAYS / 20);
        rs_bvh8_destroy(b8);
        rs_bvh_destroy(b);
    }
    soup_free(&s);
    {
        enum { GRID = 24 };
        rs_bvh *b;
        rs_bvh8 *b8 = NULL;
        soup_grid(&s, GRID, 0x9e1d);
        b = build_sah_blocks(&s.g, 8, 8);
        assert_int_equal(rs_bvh8_build(b, &s.g, &b8), RS_OK);
        hits = expect_packets_match(b8, &s.g, &s, GRID, (float)GRID, "grid");
        print_message("packets, grid: %d rays, %ld hit\n", PK_RAYS, hits);
        assert_true(hits > PK_RAYS / 3);
        rs_bvh8_destroy(b8);
        rs_bvh_destroy(b);
        soup_free(&s);
    }
}

/* ---- edge cases ---------------------------------------------------------------------------- */

static void test_empty(void **state)
{
    rs_geom g;
    rs_bvh *b = NULL;
    rs_bvh_view v;
    rs_hit h;
    uint64_t s = 3;
    int i;
    (void)state;
    memset(&g, 0, sizeof g);
    assert_int_equal(rs_bvh_build(&g, NULL, &b), RS_OK);
    assert_non_null(b);
    assert_int_equal(b->n_nodes, 0);
    assert_int_equal(b->n_prims, 0);
    v = rs_bvh_view_of(b);
    assert_int_equal(v.n_nodes, 0);
    for (i = 0; i < 100; ++i) {
        rs_ray r = mk_ray(rnd_box(&s, 10.0f), rnd_unit(&s), 0.0f, T_INF);
        h.prim = 7;
        assert_int_equal(rs_bvh_closest(&v, &g, r, &h), 0);
        assert_int_equal(h.prim, RS_NO_HIT);
        assert_int_equal(rs_bvh_occluded(&v, &g, r), 0);
    }
    {
        wide w = collapse(b, &g);
        rs_ray r = mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF);
        int k;
        assert_int_equal(w.b4->n_nodes, 0);
        assert_int_equal(w.b8->n_nodes, 0);
        for (k = 0; k < n_wide_kernels(); ++k) {
            assert_int_equal(wide_closest(&w, k, &g, r, &h), 0);
            assert_int_equal(h.prim, RS_NO_HIT);
            assert_int_equal(wide_occluded(&w, k, &g, r), 0);
        }
        wide_free(&w);
    }
    rs_bvh_destroy(b);
}

static void test_single_primitive(void **state)
{
    int kind;
    (void)state;
    for (kind = 0; kind < 3; ++kind) {
        soup s;
        rs_bvh *b;
        rs_bvh_view v;
        rs_hit h;
        soup_alloc(&s, kind == 0, kind == 1, kind == 2);
        s.spheres[0].center = rs_v3(0, 0, -5);
        s.spheres[0].radius = 1.0f;
        s.quads[0] = rs_quad_make(rs_v3(-1, -1, -5), rs_v3(2, 0, 0), rs_v3(0, 2, 0));
        s.tris[0].v0 = rs_v3(-1, -1, -5);
        s.tris[0].v1 = rs_v3(2, -1, -5);
        s.tris[0].v2 = rs_v3(-1, 2, -5);
        b = build(&s.g, 0);
        check_structure(b, &s.g, 4);
        assert_int_equal(b->n_nodes, 1);
        assert_int_equal(b->nodes[0].count, 1);
        assert_int_equal(b->prim_ids[0], 0);
        v = rs_bvh_view_of(b);
        assert_int_equal(
            rs_bvh_closest(&v, &s.g, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &h), 1);
        assert_int_equal(h.prim, 0);
        assert_true(h.t == (kind == 0 ? 4.0f : 5.0f));
        assert_int_equal(
            rs_bvh_occluded(&v, &s.g, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF)), 1);
        /* blocked only inside (tmin, tmax) */
        assert_int_equal(
            rs_bvh_occluded(&v, &s.g, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, 3.5f)), 0);
        assert_int_equal(
            rs_bvh_closest(&v, &s.g, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, 3.5f), &h), 0);
        assert_int_equal(h.prim, RS_NO_HIT);
        /* misses */
        assert_int_equal(
            rs_bvh_closest(&v, &s.g, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &h), 0);
        assert_int_equal(
            rs_bvh_occluded(&v, &s.g, mk_ray(rs_v3(5, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF)), 0);
        {
            /* a tree that is one leaf: a wide root with one leaf lane */
            wide w = collapse(b, &s.g);
            int k;
            assert_int_equal(w.b4->n_nodes, 1);
            assert_int_equal(w.b4->nodes[0].n_lanes, 1);
            assert_int_equal(w.b8->n_nodes, 1);
            assert_int_equal(w.b8->nodes[0].n_lanes, 1);
            for (k = 0; k < n_wide_kernels(); ++k) {
                rs_ray down = mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF);
                assert_int_equal(wide_closest(&w, k, &s.g, down, &h), 1);
                assert_int_equal(h.prim, 0);
                assert_true(h.t == (kind == 0 ? 4.0f : 5.0f));
                assert_int_equal(wide_occluded(&w, k, &s.g, down), 1);
                down.tmax = 3.5f;
                assert_int_equal(wide_closest(&w, k, &s.g, down, &h), 0);
                assert_int_equal(wide_occluded(&w, k, &s.g, down), 0);
            }
            wide_free(&w);
        }
        rs_bvh_destroy(b);
        soup_free(&s);
    }
}

static void test_identical_centroids(void **state)
{
    /* 400 spheres, 300 quads and 300 triangles all centred on (1, 2, 3): the median split
     * cannot separate them by position, and the build must still end with a correct tree */
    soup s;
    uint64_t seed = 0xce27;
    rs_vec3 c = rs_v3(1, 2, 3);
    uint32_t i;
    long j;
    size_t k;
    static const uint32_t leaf_sizes[] = {1, 4, 8};
    (void)state;
    soup_alloc(&s, 400, 300, 300);
    fill_identical_centroids(s.spheres, s.g.n_spheres, s.quads, s.g.n_quads, s.tris, s.g.n_tris, c);
    for (i = 0; i < rs_geom_prim_count(&s.g); ++i) {
        rs_aabb b = rs_geom_prim_bounds(&s.g, i);
        rs_vec3 m = rs_v3_scale(rs_v3_add(b.lo, b.hi), 0.5f);
        assert_true(m.x == c.x && m.y == c.y && m.z == c.z);
    }
    for (k = 0; k < 3; ++k) {
        rs_bvh *b = build(&s.g, leaf_sizes[k]);
        wide w = collapse(b, &s.g);
        check_structure(b, &s.g, leaf_sizes[k]);
        for (j = 0; j < 5000; ++j) {
            rs_ray r = mk_ray(rs_v3_add(c, rnd_box(&seed, 12.0f)), rnd_unit(&seed), 0.0f, T_INF);
            rs_hit ref;
            int ref_hit;
            if (j % 2)
                r.d = rs_v3_sub(rs_v3_add(c, rnd_box(&seed, 2.0f)), r.o);
            ref_hit = brute_closest(&s.g, &r, &ref);
            expect_same_hit(b, &w, &s.g, &r, &ref, ref_hit, "identical centroids", j);
        }
        wide_free(&w);
        rs_bvh_destroy(b);
    }
    soup_free(&s);
}

static void on_alarm(int sig)
{
    (void)sig;
    /* only async-signal-safe calls here */
    static const char msg[] = "accel_bvh_test: traversal of a NaN/Inf ray did not return\n";
    ssize_t w = write(2, msg, sizeof msg - 1);
    (void)w;
    _exit(1);
}

static void test_nan_inf_rays_terminate(void **state)
{
    /* Any answer is accepted, but each query must return (an alarm fails the test after 20 s),
     * and a reported hit must name a real primitive. */
    static const float specials[] = {NAN, INFINITY, -INFINITY, 0.0f, -0.0f, 1.0f};
    const int n_special = (int)(sizeof specials / sizeof specials[0]);
    soup s;
    rs_bvh *b;
    wide w;
    rs_bvh_view v;
    uint64_t seed = 0x7a7;
    int a, c, e, f, n = 0;
    (void)state;
    soup_random(&s, 0x5eed);
    b = build(&s.g, 0);
    w = collapse(b, &s.g);
    v = rs_bvh_view_of(b);
    signal(SIGALRM, on_alarm);
    alarm(20);
    for (a = 0; a < n_special; ++a)
        for (c = 0; c < n_special; ++c)
            for (e = 0; e < n_special; ++e)
                for (f = 0; f < 4; ++f) {
                    rs_vec3 o = f == 3 ? rs_v3(NAN, 0, 0) : rnd_box(&seed, SOUP);
                    rs_ray r = mk_ray(o, rs_v3(specials[a], specials[c], specials[e]), 0.0f,
                                      f == 1 ? NAN : (f == 2 ? INFINITY : T_INF));
                    rs_hit h;
                    int hit = rs_bvh_closest(&v, &s.g, r, &h);
                    int occ = rs_bvh_occluded(&v, &s.g, r);
                    int k;
                    assert_true(hit == 0 || hit == 1);
                    assert_true(occ == 0 || occ == 1);
                    if (hit)
                        assert_true(h.prim < rs_geom_prim_count(&s.g));
                    else
                        assert_int_equal(h.prim, RS_NO_HIT);
                    /* the wide kernels: the same answer, whatever it is */
                    for (k = 0; k < n_wide_kernels(); ++k) {
                        rs_hit hw;
                        assert_int_equal(wide_closest(&w, k, &s.g, r, &hw), hit);
                        assert_int_equal(wide_occluded(&w, k, &s.g, r), occ);
                        assert_int_equal(hw.prim, h.prim);
                    }
                    ++n;
                }
    alarm(0);
    signal(SIGALRM, SIG_DFL);
    print_message("%d NaN/Inf rays returned\n", n);
    wide_free(&w);
    rs_bvh_destroy(b);
    soup_free(&s);
}

/* An axis-aligned ray lying exactly in the scene's bounding plane x = 0 (the root's lo.x) hits a
 * triangle's edge in that plane, and a Cornell-style floor quad's edge.  Brute force finds both
 * hits; the BVH must too (its root box is hit with a ray on its face: see core/intersect.h's
 * promise for rays in a slab plane). */
static void test_ray_in_bounding_plane(void **state)
{
    soup s;
    rs_bvh *b;
    rs_bvh_view v;
    rs_hit h, ref;
    rs_ray r;
    int failures = 0;
    (void)state;
    soup_alloc(&s, 1, 1, 1);
    s.spheres[0].center = rs_v3(3, 0, 3);
    s.spheres[0].radius = 0.5f;
    /* a floor y = -2 spanning x in [0, 4], z in [0, 4] */
    s.quads[0] = rs_quad_make(rs_v3(0, -2, 0), rs_v3(4, 0, 0), rs_v3(0, 0, 4));
    /* edge v0-v1 in the plane x = 0 */
    s.tris[0].v0 = rs_v3(0, -1, 1);
    s.tris[0].v1 = rs_v3(0, 1, 1);
    s.tris[0].v2 = rs_v3(1, 0, 1);
    b = build(&s.g, 1);
    v = rs_bvh_view_of(b);
    assert_true(b->nodes[0].lo.x == 0.0f);
    /* along +z in the plane x = 0: meets the triangle's edge at (0, 0, 1), t = 6 */
    r = mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF);
    assert_int_equal(brute_closest(&s.g, &r, &ref), 1);
    assert_int_equal(ref.prim, 2);
    assert_true(ref.t == 6.0f);
    if (!rs_bvh_closest(&v, &s.g, r, &h) || h.prim != ref.prim || h.t != ref.t)
        ++failures, print_message("ray in the plane x = 0 along +z: bvh prim %u t %g, brute "
                                  "force prim %u t %g (triangle edge)\n",
                                  h.prim, h.t, ref.prim, ref.t);
    if (!rs_bvh_occluded(&v, &s.g, r))
        ++failures, print_message("ray in the plane x = 0 along +z: not occluded\n");
    /* down the wall plane x = 0 onto the floor's edge at (0, -2, 2), t = 2 */
    r = mk_ray(rs_v3(0, 2, 2), rs_v3(0, -2, 0), 0.0f, T_INF);
    assert_int_equal(brute_closest(&s.g, &r, &ref), 1);
    assert_int_equal(ref.prim, 1);
    assert_true(ref.t == 2.0f);
    if (!rs_bvh_closest(&v, &s.g, r, &h) || h.prim != ref.prim || h.t != ref.t)
        ++failures, print_message("ray in the plane x = 0 along -y: bvh prim %u t %g, brute "
                                  "force prim %u t %g (floor edge)\n",
                                  h.prim, h.t, ref.prim, ref.t);
    if (!rs_bvh_occluded(&v, &s.g, r))
        ++failures, print_message("ray in the plane x = 0 along -y: not occluded\n");
    {
        /* the wide kernels on both rays */
        wide w = collapse(b, &s.g);
        rs_ray rays[2];
        int k, kw;
        rays[0] = mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF);
        rays[1] = mk_ray(rs_v3(0, 2, 2), rs_v3(0, -2, 0), 0.0f, T_INF);
        for (kw = 0; kw < n_wide_kernels(); ++kw)
            for (k = 0; k < 2; ++k) {
                brute_closest(&s.g, &rays[k], &ref);
                if (!wide_closest(&w, kw, &s.g, rays[k], &h) || h.prim != ref.prim ||
                    h.t != ref.t)
                    ++failures, print_message("%s, ray %d in the plane x = 0: prim %u t %g, "
                                              "brute force prim %u t %g\n",
                                              wide_name(kw), k, h.prim, h.t, ref.prim, ref.t);
                if (!wide_occluded(&w, kw, &s.g, rays[k]))
                    ++failures, print_message("%s, ray %d in the plane x = 0: not occluded\n",
                                              wide_name(kw), k);
            }
        wide_free(&w);
    }
    rs_bvh_destroy(b);
    soup_free(&s);
    if (failures)
        fail_msg("%d queries along the scene's bounding plane disagree with brute force",
                 failures);
}

/* Instances in the wide trees: each prototype's bottom level is collapsed once (instances of one
 * prototype share a wide root) and walked by the same wide walk as the top tree, the ray in the
 * instance's object space; the hits are the binary two-level walk's bit for bit (t, u, v,
 * primitive), rays ending among the instances included, and the any-hit answers agree. */
static void test_wide_instances(void **state)
{
    rs_scene *s = NULL;
    rs_material m = rs_mat_lambertian(rs_v3(.5f, .5f, .5f));
    uint32_t mat, first[2], count[2], i, k;
    uint64_t rng = 0x1a57a2ce;
    /* two prototypes: a cloud of 300 small triangles (a bottom level of several wide nodes) and
     * a single triangle (a bottom level that is one leaf) */
    static const double place[5][12] = {
        {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0},
        {0.8, -0.6, 0, 2.5, 0.6, 0.8, 0, 0.25, 0, 0, 1, -1},
        {-1, 0, 0, -2.5, 0, 2, 0, 0, 0, 0, 0.5, 1.5},
        {1, 0, 0, 0, 0, 1, 0, 3, 0, 0, 1, 0},
        {0.5, 0.1, 0, -1, 0, 0.5, 0.2, 1, 0.3, 0, 0.5, -2}};
    rs_geom g;
    rs_bvh *b = NULL;
    rs_bvh4 *b4 = NULL;
    rs_bvh8 *b8 = NULL;
    rs_bvh_view v;
    long hits = 0, inst_hits = 0;
    (void)state;
    assert_int_equal(rs_scene_create("wide-instances", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &m, &mat), RS_OK);
    for (k = 0; k < 2; ++k) {
        uint32_t from = s->n_tris, n = k == 0 ? 300 : 1;
        for (i = 0; i < n; ++i) {
            rs_vec3 c = rnd_box(&rng, 1.0f);
            assert_int_equal(rs_scene_add_triangle(s, c, rs_v3_add(c, rnd_box(&rng, 0.2f)),
                                                   rs_v3_add(c, rnd_box(&rng, 0.2f)), mat),
                             RS_OK);
        }
        assert_int_equal(rs_scene_make_prototype(s, from, &first[k], &count[k]), RS_OK);
    }
    for (i = 0; i < 5; ++i)
        assert_int_equal(rs_scene_add_instance(s, first[i == 3], count[i == 3], place[i]), RS_OK);
    /* and triangles of the scene's own, in the same top tree */
    for (i = 0; i < 50; ++i) {
        rs_vec3 c = rnd_box(&rng, 3.0f);
        assert_int_equal(rs_scene_add_triangle(s, c, rs_v3_add(c, rnd_box(&rng, 0.3f)),
                                               rs_v3_add(c, rnd_box(&rng, 0.3f)), mat),
                         RS_OK);
    }
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    g = rs_scene_geom(s);
    assert_int_equal(g.n_instances, 5);
    assert_int_equal(rs_bvh_build(&g, NULL, &b), RS_OK);
    rs_bvh_attach(b, &g);
    assert_int_equal(rs_bvh4_build(b, &g, &b4), RS_OK);
    assert_non_null(b4->inst_root);
    /* one bottom level per prototype: instances 0, 1, 2 and 4 share theirs */
    assert_int_equal(b4->inst_root[0], b4->inst_root[1]);
    assert_int_equal(b4->inst_root[0], b4->inst_root[4]);
    assert_true(b4->inst_root[0] != b4->inst_root[3]);
    for (i = 0; i < 5; ++i)
        assert_true(b4->inst_root[i] > 0 && b4->inst_root[i] < b4->n_nodes);
    if (rs_bvh8_supported()) {
        assert_int_equal(rs_bvh8_build(b, &g, &b8), RS_OK);
        assert_int_equal(b8->inst_root[0], b8->inst_root[2]);
        assert_true(b8->inst_root[0] != b8->inst_root[3]);
    }
    v = rs_bvh_view_of(b);
    for (i = 0; i < 20000; ++i) {
        rs_vec3 o = rnd_box(&rng, 6.0f), to = rnd_box(&rng, 3.0f);
        rs_ray r = mk_ray(o, rs_v3_sub(to, o), 1e-4f, i % 3 == 0 ? 0.9f : T_INF);
        rs_hit want, got;
        int occ;
        rs_bvh_closest(&v, &g, r, &want);
        occ = rs_bvh_occluded(&v, &g, r);
        assert_int_equal(occ, want.prim != RS_NO_HIT);
        rs_bvh4_closest(b4, &g, r, &got);
        if (memcmp(&got, &want, sizeof got) != 0)
            fail_msg("ray %u, 4-wide: prim %u t %.9g, binary prim %u t %.9g", i, got.prim, got.t,
                     want.prim, want.t);
        assert_int_equal(rs_bvh4_occluded(b4, &g, r), occ);
        if (b8) {
            rs_bvh8_closest(b8, &g, r, &got);
            if (memcmp(&got, &want, sizeof got) != 0)
                fail_msg("ray %u, 8-wide: prim %u t %.9g, binary prim %u t %.9g", i, got.prim,
                         got.t, want.prim, want.t);
            assert_int_equal(rs_bvh8_occluded(b8, &g, r), occ);
        }
        hits += occ;
        inst_hits += want.prim != RS_NO_HIT && want.prim >= rs_geom_own_count(&g);
    }
    print_message("wide instances: 20000 rays, %ld hit, %ld on instances\n", hits, inst_hits);
    if (b8) /* the packet walk takes instances' leaves one lane at a time, the same answers */
        assert_true(expect_packets_match(b8, &g, NULL, 0, 3.0f, "instances") > PK_RAYS / 20);
    assert_true(inst_hits > 2000); /* the rays do reach the instances */
    rs_bvh8_destroy(b8);
    rs_bvh4_destroy(b4);
    rs_bvh_destroy(b);
    rs_scene_destroy(s);
}

static void test_build_out_of_memory(void **state)
{
    /* Fail each allocation of the build in turn: the build reports RS_ERR_NOMEM, hands back
     * NULL, and (under the sanitizer build) leaks nothing.  Past the last allocation it
     * succeeds. */
    soup s;
    long k;
    int succeeded = 0;
    (void)state;
    soup_random(&s, 0x5eed);
    for (k = 0; k < 16 && !succeeded; ++k) {
        rs_bvh *b = (rs_bvh *)(uintptr_t)1;
        rs_status st;
        rs_error_clear();
        rs_alloc_fail_after(k);
        st = rs_bvh_build(&s.g, NULL, &b);
        rs_alloc_fail_after(-1);
        if (st == RS_OK) {
            assert_non_null(b);
            check_structure(b, &s.g, 4);
            rs_bvh_destroy(b);
            succeeded = 1;
        } else {
            assert_int_equal(st, RS_ERR_NOMEM);
            assert_null(b);
            assert_true(rs_error_message()[0] != '\0');
        }
    }
    rs_error_clear();
    assert_true(succeeded);
    assert_true(k > 1);
    /* the same for the collapse to 4-wide nodes */
    {
        rs_bvh *b = build(&s.g, 4);
        for (succeeded = 0, k = 0; k < 8 && !succeeded; ++k) {
            rs_bvh4 *b4 = (rs_bvh4 *)(uintptr_t)1;
            rs_status st;
            rs_alloc_fail_after(k);
            st = rs_bvh4_build(b, &s.g, &b4);
            rs_alloc_fail_after(-1);
            if (st == RS_OK) {
                assert_non_null(b4);
                assert_true(b4->n_nodes >= 1 && b4->depth <= b->depth);
                rs_bvh4_destroy(b4);
                succeeded = 1;
            } else {
                assert_int_equal(st, RS_ERR_NOMEM);
                assert_null(b4);
            }
        }
        rs_error_clear();
        assert_true(succeeded);
        assert_true(k > 1);
        /* and to 8-wide nodes */
        for (succeeded = 0, k = 0; k < 8 && !succeeded; ++k) {
            rs_bvh8 *b8 = (rs_bvh8 *)(uintptr_t)1;
            rs_status st;
            rs_alloc_fail_after(k);
            st = rs_bvh8_build(b, &s.g, &b8);
            rs_alloc_fail_after(-1);
            if (st == RS_OK) {
                assert_non_null(b8);
                assert_true(b8->n_nodes >= 1 && b8->depth <= b->depth);
                rs_bvh8_destroy(b8);
                succeeded = 1;
            } else {
                assert_int_equal(st, RS_ERR_NOMEM);
                assert_null(b8);
            }
        }
        rs_error_clear();
        assert_true(succeeded);
        assert_true(k > 1);
        rs_bvh_destroy(b);
    }
    soup_free(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_structure),
        cmocka_unit_test(test_random_rays_vs_brute_force),
        cmocka_unit_test(test_shared_vertices_vs_brute_force),
        cmocka_unit_test(test_packets_match_single),
        cmocka_unit_test(test_empty),
        cmocka_unit_test(test_single_primitive),
        cmocka_unit_test(test_identical_centroids),
        cmocka_unit_test(test_nan_inf_rays_terminate),
        cmocka_unit_test(test_ray_in_bounding_plane),
        cmocka_unit_test(test_wide_instances),
        cmocka_unit_test(test_build_out_of_memory),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
