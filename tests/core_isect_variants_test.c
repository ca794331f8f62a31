/* tests/core_isect_variants_test.c — the intersection variants of core/intersect.h (thesis §5.6):
 * ray/sphere algebraic and geometric; ray/triangle Möller–Trumbore, Snyder–Barr and watertight
 * (Woop et al. 2013); ray/box slab, branchless, williams, kensler and swap.
 *
 * What is checked, for every variant (called through the rs_isect_*_by dispatch):
 *   - analytic cases: head-on hits and their t (also for non-unit directions), barycentrics at
 *     known points, both faces, parallel rays, origins inside, the open interval (tmin, tmax) of
 *     the primitive tests and the closed [tmin, tmax] of the box tests, zero-thickness boxes,
 *     NaN and zero directions;
 *   - 10^6 random rays per family against a double-precision reference written here: hit / miss
 *     agree outside a stated band around silhouettes, edges, tmin and tmax, t to a relative 1e-4
 *     (of at least 1% of the distances involved: see compare()) and (u, v) to 1e-3;
 *   - watertightness: 4 x 10^5 rays aimed exactly at points on shared edges and at shared vertices
 *     of a closed icosphere and of an interior of a bumpy height-field grid; the watertight test
 *     must hit at least one triangle of the edge's / vertex's fan every time; the misses of
 *     Möller–Trumbore and Snyder–Barr are counted and printed, not asserted;
 *   - boxes: 10^6 random rays and boxes (zero direction components, zero-thickness boxes, tmin /
 *     tmax cuts): every variant gives the slab test's answer and the same entry distance; rays
 *     lying exactly in a face plane (0 * inf = NaN) follow each variant's documented rule;
 *   - the name tables and parsers.
 * Random inputs come from tests/test_rand.h (fixed seeds). */
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

#include "core/intersect.h"

#include "test_isect_ref.h"
#include "test_rand.h"

#define T_INF    FLT_MAX
#define SENTINEL (-12345.0f)

enum { N_RANDOM = 1000000, N_WT_RAYS = 100000 };

/* ---- helpers ------------------------------------------------------------------------------- */

static void v3_set(rs_vec3 *v, int axis, float x)
{
    if (axis == 0)
        v->x = x;
    else if (axis == 1)
        v->y = x;
    else
        v->z = x;
}

/* The variants write their outputs only on a hit: each call starts from sentinels, and a miss
 * must leave them there. */
static int sphere_hit(uint32_t algo, const rs_sphere *s, rs_ray r, float *t)
{
    int h;
    *t = SENTINEL;
    h = rs_isect_sphere_by(algo, s, &r, t);
    if (!h && *t != SENTINEL)
        fail_msg("sphere %s wrote t on a miss", rs_isect_sphere_algo_name(algo));
    return h;
}

static int tri_hit(uint32_t algo, const rs_tri *tr, rs_ray r, float *t, float *u, float *v)
{
    int h;
    *t = *u = *v = SENTINEL;
    h = rs_isect_tri_by(algo, tr, &r, t, u, v);
    if (!h && (*t != SENTINEL || *u != SENTINEL || *v != SENTINEL))
        fail_msg("triangle %s wrote outputs on a miss", rs_isect_tri_algo_name(algo));
    return h;
}

static int box_hit(uint32_t algo, rs_aabb b, rs_vec3 o, rs_vec3 d, float tmin, float tmax,
                   float *te)
{
    *te = SENTINEL;
    return rs_isect_aabb_by(algo, &b, o, inv_dir(d), tmin, tmax, te);
}

/* ---- double-precision references ---------------------------------------------------------- */

/* A random ray: the origin anywhere in [-10, 10]^3; usually aimed at `target` (a point near the
 * primitive), with a random length of direction; now and then a fully random direction, a
 * positive tmin, or a tmax cut somewhere around the target. */
static rs_ray random_ray(uint64_t *s, rs_vec3 target)
{
    rs_vec3 o = rnd_box(s, 10.0f), d;
    float tmin = 0.0f, tmax = T_INF, k = rnd_range(s, 0.25, 4.0);
    if (rnd01(s) < 0.2)
        d = rs_v3_scale(rnd_unit(s), k);
    else
        d = rs_v3_scale(rs_v3_sub(target, o), k);
    if (rnd01(s) < 0.2)
        tmin = rnd_range(s, 0.0, 0.5) / k;
    if (rnd01(s) < 0.25)
        tmax = rnd_range(s, 0.5, 1.5) / k;
    return mk_ray(o, d, tmin, tmax);
}

typedef struct cmp_stats {
    int rays, ambiguous, hits, misses, failures;
    double max_rel_t, max_uv;
} cmp_stats;

/* Compares one answer with the reference; failures are counted (the first few printed) so that
 * one bad variant reports how often it is wrong rather than only its first ray.  t must agree to
 * a relative 1e-4, measured against max(|t|, 1e-2 scale): for a hit nearer than 1% of the
 * distances involved (an origin within 1% of the surface) that is 1e-6 of those distances, a few
 * float ulps of the inputs, which is all they resolve (both sphere methods subtract two nearly
 * equal terms of that size for such a root). */
static void compare(cmp_stats *st, const char *what, int i, int got, float t, float u, float v,
                    ref_result ref, int check_uv)
{
    const char *why = NULL;
    double rel = 0.0, e = 0.0;
    ++st->rays;
    if (ref.ambiguous) {
        ++st->ambiguous;
        if (got && !(t > 0.0f || t <= 0.0f))
            why = "hit with a NaN t";
    } else if (got != ref.hit) {
        why = got ? "hit, the reference misses" : "missed, the reference hits";
    } else if (!got) {
        ++st->misses;
    } else {
        ++st->hits;
        rel = fabs(t - ref.t) / fmax(fabs(ref.t), 1e-2 * ref.scale);
        if (rel > st->max_rel_t)
            st->max_rel_t = rel;
        if (!(rel <= 1e-4))
            why = "t differs";
        if (check_uv) {
            e = fmax(fabs(u - ref.u), fabs(v - ref.v));
            if (e > st->max_uv)
                st->max_uv = e;
            if (!(e <= 1e-3))
                why = "(u, v) differ";
        }
    }
    if (why) {
        if (st->failures < 5)
            print_error("%s ray %d: %s: t %.9g (u %.7g v %.7g), reference %s t %.9g (u %.7g v "
                        "%.7g)\n",
                        what, i, why, t, u, v, ref.hit ? "hit" : "miss", ref.t, ref.u, ref.v);
        ++st->failures;
    }
}

static void report(const cmp_stats *st, const char *what)
{
    print_message("%-22s %d rays: %d hits, %d misses, %d in the band; max relative t error "
                  "%.3g, max (u, v) error %.3g; %d wrong\n",
                  what, st->rays, st->hits, st->misses, st->ambiguous, st->max_rel_t, st->max_uv,
                  st->failures);
}

