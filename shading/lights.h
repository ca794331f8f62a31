/* shading/lights.h — sampling the scene's emitters (the thesis's "primitive PDF").
 *
 * A light is picked with probability proportional to its power (a CDF, binary search).  Then:
 *   quad, triangle   a point uniform by area:  p(w) = pick dist^2 / (area |cos theta_light|)
 *   sphere           a direction uniform in the cone the sphere subtends (seen from outside):
 *                    p(w) = pick / (2 pi (1 - cos theta_max)); from inside, uniform by area.
 *   environment map  a direction by the map's luminance (shading/envmap.h); picked with
 *                    probability s->env_pick, the emitters sharing the rest.
 * All pdfs are over solid angle at the shading point and include the pick probability.
 * Every function is RS_HD: the CUDA megakernel samples lights with this very code. */
#ifndef RS_SHADING_LIGHTS_H
#define RS_SHADING_LIGHTS_H

#include <float.h>

#include "core/sampling.h"
#include "scenes/scene.h"
#include "shading/envmap.h"

typedef struct rs_light_sample {
    rs_vec3 point; /* on the light */
    rs_vec3 wi;    /* unit direction from the shading point toward `point` */
    float dist;    /* distance to `point` */
    float pdf;     /* solid-angle pdf, pick probability included */
    rs_vec3 le;    /* radiance arriving along -wi (zero from the back of a one-sided light) */
    int env;       /* from the environment map: `point` and `dist` are meaningless, the shadow
                      ray runs to infinity */
} rs_light_sample;

/* Unit geometric normal of global primitive `prim` at point p on it, at `time` (spheres:
 * outward; quads: along u x v; triangles: along (v1 - v0) x (v2 - v0)). */
RS_HD rs_vec3 rs_prim_normal(const rs_scene *s, uint32_t prim, rs_vec3 p, float time)
{
    if (prim < s->n_spheres) {
        rs_geom g = rs_scene_geom(s);
        rs_vec3 c = rs_geom_sphere_center(&g, prim, time);
        return rs_v3_scale(rs_v3_sub(p, c), 1.0f / s->spheres[prim].radius);
    }
    prim -= s->n_spheres;
    if (prim < s->n_quads)
        return rs_v3_normalize(s->quads[prim].w);
    prim -= s->n_quads;
    {
        const rs_tri *t = &s->tris[prim];
        return rs_v3_normalize(rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0)));
    }
}

/* Radiance that material m emits from a surface of geometric normal ng toward a ray travelling
 * along d (that is, toward -d). */
RS_HD rs_vec3 rs_emitted(const rs_material *m, rs_vec3 ng, rs_vec3 d)
{
    if (m->type != RS_MAT_DIFFUSE_LIGHT)
        return rs_v3_splat(0.0f);
    if ((m->flags & RS_MAT_TWO_SIDED) || rs_v3_dot(ng, d) < 0.0f)
        return m->emission;
    return rs_v3_splat(0.0f);
}

