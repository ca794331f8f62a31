/* tests/shading_spawn_test.c — shading/spawn.h: rays leave surfaces without finding them again,
 * from offsets of a few ulps, at any distance from the origin.
 *
 * For spheres, parallelograms and triangles of sizes 10^-2..10^2 placed 0..10^5 units from the
 * origin (random, fixed seed), a point on the primitive (from its parameters, as shading and
 * light sampling make them) is moved off it by rs_spawn_origin, and a ray leaves toward that side
 * in a direction uniform over the hemisphere:
 *   - the origin is on the leaving side of the exact primitive (for spheres, checked in double);
 *   - every intersection test of the primitive (core/intersect.h: the sphere's two, the
 *     triangle's three, the parallelogram's) must miss it over (0, inf), or for a ray into a
 *     sphere hit it (its far side: the origin is inside);
 *   - the offset must be small: at most 8 ulps of the point's largest coordinate plus a few ulps
 *     of the primitive's size (the 1e-4-of-the-coordinates epsilon it replaced is ~840 ulps);
 *   - a shadow ray from such an origin to rs_spawn_end of a point on a light primitive must not
 *     hit the light (with tmax = 1, no shortening).
 * Spheres smaller than 64 ulps of their centre's coordinates are left out (at 10^4 units, below
 * 0.06 units: no longer round in floats), and so are triangles and parallelograms whose edges
 * meet at a sine below ~1/1024 (the margin is held there).
 * Directions closer than 1e-3 (cosine) to the tangent plane are left out for the sphere: there
 * the half-b discriminant's rounding, relative to r^2, exceeds any offset of a few ulps (such a
 * ray might find the sphere again at t ~ 0; about one ray in 10^3 of a uniform hemisphere, far
 * fewer of a cosine-weighted one). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <float.h>
#include <math.h>
#include <cmocka.h>

#include "shading/spawn.h"
#include "test_rand.h"

#define TRIALS 20000

static const double dists[] = {0.0, 1e1, 1e2, 1e3, 1e4, 1e5};
static const double sizes[] = {1e-2, 1.0, 1e2};
#define N_DISTS (sizeof dists / sizeof dists[0])
#define N_SIZES (sizeof sizes / sizeof sizes[0])

static float ulp_of(float x)
{
    float a = fabsf(x);
    return nextafterf(a, INFINITY) - a;
}

static float max_abs(rs_vec3 p) { return rs_fmaxf(fabsf(p.x), rs_fmaxf(fabsf(p.y), fabsf(p.z))); }

/* A direction uniform over the hemisphere about unit n, at least `min_cos` from its plane. */
static rs_vec3 leaving_dir(uint64_t *s, rs_vec3 n, float min_cos)
{
    for (;;) {
        rs_vec3 d = rnd_unit(s);
        float c = rs_v3_dot(d, n);
        if (c < 0.0f) {
            d = rs_v3_neg(d);
            c = -c;
        }
        if (c >= min_cos)
            return d;
    }
}

static rs_vec3 place(uint64_t *s, double dist)
{
    /* a point about `dist` from the origin in a random octant-ish direction */
    rs_vec3 u = rnd_unit(s);
    return rs_v3((float)(dist * u.x), (float)(dist * u.y), (float)(dist * u.z));
}

/* The offset must stay within 8 ulps of the point plus `size_ulps` ulps of size 1 times size. */
static void check_offset(rs_vec3 p, rs_vec3 po, float size_term, const char *what, double dist,
                         double size)
{
    float off = max_abs(rs_v3_sub(po, p));
    float bound = 8.0f * ulp_of(max_abs(p)) + size_term;
    if (!(off > 0.0f && off <= bound))
        fail_msg("%s at %g, size %g: offset %g, bound %g (ulp %g)", what, dist, size, off, bound,
                 ulp_of(max_abs(p)));
}

/* Signed distance (in double, exact inputs) of x from the plane through a spanned by e and f,
 * along +(e x f). */
static double plane_side(rs_vec3 a, rs_vec3 e, rs_vec3 f, rs_vec3 x)
{
    double nx = (double)e.y * f.z - (double)e.z * f.y, ny = (double)e.z * f.x - (double)e.x * f.z;
    double nz = (double)e.x * f.y - (double)e.y * f.x;
    return nx * ((double)x.x - a.x) + ny * ((double)x.y - a.y) + nz * ((double)x.z - a.z);
}