static void check_stats(const cmp_stats *st, const char *what)
{
    if (st->failures)
        fail_msg("%s: %d of %d rays disagree with the reference", what, st->failures, st->rays);
    /* the band must stay narrow (under 4% of the rays), or the comparison would be vacuous */
    assert_true(st->ambiguous < st->rays / 25);
    assert_true(st->hits > st->rays / 10);
    assert_true(st->misses > st->rays / 10);
}

/* ---- names --------------------------------------------------------------------------------- */

static void test_names_and_parse(void **state)
{
    static const char *const sphere_names[] = {"algebraic", "geometric"};
    static const char *const tri_names[] = {"moller", "snyder-barr", "watertight"};
    static const char *const aabb_names[] = {"slab", "branchless", "williams", "kensler", "swap"};
    uint32_t a, out;
    (void)state;
    assert_int_equal(RS_ISECT_SPHERE_COUNT, 2);
    assert_int_equal(RS_ISECT_TRI_COUNT, 3);
    assert_int_equal(RS_ISECT_AABB_COUNT, 5);
    for (a = 0; a < RS_ISECT_SPHERE_COUNT; ++a) {
        assert_string_equal(rs_isect_sphere_algo_name(a), sphere_names[a]);
        out = 99;
        assert_true(rs_isect_sphere_algo_parse(sphere_names[a], &out));
        assert_int_equal(out, a);
    }
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a) {
        assert_string_equal(rs_isect_tri_algo_name(a), tri_names[a]);
        out = 99;
        assert_true(rs_isect_tri_algo_parse(tri_names[a], &out));
        assert_int_equal(out, a);
    }
    for (a = 0; a < RS_ISECT_AABB_COUNT; ++a) {
        assert_string_equal(rs_isect_aabb_algo_name(a), aabb_names[a]);
        out = 99;
        assert_true(rs_isect_aabb_algo_parse(aabb_names[a], &out));
        assert_int_equal(out, a);
    }
    assert_int_equal(RS_ISECT_SPHERE_ALGEBRAIC, 0);
    assert_int_equal(RS_ISECT_TRI_MOLLER, 0);
    assert_int_equal(RS_ISECT_AABB_SLAB, 0);
    assert_string_equal(rs_isect_sphere_algo_name(RS_ISECT_SPHERE_COUNT), "?");
    assert_string_equal(rs_isect_tri_algo_name(7), "?");
    assert_string_equal(rs_isect_aabb_algo_name(0xffffffffu), "?");
    /* unknown names, wrong case, prefixes and NULL are refused and leave *out alone */
    out = 42;
    assert_false(rs_isect_sphere_algo_parse("Algebraic", &out));
    assert_false(rs_isect_sphere_algo_parse("", &out));
    assert_false(rs_isect_tri_algo_parse("moller-trumbore", &out));
    assert_false(rs_isect_tri_algo_parse("snyder", &out));
    assert_false(rs_isect_aabb_algo_parse("slabs", &out));
    assert_false(rs_isect_aabb_algo_parse(NULL, &out));
    assert_int_equal(out, 42);
}

/* An unknown id runs the default; the dispatch returns what the direct call returns. */
static void test_dispatch(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0, 0, -5), 1.0f);
    rs_tri tr = mk_tri(rs_v3(-1, -1, -3), rs_v3(1, -1, -3), rs_v3(0, 1, -3));
    rs_aabb b = mk_box(rs_v3(-1, -1, -6), rs_v3(1, 1, -4));
    rs_ray r = mk_ray(rs_v3(0.1f, 0.05f, 0), rs_v3(0.01f, 0.02f, -1), 0.0f, T_INF);
    float t1, t2, u1, u2, v1, v2;
    (void)state;
    assert_true(rs_isect_sphere_by(77, &s, &r, &t1) && rs_isect_sphere(&s, &r, &t2));
    assert_true(t1 == t2);
    assert_true(rs_isect_sphere_by(RS_ISECT_SPHERE_GEOMETRIC, &s, &r, &t1) &&
                rs_isect_sphere_geometric(&s, &r, &t2));
    assert_true(t1 == t2);
    assert_true(rs_isect_tri_by(77, &tr, &r, &t1, &u1, &v1) &&
                rs_isect_tri(&tr, &r, &t2, &u2, &v2));
    assert_true(t1 == t2 && u1 == u2 && v1 == v2);
    assert_true(rs_isect_tri_by(RS_ISECT_TRI_SNYDER_BARR, &tr, &r, &t1, &u1, &v1) &&
                rs_isect_tri_snyder_barr(&tr, &r, &t2, &u2, &v2));
    assert_true(t1 == t2 && u1 == u2 && v1 == v2);
    assert_true(rs_isect_tri_by(RS_ISECT_TRI_WATERTIGHT, &tr, &r, &t1, &u1, &v1) &&
                rs_isect_tri_watertight(&tr, &r, &t2, &u2, &v2));
    assert_true(t1 == t2 && u1 == u2 && v1 == v2);
    assert_true(rs_isect_aabb_by(77, &b, r.o, inv_dir(r.d), 0.0f, T_INF, &t1) &&
                rs_isect_aabb(&b, r.o, inv_dir(r.d), 0.0f, T_INF, &t2));
    assert_true(t1 == t2);
}

/* ---- spheres ------------------------------------------------------------------------------- */

static void test_sphere_analytic(void **state)
{
    uint32_t a;
    (void)state;
    for (a = 0; a < RS_ISECT_SPHERE_COUNT; ++a) {
        rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 1.0f);
        const char *name = rs_isect_sphere_algo_name(a);
        float t;
        print_message("sphere %s\n", name);
        /* o = 0, d = -z: roots 4 and 6; t is in units of |d| */
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
        assert_true(t == 4.0f);
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -2), 0.0f, T_INF), &t));
        assert_true(t == 2.0f);
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -0.5f), 0.0f, T_INF), &t));
        assert_true(t == 8.0f);
        /* an oblique ray from (3, 0, -1) along (-0.6, 0, -0.8): closest approach 0, roots 4, 6 */
        assert_true(
            sphere_hit(a, &s, mk_ray(rs_v3(3, 0, -1), rs_v3(-0.6f, 0, -0.8f), 0, T_INF), &t));
        assert_float_equal(t, 4.0f, 1e-5f);
        /* misses: pointing away, passing beside */
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &t));
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 1.5f, 0), rs_v3(0, 0, -1), 0, T_INF), &t));
        /* from inside: the far side; from the centre: the radius */
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, -5.5f), rs_v3(0, 0, -1), 0, T_INF), &t));
        assert_float_equal(t, 0.5f, 1e-6f);
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0, T_INF), &t));
        assert_true(t == 1.0f);
        /* the open interval: roots 4 and 6 */
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, 4.0f), &t));
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 4.0f, T_INF), &t));
        assert_true(t == 6.0f);
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 6.0f, T_INF), &t));
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 4.5f, 5.9f), &t) ==
                    0);
        /* a negative tmin: the geometric early out (centre behind an origin outside) must not
         * drop the roots behind the origin, at -6 and -4 */
        assert_true(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), -7.0f, 1.0f), &t));
        assert_true(t == -6.0f);
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &t));
        /* degenerate directions never hit */
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 0), 0, T_INF), &t));
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(NAN, 0, -1), 0, T_INF), &t));
        assert_false(sphere_hit(a, &s, mk_ray(rs_v3(0, 0, 0), rs_v3(NAN, NAN, NAN), 0, T_INF), &t));
    }
}