RS_HD uint32_t rs_light_pick(const rs_scene *s, float u)
{
    /* the largest l with cdf[l] <= u, so zero-probability lights are never picked */
    uint32_t lo = 0, hi = s->n_lights;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (s->light_cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* 1 - cos(theta_max) of the cone a sphere of radius r subtends at squared distance d2 > r^2,
 * written as sin^2 / (1 + cos) so that small, far spheres keep their precision. */
RS_HD float rs_cone_one_minus_cos(float r, float d2)
{
    float sin2 = r * r / d2;
    return sin2 / (1.0f + sqrtf(rs_fmaxf(0.0f, 1.0f - sin2)));
}

/* Samples a light as seen from x at `time`.  Returns 0 (and no sample) if the scene has no
 * lights or the sample is degenerate (x on the light's plane, or inside a one-point light). */
RS_HD int rs_light_sample_at(const rs_scene *s, rs_vec3 x, float time, float u_pick, float u1,
                             float u2, rs_light_sample *out)
{
    uint32_t l, prim;
    const rs_light *lt;
    rs_vec3 p, n, to;
    float d2, cos_l;
    if (!rs_scene_has_lights(s))
        return 0;
    out->env = 0;
    if (s->env_pick > 0.0f) {
        if (u_pick < s->env_pick) {
            if (!rs_env_sample(s, u1, u2, &out->wi, &out->pdf, &out->le))
                return 0;
            out->pdf *= s->env_pick;
            out->point = x;
            out->dist = FLT_MAX;
            out->env = 1;
            return 1;
        }
        /* the rest of [0, 1) picks an emitter as before */
        u_pick = (u_pick - s->env_pick) / (1.0f - s->env_pick);
    }
    l = rs_light_pick(s, u_pick);
    lt = &s->lights[l];
    prim = lt->prim;
    if (prim < s->n_spheres) {
        rs_geom g = rs_scene_geom(s);
        rs_vec3 c = rs_geom_sphere_center(&g, prim, time), axis = rs_v3_sub(c, x);
        float r = s->spheres[prim].radius, dc2 = rs_v3_dot(axis, axis);
        if (dc2 > r * r * 1.0001f) {
            /* the cone toward the sphere: every direction in it hits the sphere */
            float omc = rs_cone_one_minus_cos(r, dc2), dc = sqrtf(dc2);
            rs_onb f = rs_onb_from_normal(rs_v3_scale(axis, 1.0f / dc));
            rs_vec3 w = rs_onb_to_world(&f, rs_sample_uniform_cone(omc, u1, u2));
            float ct = rs_v3_dot(w, f.n);
            /* the near intersection, from the perpendicular distance to the centre (no
             * cancellation in dc^2 - r^2 for far spheres) */
            rs_vec3 perp = rs_v3_sub(rs_v3_scale(w, dc * ct), axis);
            float disc = r * r - rs_v3_dot(perp, perp);
            float t = dc * ct - sqrtf(rs_fmaxf(0.0f, disc));
            out->wi = w;
            out->dist = t;
            out->point = rs_v3_madd(x, w, t);
            out->pdf = lt->pick_pdf * rs_pdf_uniform_cone(omc);
            n = rs_v3_scale(rs_v3_sub(out->point, c), 1.0f / r);
            out->le = rs_emitted(rs_scene_prim_material(s, prim), n, w);
            return out->pdf > 0.0f && t > 0.0f;
        }
        /* inside (or on) the sphere: a point uniform on its surface */
        p = rs_v3_madd(c, rs_sample_uniform_sphere(u1, u2), r);
    } else if (prim - s->n_spheres < s->n_quads) {
        const rs_quad *q = &s->quads[prim - s->n_spheres];
        p = rs_v3_add(q->q, rs_v3_add(rs_v3_scale(q->u, u1), rs_v3_scale(q->v, u2)));
    } else {
        const rs_tri *t = &s->tris[prim - s->n_spheres - s->n_quads];
        float b1, b2;
        rs_sample_triangle(u1, u2, &b1, &b2);
        p = rs_v3_add(rs_v3_add(rs_v3_scale(t->v0, 1.0f - b1 - b2), rs_v3_scale(t->v1, b1)),
                      rs_v3_scale(t->v2, b2));
    }
    n = rs_prim_normal(s, prim, p, time);
    to = rs_v3_sub(p, x);
    d2 = rs_v3_dot(to, to);
    if (!(d2 > 0.0f))
        return 0;
    out->dist = sqrtf(d2);
    out->wi = rs_v3_scale(to, 1.0f / out->dist);
    cos_l = fabsf(rs_v3_dot(n, out->wi));
    if (!(cos_l > 1e-7f))
        return 0;
    out->point = p;
    out->pdf = lt->pick_pdf * d2 / (lt->area * cos_l);
    out->le = rs_emitted(rs_scene_prim_material(s, prim), n, out->wi);
    return 1;
}

/* The pdf rs_light_sample_at gives to direction w (unit) from x that reaches light `light` at
 * distance t where its normal is ng: what MIS needs when BSDF sampling hits an emitter. */
RS_HD float rs_light_pdf_hit(const rs_scene *s, uint32_t light, rs_vec3 x, float time, rs_vec3 w,
                             float t, rs_vec3 ng)
{
    const rs_light *lt = &s->lights[light];
    float cos_l;
    if (lt->prim < s->n_spheres) {
        rs_geom g = rs_scene_geom(s);
        rs_vec3 axis = rs_v3_sub(rs_geom_sphere_center(&g, lt->prim, time), x);
        float r = s->spheres[lt->prim].radius, dc2 = rs_v3_dot(axis, axis);
        if (dc2 > r * r * 1.0001f)
            return lt->pick_pdf * rs_pdf_uniform_cone(rs_cone_one_minus_cos(r, dc2));
    }
    cos_l = fabsf(rs_v3_dot(ng, w));
    if (!(cos_l > 1e-7f))
        return 0.0f;
    return lt->pick_pdf * t * t / (lt->area * cos_l);
}

/* The pdf of direction w (unit) from x summed over every light that the line x + t w meets,
 * ignoring occlusion, the environment map's included (the mixture PDF's light term). */
RS_HD float rs_lights_pdf_dir(const rs_scene *s, rs_vec3 x, float time, rs_vec3 w)
{
    rs_geom g = rs_scene_geom(s);
    rs_ray r;
    float pdf = 0.0f;
    uint32_t l;
    r.o = x;
    r.d = w;
    r.tmin = 0.0f;
    r.tmax = FLT_MAX;
    r.time = time;
    for (l = 0; l < s->n_lights; ++l) {
        float t, u, v;
        uint32_t prim = s->lights[l].prim;
        if (rs_geom_intersect(&g, prim, &r, &t, &u, &v))
            pdf += rs_light_pdf_hit(s, l, x, time, w, t,
                                    rs_prim_normal(s, prim, rs_ray_at(&r, t), time));
    }
    if (s->env_pick > 0.0f)
        pdf += s->env_pick * rs_env_pdf(s, w);
    return pdf;
}

#endif