static void test_sphere(void **state)
{
    uint64_t seed = 101;
    size_t di, si;
    int i, algo;
    (void)state;
    for (di = 0; di < N_DISTS; ++di)
        for (si = 0; si < N_SIZES; ++si)
            for (i = 0; i < TRIALS; ++i) {
                rs_sphere sp;
                rs_surface_point s;
                rs_vec3 dir, po;
                int inward = i & 1;
                sp.center = rs_v3_add(place(&seed, dists[di]), rnd_box(&seed, (float)sizes[si]));
                sp.radius = rnd_range(&seed, 0.1 * sizes[si], sizes[si]);
                if (sp.radius < 64.0f * ulp_of(max_abs(sp.center)))
                    continue; /* smaller than 64 ulps of its position: not a sphere in floats */
                s = rs_sphere_point(sp.center, sp.radius, rs_v3_scale(rnd_unit(&seed), sp.radius));
                dir = leaving_dir(&seed, inward ? rs_v3_neg(s.ng) : s.ng, 1e-3f);
                po = rs_spawn_origin(s.p, s.err, inward ? rs_v3_neg(s.ng) : s.ng);
                check_offset(s.p, po, 32.0f * FLT_EPSILON * sp.radius, "sphere", dists[di],
                             sizes[si]);
                for (algo = 0; algo < RS_ISECT_SPHERE_COUNT; ++algo) {
                    rs_ray r = mk_ray(po, dir, 0.0f, FLT_MAX);
                    float t;
                    int hit = rs_isect_sphere_by((uint32_t)algo, &sp, &r, &t);
                    if (!inward && hit)
                        fail_msg("sphere (%s) at %g, r %g: a ray leaving outward hit it at t %g",
                                 rs_isect_sphere_algo_name((uint32_t)algo), dists[di], sp.radius,
                                 t);
                    if (inward && !hit)
                        fail_msg("sphere (%s) at %g, r %g: a ray inward missed it",
                                 rs_isect_sphere_algo_name((uint32_t)algo), dists[di], sp.radius);
                }
                {
                    /* the origin on the leaving side of the true sphere (exactly, in double) */
                    double dx = (double)po.x - sp.center.x, dy = (double)po.y - sp.center.y;
                    double dz = (double)po.z - sp.center.z, r = sp.radius;
                    double d2 = dx * dx + dy * dy + dz * dz;
                    if (inward ? !(d2 < r * r) : !(d2 > r * r))
                        fail_msg("sphere at %g, r %g: the %s origin is %g from the centre",
                                 dists[di], r, inward ? "inward" : "outward", sqrt(d2));
                }
            }
}

static void test_quad(void **state)
{
    uint64_t seed = 202;
    size_t di, si;
    int i;
    (void)state;
    for (di = 0; di < N_DISTS; ++di)
        for (si = 0; si < N_SIZES; ++si)
            for (i = 0; i < TRIALS; ++i) {
                float h = (float)sizes[si];
                rs_quad q = rs_quad_make(rs_v3_add(place(&seed, dists[di]), rnd_box(&seed, h)),
                                         rnd_box(&seed, h), rnd_box(&seed, h));
                rs_surface_point s =
                    rs_quad_point(&q, rnd_range(&seed, 0, 1), rnd_range(&seed, 0, 1));
                rs_vec3 n = (i & 1) ? rs_v3_neg(s.ng) : s.ng, dir, po;
                rs_ray r;
                float t, a, b;
                if (!(rs_v3_length2(rs_v3_cross(q.u, q.v)) > 1e-6f * h * h * h * h))
                    continue; /* a degenerate draw */
                dir = leaving_dir(&seed, n, 0.0f);
                po = rs_spawn_origin(s.p, s.err, n);
                {
                    float l1 = rs_v3_norm1(q.u), l2 = rs_v3_norm1(q.v);
                    float slim = l1 * l2 * rs_v3_length(q.w);
                    if (!(slim < 1024.0f))
                        continue; /* a sliver beyond what the margin covers */
                    check_offset(s.p, po, 24.0f * FLT_EPSILON * (l1 + l2) * slim, "quad", dists[di],
                                 sizes[si]);
                }
                if (!(plane_side(q.q, q.u, q.v, po) * rs_v3_dot(n, s.ng) > 0.0))
                    fail_msg("quad at %g, size %g: the origin is not on the leaving side",
                             dists[di], sizes[si]);
                r = mk_ray(po, dir, 0.0f, FLT_MAX);
                if (rs_isect_quad(&q, &r, &t, &a, &b))
                    fail_msg("quad at %g, size %g: a leaving ray hit it at t %g", dists[di],
                             sizes[si], t);
            }
}