static void test_sphere_random_vs_reference(void **state)
{
    uint64_t s = 0x5fe7e;
    cmp_stats st[RS_ISECT_SPHERE_COUNT];
    uint32_t a;
    int i;
    (void)state;
    memset(st, 0, sizeof st);
    for (i = 0; i < N_RANDOM; ++i) {
        rs_sphere sp = mk_sphere(rnd_box(&s, 5.0f), rnd_range(&s, 0.1, 3.0));
        rs_vec3 target = rs_v3_madd(sp.center, rnd_unit(&s), sp.radius * rnd_range(&s, 0.0, 1.3));
        rs_ray r = random_ray(&s, target);
        ref_result ref = ref_sphere(&sp, &r);
        for (a = 0; a < RS_ISECT_SPHERE_COUNT; ++a) {
            float t;
            int got = sphere_hit(a, &sp, r, &t);
            compare(&st[a], rs_isect_sphere_algo_name(a), i, got, t, 0.0f, 0.0f, ref, 0);
        }
    }
    for (a = 0; a < RS_ISECT_SPHERE_COUNT; ++a) {
        char what[64];
        snprintf(what, sizeof what, "sphere %s", rs_isect_sphere_algo_name(a));
        report(&st[a], what);
    }
    for (a = 0; a < RS_ISECT_SPHERE_COUNT; ++a)
        check_stats(&st[a], rs_isect_sphere_algo_name(a));
}

/* ---- triangles: analytic ------------------------------------------------------------------- */

static void test_tri_analytic(void **state)
{
    uint32_t a;
    (void)state;
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a) {
        /* in the plane z = -2: v0 = (0,0), v1 = (2,0), v2 = (0,2) */
        rs_tri tr = mk_tri(rs_v3(0, 0, -2), rs_v3(2, 0, -2), rs_v3(0, 2, -2));
        rs_tri flipped = mk_tri(tr.v0, tr.v2, tr.v1);
        float t, u, v;
        print_message("triangle %s\n", rs_isect_tri_algo_name(a));
        /* the point (0.5, 0.5): u = v = 0.25 */
        assert_true(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        assert_true(t == 2.0f && u == 0.25f && v == 0.25f);
        /* non-unit direction, from behind (the other face) */
        assert_true(
            tri_hit(a, &tr, mk_ray(rs_v3(1.0f, 0.5f, -6), rs_v3(0, 0, 2), 0, T_INF), &t, &u, &v));
        assert_true(t == 2.0f && u == 0.5f && v == 0.25f);
        /* the flipped winding: same t, u and v swap */
        assert_true(tri_hit(a, &flipped, mk_ray(rs_v3(1.0f, 0.5f, 0), rs_v3(0, 0, -1), 0, T_INF),
                            &t, &u, &v));
        assert_true(t == 2.0f && u == 0.25f && v == 0.5f);
        /* an oblique ray to the point (0.4, 1.2, -2): u = 0.2, v = 0.6 */
        {
            rs_vec3 p = rs_v3(0.4f, 1.2f, -2.0f), o = rs_v3(3.0f, -1.0f, 4.0f);
            rs_ray r = mk_ray(o, rs_v3_sub(p, o), 0.0f, T_INF);
            assert_true(tri_hit(a, &tr, r, &t, &u, &v));
            assert_float_equal(t, 1.0f, 1e-6f);
            assert_float_equal(u, 0.2f, 1e-6f);
            assert_float_equal(v, 0.6f, 1e-6f);
        }
        /* outside each edge */
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(-0.1f, 0.5f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, -0.1f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(1.1f, 1.0f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        /* pointing away */
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, 1), 0, T_INF), &t, &u, &v));
        /* parallel to the plane: above it and lying in it */
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(-1, 0.5f, -1), rs_v3(1, 0, 0), 0, T_INF), &t, &u, &v));
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(-1, 0.5f, -2), rs_v3(1, 0, 0), 0, T_INF), &t, &u, &v));
        /* the open interval: the plane is at t = 2 */
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 0, 2.0f), &t, &u, &v));
        assert_false(tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 2.0f, T_INF), &t,
                             &u, &v));
        assert_true(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 1.9f, 2.1f), &t, &u, &v));
        /* exactly on an edge and on a vertex (exact arithmetic here): a hit, inclusive */
        assert_true(
            tri_hit(a, &tr, mk_ray(rs_v3(1.0f, 0.0f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        assert_true(t == 2.0f && u == 0.5f && v == 0.0f);
        assert_true(
            tri_hit(a, &tr, mk_ray(rs_v3(0.0f, 2.0f, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        assert_true(t == 2.0f && u == 0.0f && v == 1.0f);
        /* degenerate rays and triangles */
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, 0), 0, T_INF), &t, &u, &v));
        assert_false(
            tri_hit(a, &tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(NAN, 0, -1), 0, T_INF), &t, &u, &v));
        {
            rs_tri line = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 1, -2), rs_v3(2, 2, -2));
            assert_false(
                tri_hit(a, &line, mk_ray(rs_v3(1, 1, 0), rs_v3(0, 0, -1), 0, T_INF), &t, &u, &v));
        }
        /* every dominant axis and sign (the watertight test permutes by them) */
        {
            int axis, sgn;
            for (axis = 0; axis < 3; ++axis)
                for (sgn = -1; sgn <= 1; sgn += 2) {
                    /* tr with its plane moved to `axis` = -2 sgn; the ray mostly along -sgn axis,
                     * tilted so that the other components are non-zero but smaller, through the
                     * point (0.5, 1) of the triangle (u = 0.25, v = 0.5) at t = 2 */
                    rs_vec3 p[3], o = rs_v3(0, 0, 0), q = rs_v3(0, 0, 0);
                    rs_tri rt;
                    int k;
                    for (k = 0; k < 3; ++k) {
                        rs_vec3 src = k == 0 ? tr.v0 : (k == 1 ? tr.v1 : tr.v2);
                        p[k] = rs_v3(0, 0, 0);
                        v3_set(&p[k], axis, -2.0f * (float)sgn);
                        v3_set(&p[k], (axis + 1) % 3, src.x);
                        v3_set(&p[k], (axis + 2) % 3, src.y);
                    }
                    rt = mk_tri(p[0], p[1], p[2]);
                    v3_set(&q, axis, -(float)sgn);
                    v3_set(&q, (axis + 1) % 3, 0.125f);
                    v3_set(&q, (axis + 2) % 3, -0.0625f);
                    v3_set(&o, (axis + 1) % 3, 0.5f - 2.0f * 0.125f);
                    v3_set(&o, (axis + 2) % 3, 1.0f + 2.0f * 0.0625f);
                    assert_true(tri_hit(a, &rt, mk_ray(o, q, 0, T_INF), &t, &u, &v));
                    assert_float_equal(t, 2.0f, 1e-6f);
                    assert_float_equal(u, 0.25f, 1e-6f);
                    assert_float_equal(v, 0.5f, 1e-6f);
                }
        }
    }
}

