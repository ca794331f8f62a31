/* shading/spawn.h — where rays leave surfaces: points on primitives with a conservative bound on
 * their rounding error, and ray origins moved just past that bound (pbrt-v4's OffsetRayOrigin:
 * Pharr, Jakob & Humphreys, Physically Based Rendering 4th ed. §6.8), in place of a fixed
 * epsilon.  Shared by the host and the CUDA device (every function RS_HD).
 *
 * A point on a primitive is recomputed from the primitive's own parameters (a triangle's
 * barycentrics, a parallelogram's planar coordinates, a sphere's centre and radius), never from
 * the ray as o + t d, whose error grows with the ray's origin and length.  Its error bound `err`
 * (per coordinate, absolute) has two parts:
 *   - the rounding of the point itself: a few ulps of its coordinates (gamma(n) |.|, Higham's
 *     gamma_n = n u / (1 - n u), u = 2^-24);
 *   - the rounding of the intersection tests (core/intersect.h), which evaluate the primitive
 *     relative to the ray's origin: a ray starting at a distance d from the surface finds t of
 *     the wrong sign only when d is below a few ulps of the primitive's own size (a sphere's
 *     radius, a parallelogram's edges, a triangle's edges over the sine of its angle at v0).
 * A ray leaving along unit normal n then starts at p + n (|n| . err), with a little more for the
 * rounding of that sum, so that it is on the leaving side of every point the true surface and
 * the test could put there.  The offset is 3-4 ulps of the coordinates far from the origin
 * (3e-3 units at 10^4; the 1e-4-of-the-coordinates epsilon this replaced moved origins by 1 unit
 * there, and light leaked past contact shadows), plus a few ulps of the primitive's size:
 * docs/intersect.md#coordinate-range has the figures.  Shadow rays end at a point on the light
 * moved the same way toward the shading point (rs_spawn_end). */
#ifndef RS_SHADING_SPAWN_H
#define RS_SHADING_SPAWN_H

#include <float.h>
#include <string.h>

#include "scenes/scene.h"

/* Higham's gamma_n: a bound on the relative error of n rounded operations. */
#define RS_GAMMA(n) ((float)(n) * (0.5f * FLT_EPSILON) / (1.0f - (float)(n) * (0.5f * FLT_EPSILON)))

/* A shadow ray stops this fraction of its length short of the light's point (pbrt's
 * ShadowEpsilon): a margin on top of rs_spawn_end's offset. */
#define RS_SHADOW_EPS 1e-4f

/* A point on a surface: the point, its error bound (absolute, per coordinate, >= 0) and the
 * unit geometric normal as the primitive defines it (rs_prim_normal's). */
typedef struct rs_surface_point {
    rs_vec3 p, err, ng;
} rs_surface_point;

RS_HD rs_vec3 rs_v3_abs(rs_vec3 a) { return rs_v3(fabsf(a.x), fabsf(a.y), fabsf(a.z)); }

/* p moved along unit normal n (the side the new ray leaves toward) past the error bound err:
 * p + n d with d = |n| . err (pbrt-v4's OffsetRayOrigin) plus 2^-23 of |n| . |p|, which covers
 * the rounding of the sum itself (at most 2^-24 of each coordinate), so the new origin is at
 * least |n| . err from p along n without stepping each coordinate to the next float as pbrt
 * does (no branches). */
RS_HD_HOT rs_vec3 rs_spawn_origin(rs_vec3 p, rs_vec3 err, rs_vec3 n)
{
    rs_vec3 an = rs_v3_abs(n);
    float d = rs_v3_dot(an, rs_v3_add(err, rs_v3_scale(rs_v3_abs(p), 2.0f * RS_GAMMA(1))));
    return rs_v3_madd(p, n, d);
}

/* The end of a shadow ray at surface point (p, err) whose normal is ng, moved toward `from` (the
 * ray's origin) as rs_spawn_origin moves an origin. */
RS_HD_HOT rs_vec3 rs_spawn_end(rs_vec3 p, rs_vec3 err, rs_vec3 ng, rs_vec3 from)
{
    rs_vec3 n = rs_v3_dot(ng, rs_v3_sub(from, p)) < 0.0f ? rs_v3_neg(ng) : ng;
    return rs_spawn_origin(p, err, n);
}

/* Sum of the absolute coordinates (>= the length). */
RS_HD float rs_v3_norm1(rs_vec3 a) { return fabsf(a.x) + fabsf(a.y) + fabsf(a.z); }

/* The point of a sphere (centre c, radius r) in the direction of `rel` from its centre (a
 * vector near the surface, relative to c: c + rel itself is where a ray found it), put onto it:
 * c + r rel / |rel|.  Taking rel relative to the centre, not a point in world coordinates, keeps
 * the normal as precise far from the origin as at it.  The rounding of the projection is
 * gamma(5) of rel (PBR 4th ed. §6.8.5) and the final sum one rounding of the point; the
 * algebraic and geometric tests find a sphere's roots to about gamma(16) r from an origin near
 * it (the half-b discriminant's rounding, relative to r^2). */
