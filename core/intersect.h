/* core/intersect.h — ray/primitive and ray/box tests, shared by host and device.
 *
 * Every test takes the ray's open interval (tmin, tmax) and reports a hit only strictly inside
 * it; a NaN distance is never a hit.  The primitive tests write their outputs only on a hit; the
 * box tests take the closed interval [tmin, tmax] and may write *t_entry on a miss too (it is
 * meaningful only on a hit).
 *
 * Each family has the thesis's variants (§5.6, §A.3.3; measured in §6.3), selectable by an enum
 * stored as uint32_t, with a name table, a parser and an RS_HD dispatch (rs_isect_*_by).  The
 * unsuffixed functions (rs_isect_sphere, rs_isect_tri, rs_isect_aabb) are the defaults that the
 * traversal calls:
 *   sphere    algebraic (default), geometric
 *   triangle  moller (Möller–Trumbore, default), snyder-barr, watertight (Woop et al. 2013)
 *   box       slab (Kay–Kajiya, default), branchless (Barnes), williams, kensler, swap (thesis)
 * Triangle variants return the same (t, u, v) contract; box variants agree with the slab test on
 * hit / miss and on the entry distance (bit for bit: they evaluate the same products), except for
 * a ray lying exactly in a face plane of the box, where 0 * inf = NaN and each variant's NaN
 * handling decides (stated per function; tests/core_isect_variants_test.c checks each claim).
 *
 * Primitive layouts (byte budgets matter: these are what the traversal streams through):
 *   rs_sphere  16 B  centre + radius
 *   rs_quad    48 B  corner Q, edges u and v, w = n / (n.n) with n = u x v (Shirley, RTNW §6)
 *   rs_tri     36 B  three vertices */
#ifndef RS_CORE_INTERSECT_H
#define RS_CORE_INTERSECT_H

#include <string.h>

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
 * On a hit: *t and the planar coordinates (*a, *b).  The scale of w cancels in t.  Everything is
 * computed from q - o, so the precision depends on the distance from the ray's origin, not from
 * the world's origin. */