static void test_tri_random_vs_reference(void **state)
{
    uint64_t s = 0x7e1a;
    cmp_stats st[RS_ISECT_TRI_COUNT];
    uint32_t a;
    int i;
    (void)state;
    memset(st, 0, sizeof st);
    for (i = 0; i < N_RANDOM; ++i) {
        rs_vec3 c = rnd_box(&s, 5.0f);
        float size = rnd_range(&s, 0.2, 4.0);
        rs_tri tr = mk_tri(rs_v3_madd(c, rnd_unit(&s), size), rs_v3_madd(c, rnd_unit(&s), size),
                           rs_v3_madd(c, rnd_unit(&s), size));
        /* aim at barycentrics in [-0.2, 1.2]: about half inside */
        float bu = rnd_range(&s, -0.2, 1.2), bv = rnd_range(&s, -0.2, 1.2);
        rs_vec3 target = rs_v3_add(rs_v3_add(tr.v0, rs_v3_scale(rs_v3_sub(tr.v1, tr.v0), bu)),
                                   rs_v3_scale(rs_v3_sub(tr.v2, tr.v0), bv));
        rs_ray r = random_ray(&s, target);
        ref_result ref = ref_tri(&tr, &r);
        for (a = 0; a < RS_ISECT_TRI_COUNT; ++a) {
            float t, u, v;
            int got = tri_hit(a, &tr, r, &t, &u, &v);
            compare(&st[a], rs_isect_tri_algo_name(a), i, got, t, u, v, ref, 1);
        }
    }
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a) {
        char what[64];
        snprintf(what, sizeof what, "triangle %s", rs_isect_tri_algo_name(a));
        report(&st[a], what);
    }
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a)
        check_stats(&st[a], rs_isect_tri_algo_name(a));
}

/* ---- triangles: watertightness on shared edges and vertices -------------------------------- */

/* An indexed mesh: shared vertices are stored once, so the triangles meeting at an edge or a
 * vertex see bit-identical coordinates there (as a mesh loader produces them). */
typedef struct mesh {
    rs_vec3 *verts;
    uint32_t (*tris)[3];
    int nv, nt;
    /* fan[v][0..fan_n[v]): the triangles around vertex v */
    int (*fan)[8];
    int *fan_n;
    /* edges (a, b), a < b, each once */
    int (*edges)[2];
    int ne;
} mesh;

static void mesh_free(mesh *m)
{
    free(m->verts);
    free(m->tris);
    free(m->fan);
    free(m->fan_n);
    free(m->edges);
    memset(m, 0, sizeof *m);
}

static rs_tri mesh_tri(const mesh *m, int t)
{
    return mk_tri(m->verts[m->tris[t][0]], m->verts[m->tris[t][1]], m->verts[m->tris[t][2]]);
}

/* Builds fans and the edge list from the triangles. */
static void mesh_topology(mesh *m)
{
    int t, k;
    m->fan = (int(*)[8])calloc((size_t)m->nv, sizeof *m->fan);
    m->fan_n = (int *)calloc((size_t)m->nv, sizeof *m->fan_n);
    m->edges = (int(*)[2])malloc((size_t)m->nt * 3 * sizeof *m->edges);
    assert_non_null(m->fan);
    assert_non_null(m->fan_n);
    assert_non_null(m->edges);
    m->ne = 0;
    for (t = 0; t < m->nt; ++t)
        for (k = 0; k < 3; ++k) {
            int a = (int)m->tris[t][k], b = (int)m->tris[t][(k + 1) % 3];
            assert_true(m->fan_n[a] < 8);
            m->fan[a][m->fan_n[a]++] = t;
            /* each interior edge appears twice, once per direction: keep the a < b one (for the
             * grid's boundary edges, which appear once, this keeps about half, which is fine) */
            if (a < b) {
                m->edges[m->ne][0] = a;
                m->edges[m->ne][1] = b;
                ++m->ne;
            }
        }
}

/* Midpoint of edge (a, b) on the unit sphere, created once (a small open-addressing table). */
static int ico_midpoint(rs_vec3 *verts, int *nv, int *keys, int *vals, int cap, int a, int b)
{
    int lo = a < b ? a : b, hi = a < b ? b : a;
    int key = lo * 65536 + hi;
    unsigned h = ((unsigned)key * 2654435761u) % (unsigned)cap;
    while (keys[h] != -1 && keys[h] != key)
        h = (h + 1) % (unsigned)cap;
    if (keys[h] == key)
        return vals[h];
    keys[h] = key;
    vals[h] = *nv;
    verts[*nv] = rs_v3_normalize(rs_v3_scale(rs_v3_add(verts[a], verts[b]), 0.5f));
    return (*nv)++;
}

/* An icosphere (icosahedron subdivided `levels` times), radius `radius` around `center`,
 * consistently wound outward.  Closed: every edge is shared by exactly two triangles. */
