/* core/intersect.h — ray/primitive and ray/box tests, shared by host and device.
 *
 * Every test takes the ray's open interval (tmin, tmax) and reports a hit only strictly inside
 * it; a NaN distance is never a hit.  Each function writes its outputs only on a hit.
 *
 * Primitive layouts (byte budgets matter: these are what the traversal streams through):
 *   rs_sphere  16 B  centre + radius
 *   rs_quad    48 B  corner Q, edges u and v, w = n / (n.n) with n = u x v (Shirley, RTNW §6)
 *   rs_tri     36 B  three vertices */
#ifndef RS_CORE_INTERSECT_H
#define RS_CORE_INTERSECT_H

#include "core/ray.h"

typedef struct rs_sphere {
    rs_vec3 center;
    float radius;
} rs_sphere;

typedef struct rs_quad {
    rs_vec3 q, u, v, w;
} rs_quad;

typedef struct rs_tri {
    rs_vec3 v0, v1, v2;
} rs_tri;

typedef struct rs_aabb {
    rs_vec3 lo, hi;
} rs_aabb;

/* Builds a quad from corner and edges, precomputing w. */
RS_HD rs_quad rs_quad_make(rs_vec3 q, rs_vec3 u, rs_vec3 v)
{
    rs_quad r;
    rs_vec3 n = rs_v3_cross(u, v);
    r.q = q;
    r.u = u;
    r.v = v;
    r.w = rs_v3_scale(n, 1.0f / rs_v3_dot(n, n));
    return r;
}

/* Ray/sphere, the half-b quadratic (RTIOW §6.2) with the discriminant taken from the
 * perpendicular distance l from the centre to the line (Haines et al., Ray Tracing Gems ch. 7):
 * h^2 - a c = a (r^2 - |l|^2), l = oc - (h / a) d, which does not cancel for small or far
 * spheres the way |oc|^2 - r^2 does.  On a hit: *t, and u = v = 0 (the shading step derives
 * the sphere's parameterisation from the hit point).  A ray starting inside hits the far side. */
RS_HD int rs_isect_sphere(const rs_sphere *s, const rs_ray *r, float *t)
{
    rs_vec3 oc = rs_v3_sub(s->center, r->o);
    float a = rs_v3_dot(r->d, r->d);
    float h = rs_v3_dot(r->d, oc);
    rs_vec3 l = rs_v3_sub(oc, rs_v3_scale(r->d, h / a));
    float disc = a * (s->radius * s->radius - rs_v3_dot(l, l));
    float sq, root;
    if (!(disc >= 0.0f))
        return 0;
    sq = sqrtf(disc);
    root = (h - sq) / a;
    if (!(root > r->tmin && root < r->tmax)) {
        root = (h + sq) / a;
        if (!(root > r->tmin && root < r->tmax))
            return 0;
    }
    *t = root;
    return 1;
}

/* Ray/triangle, Möller & Trumbore 1997.  On a hit: *t and the barycentrics (*u, *v) of v1 and v2.
 * Both faces are hit; a ray in the triangle's plane misses. */
RS_HD int rs_isect_tri(const rs_tri *tr, const rs_ray *r, float *t, float *u, float *v)
{
    rs_vec3 e1 = rs_v3_sub(tr->v1, tr->v0);
    rs_vec3 e2 = rs_v3_sub(tr->v2, tr->v0);
    rs_vec3 p = rs_v3_cross(r->d, e2);
    float det = rs_v3_dot(e1, p);
    float inv, bu, bv, tt;
    rs_vec3 s, q;
    if (det == 0.0f)
        return 0;
    inv = 1.0f / det;
    s = rs_v3_sub(r->o, tr->v0);
    bu = rs_v3_dot(s, p) * inv;
    if (!(bu >= 0.0f && bu <= 1.0f))
        return 0;
    q = rs_v3_cross(s, e1);
    bv = rs_v3_dot(r->d, q) * inv;
    if (!(bv >= 0.0f && bu + bv <= 1.0f))
        return 0;
    tt = rs_v3_dot(e2, q) * inv;
    if (!(tt > r->tmin && tt < r->tmax))
        return 0;
    *t = tt;
    *u = bu;
    *v = bv;
    return 1;
}

/* Ray/parallelogram Q + a u + b v, 0 <= a, b <= 1 (Shirley, "Ray Tracing: The Next Week" §6).
 * On a hit: *t and the planar coordinates (*a, *b).  The scale of w cancels in t. */
RS_HD int rs_isect_quad(const rs_quad *qd, const rs_ray *r, float *t, float *a, float *b)
{
    float denom = rs_v3_dot(qd->w, r->d);
    float tt, alpha, beta;
    rs_vec3 ph;
    if (denom == 0.0f)
        return 0;
    tt = rs_v3_dot(qd->w, rs_v3_sub(qd->q, r->o)) / denom;
    if (!(tt > r->tmin && tt < r->tmax))
        return 0;
    ph = rs_v3_sub(rs_ray_at(r, tt), qd->q);
    alpha = rs_v3_dot(qd->w, rs_v3_cross(ph, qd->v));
    beta = rs_v3_dot(qd->w, rs_v3_cross(qd->u, ph));
    if (!(alpha >= 0.0f && alpha <= 1.0f && beta >= 0.0f && beta <= 1.0f))
        return 0;
    *t = tt;
    *a = alpha;
    *b = beta;
    return 1;
}

/* min and max that compile to single instructions (minss/maxss); when a is NaN they return b. */
RS_HD float rs_minf(float a, float b) { return a < b ? a : b; }
RS_HD float rs_maxf(float a, float b) { return a > b ? a : b; }

/* One slab of the box test: narrows [*tn, *tf] to the slab's [min(t0, t1), max(t0, t1)].  A ray
 * lying in the slab's plane makes 0 * inf = NaN for that face; such a slab is skipped, so a ray
 * running along a face counts as inside it (and primitives lying in that face can be hit). */
RS_HD void rs_slab(float t0, float t1, float *tn, float *tf)
{
    if (t0 == t0 && t1 == t1) {
        *tn = rs_maxf(rs_minf(t0, t1), *tn);
        *tf = rs_minf(rs_maxf(t0, t1), *tf);
    }
}

/* Ray/box slab test (Kay & Kajiya 1986) with a precomputed reciprocal direction.  Returns 1 and
 * the entry distance when the box overlaps [tmin, tmax]. */
RS_HD int rs_isect_aabb(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                        float *t_entry)
{
    float tn = tmin, tf = tmax;
    rs_slab((b->lo.x - o.x) * inv_d.x, (b->hi.x - o.x) * inv_d.x, &tn, &tf);
    rs_slab((b->lo.y - o.y) * inv_d.y, (b->hi.y - o.y) * inv_d.y, &tn, &tf);
    rs_slab((b->lo.z - o.z) * inv_d.z, (b->hi.z - o.z) * inv_d.z, &tn, &tf);
    *t_entry = tn;
    return tn <= tf;
}

#endif