static void test_triangle(void **state)
{
    uint64_t seed = 303;
    size_t di, si;
    int i, algo;
    (void)state;
    for (di = 0; di < N_DISTS; ++di)
        for (si = 0; si < N_SIZES; ++si)
            for (i = 0; i < TRIALS; ++i) {
                float h = (float)sizes[si], b1 = rnd_range(&seed, 0, 1), b2;
                rs_vec3 c = place(&seed, dists[di]), n, dir, po, e1, e2;
                rs_tri tr;
                rs_surface_point s;
                float slim;
                tr.v0 = rs_v3_add(c, rnd_box(&seed, h));
                tr.v1 = rs_v3_add(c, rnd_box(&seed, h));
                tr.v2 = rs_v3_add(c, rnd_box(&seed, h));
                e1 = rs_v3_sub(tr.v1, tr.v0);
                e2 = rs_v3_sub(tr.v2, tr.v0);
                slim = rs_v3_norm1(e1) * rs_v3_norm1(e2) / rs_v3_length(rs_v3_cross(e1, e2));
                if (!(slim < 1024.0f))
                    continue; /* a sliver beyond what the margin covers, or degenerate */
                b2 = rnd_range(&seed, 0, 1.0 - b1);
                s = rs_tri_point(&tr, b1, b2);
                n = (i & 1) ? rs_v3_neg(s.ng) : s.ng;
                dir = leaving_dir(&seed, n, 0.0f);
                po = rs_spawn_origin(s.p, s.err, n);
                check_offset(s.p, po,
                             24.0f * FLT_EPSILON * (rs_v3_norm1(e1) + rs_v3_norm1(e2)) * slim,
                             "triangle", dists[di], sizes[si]);
                if (!(plane_side(tr.v0, e1, e2, po) * rs_v3_dot(n, s.ng) > 0.0))
                    fail_msg("triangle at %g, size %g: the origin is not on the leaving side",
                             dists[di], sizes[si]);
                for (algo = 0; algo < RS_ISECT_TRI_COUNT; ++algo) {
                    rs_ray r = mk_ray(po, dir, 0.0f, FLT_MAX);
                    float t, u, v;
                    if (rs_isect_tri_by((uint32_t)algo, &tr, &r, &t, &u, &v))
                        fail_msg("triangle (%s) at %g, size %g, slim %g: a leaving ray hit it "
                                 "at t %g",
                                 rs_isect_tri_algo_name((uint32_t)algo), dists[di], sizes[si], slim,
                                 t);
                }
            }
}

/* Shadow rays from a point above a light to rs_spawn_end of a point on it never reach it. */
static void test_shadow_end(void **state)
{
    uint64_t seed = 404;
    size_t di;
    int i;
    (void)state;
    for (di = 0; di < N_DISTS; ++di)
        for (i = 0; i < TRIALS; ++i) {
            float h = 1.0f, t, a, b, u, v;
            rs_vec3 c = place(&seed, dists[di]);
            rs_quad q =
                rs_quad_make(rs_v3_add(c, rnd_box(&seed, h)), rnd_box(&seed, h), rnd_box(&seed, h));
            rs_tri tr;
            rs_surface_point lq = rs_quad_point(&q, rnd_range(&seed, 0, 1), rnd_range(&seed, 0, 1));
            rs_surface_point lt;
            rs_vec3 from = rs_v3_add(c, rnd_box(&seed, 4.0f)), end;
            rs_ray r;
            tr.v0 = q.q;
            tr.v1 = rs_v3_add(q.q, q.u);
            tr.v2 = rs_v3_add(q.q, q.v);
            if (!(rs_v3_length2(rs_v3_cross(q.u, q.v)) > 1e-4f))
                continue;
            end = rs_spawn_end(lq.p, lq.err, lq.ng, from);
            r = mk_ray(from, rs_v3_sub(end, from), 0.0f, 1.0f);
            if (rs_isect_quad(&q, &r, &t, &a, &b) &&
                fabsf(rs_v3_dot(lq.ng, rs_v3_normalize(r.d))) > 1e-3f)
                fail_msg("a shadow ray at %g reached its quad light at t %.9g", dists[di], t);
            lt = rs_tri_point(&tr, 0.3f * rnd_range(&seed, 0, 1), 0.3f * rnd_range(&seed, 0, 1));
            end = rs_spawn_end(lt.p, lt.err, lt.ng, from);
            r = mk_ray(from, rs_v3_sub(end, from), 0.0f, 1.0f);
            if (rs_isect_tri(&tr, &r, &t, &u, &v) &&
                fabsf(rs_v3_dot(lt.ng, rs_v3_normalize(r.d))) > 1e-3f)
                fail_msg("a shadow ray at %g reached its triangle light at t %.9g", dists[di], t);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sphere),
        cmocka_unit_test(test_quad),
        cmocka_unit_test(test_triangle),
        cmocka_unit_test(test_shadow_end),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