static void make_icosphere(mesh *m, int levels, rs_vec3 center, float radius)
{
    static const float ico_v[12][3] = {
        {-1, 1.618034f, 0}, {1, 1.618034f, 0}, {-1, -1.618034f, 0}, {1, -1.618034f, 0},
        {0, -1, 1.618034f}, {0, 1, 1.618034f}, {0, -1, -1.618034f}, {0, 1, -1.618034f},
        {1.618034f, 0, -1}, {1.618034f, 0, 1}, {-1.618034f, 0, -1}, {-1.618034f, 0, 1}};
    static const int ico_f[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                     {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                     {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                     {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    int max_t = 20, max_v, l, i, cap;
    uint32_t(*cur)[3];
    for (l = 0; l < levels; ++l)
        max_t *= 4;
    max_v = max_t / 2 + 2;
    cap = 4 * max_v;
    m->verts = (rs_vec3 *)malloc((size_t)max_v * sizeof *m->verts);
    cur = (uint32_t(*)[3])malloc((size_t)max_t * sizeof *cur);
    assert_non_null(m->verts);
    assert_non_null(cur);
    for (i = 0; i < 12; ++i)
        m->verts[i] = rs_v3_normalize(rs_v3(ico_v[i][0], ico_v[i][1], ico_v[i][2]));
    for (i = 0; i < 20; ++i) {
        cur[i][0] = (uint32_t)ico_f[i][0];
        cur[i][1] = (uint32_t)ico_f[i][1];
        cur[i][2] = (uint32_t)ico_f[i][2];
    }
    m->nv = 12;
    m->nt = 20;
    for (l = 0; l < levels; ++l) {
        int *keys = (int *)malloc((size_t)cap * sizeof *keys);
        int *vals = (int *)malloc((size_t)cap * sizeof *vals);
        uint32_t(*next)[3] = (uint32_t(*)[3])malloc((size_t)max_t * sizeof *next);
        int nt = 0;
        assert_non_null(keys);
        assert_non_null(vals);
        assert_non_null(next);
        for (i = 0; i < cap; ++i)
            keys[i] = -1;
        for (i = 0; i < m->nt; ++i) {
            int a = (int)cur[i][0], b = (int)cur[i][1], c = (int)cur[i][2];
            int ab = ico_midpoint(m->verts, &m->nv, keys, vals, cap, a, b);
            int bc = ico_midpoint(m->verts, &m->nv, keys, vals, cap, b, c);
            int ca = ico_midpoint(m->verts, &m->nv, keys, vals, cap, c, a);
            int quad[4][3] = {{a, ab, ca}, {b, bc, ab}, {c, ca, bc}, {ab, bc, ca}};
            int q;
            for (q = 0; q < 4; ++q, ++nt) {
                next[nt][0] = (uint32_t)quad[q][0];
                next[nt][1] = (uint32_t)quad[q][1];
                next[nt][2] = (uint32_t)quad[q][2];
            }
        }
        free(cur);
        free(keys);
        free(vals);
        cur = next;
        m->nt = nt;
    }
    for (i = 0; i < m->nv; ++i)
        m->verts[i] = rs_v3_madd(center, m->verts[i], radius);
    m->tris = cur;
    mesh_topology(m);
    assert_int_equal(m->ne, m->nt * 3 / 2); /* closed: every edge twice */
    for (i = 0; i < m->nv; ++i)
        assert_true(m->fan_n[i] == 5 || m->fan_n[i] == 6);
}

/* A bumpy height field over n x n cells (cell size h), each cell split along an alternating
 * diagonal, then rotated by the orthonormal frame (ex, ey, ez) and moved to `origin`.  The
 * heights are small (under 0.05 h: slopes under 6 degrees) so that rays within the cone used
 * below (73 degrees around +-ez) never graze a triangle and the fans never fold in projection. */
static void make_grid(mesh *m, int n, float h, rs_vec3 origin, rs_vec3 ex, rs_vec3 ey, rs_vec3 ez,
                      uint64_t *seed)
{
    int i, j, t = 0;
    m->nv = (n + 1) * (n + 1);
    m->nt = 2 * n * n;
    m->verts = (rs_vec3 *)malloc((size_t)m->nv * sizeof *m->verts);
    m->tris = (uint32_t(*)[3])malloc((size_t)m->nt * sizeof *m->tris);
    assert_non_null(m->verts);
    assert_non_null(m->tris);
    for (j = 0; j <= n; ++j)
        for (i = 0; i <= n; ++i) {
            float x = (float)i * h, y = (float)j * h, z = rnd_range(seed, -0.05, 0.05) * h;
            rs_vec3 p = rs_v3_madd(rs_v3_madd(rs_v3_madd(origin, ex, x), ey, y), ez, z);
            m->verts[j * (n + 1) + i] = p;
        }
    for (j = 0; j < n; ++j)
        for (i = 0; i < n; ++i) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)(n + 1),
                     d = c + 1;
            if ((i + j) % 2) {
                m->tris[t][0] = a, m->tris[t][1] = b, m->tris[t][2] = d, ++t;
                m->tris[t][0] = a, m->tris[t][1] = d, m->tris[t][2] = c, ++t;
            } else {
                m->tris[t][0] = a, m->tris[t][1] = b, m->tris[t][2] = c, ++t;
                m->tris[t][0] = b, m->tris[t][1] = d, m->tris[t][2] = c, ++t;
            }
        }
    mesh_topology(m);
}

/* A random unit vector within the cone of half-angle acos(min_cos) around the unit vector n. */
static rs_vec3 rnd_in_cone(uint64_t *s, rs_vec3 n, float min_cos)
{
    for (;;) {
        rs_vec3 w = rnd_unit(s);
        if (rs_v3_dot(w, n) >= min_cos)
            return w;
    }
}

typedef struct wt_stats {
    int rays;
    int miss[RS_ISECT_TRI_COUNT];       /* no triangle of the fan was hit */
    int double_hit[RS_ISECT_TRI_COUNT]; /* two or more were (harmless) */
    double max_t_err;                   /* watertight: |t k - 1| of its hits */
} wt_stats;

/* Shoots one ray through the point p (on a shared edge, or a shared vertex) from the side n,
 * at the triangles in `cand` (the fans of the edge's end points, or of the vertex). */
static void shoot(wt_stats *st, const mesh *m, const int *cand, int nc, rs_vec3 p, rs_vec3 n,
                  uint64_t *s)
{
    rs_vec3 w = rnd_in_cone(s, n, 0.3f);
    float dist = rnd_range(s, 0.05, 20.0), k = rnd_range(s, 0.25, 4.0);
    rs_vec3 o = rs_v3_madd(p, w, dist);
    /* d = (p - o) k: the ray passes through (the float rounding of) p at t = 1 / k */
    rs_ray r = mk_ray(o, rs_v3_scale(rs_v3_sub(p, o), k), 0.0f, T_INF);
    uint32_t a;
    int c;
    ++st->rays;
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a) {
        int hits = 0;
        for (c = 0; c < nc; ++c) {
            rs_tri tr = mesh_tri(m, cand[c]);
            float t, u, v;
            if (rs_isect_tri_by(a, &tr, &r, &t, &u, &v)) {
                ++hits;
                if (a == RS_ISECT_TRI_WATERTIGHT) {
                    double e = fabs((double)t * k - 1.0);
                    if (e > st->max_t_err)
                        st->max_t_err = e;
                }
            }
        }
        if (hits == 0)
            ++st->miss[a];
        else if (hits > 1)
            ++st->double_hit[a];
    }
}

/* Candidate triangles for a ray through edge (a, b): the fans of both end points (the ray may
 * pass, within rounding, just beyond an end point), each triangle once. */
static int edge_candidates(const mesh *m, int a, int b, int *cand)
{
    int n = 0, k, j;
    for (k = 0; k < m->fan_n[a]; ++k)
        cand[n++] = m->fan[a][k];
    for (k = 0; k < m->fan_n[b]; ++k) {
        for (j = 0; j < m->fan_n[a] && cand[j] != m->fan[b][k]; ++j)
            ;
        if (j == m->fan_n[a])
            cand[n++] = m->fan[b][k];
    }
    return n;
}

static void wt_report(const wt_stats *st, const char *what)
{
    uint32_t a;
    print_message("%s: %d rays\n", what, st->rays);
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a)
        print_message("    %-12s missed %6d (%.4f%%), hit two or more triangles %6d\n",
                      rs_isect_tri_algo_name(a), st->miss[a], 100.0 * st->miss[a] / st->rays,
                      st->double_hit[a]);
}