RS_HD int rs_isect_quad(const rs_quad *qd, const rs_ray *r, float *t, float *a, float *b)
{
    float denom = rs_v3_dot(qd->w, r->d);
    float tt, alpha, beta;
    rs_vec3 oq, ph;
    if (denom == 0.0f)
        return 0;
    oq = rs_v3_sub(qd->q, r->o);
    tt = rs_v3_dot(qd->w, oq) / denom;
    if (!(tt > r->tmin && tt < r->tmax))
        return 0;
    /* the hit relative to q as t d - (q - o): no coordinate of the size of o or q is rounded, so
     * the test is as precise far from the origin as at it */
    ph = rs_v3_sub(rs_v3_scale(r->d, tt), oq);
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

/* ==== Variants (thesis §5.6, §A.3.3); timings: bench/intersect_bench.c, docs/intersect.md */

/* ---- ray/sphere ---------------------------------------------------------------------------- */

/* Ray/sphere, the classic geometric solution (Haines, in Glassner 1989 ch. 2; Akenine-Möller et
 * al., Real-Time Rendering 4th ed. §22.6.2; the thesis §A.3.3.1): with l = c - o and the unit
 * direction d / |d|, s = l . d / |d| is the distance along the ray to the point closest to the
 * centre and m^2 = |l|^2 - s^2 the squared perpendicular distance; the ray misses when
 * m^2 > r^2, else the roots lie at s -+ sqrt(r^2 - m^2) (in units of length, divided by |d| to
 * get t).  RTR's early out, "centre behind an origin outside the sphere", is taken only when
 * tmin >= 0, where it cannot drop a root.  Same contract as rs_isect_sphere.
 * Numerics: |l|^2 - s^2 cancels for small far spheres (its error is a few ulps of |l|^2), which
 * is what the algebraic default avoids by forming l - s d first (Ray Tracing Gems ch. 7). */
RS_HD int rs_isect_sphere_geometric(const rs_sphere *s, const rs_ray *r, float *t)
{
    rs_vec3 l = rs_v3_sub(s->center, r->o);
    float inv_len = 1.0f / rs_v3_length(r->d);
    float sp = rs_v3_dot(l, r->d) * inv_len;
    float l2 = rs_v3_dot(l, l), r2 = s->radius * s->radius;
    float m2, q, root;
    if (sp < 0.0f && l2 > r2 && r->tmin >= 0.0f)
        return 0;
    m2 = l2 - sp * sp;
    if (!(m2 <= r2)) /* also rejects a NaN (zero or NaN direction) */
        return 0;
    q = sqrtf(r2 - m2);
    root = (sp - q) * inv_len;
    if (!(root > r->tmin && root < r->tmax)) {
        root = (sp + q) * inv_len;
        if (!(root > r->tmin && root < r->tmax))
            return 0;
    }
    *t = root;
    return 1;
}

/* ---- ray/triangle -------------------------------------------------------------------------- */

/* Ray/triangle, "Snyder & Barr" as the thesis implements and describes it (§A.3.3.2): the ray
 * o + t d equated with the triangle's parametric plane a + beta (b - a) + gamma (c - a) gives a
 * 3x3 linear system in (beta, gamma, t), solved by Cramer's rule in the order and with the
 * letters of Shirley's Fundamentals of Computer Graphics §4.4.2, which cites Snyder & Barr 1987
 * for it: first t (the plane intersection) and its interval test, then gamma, then beta (the
 * barycentrics, each a ratio of triple products, i.e. of signed areas of the triangle projected
 * along d).  Same contract as rs_isect_tri: *u = beta (weight of v1), *v = gamma (of v2). */
RS_HD int rs_isect_tri_snyder_barr(const rs_tri *tr, const rs_ray *r, float *t, float *u, float *v)
{
    /* FCG's A..L: columns a - b, a - c, d of the matrix and the right-hand side a - o */
    float ca = tr->v0.x - tr->v1.x, cb = tr->v0.y - tr->v1.y, cc = tr->v0.z - tr->v1.z;
    float cd = tr->v0.x - tr->v2.x, ce = tr->v0.y - tr->v2.y, cf = tr->v0.z - tr->v2.z;
    float cg = r->d.x, ch = r->d.y, ci = r->d.z;
    float cj = tr->v0.x - r->o.x, ck = tr->v0.y - r->o.y, cl = tr->v0.z - r->o.z;
    float ei_hf = ce * ci - ch * cf, gf_di = cg * cf - cd * ci, dh_eg = cd * ch - ce * cg;
    float ak_jb = ca * ck - cj * cb, jc_al = cj * cc - ca * cl, bl_kc = cb * cl - ck * cc;
    float m = ca * ei_hf + cb * gf_di + cc * dh_eg;
    float tt, gamma, beta;
    if (m == 0.0f) /* the ray is parallel to the plane */
        return 0;
    tt = -(cf * ak_jb + ce * jc_al + cd * bl_kc) / m;
    if (!(tt > r->tmin && tt < r->tmax))
        return 0;
    gamma = (ci * ak_jb + ch * jc_al + cg * bl_kc) / m;
    if (!(gamma >= 0.0f && gamma <= 1.0f))
        return 0;
    beta = (cj * ei_hf + ck * gf_di + cl * dh_eg) / m;
    if (!(beta >= 0.0f && beta <= 1.0f - gamma))
        return 0;
    *t = tt;
    *u = beta;
    *v = gamma;
    return 1;
}

/* The per-ray part of the watertight test (Woop, Benthin & Wald 2013, JCGT 2(1), §3): kz is the
 * axis along which |d| is largest, kx and ky the other two (swapped when d[kz] < 0 to keep the
 * triangles' winding), and the shear (sx, sy) and scale sz that map d to (0, 0, 1).  Computed
 * once per ray when a ray meets many triangles.  44 B. */
typedef struct rs_wt_ray {
    rs_vec3 o;
    float sx, sy, sz;
    uint32_t kx, ky, kz;
    float tmin, tmax;
} rs_wt_ray;

RS_HD rs_wt_ray rs_wt_ray_make(const rs_ray *r)
{
    rs_wt_ray w;
    float ax = fabsf(r->d.x), ay = fabsf(r->d.y), az = fabsf(r->d.z), dz;
    w.kz = ax > ay ? (ax > az ? 0u : 2u) : (ay > az ? 1u : 2u);
    w.kx = w.kz == 2u ? 0u : w.kz + 1u;
    w.ky = w.kx == 2u ? 0u : w.kx + 1u;
    dz = rs_v3_get(r->d, (int)w.kz);
    if (dz < 0.0f) {
        uint32_t k = w.kx;
        w.kx = w.ky;
        w.ky = k;
    }
    w.sx = rs_v3_get(r->d, (int)w.kx) / dz;
    w.sy = rs_v3_get(r->d, (int)w.ky) / dz;
    w.sz = 1.0f / dz;
    w.o = r->o;
    w.tmin = r->tmin;
    w.tmax = r->tmax;
    return w;
}

/* Ray/triangle, watertight (Woop, Benthin & Wald 2013, Listing 1, both faces): the vertices,
 * relative to the origin, are sheared so that the ray becomes the +z axis; the 2D edge functions
 * U, V, W of the projected triangle at (0, 0) decide inside, and t = (U az + V bz + W cz) / det.
 * Watertight: an edge shared by two triangles is evaluated from the same sheared vertices in
 * both, as fl(fl(p) - fl(q)) one way and fl(fl(q) - fl(p)) the other, i.e. exactly negated, so a
 * ray cannot slip between them; an edge function that is exactly 0 is recomputed in double,
 * where the products of floats are exact and the sign is right (the paper's fallback).  This
 * needs a * b - c * d evaluated without contracting it into a fused multiply-add: the C11 host
 * build does not contract (ISO C mode), and RS_MUL_EXACT (core/hd.h) keeps nvcc, which
 * contracts by default, from doing it on the GPU.  Same contract as rs_isect_tri:
 * *u = V / det (weight of v1), *v = W / det (of v2). */
RS_HD int rs_isect_tri_watertight_pre(const rs_tri *tr, const rs_wt_ray *w, float *t, float *u,
                                      float *v)
{
    rs_vec3 a = rs_v3_sub(tr->v0, w->o), b = rs_v3_sub(tr->v1, w->o), c = rs_v3_sub(tr->v2, w->o);
    int kx = (int)w->kx, ky = (int)w->ky, kz = (int)w->kz;
    float az = rs_v3_get(a, kz), bz = rs_v3_get(b, kz), cz = rs_v3_get(c, kz);
    float ax = rs_v3_get(a, kx) - w->sx * az, ay = rs_v3_get(a, ky) - w->sy * az;
    float bx = rs_v3_get(b, kx) - w->sx * bz, by = rs_v3_get(b, ky) - w->sy * bz;
    float cx = rs_v3_get(c, kx) - w->sx * cz, cy = rs_v3_get(c, ky) - w->sy * cz;
    /* RS_MUL_EXACT: no fused multiply-add, or a shared edge is no longer exactly negated */
    float eu = RS_MUL_EXACT(cx, by) - RS_MUL_EXACT(cy, bx);
    float ev = RS_MUL_EXACT(ax, cy) - RS_MUL_EXACT(ay, cx);
    float ew = RS_MUL_EXACT(bx, ay) - RS_MUL_EXACT(by, ax);
    float det, tt, rcp;
    if (eu == 0.0f || ev == 0.0f || ew == 0.0f) {
        eu = (float)((double)cx * (double)by - (double)cy * (double)bx);
        ev = (float)((double)ax * (double)cy - (double)ay * (double)cx);
        ew = (float)((double)bx * (double)ay - (double)by * (double)ax);
    }
    if ((eu < 0.0f || ev < 0.0f || ew < 0.0f) && (eu > 0.0f || ev > 0.0f || ew > 0.0f))
        return 0;
    det = eu + ev + ew;
    if (det == 0.0f) /* the ray is parallel to the plane, or the triangle is degenerate */
        return 0;
    rcp = 1.0f / det;
    tt = (eu * (w->sz * az) + ev * (w->sz * bz) + ew * (w->sz * cz)) * rcp;
    if (!(tt > w->tmin && tt < w->tmax))
        return 0;
    *t = tt;
    *u = ev * rcp;
    *v = ew * rcp;
    return 1;
}

/* The watertight test with the per-ray setup done here (the traversal may hoist it). */
RS_HD int rs_isect_tri_watertight(const rs_tri *tr, const rs_ray *r, float *t, float *u, float *v)
{
    rs_wt_ray w = rs_wt_ray_make(r);
    return rs_isect_tri_watertight_pre(tr, &w, t, u, v);
}

/* ---- ray/box ------------------------------------------------------------------------------- */
/* All take the box, the origin, the reciprocal direction (1 / d per component: +-inf for a zero
 * component), the closed interval [tmin, tmax] and return 1 with the entry distance
 * max(tmin, slab entries) when the box overlaps it.  Each computes the slab distances exactly as
 * rs_isect_aabb does, (lo - o) * inv_d and (hi - o) * inv_d, so the answers are the same bit for
 * bit; they differ only in how the six distances are ordered and combined, and so in what a NaN
 * (0 * inf, from a ray lying in a face plane) does. */

/* Branchless min/max formulation (Barnes 2011, "Fast, branchless ray/bounding box
 * intersections"; the IEEE idea from Smits 1998): per axis tn = max(tn, min(t0, t1)),
 * tf = min(tf, max(t0, t1)) with minss/maxss-style rs_minf/rs_maxf.  NaN: with t0 = NaN (origin
 * in the lo plane) min and max both give t1 = +-inf and the box is missed; with t1 = NaN (hi
 * plane) both give NaN, which rs_maxf(NaN, tn) / rs_minf(NaN, tf) drop, so that slab counts as
 * inside and the ray can hit.  A zero-thickness slab in its own plane (both NaN) counts as
 * inside.  (Barnes 2015, part 2, discusses this asymmetry.) */
RS_HD int rs_isect_aabb_branchless(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin,
                                   float tmax, float *t_entry)
{
    float tn = tmin, tf = tmax, t0, t1;
    t0 = (b->lo.x - o.x) * inv_d.x;
    t1 = (b->hi.x - o.x) * inv_d.x;
    tn = rs_maxf(rs_minf(t0, t1), tn);
    tf = rs_minf(rs_maxf(t0, t1), tf);
    t0 = (b->lo.y - o.y) * inv_d.y;
    t1 = (b->hi.y - o.y) * inv_d.y;
    tn = rs_maxf(rs_minf(t0, t1), tn);
    tf = rs_minf(rs_maxf(t0, t1), tf);
    t0 = (b->lo.z - o.z) * inv_d.z;
    t1 = (b->hi.z - o.z) * inv_d.z;
    tn = rs_maxf(rs_minf(t0, t1), tn);
    tf = rs_minf(rs_maxf(t0, t1), tf);
    *t_entry = tn;
    return tn <= tf;
}

/* Williams, Barrus, Morley & Shirley 2005, "An efficient and robust ray-box intersection
 * algorithm" (JGT 10(1), Fig. 3 / the "optimized" listing): the sign of each inv_d component picks
 * the near and far bound directly (bounds[sign] and bounds[1 - sign]), so no min/max is needed,
 * and the axes are merged with early outs.  The paper keeps sign[] in the ray; here it is taken
 * from inv_d (inv_d < 0, so -0 counts as negative) to keep one signature (inlined in a loop over
 * boxes, the compiler hoists it).  bounds[sign] is written as a select on sign, not as an index
 * into a local copy of the box: that copy went through the stack on the CPU and would go to local
 * memory on the GPU (bench/intersect_bench.c: the select is 1.3x faster when one ray meets box
 * after box, 1.3x slower when every test has a new ray, as GCC turns it into a branch).  The
 * paper's final test is open, (tn < tmax && tf > tmin); here it is closed as the house contract
 * says, and also asks tmin
 * <= tmax so that an empty interval misses as in the slab test.  NaN: comparisons with NaN are
 * false, so a ray in a y or z face plane keeps that slab from narrowing anything (it counts as
 * inside, like the slab test), but a ray in an x face plane carries the NaN to the final test and
 * misses. */
RS_HD int rs_isect_aabb_williams(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                                 float *t_entry)
{
    int sx = inv_d.x < 0.0f, sy = inv_d.y < 0.0f, sz = inv_d.z < 0.0f;
    float tn, tf, tyn, tyf, tzn, tzf;
    tn = ((sx ? b->hi.x : b->lo.x) - o.x) * inv_d.x;
    tf = ((sx ? b->lo.x : b->hi.x) - o.x) * inv_d.x;
    tyn = ((sy ? b->hi.y : b->lo.y) - o.y) * inv_d.y;
    tyf = ((sy ? b->lo.y : b->hi.y) - o.y) * inv_d.y;
    if (tn > tyf || tyn > tf)
        return 0;
    if (tyn > tn)
        tn = tyn;
    if (tyf < tf)
        tf = tyf;
    tzn = ((sz ? b->hi.z : b->lo.z) - o.z) * inv_d.z;
    tzf = ((sz ? b->lo.z : b->hi.z) - o.z) * inv_d.z;
    if (tn > tzf || tzn > tf)
        return 0;
    if (tzn > tn)
        tn = tzn;
    if (tzf < tf)
        tf = tzf;
    if (!(tn <= tmax && tf >= tmin && tmin <= tmax))
        return 0;
    *t_entry = tn > tmin ? tn : tmin;
    return 1;
}

/* Kensler's test as Shirley gives it in "Ray Tracing: The Next Week" (§3, "an optimized AABB hit
 * method"): per axis, swap the slab distances when inv_d < 0 and narrow [tn, tf] with plain
 * comparisons, leaving at the first empty interval.  RTNW leaves on tf <= tn, which misses
 * zero-thickness boxes (RTNW pads them); here the interval is closed (tf < tn).  NaN: a NaN
 * distance fails its comparison and narrows nothing, so a ray in any face plane counts as inside
 * that slab, as in the slab test. */
RS_HD int rs_isect_aabb_kensler(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                                float *t_entry)
{
    float tn = tmin, tf = tmax;
    int a;
    for (a = 0; a < 3; ++a) {
        float inv = rs_v3_get(inv_d, a), oa = rs_v3_get(o, a);
        float t0 = (rs_v3_get(b->lo, a) - oa) * inv, t1 = (rs_v3_get(b->hi, a) - oa) * inv;
        if (inv < 0.0f) {
            float s = t0;
            t0 = t1;
            t1 = s;
        }
        if (t0 > tn)
            tn = t0;
        if (t1 < tf)
            tf = t1;
        if (tf < tn)
            return 0;
    }
    *t_entry = tn;
    return 1;
}

/* The thesis's swap variant (§5.6.2, Listing 5.3): Barnes's per-axis min/max of (t0, t1)
 * replaced by "if (t0 > t1) swap", then tn = max(t0, tn), tf = min(t1, tf) and an early out per
 * axis.  Unlike Kensler's test the swap is decided by the distances, not by the sign of inv_d.
 * The listing leaves on tf <= tn; here the interval is closed (tf < tn), as in the house
 * contract.  NaN: the swap test is false, and rs_maxf(NaN, tn) / rs_minf(NaN, tf) keep tn / tf,
 * so the NaN end is dropped and the other end, +-inf, is kept as it comes: a ray in a face plane
 * with a +0 direction component counts as inside (the other end is -inf as t0 or +inf as t1),
 * with a -0 component it misses (+inf lands in t0 or -inf in t1). */
RS_HD int rs_isect_aabb_swap(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                             float *t_entry)
{
    float tn = tmin, tf = tmax;
    int a;
    for (a = 0; a < 3; ++a) {
        float inv = rs_v3_get(inv_d, a), oa = rs_v3_get(o, a);
        float t0 = (rs_v3_get(b->lo, a) - oa) * inv, t1 = (rs_v3_get(b->hi, a) - oa) * inv;
        if (t0 > t1) {
            float s = t0;
            t0 = t1;
            t1 = s;
        }
        tn = rs_maxf(t0, tn);
        tf = rs_minf(t1, tf);
        if (tf < tn)
            return 0;
    }
    *t_entry = tn;
    return 1;
}

/* ---- selecting a variant ------------------------------------------------------------------- */

/* Algorithm ids, stored as uint32_t; the first of each family (0) is the default. */
typedef enum rs_isect_sphere_algo {
    RS_ISECT_SPHERE_ALGEBRAIC = 0, /* rs_isect_sphere */
    RS_ISECT_SPHERE_GEOMETRIC = 1, /* rs_isect_sphere_geometric */
    RS_ISECT_SPHERE_COUNT = 2
} rs_isect_sphere_algo;

typedef enum rs_isect_tri_algo {
    RS_ISECT_TRI_MOLLER = 0,      /* rs_isect_tri */
    RS_ISECT_TRI_SNYDER_BARR = 1, /* rs_isect_tri_snyder_barr */
    RS_ISECT_TRI_WATERTIGHT = 2,  /* rs_isect_tri_watertight */
    RS_ISECT_TRI_COUNT = 3
} rs_isect_tri_algo;

typedef enum rs_isect_aabb_algo {
    RS_ISECT_AABB_SLAB = 0,       /* rs_isect_aabb */
    RS_ISECT_AABB_BRANCHLESS = 1, /* rs_isect_aabb_branchless */
    RS_ISECT_AABB_WILLIAMS = 2,   /* rs_isect_aabb_williams */
    RS_ISECT_AABB_KENSLER = 3,    /* rs_isect_aabb_kensler */
    RS_ISECT_AABB_SWAP = 4,       /* rs_isect_aabb_swap */
    RS_ISECT_AABB_COUNT = 5
} rs_isect_aabb_algo;

/* Dispatch on an algorithm id (an unknown id runs the default).  Inside a loop with a
 * loop-invariant id the compiler unswitches the switch; in the hot path prefer calling the
 * function directly. */
RS_HD int rs_isect_sphere_by(uint32_t algo, const rs_sphere *s, const rs_ray *r, float *t)
{
    switch (algo) {
    case RS_ISECT_SPHERE_GEOMETRIC: return rs_isect_sphere_geometric(s, r, t);
    default: return rs_isect_sphere(s, r, t);
    }
}

RS_HD int rs_isect_tri_by(uint32_t algo, const rs_tri *tr, const rs_ray *r, float *t, float *u,
                          float *v)
{
    switch (algo) {
    case RS_ISECT_TRI_SNYDER_BARR: return rs_isect_tri_snyder_barr(tr, r, t, u, v);
    case RS_ISECT_TRI_WATERTIGHT: return rs_isect_tri_watertight(tr, r, t, u, v);
    default: return rs_isect_tri(tr, r, t, u, v);
    }
}

RS_HD int rs_isect_aabb_by(uint32_t algo, const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin,
                           float tmax, float *t_entry)
{
    switch (algo) {
    case RS_ISECT_AABB_BRANCHLESS:
        return rs_isect_aabb_branchless(b, o, inv_d, tmin, tmax, t_entry);
    case RS_ISECT_AABB_WILLIAMS: return rs_isect_aabb_williams(b, o, inv_d, tmin, tmax, t_entry);
    case RS_ISECT_AABB_KENSLER: return rs_isect_aabb_kensler(b, o, inv_d, tmin, tmax, t_entry);
    case RS_ISECT_AABB_SWAP: return rs_isect_aabb_swap(b, o, inv_d, tmin, tmax, t_entry);
    default: return rs_isect_aabb(b, o, inv_d, tmin, tmax, t_entry);
    }
}

/* Names (host only: option parsing, benchmark tables), indexed by id; "?" for an unknown id. */
static inline const char *rs_isect_sphere_algo_name(uint32_t algo)
{
    static const char *const names[RS_ISECT_SPHERE_COUNT] = {"algebraic", "geometric"};
    return algo < RS_ISECT_SPHERE_COUNT ? names[algo] : "?";
}

static inline const char *rs_isect_tri_algo_name(uint32_t algo)
{
    static const char *const names[RS_ISECT_TRI_COUNT] = {"moller", "snyder-barr", "watertight"};
    return algo < RS_ISECT_TRI_COUNT ? names[algo] : "?";
}

static inline const char *rs_isect_aabb_algo_name(uint32_t algo)
{
    static const char *const names[RS_ISECT_AABB_COUNT] = {"slab", "branchless", "williams",
                                                           "kensler", "swap"};
    return algo < RS_ISECT_AABB_COUNT ? names[algo] : "?";
}

/* The id whose name (by `name_of`) is `text`, exact and case-sensitive: returns 1 and stores it,
 * or 0 and leaves *out alone when the name is unknown or text is NULL. */
static inline int rs_isect_algo_parse(const char *text, uint32_t count,
                                      const char *(*name_of)(uint32_t), uint32_t *out)
{
    uint32_t a;
    for (a = 0; text && a < count; ++a)
        if (strcmp(text, name_of(a)) == 0) {
            *out = a;
            return 1;
        }
    return 0;
}

static inline int rs_isect_sphere_algo_parse(const char *text, uint32_t *out)
{
    return rs_isect_algo_parse(text, RS_ISECT_SPHERE_COUNT, rs_isect_sphere_algo_name, out);
}

static inline int rs_isect_tri_algo_parse(const char *text, uint32_t *out)
{
    return rs_isect_algo_parse(text, RS_ISECT_TRI_COUNT, rs_isect_tri_algo_name, out);
}

static inline int rs_isect_aabb_algo_parse(const char *text, uint32_t *out)
{
    return rs_isect_algo_parse(text, RS_ISECT_AABB_COUNT, rs_isect_aabb_algo_name, out);
}

#endif
