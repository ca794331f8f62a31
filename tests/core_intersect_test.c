/* tests/core_intersect_test.c — core/intersect.h: rays against spheres, triangles, quads, boxes.
 *
 * What is checked:
 *   - analytic cases with exact answers: head-on hits and their t (also for non-unit directions),
 *     misses, rays starting inside a sphere, barycentric / planar coordinates at known points,
 *     both faces of triangles and quads, rays parallel to a triangle's or quad's plane;
 *   - the open interval (tmin, tmax): a hit exactly at tmin or tmax is not reported, and a
 *     sphere's nearer root outside the interval falls back to the far root;
 *   - grazing rays: tangent to a sphere (either answer within a small band, never a NaN t, and a
 *     hit close to the tangent point), NaN / zero directions never hit;
 *   - boxes: entry distance, boxes behind the origin, origins inside, the closed [tmin, tmax],
 *     rays with zero direction components, rays lying exactly in a slab plane (the header
 *     promises such a ray counts as inside that slab), zero-thickness boxes (a quad's bounds),
 *     and that a primitive's bounding box is hit whenever the primitive is;
 *   - 10^5 random rays per primitive type against a double-precision reference written here:
 *     hit / miss agree except inside a stated band around the silhouette, edges, tmin and tmax,
 *     and t agrees to a relative 1e-4.  The same for boxes.
 * Random inputs come from a fixed-seed splitmix64. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>

#include "core/intersect.h"

#include "test_isect_ref.h"
#include "test_rand.h"

#define T_INF FLT_MAX

/* ---- helpers ------------------------------------------------------------------------------- */

/* Sentinels: intersection routines write their outputs only on a hit. */
#define SENTINEL (-12345.0f)

static int sphere_hit(const rs_sphere *s, rs_ray r, float *t)
{
    *t = SENTINEL;
    return rs_isect_sphere(s, &r, t);
}

static int tri_hit(const rs_tri *tr, rs_ray r, float *t, float *u, float *v)
{
    *t = *u = *v = SENTINEL;
    return rs_isect_tri(tr, &r, t, u, v);
}

static int quad_hit(const rs_quad *q, rs_ray r, float *t, float *a, float *b)
{
    *t = *a = *b = SENTINEL;
    return rs_isect_quad(q, &r, t, a, b);
}

static int box_hit(rs_aabb b, rs_vec3 o, rs_vec3 d, float tmin, float tmax, float *te)
{
    *te = SENTINEL;
    return rs_isect_aabb(&b, o, inv_dir(d), tmin, tmax, te);
}

/* ---- spheres: analytic cases ---------------------------------------------------------------- */

static void test_sphere_head_on(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 1.0f);
    float t;
    (void)state;
    /* o = 0, d = -z: roots 4 and 6 */
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    assert_true(t == 4.0f);
    /* t is in units of |d|: d = -2z halves it */
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -2), 0.0f, T_INF), &t));
    assert_true(t == 2.0f);
    /* an oblique hit: from (3, 0, -1) along (-3, 0, -4)/5 the ray meets the sphere at (0,0,-5)+..
     * check the hit point lies on the sphere and is the first crossing */
    {
        rs_ray r = mk_ray(rs_v3(3, 0, -1), rs_v3(-0.6f, 0.0f, -0.8f), 0.0f, T_INF);
        rs_vec3 p;
        assert_true(sphere_hit(&s, r, &t));
        p = rs_v3_sub(rs_ray_at(&r, t), s.center);
        assert_float_equal(rs_v3_length(p), 1.0f, 1e-5f);
        /* the normal at the first crossing faces the ray */
        assert_true(rs_v3_dot(p, r.d) < 0.0f);
        /* distance from (3,0,-1) to the centre along d is 5: roots 5 -+ sqrt(1 - 0) = 4, 6 */
        assert_float_equal(t, 4.0f, 1e-5f);
    }
}

static void test_sphere_miss(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 1.0f);
    float t;
    (void)state;
    /* pointing away: both roots negative */
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &t));
    assert_true(t == SENTINEL);
    /* passing beside it */
    assert_false(sphere_hit(&s, mk_ray(rs_v3(2, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 1.001f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    assert_true(t == SENTINEL);
    /* behind the origin, also when the line would cross it */
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 0, -10), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
}

static void test_sphere_inside(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 2.0f);
    float t;
    (void)state;
    /* from the centre: the far side at t = r in every direction */
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, -5), rs_v3(1, 0, 0), 0.0f, T_INF), &t));
    assert_true(t == 2.0f);
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, -5), rs_v3(0, -1, 0), 0.0f, T_INF), &t));
    assert_true(t == 2.0f);
    /* off-centre: from (0, 0, -4) along -z the far side is at z = -7, t = 3; along +z t = 1 */
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, -4), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    assert_true(t == 3.0f);
    assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0, -4), rs_v3(0, 0, 1), 0.0f, T_INF), &t));
    assert_true(t == 1.0f);
}