static void test_watertight_icosphere(void **state)
{
    uint64_t s = 0x1c05;
    mesh m;
    wt_stats edge_st, vert_st;
    rs_vec3 center = rs_v3(0.3f, -1.7f, 2.1f);
    float radius = 3.7f;
    int i, cand[16];
    (void)state;
    memset(&m, 0, sizeof m);
    memset(&edge_st, 0, sizeof edge_st);
    memset(&vert_st, 0, sizeof vert_st);
    make_icosphere(&m, 4, center, radius); /* 5120 triangles, 2562 vertices */
    for (i = 0; i < N_WT_RAYS; ++i) {
        int e = (int)(splitmix64(&s) % (uint64_t)m.ne);
        int a = m.edges[e][0], b = m.edges[e][1];
        float f = rnd_range(&s, 0.0, 1.0);
        rs_vec3 p = rs_v3_madd(m.verts[a], rs_v3_sub(m.verts[b], m.verts[a]), f);
        int nc = edge_candidates(&m, a, b, cand);
        shoot(&edge_st, &m, cand, nc, p, rs_v3_normalize(rs_v3_sub(p, center)), &s);
    }
    for (i = 0; i < N_WT_RAYS; ++i) {
        int v = (int)(splitmix64(&s) % (uint64_t)m.nv);
        rs_vec3 p = m.verts[v];
        shoot(&vert_st, &m, m.fan[v], m.fan_n[v], p, rs_v3_normalize(rs_v3_sub(p, center)), &s);
    }
    wt_report(&edge_st, "icosphere (5120 triangles), rays through points on shared edges");
    wt_report(&vert_st, "icosphere (5120 triangles), rays through shared vertices");
    print_message("    watertight: max |t - t_expected| / t_expected %.3g\n",
                  fmax(edge_st.max_t_err, vert_st.max_t_err));
    assert_int_equal(edge_st.miss[RS_ISECT_TRI_WATERTIGHT], 0);
    assert_int_equal(vert_st.miss[RS_ISECT_TRI_WATERTIGHT], 0);
    assert_true(edge_st.max_t_err < 1e-4 && vert_st.max_t_err < 1e-4);
    mesh_free(&m);
}

static void test_watertight_grid(void **state)
{
    uint64_t s = 0x96d;
    mesh m;
    wt_stats edge_st, vert_st;
    enum { N = 48 };
    /* an orthonormal frame rotated off the axes */
    rs_vec3 ex = rs_v3_normalize(rs_v3(0.86f, 0.31f, -0.41f)), ez, ey;
    int i, cand[16];
    (void)state;
    ez = rs_v3_normalize(rs_v3_cross(ex, rs_v3(0.2f, 0.9f, 0.3f)));
    ey = rs_v3_cross(ez, ex);
    memset(&m, 0, sizeof m);
    memset(&edge_st, 0, sizeof edge_st);
    memset(&vert_st, 0, sizeof vert_st);
    make_grid(&m, N, 0.37f, rs_v3(-5.3f, 2.9f, -1.1f), ex, ey, ez, &s);
    for (i = 0; i < N_WT_RAYS; ++i) {
        /* an interior edge: both end points off the boundary, so every side is covered */
        int e, a, b, ia, ja, ib, jb;
        float f;
        rs_vec3 p;
        do {
            e = (int)(splitmix64(&s) % (uint64_t)m.ne);
            a = m.edges[e][0];
            b = m.edges[e][1];
            ia = a % (N + 1), ja = a / (N + 1), ib = b % (N + 1), jb = b / (N + 1);
        } while (ia == 0 || ia == N || ja == 0 || ja == N || ib == 0 || ib == N || jb == 0 ||
                 jb == N);
        f = rnd_range(&s, 0.0, 1.0);
        p = rs_v3_madd(m.verts[a], rs_v3_sub(m.verts[b], m.verts[a]), f);
        shoot(&edge_st, &m, cand, edge_candidates(&m, a, b, cand), p,
              rnd_range(&s, 0.0, 1.0) < 0.5 ? ez : rs_v3_neg(ez), &s);
    }
    for (i = 0; i < N_WT_RAYS; ++i) {
        int v, iv, jv;
        do {
            v = (int)(splitmix64(&s) % (uint64_t)m.nv);
            iv = v % (N + 1), jv = v / (N + 1);
        } while (iv == 0 || iv == N || jv == 0 || jv == N);
        shoot(&vert_st, &m, m.fan[v], m.fan_n[v], m.verts[v],
              rnd_range(&s, 0.0, 1.0) < 0.5 ? ez : rs_v3_neg(ez), &s);
    }
    wt_report(&edge_st, "bumpy grid (4608 triangles), rays through points on interior edges");
    wt_report(&vert_st, "bumpy grid (4608 triangles), rays through interior vertices");
    assert_int_equal(edge_st.miss[RS_ISECT_TRI_WATERTIGHT], 0);
    assert_int_equal(vert_st.miss[RS_ISECT_TRI_WATERTIGHT], 0);
    assert_true(edge_st.max_t_err < 1e-4 && vert_st.max_t_err < 1e-4);
    mesh_free(&m);
}

/* Axis-aligned rays exactly along a flat, axis-aligned grid's edges' lines are the paper's
 * classic failure for non-watertight tests: the ray hits the edge exactly, and the double
 * fallback decides.  All three must hit here, where everything is exact. */
static void test_watertight_exact_edges(void **state)
{
    rs_tri left = mk_tri(rs_v3(0, 0, -1), rs_v3(1, 0, -1), rs_v3(0, 1, -1));
    rs_tri right = mk_tri(rs_v3(1, 0, -1), rs_v3(1, 1, -1), rs_v3(0, 1, -1));
    uint32_t a;
    int k;
    (void)state;
    for (a = 0; a < RS_ISECT_TRI_COUNT; ++a)
        for (k = 1; k < 64; ++k) {
            /* points on the diagonal edge (1, 0) - (0, 1), exactly representable */
            float x = (float)k / 64.0f, t, u, v;
            rs_ray r = mk_ray(rs_v3(x, 1.0f - x, 0), rs_v3(0, 0, -1), 0.0f, T_INF);
            int h = rs_isect_tri_by(a, &left, &r, &t, &u, &v) +
                    rs_isect_tri_by(a, &right, &r, &t, &u, &v);
            if (h == 0)
                fail_msg("%s: the ray through (%g, %g) on the shared edge misses both",
                         rs_isect_tri_algo_name(a), x, 1.0f - x);
        }
}

