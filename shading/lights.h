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
#include "shading/light_bvh.h"
#include "shading/spawn.h"

typedef struct rs_light_sample {
    rs_vec3 point; /* on the light */
    rs_vec3 err;   /* point's error bound, and the light's unit normal there (emitters only: */
    rs_vec3 n;     /* a shadow ray ends at the point moved off the emitter, shading/spawn.h) */
    rs_vec3 wi;    /* unit direction from the shading point toward `point` */
    float dist;    /* distance to `point` */
    float pdf;     /* solid-angle pdf, pick probability included */
    rs_vec3 le;    /* radiance arriving along -wi (zero from the back of a one-sided light) */
    int env;       /* from the environment map or a directional light: `point` and `dist` are
                      meaningless, the shadow ray runs to infinity */
    int delta;     /* from a punctual light: no BSDF sample can find it (no MIS weight); `pdf`
                      is the pick probability alone and `le` includes 1 / dist^2 */
} rs_light_sample;

/* Which lights a sample may come from. */
#define RS_LIGHTS_ALL   0 /* every light (MIS's next-event estimation) */
#define RS_LIGHTS_AREA  1 /* the map and the emitters (the mixture's light half) */
#define RS_LIGHTS_DELTA 2 /* the punctual lights (the mixture's next-event estimation) */
/* How every light's pick is made (by power, or by the light BVH at the point) is the light
 * sampler's: shading/light_sampler.h. */

/* Whether the map or an emitter can be sampled (the mixture's light half has something). */
RS_HD int rs_scene_has_area_lights(const rs_scene *s)
{
    return s->n_area_lights > 0 || s->env_pick > 0.0f;
}

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
    {
        rs_tri t = rs_scene_tri(s, prim + s->n_spheres);
        return rs_v3_normalize(rs_v3_cross(rs_v3_sub(t.v1, t.v0), rs_v3_sub(t.v2, t.v0)));
    }
}

/* Radiance that material m emits from a surface of geometric normal ng toward a ray travelling
 * along d (that is, toward -d). */
RS_HD rs_vec3 rs_emitted(const rs_material *m, rs_vec3 ng, rs_vec3 d)
{
    if (m->type == RS_MAT_PBR) /* glTF's emission: both sides (a textured one is not sampled) */
        return m->emission_tex == RS_NO_TEXTURE ? m->emission : rs_v3_splat(0.0f);
    if (m->type != RS_MAT_DIFFUSE_LIGHT)
        return rs_v3_splat(0.0f);
    if ((m->flags & RS_MAT_TWO_SIDED) || rs_v3_dot(ng, d) < 0.0f)
        return m->emission;
    return rs_v3_splat(0.0f);
}

/* Among lights [0, n): the largest l with cdf[l] <= u, so zero-probability lights are never
 * picked. */