static void test_sphere_interval(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 1.0f);
    rs_vec3 o = rs_v3(0, 0, 0), d = rs_v3(0, 0, -1);
    float t;
    (void)state;
    /* roots 4 and 6; the interval is open */
    assert_true(sphere_hit(&s, mk_ray(o, d, 3.9f, 6.1f), &t));
    assert_true(t == 4.0f);
    /* tmin exactly at the near root: the near root is out, the far root is the hit */
    assert_true(sphere_hit(&s, mk_ray(o, d, 4.0f, T_INF), &t));
    assert_true(t == 6.0f);
    /* the near root below tmin: fall back to the far root */
    assert_true(sphere_hit(&s, mk_ray(o, d, 5.0f, T_INF), &t));
    assert_true(t == 6.0f);
    /* tmax exactly at the near root: nothing inside (0, 4) */
    assert_false(sphere_hit(&s, mk_ray(o, d, 0.0f, 4.0f), &t));
    assert_true(t == SENTINEL);
    /* just past it */
    assert_true(sphere_hit(&s, mk_ray(o, d, 0.0f, 4.0001f), &t));
    assert_true(t == 4.0f);
    /* both roots excluded: (4, 6) open contains neither */
    assert_false(sphere_hit(&s, mk_ray(o, d, 4.0f, 6.0f), &t));
    /* tmin exactly at the far root */
    assert_false(sphere_hit(&s, mk_ray(o, d, 6.0f, T_INF), &t));
    /* interval between the roots */
    assert_false(sphere_hit(&s, mk_ray(o, d, 4.5f, 5.5f), &t));
}

static void test_sphere_degenerate_rays(void **state)
{
    rs_sphere s = mk_sphere(rs_v3(0.0f, 0.0f, -5.0f), 1.0f);
    float t;
    (void)state;
    /* a NaN distance is never a hit */
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(NAN, 0, -1), 0.0f, T_INF), &t));
    assert_false(sphere_hit(&s, mk_ray(rs_v3(NAN, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    /* a zero direction gives 0 / 0, outside and inside the sphere */
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 0), 0.0f, T_INF), &t));
    assert_false(sphere_hit(&s, mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 0), 0.0f, T_INF), &t));
    /* an infinite direction component: no finite answer either */
    if (sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -INFINITY), 0.0f, T_INF), &t))
        assert_false(isnan(t));
    assert_true(t == SENTINEL || !isnan(t));
}

/* ---- triangles: analytic cases ----------------------------------------------------------- */