/* ---- boxes --------------------------------------------------------------------------------- */

static void test_aabb_analytic(void **state)
{
    uint32_t a;
    (void)state;
    for (a = 0; a < RS_ISECT_AABB_COUNT; ++a) {
        rs_aabb b = mk_box(rs_v3(-1, -1, -6), rs_v3(1, 1, -4));
        rs_aabb flat = mk_box(rs_v3(-1, -1, -3), rs_v3(1, 1, -3));
        float te;
        print_message("box %s\n", rs_isect_aabb_algo_name(a));
        /* head on: entry 4, also with a non-unit direction and from the other side */
        assert_true(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, T_INF, &te) && te == 4.0f);
        assert_true(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -2), 0, T_INF, &te) && te == 2.0f);
        assert_true(box_hit(a, b, rs_v3(0, 0, -10), rs_v3(0, 0, 1), 0, T_INF, &te) && te == 4.0f);
        /* oblique: x enters at 2, z at 4 */
        assert_true(box_hit(a, b, rs_v3(-3, 0, 0), rs_v3(1, 0, -1), 0, T_INF, &te) && te == 4.0f);
        /* misses: behind, beside, diverging */
        assert_false(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0, T_INF, &te));
        assert_false(box_hit(a, b, rs_v3(2, 0, 0), rs_v3(0, 0, -1), 0, T_INF, &te));
        assert_false(box_hit(a, b, rs_v3(-3, 0, 0), rs_v3(1, 0, -0.1f), 0, T_INF, &te));
        assert_false(box_hit(a, b, rs_v3(-3, 0, 0), rs_v3(1, 0.8f, -1), 0, T_INF, &te));
        /* origin inside: entry = tmin */
        assert_true(box_hit(a, b, rs_v3(0, 0, -5), rs_v3(0.3f, -0.2f, 1), 0, T_INF, &te) &&
                    te == 0.0f);
        assert_true(box_hit(a, b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.5f, T_INF, &te) && te == 0.5f);
        /* the closed interval [tmin, tmax]: the box spans t in [4, 6] */
        assert_false(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, 3.99f, &te));
        assert_false(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 6.01f, T_INF, &te));
        assert_true(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, 4.0f, &te) && te == 4.0f);
        assert_true(box_hit(a, b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 6.0f, T_INF, &te) && te == 6.0f);
        /* zero direction components: inside or outside the slab */
        assert_true(box_hit(a, b, rs_v3(0.5f, -0.5f, 0), rs_v3(0, 0, -1), 0, T_INF, &te));
        assert_true(box_hit(a, b, rs_v3(0.5f, -0.5f, 0), rs_v3(-0.0f, -0.0f, -1), 0, T_INF, &te));
        assert_false(box_hit(a, b, rs_v3(1.5f, 0, 0), rs_v3(0, 0, -1), 0, T_INF, &te));
        assert_false(box_hit(a, b, rs_v3(1.5f, 0, 0), rs_v3(-0.0f, 0, -1), 0, T_INF, &te));
        /* zero-thickness boxes (a quad's bounds) and a point */
        assert_true(box_hit(a, flat, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, T_INF, &te) && te == 3.0f);
        assert_true(box_hit(a, flat, rs_v3(0, 0, 0), rs_v3(0.1f, -0.2f, -1), 0, T_INF, &te));
        assert_float_equal(te, 3.0f, 1e-6f);
        assert_true(box_hit(a, flat, rs_v3(0, 0, -6), rs_v3(0, 0, 1), 0, T_INF, &te) && te == 3.0f);
        assert_false(box_hit(a, flat, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0, 2.9f, &te));
        /* a NaN direction: any answer, but 0 or 1 */
        {
            int h = box_hit(a, b, rs_v3(0, 0, 0), rs_v3(NAN, NAN, NAN), 0, T_INF, &te);
            assert_true(h == 0 || h == 1);
        }
    }
}

/* The slab distances of the random box test, shared by every variant: origins anywhere in
 * [-10, 10]^3, boxes around [-5, 5]^3 up to 6 wide, directions aimed near the box with a random
 * length; a quarter with a zero component (+0 or -0), a tenth zero-thickness in z, and tmin / tmax
 * cuts.  The slab test itself is checked against a double reference in core_intersect_test.c. */
static void test_aabb_random_vs_slab(void **state)
{
    uint64_t s = 0xb0c5e;
    int i, hits = 0, zero_dir = 0;
    int wrong[RS_ISECT_AABB_COUNT];
    uint32_t a;
    (void)state;
    memset(wrong, 0, sizeof wrong);
    for (i = 0; i < N_RANDOM; ++i) {
        rs_vec3 c = rnd_box(&s, 5.0f), h, o, d, inv;
        rs_aabb b;
        float tmin = 0.0f, tmax = T_INF, te_ref = SENTINEL;
        int ref;
        h = rs_v3(rnd_range(&s, 0.0, 3.0), rnd_range(&s, 0.0, 3.0), rnd_range(&s, 0.0, 3.0));
        if (i % 10 == 0)
            h.z = 0.0f;
        b = mk_box(rs_v3_sub(c, h), rs_v3_add(c, h));
        o = rnd_box(&s, 10.0f);
        d = rs_v3_scale(rs_v3_sub(rs_v3_madd(c, rnd_box(&s, 1.0f), 1.5f * rs_v3_max_comp(h)), o),
                        rnd_range(&s, 0.25, 4.0));
        if (i % 4 == 1) {
            v3_set(&d, (int)(splitmix64(&s) % 3), (i & 8) ? -0.0f : 0.0f);
            ++zero_dir;
        }
        if (i % 5 == 2)
            tmax = rnd_range(&s, 0.2, 2.0);
        if (i % 7 == 3)
            tmin = rnd_range(&s, 0.0, 0.5);
        inv = inv_dir(d);
        ref = rs_isect_aabb(&b, o, inv, tmin, tmax, &te_ref);
        hits += ref;
        for (a = 1; a < RS_ISECT_AABB_COUNT; ++a) {
            float te = SENTINEL;
            int got = rs_isect_aabb_by(a, &b, o, inv, tmin, tmax, &te);
            if (got != ref || (got && te != te_ref)) {
                if (wrong[a] < 5)
                    print_error("box %s ray %d: got %d (entry %.9g), slab %d (entry %.9g)\n",
                                rs_isect_aabb_algo_name(a), i, got, te, ref, te_ref);
                ++wrong[a];
            }
        }
    }
    print_message("box: %d random rays (%d with a zero direction component), %d slab hits\n",
                  N_RANDOM, zero_dir, hits);
    for (a = 1; a < RS_ISECT_AABB_COUNT; ++a) {
        print_message("    %-10s disagrees with the slab test on %d rays\n",
                      rs_isect_aabb_algo_name(a), wrong[a]);
        assert_int_equal(wrong[a], 0);
    }
    assert_true(hits > N_RANDOM / 5 && hits < N_RANDOM * 4 / 5);
}