RS_HD uint32_t rs_light_pick_n(const rs_scene *s, float u, uint32_t n)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (s->light_cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

RS_HD uint32_t rs_light_pick(const rs_scene *s, float u) { return rs_light_pick_n(s, u, s->n_lights); }

/* A sample of punctual light p from x, picked with probability `pick`. */
RS_HD_COLD int rs_punctual_sample(const rs_punctual *p, rs_vec3 x, float pick,
                              rs_light_sample *out)
{
    rs_vec3 to;
    float d2;
    out->delta = 1;
    out->pdf = pick;
    if (p->type == RS_PUNCTUAL_DIRECTIONAL) {
        out->wi = rs_v3_neg(p->dir);
        out->dist = FLT_MAX;
        out->point = x;
        out->env = 1;
        out->le = p->intensity;
        return pick > 0.0f;
    }
    to = rs_v3_sub(p->pos, x);
    d2 = rs_v3_dot(to, to);
    if (!(d2 > 0.0f) || !(pick > 0.0f))
        return 0;
    out->dist = sqrtf(d2);
    out->wi = rs_v3_scale(to, 1.0f / out->dist);
    out->point = p->pos;
    out->le = rs_v3_scale(p->intensity, 1.0f / d2);
    if (p->type == RS_PUNCTUAL_SPOT) {
        /* glTF's falloff: the square of the linear ramp from the outer cone to the inner */
        float cd = -rs_v3_dot(out->wi, p->dir), t;
        float span = p->cos_inner - p->cos_outer;
        t = span > 0.0f ? (cd - p->cos_outer) / span : (cd >= p->cos_outer ? 1.0f : 0.0f);
        t = rs_fminf(1.0f, rs_fmaxf(0.0f, t));
        out->le = rs_v3_scale(out->le, t * t);
        if (!(t > 0.0f))
            return 0;
    }
    return 1;
}

/* 1 - cos(theta_max) of the cone a sphere of radius r subtends at squared distance d2 > r^2,
 * written as sin^2 / (1 + cos) so that small, far spheres keep their precision. */
RS_HD float rs_cone_one_minus_cos(float r, float d2)
{
    float sin2 = r * r / d2;
    return sin2 / (1.0f + sqrtf(rs_fmaxf(0.0f, 1.0f - sin2)));
}

/* A punctual light picked by u_pick among the punctual lights alone. */
RS_HD_COLD int rs_light_sample_delta(const rs_scene *s, rs_vec3 x, float u_pick,
                                     rs_light_sample *out)
{
    /* the part of the CDF after the emitters, scaled back to [0, 1) */
    float a = s->n_area_lights ? s->light_cdf[s->n_area_lights] : 0.0f;
    uint32_t l;
    if (s->n_lights == s->n_area_lights)
        return 0;
    l = rs_light_pick(s, a + u_pick * (1.0f - a));
    if (l < s->n_area_lights)
        l = s->n_area_lights;
    return rs_punctual_sample(&s->punctuals[s->lights[l].prim & ~RS_LIGHT_PUNCTUAL], x,
                              s->lights[l].pick_pdf / ((1.0f - s->env_pick) * (1.0f - a)), out);
}

/* A direction toward the environment map from x (surface normal n_x, zero: none), picked with
 * probability env_pick. */
RS_HD int rs_light_sample_env(const rs_scene *s, rs_vec3 x, rs_vec3 n_x, float env_pick, float u1,
                              float u2, rs_light_sample *out)
{
    if (!rs_env_sample_at(s, n_x, u1, u2, &out->wi, &out->pdf, &out->le))
        return 0;
    out->pdf *= env_pick;
    out->point = x;
    out->dist = FLT_MAX;
    out->env = 1;
    return 1;
}

RS_HD_HOT int rs_light_sample_one(const rs_scene *s, uint32_t l, float pick, float inv_mass,
                                  rs_vec3 x, float time, float u1, float u2, rs_light_sample *out);

/* Samples a light of `subset` (RS_LIGHTS_*) as seen from x at `time` on a surface with unit
 * normal n_x (zero: none; a uniform sky is sampled about it, shading/envmap.h); the pdf is relative
 * to the subset (the pick probability divided by the subset's).  Returns 0 (and no sample) if
 * the subset is empty or the sample is degenerate (x on the light's plane, or inside a one-point
 * light). */
RS_HD int rs_light_sample_from(const rs_scene *s, int subset, rs_vec3 x, rs_vec3 n_x,
                               float time, float u_pick, float u1, float u2, rs_light_sample *out)
{
    uint32_t l, n = s->n_lights;
    float env_pick = s->env_pick, inv_mass = 1.0f;
    if (!rs_scene_has_lights(s))
        return 0;
    out->env = 0;
    out->delta = 0;
    if (subset == RS_LIGHTS_DELTA)
        return rs_light_sample_delta(s, x, u_pick, out);
    if (subset == RS_LIGHTS_AREA && s->n_lights > s->n_area_lights) {
        /* the map and the emitters only: their picks, divided by their share */
        if (!(s->area_mass > 0.0f))
            return 0;
        inv_mass = 1.0f / s->area_mass;
        env_pick = s->env_pick * inv_mass;
        n = s->n_area_lights;
    }
    if (env_pick > 0.0f) {
        if (u_pick < env_pick)
            return rs_light_sample_env(s, x, n_x, env_pick, u1, u2, out);
        /* the rest of [0, 1) picks an emitter as before */
        u_pick = (u_pick - env_pick) / (1.0f - env_pick);
    }
    if (n == 0)
        return 0;
    if (n < s->n_lights) /* the emitters' part of the CDF */
        u_pick *= s->light_cdf[n];
    l = rs_light_pick_n(s, u_pick, n);
    return rs_light_sample_one(s, l, s->lights[l].pick_pdf, inv_mass, x, time, u1, u2, out);
}

/* A point on light l, picked with probability `pick` (times inv_mass: relative to a subset),
 * as seen from x at `time`: out's direction, distance, radiance and pdf (pick included).  0
 * when the sample is degenerate. */
RS_HD_HOT int rs_light_sample_one(const rs_scene *s, uint32_t l, float pick, float inv_mass,
                                  rs_vec3 x, float time, float u1, float u2, rs_light_sample *out)
{
    const rs_light *lt = &s->lights[l];
    uint32_t prim = lt->prim;
    rs_surface_point sp;
    rs_vec3 p, n_l, to;
    float d2, cos_l;
    if (prim & RS_LIGHT_PUNCTUAL)
        return rs_punctual_sample(&s->punctuals[prim & ~RS_LIGHT_PUNCTUAL], x, pick, out);
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
            sp = rs_sphere_point(c, r, rs_v3_sub(rs_v3_scale(w, t), axis));
            out->wi = w;
            out->dist = t;
            out->point = sp.p;
            out->err = sp.err;
            out->n = sp.ng;
            out->pdf = pick * rs_pdf_uniform_cone(omc);
            out->le = rs_emitted(rs_scene_prim_material(s, prim), sp.ng, w);
            if (inv_mass != 1.0f)
                out->pdf *= inv_mass;
            return out->pdf > 0.0f && t > 0.0f;
        }
        /* inside (or on) the sphere: a point uniform on its surface */
        sp = rs_sphere_point(c, r, rs_v3_scale(rs_sample_uniform_sphere(u1, u2), r));
    } else if (prim - s->n_spheres < s->n_quads) {
        sp = rs_quad_point(&s->quads[prim - s->n_spheres], u1, u2);
    } else {
        float b1, b2;
        rs_sample_triangle(u1, u2, &b1, &b2);
        sp = rs_tri_point(&s->tris[prim - s->n_spheres - s->n_quads], b1, b2);
    }
    p = sp.p;
    n_l = sp.ng;
    to = rs_v3_sub(p, x);
    d2 = rs_v3_dot(to, to);
    if (!(d2 > 0.0f))
        return 0;
    out->dist = sqrtf(d2);
    out->wi = rs_v3_scale(to, 1.0f / out->dist);
    cos_l = fabsf(rs_v3_dot(n_l, out->wi));
    if (!(cos_l > 1e-7f))
        return 0;
    out->point = p;
    out->err = sp.err;
    out->n = n_l;
    out->pdf = pick * d2 / (lt->area * cos_l);
    if (inv_mass != 1.0f)
        out->pdf *= inv_mass;
    out->le = rs_emitted(rs_scene_prim_material(s, prim), n_l, out->wi);
    return 1;
}