RS_HD rs_surface_point rs_sphere_point(rs_vec3 c, float r, rs_vec3 rel)
{
    rs_surface_point s;
    float len = rs_v3_length(rel);
    if (len > 0.0f)
        rel = rs_v3_scale(rel, r / len);
    else
        rel = rs_v3(0.0f, r, 0.0f);
    s.p = rs_v3_add(c, rel);
    s.ng = rs_v3_scale(rel, 1.0f / r);
    s.err = rs_v3_add(rs_v3_add(rs_v3_scale(rs_v3_abs(rel), RS_GAMMA(5)),
                                rs_v3_scale(rs_v3_abs(s.p), RS_GAMMA(1))),
                      rs_v3_splat(RS_GAMMA(16) * r));
    return s;
}

/* The point q + a u + b v of a parallelogram and its normal.  The point's rounding: gamma(3) of
 * its terms.  The ray test takes the plane as w . (x - q) = 0 with w = n / (n . n), n = u x v
 * rounded: its tilt is a few ulps times |u| |v| / |u x v| (the sine of the angle between the
 * edges, as for triangles), so a point an edge away from q can be off that plane by
 * about gamma(12) (|u| + |v|) |u| |v| / |u x v|; |u x v| = 1 / |w|. */
RS_HD_HOT rs_surface_point rs_quad_point(const rs_quad *qd, float a, float b)
{
    rs_surface_point s;
    rs_vec3 au = rs_v3_scale(qd->u, a), bv = rs_v3_scale(qd->v, b);
    float l1 = rs_v3_norm1(qd->u), l2 = rs_v3_norm1(qd->v), len = rs_v3_length(qd->w);
    float slim = rs_fminf(l1 * l2 * len, 1024.0f);
    s.p = rs_v3_add(qd->q, rs_v3_add(au, bv));
    s.ng = rs_v3_scale(qd->w, 1.0f / len); /* rs_v3_normalize(w), rs_prim_normal's */
    s.err =
        rs_v3_add(rs_v3_scale(rs_v3_add(rs_v3_abs(qd->q), rs_v3_add(rs_v3_abs(au), rs_v3_abs(bv))),
                              RS_GAMMA(3)),
                  rs_v3_splat(RS_GAMMA(12) * (l1 + l2) * slim));
    return s;
}

/* The point of a triangle at barycentrics (b1, b2) of v1 and v2, v0 + b1 e1 + b2 e2, and its
 * normal (along e1 x e2).  The point's rounding: gamma(4) of its terms (the edges' own rounding
 * included).  The ray tests evaluate e2 . ((o - v0) x e1), whose rounding, as a distance from
 * the plane, is about gamma(6) |o - v0| |e1| |e2| / |e1 x e2|: the edges over the sine of the
 * angle at v0, held below 1024 (a sliver thinner than that keeps only this much margin). */
RS_HD rs_surface_point rs_tri_point(const rs_tri *t, float b1, float b2)
{
    rs_surface_point s;
    rs_vec3 e1 = rs_v3_sub(t->v1, t->v0), e2 = rs_v3_sub(t->v2, t->v0);
    rs_vec3 n = rs_v3_cross(e1, e2), t1 = rs_v3_scale(e1, b1), t2 = rs_v3_scale(e2, b2);
    float len = rs_v3_length(n), l1 = rs_v3_norm1(e1), l2 = rs_v3_norm1(e2);
    float slim = len > 0.0f ? rs_fminf(l1 * l2 / len, 1024.0f) : 1024.0f;
    s.p = rs_v3_add(t->v0, rs_v3_add(t1, t2));
    s.ng = rs_v3_scale(n, 1.0f / len);
    s.err =
        rs_v3_add(rs_v3_scale(rs_v3_add(rs_v3_abs(t->v0), rs_v3_add(rs_v3_abs(t1), rs_v3_abs(t2))),
                              RS_GAMMA(4)),
                  rs_v3_splat(RS_GAMMA(12) * (l1 + l2) * slim));
    return s;
}

/* The hit (t, hu, hv) of ray r on global primitive `prim` as a surface point. */
RS_HD rs_surface_point rs_surface_at(const rs_scene *sc, uint32_t prim, const rs_ray *r, float t,
                                     float hu, float hv)
{
    if (prim < sc->n_spheres) {
        rs_geom g = rs_scene_geom(sc);
        rs_vec3 c = rs_geom_sphere_center(&g, prim, r->time);
        /* (o - c) + t d: the ray's origin and the centre are near each other, so no rounding at
         * the size of their coordinates */
        return rs_sphere_point(c, sc->spheres[prim].radius,
                               rs_v3_madd(rs_v3_sub(r->o, c), r->d, t));
    }
    if (prim - sc->n_spheres < sc->n_quads)
        return rs_quad_point(&sc->quads[prim - sc->n_spheres], hu, hv);
    {
        rs_tri tr = rs_scene_tri(sc, prim);
        return rs_tri_point(&tr, hu, hv);
    }
}

#endif