/* What each variant does with a ray lying exactly in a face plane of the box, parallel to it:
 * that slab's distance to the plane is 0 * inf = NaN.  The slab test skips the slab (the ray
 * counts as inside it); the others, as core/intersect.h states:
 *   branchless  lo plane: miss; hi plane: as slab (inside); a zero-thickness slab: as slab
 *   williams    x planes: miss; y and z planes: as slab
 *   kensler     as slab
 *   swap        direction component +0: as slab; -0: miss; a zero-thickness slab: as slab
 * Returns 1 when the variant answers like the slab test, 0 when it must miss. */
static int in_plane_rule(uint32_t algo, int axis, int hi_side, int neg_zero, int thin)
{
    switch (algo) {
    case RS_ISECT_AABB_BRANCHLESS: return thin || hi_side;
    case RS_ISECT_AABB_WILLIAMS: return axis != 0;
    case RS_ISECT_AABB_SWAP: return thin || !neg_zero;
    default: return 1;
    }
}

static void test_aabb_in_face_plane(void **state)
{
    uint64_t s = 0xfa5e;
    int i, slab_hits = 0, n_rays = 200000;
    int wrong[RS_ISECT_AABB_COUNT];
    uint32_t a;
    (void)state;
    memset(wrong, 0, sizeof wrong);
    /* the fixed cases: unit box, origin on each face plane 5 before the box, moving along the next
     * axis: the slab test hits at 4 */
    {
        rs_aabb b = mk_box(rs_v3(-1, -1, -1), rs_v3(1, 1, 1));
        int axis, side, zi;
        for (a = 0; a < RS_ISECT_AABB_COUNT; ++a)
            for (axis = 0; axis < 3; ++axis)
                for (side = 0; side < 2; ++side)
                    for (zi = 0; zi < 2; ++zi) {
                        rs_vec3 o = rs_v3(0, 0, 0), d = rs_v3(0, 0, 0);
                        int along = (axis + 1) % 3, expect = in_plane_rule(a, axis, side, zi, 0);
                        float te;
                        int got;
                        v3_set(&o, axis, side ? 1.0f : -1.0f);
                        v3_set(&o, along, -5.0f);
                        v3_set(&d, axis, zi ? -0.0f : 0.0f);
                        v3_set(&d, along, 1.0f);
                        got = box_hit(a, b, o, d, 0.0f, T_INF, &te);
                        if (got != expect || (got && te != 4.0f))
                            fail_msg("box %s, ray in the %s-%c plane with d.%c = %s0: got %d "
                                     "(entry %g), expected %d",
                                     rs_isect_aabb_algo_name(a), side ? "hi" : "lo", "xyz"[axis],
                                     "xyz"[axis], zi ? "-" : "+", got, te, expect);
                    }
    }
    /* a point box on the ray's line: the x and y slabs are zero-thickness planes holding it */
    {
        rs_aabb pt = mk_box(rs_v3(0, 0, -3), rs_v3(0, 0, -3));
        for (a = 0; a < RS_ISECT_AABB_COUNT; ++a) {
            int expect = in_plane_rule(a, 0, 0, 0, 1) && in_plane_rule(a, 1, 0, 0, 1);
            float te;
            int got = box_hit(a, pt, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF, &te);
            if (got != expect || (got && te != 3.0f))
                fail_msg("box %s, point box on the ray: got %d (entry %g), expected %d",
                         rs_isect_aabb_algo_name(a), got, te, expect);
        }
    }
    /* random boxes (a fifth zero-thickness on the chosen axis), origins on a random face plane */
    for (i = 0; i < n_rays; ++i) {
        rs_vec3 c = rnd_box(&s, 5.0f), h, o, d, inv;
        rs_aabb b;
        int axis = (int)(splitmix64(&s) % 3), side = (int)(splitmix64(&s) & 1);
        int neg_zero = (int)(splitmix64(&s) & 1), thin = i % 5 == 0, ref;
        float te_ref = SENTINEL;
        h = rs_v3(rnd_range(&s, 0.1, 3.0), rnd_range(&s, 0.1, 3.0), rnd_range(&s, 0.1, 3.0));
        if (thin)
            v3_set(&h, axis, 0.0f);
        b = mk_box(rs_v3_sub(c, h), rs_v3_add(c, h));
        o = rnd_box(&s, 10.0f);
        v3_set(&o, axis, rs_v3_get(side ? b.hi : b.lo, axis));
        d = rs_v3_sub(rs_v3_madd(c, rnd_box(&s, 1.0f), 1.5f * rs_v3_max_comp(h)), o);
        v3_set(&d, axis, neg_zero ? -0.0f : 0.0f);
        inv = inv_dir(d);
        ref = rs_isect_aabb(&b, o, inv, 0.0f, T_INF, &te_ref);
        slab_hits += ref;
        for (a = 1; a < RS_ISECT_AABB_COUNT; ++a) {
            float te = SENTINEL;
            int got = rs_isect_aabb_by(a, &b, o, inv, 0.0f, T_INF, &te);
            int expect = in_plane_rule(a, axis, side, neg_zero, thin) ? ref : 0;
            if (got != expect || (got && te != te_ref)) {
                if (wrong[a] < 5)
                    print_error("box %s in-plane ray %d (%s-%c, %s0%s): got %d, expected %d\n",
                                rs_isect_aabb_algo_name(a), i, side ? "hi" : "lo", "xyz"[axis],
                                neg_zero ? "-" : "+", thin ? ", thin" : "", got, expect);
                ++wrong[a];
            }
        }
    }
    print_message("box: %d random rays in a face plane, %d slab hits\n", n_rays, slab_hits);
    for (a = 1; a < RS_ISECT_AABB_COUNT; ++a)
        assert_int_equal(wrong[a], 0);
    assert_true(slab_hits > n_rays / 10);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names_and_parse),
        cmocka_unit_test(test_dispatch),
        cmocka_unit_test(test_sphere_analytic),
        cmocka_unit_test(test_sphere_random_vs_reference),
        cmocka_unit_test(test_tri_analytic),
        cmocka_unit_test(test_tri_random_vs_reference),
        cmocka_unit_test(test_watertight_exact_edges),
        cmocka_unit_test(test_watertight_icosphere),
        cmocka_unit_test(test_watertight_grid),
        cmocka_unit_test(test_aabb_analytic),
        cmocka_unit_test(test_aabb_random_vs_slab),
        cmocka_unit_test(test_aabb_in_face_plane),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