/* The same seen from no surface. */
RS_HD int rs_light_sample_in(const rs_scene *s, int subset, rs_vec3 x, float time, float u_pick,
                             float u1, float u2, rs_light_sample *out)
{
    return rs_light_sample_from(s, subset, x, rs_v3_splat(0.0f), time, u_pick, u1, u2, out);
}

/* A sample of any light (RS_LIGHTS_ALL). */
RS_HD int rs_light_sample_at(const rs_scene *s, rs_vec3 x, float time, float u_pick, float u1,
                             float u2, rs_light_sample *out)
{
    return rs_light_sample_in(s, RS_LIGHTS_ALL, x, time, u_pick, u1, u2, out);
}

/* The pdf that a sampler picking light `light` with probability `pick` gives to direction w
 * (unit) from x that reaches the light at distance t where its normal is ng: what MIS needs
 * when BSDF sampling hits an emitter. */
RS_HD float rs_light_pdf_hit_pick(const rs_scene *s, uint32_t light, float pick, rs_vec3 x,
                                  float time, rs_vec3 w, float t, rs_vec3 ng)
{
    const rs_light *lt = &s->lights[light];
    float cos_l;
    if (lt->prim < s->n_spheres) {
        rs_geom g = rs_scene_geom(s);
        rs_vec3 axis = rs_v3_sub(rs_geom_sphere_center(&g, lt->prim, time), x);
        float r = s->spheres[lt->prim].radius, dc2 = rs_v3_dot(axis, axis);
        if (dc2 > r * r * 1.0001f)
            return pick * rs_pdf_uniform_cone(rs_cone_one_minus_cos(r, dc2));
    }
    cos_l = fabsf(rs_v3_dot(ng, w));
    if (!(cos_l > 1e-7f))
        return 0.0f;
    return pick * t * t / (lt->area * cos_l);
}

/* The same with the light's pick probability by power (rs_light_sample_at's). */
RS_HD float rs_light_pdf_hit(const rs_scene *s, uint32_t light, rs_vec3 x, float time, rs_vec3 w,
                             float t, rs_vec3 ng)
{
    return rs_light_pdf_hit_pick(s, light, s->lights[light].pick_pdf, x, time, w, t, ng);
}

/* The pdf of direction w (unit) from x summed over every light that the line x + t w meets,
 * ignoring occlusion, the environment map's included: the pdf of RS_LIGHTS_AREA sampling (the
 * mixture PDF's light term). */
RS_HD float rs_lights_pdf_dir_at(const rs_scene *s, rs_vec3 x, rs_vec3 n, float time, rs_vec3 w)
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
    for (l = 0; l < s->n_area_lights; ++l) {
        float t, u, v;
        uint32_t prim = s->lights[l].prim;
        if (rs_geom_intersect(&g, prim, &r, &t, &u, &v))
            pdf += rs_light_pdf_hit(s, l, x, time, w, t,
                                    rs_prim_normal(s, prim, rs_ray_at(&r, t), time));
    }
    if (s->env_pick > 0.0f)
        pdf += s->env_pick * rs_env_pdf_at(s, n, w);
    if (s->n_lights > s->n_area_lights && s->area_mass > 0.0f)
        pdf /= s->area_mass; /* relative to what RS_LIGHTS_AREA picks from */
    return pdf;
}

/* The same seen from no surface. */
RS_HD float rs_lights_pdf_dir(const rs_scene *s, rs_vec3 x, float time, rs_vec3 w)
{
    return rs_lights_pdf_dir_at(s, x, rs_v3_splat(0.0f), time, w);
}

#endif