static void test_tri_head_on_and_barycentrics(void **state)
{
    rs_tri tr = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 0, -2), rs_v3(0, 1, -2));
    float t, u, v;
    (void)state;
    assert_true(
        tri_hit(&tr, mk_ray(rs_v3(0.25f, 0.25f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(t == 2.0f);
    assert_true(u == 0.25f && v == 0.25f);
    /* u weights v1 = (1,0,.), v weights v2 = (0,1,.) */
    assert_true(
        tri_hit(&tr, mk_ray(rs_v3(0.5f, 0.125f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(u == 0.5f && v == 0.125f);
    /* at the vertices and on the edges (closed triangle) */
    assert_true(tri_hit(&tr, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(u == 0.0f && v == 0.0f);
    assert_true(tri_hit(&tr, mk_ray(rs_v3(1, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(u == 1.0f && v == 0.0f);
    assert_true(tri_hit(&tr, mk_ray(rs_v3(0, 1, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(u == 0.0f && v == 1.0f);
    assert_true(
        tri_hit(&tr, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_true(u == 0.5f && v == 0.5f);
    /* the centroid of a general triangle, from an oblique origin, with a non-unit direction */
    {
        rs_tri g = mk_tri(rs_v3(1, 2, 3), rs_v3(-2, 0.5f, 4), rs_v3(0.5f, -1, -2));
        rs_vec3 cen = rs_v3_scale(rs_v3_add(rs_v3_add(g.v0, g.v1), g.v2), 1.0f / 3.0f);
        rs_vec3 o = rs_v3(7, -5, 9), d = rs_v3_scale(rs_v3_sub(cen, o), 0.5f);
        assert_true(tri_hit(&g, mk_ray(o, d, 0.0f, T_INF), &t, &u, &v));
        assert_float_equal(t, 2.0f, 2e-6f);
        assert_float_equal(u, 1.0f / 3.0f, 1e-6f);
        assert_float_equal(v, 1.0f / 3.0f, 1e-6f);
    }
}

static void test_tri_miss_and_both_faces(void **state)
{
    rs_tri tr = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 0, -2), rs_v3(0, 1, -2));
    float t, u, v;
    (void)state;
    /* the back face: from below the plane looking up +z */
    assert_true(
        tri_hit(&tr, mk_ray(rs_v3(0.25f, 0.25f, -4), rs_v3(0, 0, 1), 0.0f, T_INF), &t, &u, &v));
    assert_true(t == 2.0f);
    assert_true(u == 0.25f && v == 0.25f);
    /* the same with the winding reversed (the other face now faces the ray) */
    {
        rs_tri rev = mk_tri(tr.v0, tr.v2, tr.v1);
        assert_true(
            tri_hit(&rev, mk_ray(rs_v3(0.25f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
        assert_true(t == 2.0f && u == 0.5f && v == 0.25f);
    }
    /* outside each edge */
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(0.6f, 0.6f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(-0.1f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(0.5f, -0.1f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    /* just outside the hypotenuse and the legs (u + v = 1 + 2^-14, u = -2^-14): exact here */
    assert_false(tri_hit(
        &tr, mk_ray(rs_v3(0.5f + 0x1.0p-14f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_false(tri_hit(&tr, mk_ray(rs_v3(-0x1.0p-14f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t,
                         &u, &v));
    assert_false(tri_hit(&tr, mk_ray(rs_v3(0.5f, -0x1.0p-14f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t,
                         &u, &v));
    /* behind the origin */
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(0.25f, 0.25f, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &t, &u, &v));
    assert_true(t == SENTINEL && u == SENTINEL && v == SENTINEL);
}

static void test_tri_parallel(void **state)
{
    rs_tri tr = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 0, -2), rs_v3(0, 1, -2));
    float t, u, v;
    (void)state;
    /* in the plane, crossing the triangle */
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(-1, 0.25f, -2), rs_v3(1, 0, 0), 0.0f, T_INF), &t, &u, &v));
    assert_false(tri_hit(&tr, mk_ray(rs_v3(-1, -1, -2), rs_v3(1, 1, 0), 0.0f, T_INF), &t, &u, &v));
    /* parallel, above the plane */
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(-1, 0.25f, -1), rs_v3(1, 0, 0), 0.0f, T_INF), &t, &u, &v));
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(-1, 0.25f, -3), rs_v3(3, 2, 0), 0.0f, T_INF), &t, &u, &v));
    /* a degenerate (zero-area) triangle is never hit */
    {
        rs_tri line = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 1, -2), rs_v3(2, 2, -2));
        assert_false(
            tri_hit(&line, mk_ray(rs_v3(0.5f, 0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &u, &v));
    }
    /* NaN directions never hit */
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(0.25f, 0.25f, 0), rs_v3(NAN, 0, -1), 0.0f, T_INF), &t, &u, &v));
    assert_false(
        tri_hit(&tr, mk_ray(rs_v3(0.25f, 0.25f, 0), rs_v3(0, 0, 0), 0.0f, T_INF), &t, &u, &v));
    assert_true(t == SENTINEL);
}

static void test_tri_interval(void **state)
{
    rs_tri tr = mk_tri(rs_v3(0, 0, -2), rs_v3(1, 0, -2), rs_v3(0, 1, -2));
    rs_vec3 o = rs_v3(0.25f, 0.25f, 0), d = rs_v3(0, 0, -1);
    float t, u, v;
    (void)state;
    assert_false(tri_hit(&tr, mk_ray(o, d, 0.0f, 2.0f), &t, &u, &v));
    assert_false(tri_hit(&tr, mk_ray(o, d, 2.0f, T_INF), &t, &u, &v));
    assert_true(t == SENTINEL);
    assert_true(tri_hit(&tr, mk_ray(o, d, 1.9999f, 2.0001f), &t, &u, &v));
    assert_true(t == 2.0f);
    assert_false(tri_hit(&tr, mk_ray(o, d, 2.5f, 3.0f), &t, &u, &v));
}

/* ---- quads: analytic cases ----------------------------------------------------------------- */

static void test_quad_analytic(void **state)
{
    rs_quad q = rs_quad_make(rs_v3(-1, -1, -3), rs_v3(2, 0, 0), rs_v3(0, 2, 0));
    float t, a, b;
    (void)state;
    /* w = n / (n . n) with n = u x v = (0, 0, 4) */
    assert_true(q.w.x == 0.0f && q.w.y == 0.0f && q.w.z == 0.25f);
    assert_true(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_true(t == 3.0f && a == 0.5f && b == 0.5f);
    /* planar coordinates at the corners and along the edges (closed parallelogram) */
    assert_true(quad_hit(&q, mk_ray(rs_v3(-1, -1, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_true(a == 0.0f && b == 0.0f);
    assert_true(quad_hit(&q, mk_ray(rs_v3(1, 1, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_true(a == 1.0f && b == 1.0f);
    assert_true(
        quad_hit(&q, mk_ray(rs_v3(0.5f, -0.5f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_true(a == 0.75f && b == 0.25f);
    /* the back face, with a non-unit direction */
    assert_true(
        quad_hit(&q, mk_ray(rs_v3(0.5f, -0.5f, -7), rs_v3(0, 0, 2), 0.0f, T_INF), &t, &a, &b));
    assert_true(t == 2.0f && a == 0.75f && b == 0.25f);
    /* just outside the sides: a = 1 + 2^-13, b = -2^-13 (exact here) */
    assert_false(quad_hit(&q, mk_ray(rs_v3(1.0f + 0x1.0p-12f, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF),
                          &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, -1.0f - 0x1.0p-12f, 0), rs_v3(0, 0, -1), 0.0f, T_INF),
                          &t, &a, &b));
    /* misses: outside each side, behind, parallel in and off the plane */
    assert_false(quad_hit(&q, mk_ray(rs_v3(1.1f, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_false(
        quad_hit(&q, mk_ray(rs_v3(-1.1f, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 1.1f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_false(
        quad_hit(&q, mk_ray(rs_v3(0, -1.1f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(-5, 0, -3), rs_v3(1, 0, 0), 0.0f, T_INF), &t, &a, &b));
    assert_false(
        quad_hit(&q, mk_ray(rs_v3(-5, 0, -2), rs_v3(1, 0.5f, 0), 0.0f, T_INF), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(NAN, 0, -1), 0.0f, T_INF), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, 0), 0.0f, T_INF), &t, &a, &b));
    assert_true(t == SENTINEL && a == SENTINEL && b == SENTINEL);
    /* the open interval */
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, 3.0f), &t, &a, &b));
    assert_false(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 3.0f, T_INF), &t, &a, &b));
    assert_true(quad_hit(&q, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 2.999f, 3.001f), &t, &a, &b));
    assert_true(t == 3.0f);
}

static void test_quad_skewed(void **state)
{
    /* a parallelogram with non-orthogonal, unequal edges: (a, b) are coordinates in the (u, v)
     * basis, not distances */
    rs_quad q = rs_quad_make(rs_v3(1, 2, 3), rs_v3(2, 0, 1), rs_v3(1, 3, 0));
    float t, a, b;
    int i;
    (void)state;
    for (i = 0; i <= 10; ++i) {
        float wa = 0.1f * (float)i, wb = 1.0f - 0.07f * (float)i;
        rs_vec3 p = rs_v3_add(rs_v3_add(q.q, rs_v3_scale(q.u, wa)), rs_v3_scale(q.v, wb));
        rs_vec3 o = rs_v3(-4, 5, 9), d = rs_v3_sub(p, o);
        assert_true(quad_hit(&q, mk_ray(o, d, 0.0f, T_INF), &t, &a, &b));
        assert_float_equal(t, 1.0f, 1e-5f);
        assert_float_equal(a, wa, 1e-5f);
        assert_float_equal(b, wb, 1e-5f);
        /* from the other side */
        o = rs_v3_madd(p, d, 2.0f);
        assert_true(quad_hit(&q, mk_ray(o, rs_v3_neg(d), 0.0f, T_INF), &t, &a, &b));
        assert_float_equal(t, 2.0f, 1e-5f);
        assert_float_equal(a, wa, 1e-5f);
        assert_float_equal(b, wb, 1e-5f);
    }
}

/* ---- boxes --------------------------------------------------------------------------------- */

static void test_aabb_basic(void **state)
{
    rs_aabb b = mk_box(rs_v3(-1, -1, -1), rs_v3(1, 1, 1));
    float te;
    (void)state;
    /* zero x and y direction components: inv_d = +-inf there */
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_true(te == 4.0f);
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(-0.0f, -0.0f, 1), 0.0f, T_INF, &te));
    assert_true(te == 4.0f);
    assert_true(box_hit(b, rs_v3(0.5f, -0.5f, 5), rs_v3(0, 0, -2), 0.0f, T_INF, &te));
    assert_true(te == 2.0f);
    /* oblique */
    assert_true(box_hit(b, rs_v3(-3, -3, -3), rs_v3(1, 1, 1), 0.0f, T_INF, &te));
    assert_true(te == 2.0f);
    /* misses with zero direction components: outside the x slab */
    assert_false(box_hit(b, rs_v3(2, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_false(box_hit(b, rs_v3(-2, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_false(box_hit(b, rs_v3(2, 0, -5), rs_v3(-0.0f, 0, 1), 0.0f, T_INF, &te));
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(0.1f, 0, 1), 0.0f, T_INF, &te));
    assert_float_equal(te, 4.0f, 1e-6f);
    /* missing past a corner */
    assert_false(box_hit(b, rs_v3(-3, 0, 0), rs_v3(1, 2, 0), 0.0f, T_INF, &te));
    /* origin inside: entry at tmin */
    assert_true(box_hit(b, rs_v3(0.5f, 0.5f, 0.5f), rs_v3(1, 0, 0), 0.0f, T_INF, &te));
    assert_true(te == 0.0f);
    assert_true(box_hit(b, rs_v3(0.5f, 0.5f, 0.5f), rs_v3(0, 0, 0), 0.25f, 3.0f, &te));
    /* a box behind the origin */
    assert_false(box_hit(b, rs_v3(0, 0, 5), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_false(box_hit(b, rs_v3(3, 3, 3), rs_v3(1, 1, 1), 0.0f, T_INF, &te));
    /* [tmin, tmax]: the box spans t in [4, 6] */
    assert_false(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, 3.99f, &te));
    assert_false(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 6.01f, T_INF, &te));
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, 4.0f, &te));
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 5.0f, T_INF, &te));
    assert_true(te == 5.0f);
}

static void test_aabb_in_slab_plane(void **state)
{
    /* Rays lying exactly in one of the box's face planes, parallel to it: 0 * inf = NaN there.
     * core/intersect.h promises "such a ray is treated as inside that slab", so each of these is a
     * hit (the ray runs along a face of the box). */
    rs_aabb b = mk_box(rs_v3(-1, -1, -1), rs_v3(1, 1, 1));
    static const float zeros[2] = {0.0f, -0.0f};
    char failed[1024] = "";
    size_t len = 0;
    float te;
    int axis, side, zi, n_failed = 0;
    (void)state;
    for (axis = 0; axis < 3; ++axis)
        for (side = 0; side < 2; ++side)
            for (zi = 0; zi < 2; ++zi) {
                /* origin on the face plane of `axis` (lo or hi), 5 units before the box along the
                 * next axis, moving along that axis; direction zero on `axis` (+0 or -0) */
                float o[3] = {0, 0, 0}, d[3] = {0, 0, 0};
                int along = (axis + 1) % 3, ok;
                o[axis] = side ? 1.0f : -1.0f;
                o[along] = -5.0f;
                d[axis] = zeros[zi];
                d[along] = 1.0f;
                ok = box_hit(b, rs_v3(o[0], o[1], o[2]), rs_v3(d[0], d[1], d[2]), 0.0f, T_INF,
                             &te) &&
                     te == 4.0f;
                if (!ok) {
                    ++n_failed;
                    if (len < sizeof failed - 64)
                        len += (size_t)snprintf(failed + len, sizeof failed - len,
                                                " [%s-%c plane, d.%c = %s0]", side ? "hi" : "lo",
                                                "xyz"[axis], "xyz"[axis], zi ? "-" : "+");
                }
            }
    if (n_failed)
        fail_msg("%d of 12 rays lying in a face plane of the box miss it:%s", n_failed, failed);
}

static void test_aabb_zero_thickness(void **state)
{
    /* the bounds of an axis-aligned quad: lo.z == hi.z */
    rs_aabb b = mk_box(rs_v3(-1, -1, -3), rs_v3(1, 1, -3));
    float te;
    (void)state;
    assert_true(box_hit(b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF, &te));
    assert_true(te == 3.0f);
    assert_true(box_hit(b, rs_v3(0, 0, 0), rs_v3(0.1f, -0.2f, -1), 0.0f, T_INF, &te));
    assert_float_equal(te, 3.0f, 1e-6f);
    assert_true(box_hit(b, rs_v3(0, 0, -6), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_true(te == 3.0f);
    assert_false(box_hit(b, rs_v3(2, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF, &te));
    assert_false(box_hit(b, rs_v3(0, 0, 0), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
    assert_false(box_hit(b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, 2.9f, &te));
    /* a ray lying in the box's plane: lo.z = hi.z = o.z, both slab distances NaN */
    assert_true(box_hit(b, rs_v3(-5, 0, -3), rs_v3(1, 0, 0), 0.0f, T_INF, &te));
    assert_true(te == 4.0f);
    /* a fully degenerate box (a point) on the ray */
    b = mk_box(rs_v3(0, 0, -3), rs_v3(0, 0, -3));
    assert_true(box_hit(b, rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF, &te));
    assert_true(te == 3.0f);
}

static void test_aabb_nan_ray(void **state)
{
    rs_aabb b = mk_box(rs_v3(-1, -1, -1), rs_v3(1, 1, 1));
    float te;
    (void)state;
    /* any answer is allowed for a NaN direction, but the call must return 0 or 1 */
    int h = box_hit(b, rs_v3(0, 0, -5), rs_v3(NAN, NAN, NAN), 0.0f, T_INF, &te);
    assert_true(h == 0 || h == 1);
    h = box_hit(b, rs_v3(0, 0, -5), rs_v3(INFINITY, 0, 1), 0.0f, T_INF, &te);
    assert_true(h == 0 || h == 1);
}

/* The BVH relies on this: whenever a primitive is hit inside (tmin, tmax), its bounding box is hit
 * too, with an entry distance no larger than the hit's.  Here for a triangle whose edge lies on
 * the box's lo-x face, hit by a ray running in that face's plane. */
static void test_aabb_bounds_primitive_edge_on_face(void **state)
{
    rs_tri tr = mk_tri(rs_v3(0, -1, 1), rs_v3(0, 1, 1), rs_v3(1, 0, 1));
    rs_aabb b = mk_box(rs_v3(0, -1, 1), rs_v3(1, 1, 1));
    float t, u, v, te;
    (void)state;
    /* Moller-Trumbore: the ray meets the edge v0-v1 at (0, 0, 1), t = 6, v = 0, exactly */
    assert_true(tri_hit(&tr, mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF), &t, &u, &v));
    assert_true(t == 6.0f && u == 0.5f && v == 0.0f);
    if (!box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF, &te))
        fail_msg("the triangle is hit at t = 6 but its bounding box is missed (ray in the lo-x "
                 "face plane)");
    assert_true(te <= t);
    /* the mirror image, edge on the hi-x face, for comparison */
    tr = mk_tri(rs_v3(0, -1, 1), rs_v3(0, 1, 1), rs_v3(-1, 0, 1));
    b = mk_box(rs_v3(-1, -1, 1), rs_v3(0, 1, 1));
    assert_true(tri_hit(&tr, mk_ray(rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF), &t, &u, &v));
    assert_true(box_hit(b, rs_v3(0, 0, -5), rs_v3(0, 0, 1), 0.0f, T_INF, &te));
}

/* ---- randomized comparison with double-precision references -------------------------------- */

static void test_sphere_tangent(void **state)
{
    uint64_t seed = 11;
    int i, inside = 0, outside = 0, band = 0;
    float t;
    (void)state;
    /* exactly tangent: disc = 0, one root t = 5 at the tangent point (0, 1, -5) */
    {
        rs_sphere s = mk_sphere(rs_v3(0.0f, 1.0f, -5.0f), 1.0f);
        int h = sphere_hit(&s, mk_ray(rs_v3(0, 0, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t);
        if (h)
            assert_true(t == 5.0f);
        /* clearly inside and clearly outside the silhouette */
        assert_true(sphere_hit(&s, mk_ray(rs_v3(0, 0.01f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
        assert_false(sphere_hit(&s, mk_ray(rs_v3(0, -0.01f, 0), rs_v3(0, 0, -1), 0.0f, T_INF), &t));
    }
    /* Random grazing rays passing at distance r (1 + e) from the centre, |e| <= 2e-3.  e is
     * measured in double on the float ray actually built.  Inside the band where float cannot
     * resolve the discriminant (the randomized test's band: |disc| < 1e-5 a (|oc|^2 + r^2), about
     * |e| < 1e-4 here) either answer is right; beyond it the answer must be the geometric one.
     * A hit must never carry a NaN and must lie close to the point of closest approach: the
     * half-chord there is r sqrt(-2e - e^2), and float error adds a few 1e-3 near e = 0. */
    for (i = 0; i < 100000; ++i) {
        rs_vec3 c = rnd_box(&seed, 5.0f), dir = rnd_unit(&seed), perp;
        float r = rnd_range(&seed, 0.5, 2.0), e = rnd_range(&seed, -2e-3, 2e-3);
        float back = rnd_range(&seed, 1.0, 3.0);
        rs_sphere s = mk_sphere(c, r);
        rs_vec3 closest, o;
        rs_ray ray;
        double ocx, ocy, ocz, along, perp2, e_act;
        int h;
        perp = rs_v3_normalize(
            rs_v3_cross(dir, fabsf(dir.x) < 0.5f ? rs_v3(1, 0, 0) : rs_v3(0, 1, 0)));
        closest = rs_v3_madd(c, perp, r * (1.0f + e));
        o = rs_v3_madd(closest, dir, -back);
        ray = mk_ray(o, dir, 0.0f, T_INF);
        h = sphere_hit(&s, ray, &t);
        /* the float ray's actual distance from the centre, in double */
        ocx = (double)c.x - o.x;
        ocy = (double)c.y - o.y;
        ocz = (double)c.z - o.z;
        along = (ocx * dir.x + ocy * dir.y + ocz * dir.z) /
                ((double)dir.x * dir.x + (double)dir.y * dir.y + (double)dir.z * dir.z);
        perp2 =
            ocx * ocx + ocy * ocy + ocz * ocz -
            along * along * ((double)dir.x * dir.x + (double)dir.y * dir.y + (double)dir.z * dir.z);
        e_act = sqrt(fmax(perp2, 0.0)) / r - 1.0;
        if (h) {
            double half = r * sqrt(fmax(-2.0 * e_act - e_act * e_act, 0.0));
            if (isnan(t) || isinf(t))
                fail_msg("grazing ray %d: non-finite t %g", i, t);
            if (!(fabs(t - along) <= half + 5e-3 * r))
                fail_msg("grazing ray %d: t %.7g, closest approach at %.7g, e %.3g", i, t, along,
                         e_act);
        }
        if (ref_sphere(&s, &ray).ambiguous) {
            ++band;
        } else if (e_act < 0.0) {
            if (!h)
                fail_msg("ray %d passing inside the sphere (e = %.3g) missed", i, e_act);
            ++inside;
        } else {
            if (h)
                fail_msg("ray %d passing outside the sphere (e = %.3g) hit at t %.7g", i, e_act, t);
            ++outside;
        }
    }
    print_message("grazing: %d inside, %d outside, %d within the band\n", inside, outside, band);
    assert_true(inside > 30000 && outside > 30000);
}

/* Quad.  Reference: the same plane and planar coordinates, in double from q, u, v (not from the
 * stored float w). */
static ref_result ref_quad(const rs_quad *q, const rs_ray *r)
{
    ref_result out = {0, 0, 0.0, 0.0, 0.0, 0.0};
    dv3 q0 = dv(q->q), eu = dv(q->u), ev = dv(q->v), o = dv(r->o), d = dv(r->d);
    dv3 n = dcross(eu, ev), p;
    double denom = ddot(n, d), t, a, b, band, m;
    double scale = (sqrt(ddot(dsub(q0, o), dsub(q0, o))) + sqrt(ddot(eu, eu) + ddot(ev, ev))) /
                   sqrt(ddot(d, d));
    band = edge_band(eu, ev, dsub(o, q0), d);
    if (band > 1e-3)
        out.ambiguous = 1;
    if (denom == 0.0)
        return out;
    t = ddot(n, dsub(q0, o)) / denom;
    p.x = o.x + t * d.x - q0.x;
    p.y = o.y + t * d.y - q0.y;
    p.z = o.z + t * d.z - q0.z;
    a = ddot(n, dcross(p, ev)) / ddot(n, n);
    b = ddot(n, dcross(eu, p)) / ddot(n, n);
    m = fmin(fmin(a, 1.0 - a), fmin(b, 1.0 - b));
    if (fabs(m) <= band || near_bound(t, r->tmin, r->tmax, scale))
        out.ambiguous = 1;
    if (m >= 0.0 && t > r->tmin && t < r->tmax) {
        out.hit = 1;
        out.t = t;
        out.u = a;
        out.v = b;
    }
    return out;
}

/* A random ray: the origin anywhere in [-10, 10]^3; usually aimed at `target` (a point near the
 * primitive), with a random length of direction; now and then a fully random direction, a
 * positive tmin, or a tmax cut somewhere around the target. */
static rs_ray random_ray(uint64_t *s, rs_vec3 target)
{
    rs_vec3 o = rnd_box(s, 10.0f), d;
    float tmin = 0.0f, tmax = T_INF, k = rnd_range(s, 0.25, 4.0);
    double pick = rnd01(s);
    if (pick < 0.2)
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
    int rays, ambiguous, hits, misses;
    double max_rel_t, max_uv;
} cmp_stats;

static void compare(cmp_stats *st, const char *what, int i, int got, float t, float u, float v,
                    ref_result ref, int check_uv)
{
    ++st->rays;
    if (ref.ambiguous) {
        ++st->ambiguous;
        if (got && !(t > 0.0f || t <= 0.0f))
            fail_msg("%s ray %d: hit with NaN t", what, i);
        return;
    }
    if (got != ref.hit)
        fail_msg("%s ray %d: got %s, reference %s (t %.9g)", what, i, got ? "hit" : "miss",
                 ref.hit ? "hit" : "miss", ref.t);
    if (!got) {
        ++st->misses;
        return;
    }
    ++st->hits;
    {
        double rel = fabs(t - ref.t) / fabs(ref.t);
        if (rel > st->max_rel_t)
            st->max_rel_t = rel;
        if (!(rel <= 1e-4))
            fail_msg("%s ray %d: t %.9g, reference %.9g (relative error %.3g)", what, i, t, ref.t,
                     rel);
    }
    if (check_uv) {
        double e = fmax(fabs(u - ref.u), fabs(v - ref.v));
        if (e > st->max_uv)
            st->max_uv = e;
        if (!(e <= 1e-3))
            fail_msg("%s ray %d: (u, v) (%.7g, %.7g), reference (%.7g, %.7g)", what, i, u, v, ref.u,
                     ref.v);
    }
}

static void report(const cmp_stats *st, const char *what)
{
    print_message("%s: %d rays, %d hits, %d misses, %d in the ambiguity band; max relative t "
                  "error %.3g, max (u, v) error %.3g\n",
                  what, st->rays, st->hits, st->misses, st->ambiguous, st->max_rel_t, st->max_uv);
    /* the bands must stay narrow (under 4% of the rays), or the comparison would be vacuous */
    assert_true(st->ambiguous < st->rays / 25);
    assert_true(st->hits > st->rays / 10);
    assert_true(st->misses > st->rays / 10);
}

enum { N_RANDOM = 100000 };

static void test_sphere_random_vs_reference(void **state)
{
    uint64_t s = 0xa11ce;
    cmp_stats st = {0, 0, 0, 0, 0.0, 0.0};
    int i;
    (void)state;
    for (i = 0; i < N_RANDOM; ++i) {
        rs_sphere sp = mk_sphere(rnd_box(&s, 5.0f), rnd_range(&s, 0.1, 3.0));
        rs_vec3 target = rs_v3_madd(sp.center, rnd_unit(&s), sp.radius * rnd_range(&s, 0.0, 1.3));
        rs_ray r = random_ray(&s, target);
        float t;
        int got = sphere_hit(&sp, r, &t);
        compare(&st, "sphere", i, got, t, 0.0f, 0.0f, ref_sphere(&sp, &r), 0);
    }
    report(&st, "sphere");
}

static void test_tri_random_vs_reference(void **state)
{
    uint64_t s = 0xb0b;
    cmp_stats st = {0, 0, 0, 0, 0.0, 0.0};
    int i;
    (void)state;
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
        float t, u, v;
        int got = tri_hit(&tr, r, &t, &u, &v);
        compare(&st, "triangle", i, got, t, u, v, ref_tri(&tr, &r), 1);
    }
    report(&st, "triangle");
}

static void test_quad_random_vs_reference(void **state)
{
    uint64_t s = 0xc0ffee;
    cmp_stats st = {0, 0, 0, 0, 0.0, 0.0};
    int i;
    (void)state;
    for (i = 0; i < N_RANDOM; ++i) {
        rs_vec3 q0 = rnd_box(&s, 5.0f);
        rs_quad q = rs_quad_make(q0, rs_v3_scale(rnd_unit(&s), rnd_range(&s, 0.2, 4.0)),
                                 rs_v3_scale(rnd_unit(&s), rnd_range(&s, 0.2, 4.0)));
        float a = rnd_range(&s, -0.3, 1.3), b = rnd_range(&s, -0.3, 1.3);
        rs_vec3 target = rs_v3_add(rs_v3_add(q.q, rs_v3_scale(q.u, a)), rs_v3_scale(q.v, b));
        rs_ray r = random_ray(&s, target);
        float t, u, v;
        int got = quad_hit(&q, r, &t, &u, &v);
        compare(&st, "quad", i, got, t, u, v, ref_quad(&q, &r), 1);
    }
    report(&st, "quad");
}

/* Boxes against a double slab test.  The reference works on the ray's line directly (no
 * reciprocals), so zero direction components are exact: such a slab is all of t when the
 * origin lies inside it and empty otherwise.  Ambiguous when entry and exit distances are within
 * 1e-5 (relative to the box's distance along the ray) of each other.  A quarter of the rays have
 * a zero direction component (+0 or -0); a tenth of the boxes have zero thickness.  Origins
 * exactly on a face plane are left to test_aabb_in_slab_plane. */
static void test_aabb_random_vs_reference(void **state)
{
    uint64_t s = 0xb0c5;
    int i, ambiguous = 0, hits = 0, misses = 0;
    (void)state;
    for (i = 0; i < N_RANDOM; ++i) {
        rs_vec3 c = rnd_box(&s, 5.0f), h, o, d, lo, hi;
        float tmin = 0.0f, tmax = T_INF, te;
        double tn, tf, scale;
        int axis, got, ref, amb = 0;
        h = rs_v3(rnd_range(&s, 0.0, 3.0), rnd_range(&s, 0.0, 3.0), rnd_range(&s, 0.0, 3.0));
        if (i % 10 == 0)
            h.z = 0.0f; /* zero thickness */
        lo = rs_v3_sub(c, h);
        hi = rs_v3_add(c, h);
        o = rnd_box(&s, 10.0f);
        d = rs_v3_scale(rs_v3_sub(rs_v3_madd(c, rnd_box(&s, 1.0f), 1.5f * rs_v3_max_comp(h)), o),
                        rnd_range(&s, 0.25, 4.0));
        if (i % 4 == 1) {
            axis = (int)(splitmix64(&s) % 3);
            if (axis == 0)
                d.x = (i & 8) ? -0.0f : 0.0f;
            else if (axis == 1)
                d.y = (i & 8) ? -0.0f : 0.0f;
            else
                d.z = (i & 8) ? -0.0f : 0.0f;
        }
        if (i % 5 == 2)
            tmax = rnd_range(&s, 0.2, 2.0);
        if (i % 7 == 3)
            tmin = rnd_range(&s, 0.0, 0.5);
        /* reference */
        tn = tmin;
        tf = tmax;
        scale = 0.0;
        for (axis = 0; axis < 3; ++axis) {
            double oa = rs_v3_get(o, axis), da = rs_v3_get(d, axis);
            double la = rs_v3_get(lo, axis), ha = rs_v3_get(hi, axis);
            if (da == 0.0) {
                if (oa < la || oa > ha)
                    tn = INFINITY, tf = -INFINITY;
            } else {
                double t0 = (la - oa) / da, t1 = (ha - oa) / da;
                scale = fmax(scale, fmax(fabs(t0), fabs(t1)));
                tn = fmax(tn, fmin(t0, t1));
                tf = fmin(tf, fmax(t0, t1));
            }
        }
        ref = tn <= tf;
        if (fabs(tn - tf) <= 1e-5 * scale)
            amb = 1;
        got = box_hit(mk_box(lo, hi), o, d, tmin, tmax, &te);
        if (amb) {
            ++ambiguous;
            continue;
        }
        if (got != ref)
            fail_msg("box ray %d: got %s, reference %s (entry %.9g, exit %.9g); o (%.9g %.9g "
                     "%.9g) d (%.9g %.9g %.9g) lo (%.9g %.9g %.9g) hi (%.9g %.9g %.9g)",
                     i, got ? "hit" : "miss", ref ? "hit" : "miss", tn, tf, o.x, o.y, o.z, d.x, d.y,
                     d.z, lo.x, lo.y, lo.z, hi.x, hi.y, hi.z);
        if (got) {
            ++hits;
            if (!(fabs(te - tn) <= 1e-5 * fmax(fabs(tn), 1e-3 * scale)))
                fail_msg("box ray %d: entry %.9g, reference %.9g", i, te, tn);
        } else {
            ++misses;
        }
    }
    print_message("box: %d rays, %d hits, %d misses, %d ambiguous\n", N_RANDOM, hits, misses,
                  ambiguous);
    assert_true(ambiguous < N_RANDOM / 50);
    assert_true(hits > N_RANDOM / 5 && misses > N_RANDOM / 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere_head_on),
        cmocka_unit_test(test_sphere_miss),
        cmocka_unit_test(test_sphere_inside),
        cmocka_unit_test(test_sphere_interval),
        cmocka_unit_test(test_sphere_tangent),
        cmocka_unit_test(test_sphere_degenerate_rays),
        cmocka_unit_test(test_tri_head_on_and_barycentrics),
        cmocka_unit_test(test_tri_miss_and_both_faces),
        cmocka_unit_test(test_tri_parallel),
        cmocka_unit_test(test_tri_interval),
        cmocka_unit_test(test_quad_analytic),
        cmocka_unit_test(test_quad_skewed),
        cmocka_unit_test(test_aabb_basic),
        cmocka_unit_test(test_aabb_in_slab_plane),
        cmocka_unit_test(test_aabb_zero_thickness),
        cmocka_unit_test(test_aabb_nan_ray),
        cmocka_unit_test(test_aabb_bounds_primitive_edge_on_face),
        cmocka_unit_test(test_sphere_random_vs_reference),
        cmocka_unit_test(test_tri_random_vs_reference),
        cmocka_unit_test(test_quad_random_vs_reference),
        cmocka_unit_test(test_aabb_random_vs_reference),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
