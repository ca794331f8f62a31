/* tests/test_isect_ref.h — what the intersection tests share: constructors, and the
 * double-precision references with their "either answer is right" bands (test-only). */
#ifndef RS_TESTS_TEST_ISECT_REF_H
#define RS_TESTS_TEST_ISECT_REF_H

#include <float.h>
#include <math.h>

#include "core/intersect.h"

#ifndef T_INF
#  define T_INF FLT_MAX
#endif

static inline rs_tri mk_tri(rs_vec3 a, rs_vec3 b, rs_vec3 c)
{
    rs_tri t;
    t.v0 = a;
    t.v1 = b;
    t.v2 = c;
    return t;
}

static inline rs_sphere mk_sphere(rs_vec3 c, float r)
{
    rs_sphere s;
    s.center = c;
    s.radius = r;
    return s;
}

static inline rs_aabb mk_box(rs_vec3 lo, rs_vec3 hi)
{
    rs_aabb b;
    b.lo = lo;
    b.hi = hi;
    return b;
}

static inline rs_vec3 inv_dir(rs_vec3 d) { return rs_v3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z); }

typedef struct ref_result {
    int hit;       /* the exact answer for the float inputs */
    int ambiguous; /* within the stated band: either answer is accepted, t is not compared */
    double t;      /* on a hit */
    double u, v;   /* on a hit: barycentrics of v1 and v2 */
    double scale;  /* the distances involved, in units of t (|o - primitive| + its size) / |d| */
} ref_result;

typedef struct dv3 {
    double x, y, z;
} dv3;

static inline dv3 dv(rs_vec3 a)
{
    dv3 r;
    r.x = a.x;
    r.y = a.y;
    r.z = a.z;
    return r;
}

static inline dv3 dsub(dv3 a, dv3 b)
{
    dv3 r;
    r.x = a.x - b.x;
    r.y = a.y - b.y;
    r.z = a.z - b.z;
    return r;
}

static inline double ddot(dv3 a, dv3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

static inline dv3 dcross(dv3 a, dv3 b)
{
    dv3 r;
    r.x = a.y * b.z - a.z * b.y;
    r.y = a.z * b.x - a.x * b.z;
    r.z = a.x * b.y - a.y * b.x;
    return r;
}

/* Relative band around tmin and tmax in which either answer is accepted: a root that close to an
 * end of the interval is decided by float rounding of t itself. */
#define T_BAND 1e-4

static inline int near_bound(double t, double tmin, double tmax, double scale)
{
    double band = T_BAND * scale;
    return fabs(t - tmin) <= band || (tmax < T_INF && fabs(t - tmax) <= band);
}

/* Edge band for triangles, in barycentric units.  Each float variant forms the barycentrics from
 * products of coordinates relative to v0 (Möller–Trumbore: s . (d x e2) / det; Snyder–Barr: the
 * same Cramer determinants with other factors; watertight: 2D edge functions of vertices sheared
 * by d / d[kz]), so each is off by about eps (distance / edge length) aspect / cos, where
 * aspect = |e1||e2| / |e1 x e2| and cos is that of the angle between the ray and the normal.  The
 * band is 16 times that (eps = 2^-24 ~ 6e-8); closer to an edge than that either answer is
 * accepted.  (The same band as tests/core_intersect_test.c.) */
static inline double edge_band(dv3 e1, dv3 e2, dv3 o_minus_v0, dv3 d)
{
    dv3 n = dcross(e1, e2);
    double nn = sqrt(ddot(n, n)), cosang = fabs(ddot(n, d)) / (nn * sqrt(ddot(d, d)));
    double aspect = sqrt(ddot(e1, e1) * ddot(e2, e2)) / nn;
    double edge = sqrt(fmin(ddot(e1, e1), ddot(e2, e2)));
    double dist = sqrt(ddot(o_minus_v0, o_minus_v0));
    return 16.0 * 0x1.0p-24 * (1.0 + dist / edge) * aspect / fmax(cosang, 1e-30);
}

/* Sphere: the quadratic in double.  Ambiguous when |disc| < 1e-5 a (|oc|^2 + r^2).  Both float
 * variants get the discriminant (algebraic: a (r^2 - |l|^2); geometric: r^2 - (|oc|^2 - s^2))
 * with an error of a few ulps of |oc|^2 or better, far inside that band; the square root then
 * amplifies the error near the silhouette, and the band keeps the t error of a hit below 1e-4
 * relative. */
static inline ref_result ref_sphere(const rs_sphere *s, const rs_ray *r)
{
    ref_result out = {0, 0, 0.0, 0.0, 0.0, 0.0};
    dv3 oc = dsub(dv(s->center), dv(r->o)), d = dv(r->d);
    double a = ddot(d, d), h = ddot(d, oc), rad = s->radius;
    double c = ddot(oc, oc) - rad * rad, disc = h * h - a * c;
    double size = ddot(oc, oc) + rad * rad, scale = sqrt(size / a);
    double sq, t0, t1;
    out.scale = scale;
    out.ambiguous = fabs(disc) < 1e-5 * a * size;
    if (disc < 0.0)
        return out;
    sq = sqrt(disc);
    t0 = (h - sq) / a;
    t1 = (h + sq) / a;
    if (near_bound(t0, r->tmin, r->tmax, scale) || near_bound(t1, r->tmin, r->tmax, scale))
        out.ambiguous = 1;
    if (t0 > r->tmin && t0 < r->tmax) {
        out.hit = 1;
        out.t = t0;
    } else if (t1 > r->tmin && t1 < r->tmax) {
        out.hit = 1;
        out.t = t1;
    }
    return out;
}

/* Triangle: the plane intersection, then barycentrics from signed areas, in double. */
static inline ref_result ref_tri(const rs_tri *tr, const rs_ray *r)
{
    ref_result out = {0, 0, 0.0, 0.0, 0.0, 0.0};
    dv3 v0 = dv(tr->v0), e1 = dsub(dv(tr->v1), v0), e2 = dsub(dv(tr->v2), v0);
    dv3 o = dv(r->o), d = dv(r->d), n = dcross(e1, e2), p;
    double denom = ddot(n, d), t, u, v, band, m;
    double scale = (sqrt(ddot(dsub(v0, o), dsub(v0, o))) + sqrt(ddot(e1, e1) + ddot(e2, e2))) /
                   sqrt(ddot(d, d));
    out.scale = scale;
    band = edge_band(e1, e2, dsub(o, v0), d);
    if (band > 1e-3) /* grazing or sliver: the float answer is not meaningful to compare */
        out.ambiguous = 1;
    if (denom == 0.0)
        return out;
    t = ddot(n, dsub(v0, o)) / denom;
    p.x = o.x + t * d.x - v0.x;
    p.y = o.y + t * d.y - v0.y;
    p.z = o.z + t * d.z - v0.z;
    u = ddot(n, dcross(p, e2)) / ddot(n, n);
    v = ddot(n, dcross(e1, p)) / ddot(n, n);
    m = fmin(fmin(u, v), 1.0 - u - v);
    if (fabs(m) <= band || near_bound(t, r->tmin, r->tmax, scale))
        out.ambiguous = 1;
    if (m >= 0.0 && t > r->tmin && t < r->tmax) {
        out.hit = 1;
        out.t = t;
        out.u = u;
        out.v = v;
    }
    return out;
}

#endif
