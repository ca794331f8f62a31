/* shading/path.h — one path of the path tracer, written once for the host and the CUDA device
 * (every function RS_HD): its camera ray, the shading of each of its vertices, and the step from
 * one vertex to the next for the megakernel integrators.  Nothing here traces: whoever calls it
 * owns the traversal.
 *
 * The wavefront stages (shading/integrator.c) call rs_path_begin_at and rs_path_shade_at on each
 * entry of a stream; the megakernels (the devices' render_pass: cpu/cpu_megakernel.c with the
 * CPU's wide BVH, gpu/megakernel_path.h with the binary BVH for gpu/cuda_megakernel.cu and
 * gpu/gpu_fallback.c) loop over rs_path_start, rs_path_step and rs_path_unoccluded, which call
 * the same two, with their own traversal between.
 * A path is named by its pixel and sample (from its index in a plan, scheduler/plan.h); with the
 * bounce they pick its random numbers, so every integrator makes the same paths.
 *
 * Estimators, per sampling mode, at a non-delta vertex with BSDF f and its sampling pdf p_b:
 *   mis      next-event: light sample with pdf p_l, weight w_l = p_l^2 / (p_l^2 + p_b^2),
 *            adds beta f cos Le w_l / p_l if the shadow ray is free; then a BSDF sample,
 *            beta *= f cos / p_b; an emitter that ray hits adds beta Le w_b with
 *            w_b = p_b^2 / (p_b^2 + p_l^2)  (Veach 1998, power heuristic).
 *   mixture  one direction from p = 1/2 p_light + 1/2 p_b; beta *= f cos / p; emitters add
 *            beta Le in full (the thesis's radiance_mixture).
 *   bsdf     BSDF sample; emitters add beta Le.
 *   uniform  uniform hemisphere, p = 1 / 2pi; emitters add beta Le.
 * Delta materials (mirror, glass) are always sampled by their BSDF, and the emitter their ray
 * hits counts in full.  All four estimate the same integral (tested). */
#ifndef RS_SHADING_PATH_H
#define RS_SHADING_PATH_H

#include <float.h>

#include "core/rng.h"
#include "core/sobol.h"
#include "core/zsobol.h"
#include "shading/bsdf.h"
#include "shading/camera.h"
#include "shading/filter.h"
#include "shading/dims.h"
#include "shading/light_sampler.h"
#include "shading/lights.h"
#include "shading/spawn.h"
#include "shading/texture.h"
#include "streams/paths.h"

typedef enum rs_sampling {
    RS_SAMPLING_MIS = 0,     /* light sampling + BSDF sampling, power heuristic (Veach 1998) */
    RS_SAMPLING_MIXTURE = 1, /* one direction from 1/2 light pdf + 1/2 BSDF pdf (the thesis's
                                radiance_mixture, Shirley's "The Rest of Your Life") */
    RS_SAMPLING_BSDF = 2,    /* BSDF importance sampling only */
    RS_SAMPLING_UNIFORM = 3  /* uniform hemisphere, no light sampling ("no importance sampling") */
} rs_sampling;

/* Where a path's random numbers come from (each group of four: shading/dims.h). */
typedef enum rs_sampler {
    RS_SAMPLER_INDEPENDENT = 0, /* Philox-4x32-10 (core/rng.h): independent uniform numbers */
    RS_SAMPLER_SOBOL = 1,       /* Owen-scrambled shuffled Sobol points (core/sobol.h) */
    RS_SAMPLER_ZSOBOL = 2       /* Owen-scrambled Sobol points in Morton order over the image
                                   (core/zsobol.h): blue-noise error across pixels */
} rs_sampler;

/* Path flags. */
#define RS_PATH_SPECULAR 1u /* the current ray left the camera or a delta BSDF: no MIS weight */
#define RS_PATH_NEGATIVE 2u /* the camera sample fell under a negative lobe of the pixel filter
                               (shading/filter.h): the film takes -radiance (rs_path_result) */

/* What rs_path_shade_at made. */
#define RS_SHADE_NEXT   1u /* the path goes on with *next */
#define RS_SHADE_SHADOW 2u /* a shadow ray *shadow carries ps->pending */

/* The render's constants, shared by every path: fixed-width plain data, the same bytes on the
 * host and a device, passed by value to the CUDA kernel.  `scene` is the only pointer: each
 * device that has memory of its own points its copy at its mirror of the scene
 * (scheduler/device_copy.h).  Built by rs_render_constants (scheduler/render.h) for both
 * integrators.  Nothing host-only belongs here (how many host threads run a stage, the pixels of
 * the plan being run: shading/integrator.h's rs_path_map); scheduler/device_copy.c asserts at
 * compile time that the struct is exactly these fields. */
typedef struct rs_render_consts {
    const rs_scene *scene;
    rs_camera camera;
    uint64_t seed;
    uint32_t width, height, npix;
    uint32_t spp;       /* the render's samples per pixel (the zsobol sampler's block size) */
    uint32_t max_depth; /* most ray segments a path may have, camera ray included (>= 1) */
    uint32_t rr_depth;  /* Russian roulette from this segment on */
    uint32_t sampling;  /* rs_sampling */
    uint32_t sampler;   /* rs_sampler */
    rs_filter filter;   /* the pixel filter the camera samples are drawn from */
    float tex_spread;   /* the camera's pixel spread angle (radians): |du| over the focus
                           distance, for image textures' level of detail (rs_texture_footprint);
                           0: bilinear textures on level 0 (--texture-filter bilinear) */
    uint32_t light_sampler; /* rs_light_sampler: how MIS's next-event estimation picks a light */
    uint32_t passes; /* 1: each path's first vertex records what its camera ray showed for the
                        film's passes (shading/aov.h rs_path_aux_at, shading/film.h) */
} rs_render_consts;

/* The Sobol samplers' numbers of group `group` in the order the decisions take them: the
 * light's point (v[1], v[2]) is one stratified pair, the pick and the mixture choice (v[0],
 * v[3]) the other. */
RS_HD rs_rng_f4 rs_path_sobol_order(rs_rng_f4 f, uint32_t group)
{
    if (group == RS_DIM_LIGHT) {
        float pick = f.v[2];
        f.v[2] = f.v[1];
        f.v[1] = f.v[0];
        f.v[0] = pick;
    }
    return f;
}

/* Four numbers in [0, 1) for decision group `group` (shading/dims.h) of path (pixel, sample)
 * at segment `bounce`, from the render's sampler.  (The host's stream stages make them for many
 * paths at once, shading/integrator.c, with the same result.) */
RS_HD rs_rng_f4 rs_path_rand(const rs_render_consts *it, uint32_t pixel, uint32_t sample,
                             uint32_t bounce, uint32_t group)
{
    rs_rng_f4 f;
    if (it->sampler == RS_SAMPLER_SOBOL)
        f = rs_sobol_float4(it->seed, pixel, sample, bounce, group);
    else if (it->sampler == RS_SAMPLER_ZSOBOL)
        f = rs_zsobol_float4(it->seed, pixel % it->width, pixel / it->width, sample,
                             rs_ceil_log2(it->spp), rs_zsobol_log2_res(it->width, it->height),
                             bounce, group);
    else
        return rs_rng_float4(it->seed, pixel, sample, bounce, group);
    return rs_path_sobol_order(f, group);
}

/* One path's state between its vertices: rs_path_state, declared once in streams/paths.h. */

/* The camera ray of path (pixel, sample), and its state reset.  `pre`: its numbers made ahead,
 * pre[0] group RS_DIM_CAMERA and pre[1] RS_DIM_TIME (read only with a shutter interval); NULL:
 * made here. */
RS_HD rs_ray rs_path_begin_at(const rs_render_consts *it, uint32_t pixel, uint32_t sample,
                              const rs_rng_f4 *pre, rs_path_state *ps)
{
    const rs_camera_desc *cd = &it->scene->camera;
    rs_rng_f4 r = pre ? pre[0] : rs_path_rand(it, pixel, sample, 0, RS_DIM_CAMERA);
    float jx, jy, w;
    rs_ray ray;
    float time = cd->shutter_open;
    rs_filter_sample(&it->filter, r.v[0], r.v[1], &jx, &jy);
    ray = rs_camera_ray(&it->camera, pixel % it->width, pixel / it->width, jx, jy, r.v[2], r.v[3]);
    w = rs_filter_weight(&it->filter, r.v[0], r.v[1]);
    if (cd->shutter_close != cd->shutter_open) {
        rs_rng_f4 rt = pre ? pre[1] : rs_path_rand(it, pixel, sample, 0, RS_DIM_TIME);
        time += rt.v[0] * (cd->shutter_close - cd->shutter_open);
    }
    ray.time = time;
    ps->throughput = rs_v3_splat(w < 0.0f ? -w : w);
    ps->radiance = rs_v3_splat(0.0f);
    ps->pending = rs_v3_splat(0.0f);
    ps->bsdf_pdf = 0.0f;
    ps->env_pdf = 0.0f;
    ps->time = time;
    ps->flags = (uint8_t)(RS_PATH_SPECULAR | (w < 0.0f ? RS_PATH_NEGATIVE : 0u));
    return ray;
}

/* What a finished path adds to its pixel: its radiance, negated when its camera sample fell under
 * a negative lobe of the filter.  (`flags` is the path's last rs_path_state flags.) */
RS_HD rs_vec3 rs_path_result(rs_vec3 radiance, uint32_t flags)
{
    return flags & RS_PATH_NEGATIVE ? rs_v3_scale(radiance, -1.0f) : radiance;
}

RS_HD float rs_power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* Surface coordinates at a hit: spheres by longitude/latitude (RTIOW), quads by their planar
 * coordinates, triangles by interpolating their UVs (or the barycentrics). */
RS_HD void rs_surface_uv(const rs_scene *sc, uint32_t prim, float hu, float hv, rs_vec3 n_out,
                         float *u, float *v)
{
    if (prim < sc->n_spheres) {
        float theta = rs_acosf(rs_fminf(1.0f, rs_fmaxf(-1.0f, -n_out.y)));
        float phi = rs_atan2f(-n_out.z, n_out.x) + RS_PI;
        *u = phi * (0.5f * RS_INV_PI);
        *v = theta * RS_INV_PI;
        return;
    }
    if (prim - sc->n_spheres < sc->n_quads || (!sc->tri_uv && !sc->inst_tri_uv)) {
        *u = hu;
        *v = hv;
        return;
    }
    {
        float tmp[6];
        const float *uv = rs_scene_tri_uv(sc, prim, tmp);
        float b0 = 1.0f - hu - hv;
        *u = b0 * uv[0] + hu * uv[2] + hv * uv[4];
        *v = b0 * uv[1] + hu * uv[3] + hv * uv[5];
    }
}

/* UV length per world length at a hit on `prim` (n_out: its outward normal there): the square
 * root of the UV area over the world area its parametrisation maps it to (rs_surface_uv's).
 * Triangles: their UVs (or barycentrics) against their world area; quads: 1 / sqrt|u x v|;
 * spheres: u = phi / 2pi, v = theta / pi cover 2 pi^2 r^2 sin(theta) du dv.  0 where the
 * mapping is degenerate (no filtering). */
RS_HD_COLD float rs_surface_uv_density(const rs_scene *sc, uint32_t prim, rs_vec3 n_out)
{
    if (prim < sc->n_spheres) {
        float y = n_out.y / rs_v3_length(n_out);
        float s = sqrtf(rs_fmaxf(1.0f - y * y, 1e-12f));
        return 1.0f / (sc->spheres[prim].radius * RS_PI * sqrtf(2.0f * s));
    }
    if (prim - sc->n_spheres < sc->n_quads) {
        const rs_quad *q = &sc->quads[prim - sc->n_spheres];
        float a = rs_v3_length(rs_v3_cross(q->u, q->v));
        return a > 0.0f ? 1.0f / sqrtf(a) : 0.0f;
    }
    {
        float tmp[6];
        const float *uv = rs_scene_tri_uv(sc, prim, tmp);
        rs_tri tr = rs_scene_tri(sc, prim);
        float a = rs_v3_length(rs_v3_cross(rs_v3_sub(tr.v1, tr.v0), rs_v3_sub(tr.v2, tr.v0)));
        float det;
        if (!uv)
            uv = rs_default_tri_uv(tmp);
        det = fabsf((uv[2] - uv[0]) * (uv[5] - uv[1]) - (uv[4] - uv[0]) * (uv[3] - uv[1]));
        return a > 0.0f ? sqrtf(det / a) : 0.0f;
    }
}

/* Whether material m looks up a texture at a hit (its albedo, or glTF's other maps). */
RS_HD int rs_material_textured(const rs_material *m)
{
    return m->albedo_tex != RS_NO_TEXTURE ||
           (m->type >= RS_MAT_CONDUCTOR &&
            (m->mr_tex != RS_NO_TEXTURE || m->emission_tex != RS_NO_TEXTURE ||
             m->normal_tex != RS_NO_TEXTURE));
}

/* The width in world units of what one pixel covers at surface point x (geometric normal ng)
 * of a material with textures: pbrt-v4's camera approximation (Camera::Approximate_dp_dxy), a
 * cone from the camera of the pixel's spread angle, at any vertex of the path: its width at
 * x's distance from the camera, over |cos| between ng and the direction from the camera (the
 * ray cone's footprint on the surface, Akenine-Moller et al. 2021).  0 without textures or
 * with bilinear filtering.  Shading passes it to the lookups below. */
RS_HD float rs_texture_footprint(const rs_render_consts *it, const rs_material *m, rs_vec3 x,
                                 rs_vec3 ng)
{
    rs_vec3 d;
    float dist, c;
    if (!(it->tex_spread > 0.0f) || !rs_material_textured(m))
        return 0.0f;
    d = rs_v3_sub(x, it->camera.origin);
    dist = rs_v3_length(d);
    if (!(dist > 0.0f))
        return 0.0f;
    c = fabsf(rs_v3_dot(ng, d)) / (dist * rs_v3_length(ng));
    return it->tex_spread * dist / rs_fmaxf(c, 1e-6f);
}

/* A lookup's footprint in UV units: the world footprint fw times the primitive's UV density. */
RS_HD float rs_surface_uv_footprint(const rs_scene *sc, uint32_t prim, rs_vec3 ng, float fw)
{
    return fw > 0.0f ? fw * rs_surface_uv_density(sc, prim, ng) : 0.0f;
}

/* The material's albedo at a hit; fw: the world footprint (rs_texture_footprint). */
RS_HD rs_vec3 rs_surface_albedo(const rs_scene *sc, const rs_material *m, uint32_t prim, float hu,
                                float hv, rs_vec3 x, rs_vec3 ng, float fw)
{
    float u, v;
    const rs_texture *t;
    if (m->albedo_tex == RS_NO_TEXTURE)
        return m->albedo;
    rs_surface_uv(sc, prim, hu, hv, ng, &u, &v);
    t = &sc->textures[m->albedo_tex];
    /* only an image has levels: a procedural texture skips the UV density */
    return rs_texture_eval_lod(t, sc->images, u, v, x,
                               t->type == RS_TEX_IMAGE ? rs_surface_uv_footprint(sc, prim, ng, fw)
                                                       : 0.0f);
}

/* The material at a hit with its textures other than the albedo applied (glTF's metallic-
 * roughness and emissive textures): m itself when it has none, else *local, filled. */
RS_HD_COLD const rs_material *rs_surface_material(const rs_scene *sc, const rs_material *m,
                                                  uint32_t prim, float hu, float hv, rs_vec3 x,
                                                  rs_vec3 ng, float fw, rs_material *local)
{
    float u, v, uvw;
    if (m->mr_tex == RS_NO_TEXTURE && m->emission_tex == RS_NO_TEXTURE)
        return m;
    *local = *m;
    rs_surface_uv(sc, prim, hu, hv, ng, &u, &v);
    uvw = rs_surface_uv_footprint(sc, prim, ng, fw);
    if (m->mr_tex != RS_NO_TEXTURE) {
        rs_vec3 t = rs_texture_eval_lod(&sc->textures[m->mr_tex], sc->images, u, v, x, uvw);
        float r = sqrtf(m->alpha) * rs_fminf(1.0f, rs_fmaxf(0.0f, t.y));
        local->alpha = rs_fmaxf(r * r, RS_GGX_DELTA_ALPHA);
        local->metallic = m->metallic * rs_fminf(1.0f, rs_fmaxf(0.0f, t.z));
    }
    if (m->emission_tex != RS_NO_TEXTURE)
        local->emission = rs_v3_mul(m->emission, rs_texture_eval_lod(&sc->textures[m->emission_tex],
                                                                     sc->images, u, v, x, uvw));
    return local;
}

/* The shading normal n (on the incoming side; `front`: that is the side ng faces) bent by the
 * material's tangent-space normal map, on a triangle with UVs: the tangent frame follows the UV
 * gradient (dp/du, dp/dv), made orthonormal about the unbent normal.  n where there is no map,
 * no UVs or a degenerate UV mapping, or where the bent normal would face away from wo. */
RS_HD_COLD rs_vec3 rs_normal_mapped(const rs_scene *sc, const rs_material *m, uint32_t prim,
                                    float hu, float hv, rs_vec3 x, rs_vec3 n, int front, rs_vec3 wo,
                                    float fw)
{
    rs_tri tr;
    const float *uv;
    float tmp[6];
    rs_vec3 e1, e2, T, B, nf, tex, nm;
    float du1, dv1, du2, dv2, det, u, v, hand;
    if (m->normal_tex == RS_NO_TEXTURE || prim < sc->n_spheres + sc->n_quads)
        return n;
    uv = rs_scene_tri_uv(sc, prim, tmp);
    if (!uv)
        return n;
    tr = rs_scene_tri(sc, prim);
    e1 = rs_v3_sub(tr.v1, tr.v0);
    e2 = rs_v3_sub(tr.v2, tr.v0);
    du1 = uv[2] - uv[0], dv1 = uv[3] - uv[1], du2 = uv[4] - uv[0], dv2 = uv[5] - uv[1];
    det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-12f))
        return n;
    nf = front ? n : rs_v3_neg(n); /* the map is in the frame of the surface's own side */
    T = rs_v3_scale(rs_v3_sub(rs_v3_scale(e1, dv2), rs_v3_scale(e2, dv1)), 1.0f / det);
    B = rs_v3_scale(rs_v3_sub(rs_v3_scale(e2, du1), rs_v3_scale(e1, du2)), 1.0f / det);
    T = rs_v3_sub(T, rs_v3_scale(nf, rs_v3_dot(nf, T)));
    if (!(rs_v3_length2(T) > 0.0f))
        return n;
    T = rs_v3_normalize(T);
    hand = rs_v3_dot(rs_v3_cross(nf, T), B) < 0.0f ? -1.0f : 1.0f;
    B = rs_v3_scale(rs_v3_cross(nf, T), hand);
    u = (1.0f - hu - hv) * uv[0] + hu * uv[2] + hv * uv[4];
    v = (1.0f - hu - hv) * uv[1] + hu * uv[3] + hv * uv[5];
    /* the UV density from the world triangle and its UVs at hand (rs_surface_uv_density's) */
    if (fw > 0.0f) {
        float a = rs_v3_length(rs_v3_cross(e1, e2));
        fw = a > 0.0f ? fw * sqrtf(fabsf(det) / a) : 0.0f;
    }
    tex = rs_texture_eval_lod(&sc->textures[m->normal_tex], sc->images, u, v, x, fw);
    tex = rs_v3((2.0f * tex.x - 1.0f) * m->normal_scale, (2.0f * tex.y - 1.0f) * m->normal_scale,
                2.0f * tex.z - 1.0f);
    nm = rs_v3_add(rs_v3_add(rs_v3_scale(T, tex.x), rs_v3_scale(B, tex.y)), rs_v3_scale(nf, tex.z));
    if (!(rs_v3_length2(nm) > 1e-12f))
        return n;
    nm = rs_v3_normalize(nm);
    if (!front)
        nm = rs_v3_neg(nm);
    return rs_v3_dot(nm, wo) > 0.0f ? nm : n;
}

/* The shading normal at a hit: the interpolated vertex normal of a triangle that has them,
 * turned to the side of n_geo (the geometric normal on the incoming side); n_geo otherwise, or
 * where the vertex normal would face away from wo. */
RS_HD rs_vec3 rs_shading_normal(const rs_scene *sc, uint32_t prim, float hu, float hv,
                                rs_vec3 n_geo, rs_vec3 wo)
{
    const float *vn;
    float tmp[9];
    rs_vec3 ns;
    float len;
    if ((!sc->tri_normal && !sc->inst_tri_normal) || prim < sc->n_spheres + sc->n_quads)
        return n_geo;
    vn = rs_scene_tri_normals(sc, prim, tmp);
    if (!vn)
        return n_geo;
    ns = rs_v3_add(rs_v3_add(rs_v3_scale(rs_v3(vn[0], vn[1], vn[2]), 1.0f - hu - hv),
                             rs_v3_scale(rs_v3(vn[3], vn[4], vn[5]), hu)),
                   rs_v3_scale(rs_v3(vn[6], vn[7], vn[8]), hv));
    len = rs_v3_length(ns);
    if (!(len > 1e-6f))
        return n_geo;
    ns = rs_v3_scale(ns, 1.0f / len);
    if (rs_v3_dot(ns, n_geo) < 0.0f)
        ns = rs_v3_neg(ns);
    return rs_v3_dot(ns, wo) > 0.0f ? ns : n_geo;
}

/* Russian roulette's survival probability at a vertex reached with `throughput`: the throughput
 * the path expects after reflecting there (times the albedo, plus Phong's specular part), in
 * [0.05, 0.95].  Any q > 0 keeps the estimate unbiased (the survivors are divided by q); the
 * floor keeps a surface whose reflectance the estimate misses from ending every path. */
RS_HD float rs_roulette_survival(rs_vec3 throughput, const rs_material *m, rs_vec3 albedo)
{
    rs_vec3 r = m->type == RS_MAT_PHONG ? rs_v3_add(albedo, m->specular) : albedo;
    return rs_fminf(rs_fmaxf(rs_v3_max_comp(rs_v3_mul(throughput, r)), 0.05f), 0.95f);
}

/* A surface vertex of a path, as its shading steps see it. */
typedef struct rs_vertex {
    const rs_material *m;
    uint32_t prim;
    int front;      /* the ray arrived on the side ng faces */
    rs_vec3 x;      /* the hit point */
    rs_vec3 ng;     /* the geometric normal as the primitive defines it */
    rs_vec3 n_geo;  /* the geometric normal on the incoming ray's side */
    rs_vec3 n;      /* the shading normal (rs_shading_normal) */
    rs_vec3 wo;     /* toward where the ray came from */
    rs_vec3 albedo; /* the material's albedo there (textured or not) */
    rs_vec3 err;    /* x's error bound (shading/spawn.h) */
    rs_vec3 origin; /* where rays leaving the reflecting side start (rs_spawn_origin) */
} rs_vertex;

/* An emitter hit: its radiance, MIS-weighted against the light sampling that could also have
 * found it when the path came by BSDF sampling (not after a delta bounce or from the camera,
 * where none could). */
RS_HD void rs_shade_emitter(const rs_render_consts *it, const rs_ray *r, float t, uint32_t prim,
                            const rs_material *m, rs_vec3 ng, rs_vec3 beta, rs_path_state *ps)
{
    const rs_scene *sc = it->scene;
    rs_vec3 le = rs_emitted(m, ng, r->d);
    float w = 1.0f;
    int32_t l = rs_scene_prim_light(sc, prim);
    if (it->sampling == RS_SAMPLING_MIS && !(ps->flags & RS_PATH_SPECULAR) && l >= 0) {
        float pick = rs_light_sampler_pmf(sc, it->light_sampler, (uint32_t)l, r->o);
        w = rs_power_heuristic(ps->bsdf_pdf, rs_light_pdf_hit_pick(sc, (uint32_t)l, pick, r->o,
                                                                   r->time, r->d, t, ng));
    }
    ps->radiance = rs_v3_add(ps->radiance, rs_v3_scale(rs_v3_mul(beta, le), w));
}

/* Mirror or glass: the only direction that carries light is the sampled one.  0: the path ends
 * here. */
RS_HD int rs_shade_delta(rs_vertex *v, rs_rng_f4 rb, rs_vec3 *beta, rs_vec3 *wi)
{
    rs_scatter bs;
    if (!rs_bsdf_sample(v->m, v->albedo, v->n, v->wo, v->front, rb.v[0], rb.v[1], rb.v[2], &bs))
        return 0;
    *wi = bs.wi;
    /* with a shading normal, a direction can land on the wrong side of the real surface */
    if ((rs_v3_dot(*wi, v->n_geo) > 0.0f) == (bs.transmit != 0))
        return 0;
    *beta = rs_v3_mul(*beta, bs.weight);
    v->origin = rs_spawn_origin(v->x, v->err, bs.transmit ? rs_v3_neg(v->n_geo) : v->n_geo);
    return 1;
}

/* Whether direction w (c = n.w, `through`: w on the far side of the geometric surface) can
 * carry light at vertex v: above both the shading and the geometric surface, or for a
 * transmitting material, on the same side of both. */
RS_HD int rs_vertex_side_ok(const rs_vertex *v, rs_vec3 w, float c, int through)
{
    (void)w;
    if (through)
        return rs_material_transmits(v->m) && c < 0.0f;
    return c > 0.0f;
}

/* Where rays leaving v through the surface start: the hit point moved to the far side. */
RS_HD rs_vec3 rs_vertex_far_origin(const rs_vertex *v)
{
    return rs_spawn_origin(v->x, v->err, rs_v3_neg(v->n_geo));
}

/* Next-event estimation (mis): a shadow ray toward a sampled point on a light of `subset`
 * (RS_LIGHTS_ALL: picked by `sampler`, an rs_light_sampler; RS_LIGHTS_DELTA: the punctual
 * lights, by power), its MIS-weighted contribution in ps->pending.  Returns RS_SHADE_SHADOW when
 * it made one. */
RS_HD_HOT uint32_t rs_shade_next_event(const rs_scene *sc, const rs_vertex *v, const rs_ray *r,
                                   rs_rng_f4 rl, rs_vec3 beta, rs_path_state *ps, rs_ray *shadow,
                                   int subset, uint32_t sampler)
{
    rs_light_sample ls;
    float c;
    rs_vec3 fl;
    int through;
    /* the light seen from the surface point itself (its distance, direction and pdf); only the
     * shadow ray starts at the offset origin */
    if (subset == RS_LIGHTS_ALL
            ? !rs_light_sampler_sample(sc, sampler, v->x, v->n, v->origin, r->time, rl.v[0],
                                       rl.v[1], rl.v[2], &ls)
            : !rs_light_sample_from(sc, subset, v->x, v->n, r->time, rl.v[0], rl.v[1], rl.v[2],
                                    &ls))
        return 0;
    c = rs_v3_dot(v->n, ls.wi);
    through = !(rs_v3_dot(v->n_geo, ls.wi) > 0.0f); /* beyond a transmitting surface */
    if (!rs_vertex_side_ok(v, ls.wi, c, through) || rs_v3_is_zero(ls.le))
        return 0;
    fl = rs_bsdf_eval_side(v->m, v->albedo, v->n, v->wo, ls.wi, v->front);
    if (rs_v3_is_zero(fl))
        return 0;
    {
        /* a punctual light: BSDF sampling never finds it, so its sample counts in full */
        float w = ls.delta ? 1.0f
                           : rs_power_heuristic(ls.pdf, rs_bsdf_pdf_side(v->m, v->albedo, v->n,
                                                                         v->wo, ls.wi, v->front));
        ps->pending = rs_v3_scale(rs_v3_mul(rs_v3_mul(beta, fl), ls.le), fabsf(c) * w / ls.pdf);
    }
    shadow->o = through ? rs_vertex_far_origin(v) : v->origin;
    shadow->tmin = 0.0f;
    if (ls.env) {
        shadow->d = ls.wi; /* toward the map: anything in the way occludes */
        shadow->tmax = FLT_MAX;
    } else {
        /* unnormalised: the light's point (moved off an emitter toward the origin, as the
         * origin is moved off the surface) at t = 1 */
        rs_vec3 end = ls.delta ? ls.point : rs_spawn_end(ls.point, ls.err, ls.n, shadow->o);
        shadow->d = rs_v3_sub(end, shadow->o);
        shadow->tmax = 1.0f - RS_SHADOW_EPS;
    }
    shadow->time = r->time;
    return RS_SHADE_SHADOW;
}

/* The next direction at a non-delta vertex, by the render's sampling mode; *beta gains f cos /
 * pdf and *pdf is the solid-angle pdf it was drawn with.  0: the path ends here. */
RS_HD_HOT int rs_shade_direction(const rs_render_consts *it, const rs_vertex *v, const rs_ray *r,
                                 rs_rng_f4 rb, rs_rng_f4 rl, rs_vec3 *beta, rs_vec3 *wi, float *pdf)
{
    const rs_scene *sc = it->scene;
    float ci;
    rs_vec3 f;
    if (it->sampling == RS_SAMPLING_UNIFORM) {
        /* no importance sampling at all: uniform hemisphere, f cos / (1 / 2pi) (the whole
         * sphere, 1 / 4pi, where the material transmits) */
        rs_onb frame = rs_onb_from_normal(v->n);
        if (rs_material_transmits(v->m)) {
            *wi = rs_sample_uniform_sphere(rb.v[0], rb.v[1]);
            *pdf = 0.25f * RS_INV_PI;
        } else {
            *wi = rs_onb_to_world(&frame, rs_sample_uniform_hemisphere(rb.v[0], rb.v[1]));
            *pdf = rs_pdf_uniform_hemisphere(rs_v3_dot(v->n, *wi));
        }
        ci = rs_v3_dot(v->n, *wi);
        f = rs_bsdf_eval_side(v->m, v->albedo, v->n, v->wo, *wi, v->front);
        if (!(*pdf > 0.0f))
            return 0;
        *beta = rs_v3_mul(*beta, rs_v3_scale(f, fabsf(ci) / *pdf));
    } else if (it->sampling == RS_SAMPLING_MIXTURE && rs_scene_has_area_lights(sc)) {
        /* the thesis's radiance_mixture: one direction from 1/2 light pdf + 1/2 BSDF pdf (the
         * map and the emitters; punctual lights have a shadow ray of their own) */
        if (rl.v[3] < 0.5f) {
            rs_light_sample ls;
            if (!rs_light_sample_from(sc, RS_LIGHTS_AREA, v->x, v->n, r->time, rl.v[0],
                                      rl.v[1], rl.v[2], &ls))
                return 0;
            *wi = ls.wi;
        } else {
            rs_scatter bs;
            if (!rs_bsdf_sample(v->m, v->albedo, v->n, v->wo, v->front, rb.v[0], rb.v[1], rb.v[2],
                                &bs))
                return 0;
            *wi = bs.wi;
        }
        ci = rs_v3_dot(v->n, *wi);
        if (!rs_vertex_side_ok(v, *wi, ci, !(rs_v3_dot(v->n_geo, *wi) > 0.0f)))
            return 0; /* f = 0 below the surface: the path carries nothing further */
        *pdf = 0.5f * rs_lights_pdf_dir_at(sc, v->x, v->n, r->time, *wi) +
               0.5f * rs_bsdf_pdf_side(v->m, v->albedo, v->n, v->wo, *wi, v->front);
        f = rs_bsdf_eval_side(v->m, v->albedo, v->n, v->wo, *wi, v->front);
        if (!(*pdf > 0.0f))
            return 0;
        *beta = rs_v3_mul(*beta, rs_v3_scale(f, fabsf(ci) / *pdf));
    } else {
        /* mis, bsdf, and mixture without lights: the material's own sampling */
        rs_scatter bs;
        if (!rs_bsdf_sample(v->m, v->albedo, v->n, v->wo, v->front, rb.v[0], rb.v[1], rb.v[2], &bs))
            return 0;
        *wi = bs.wi;
        *pdf = bs.pdf;
        *beta = rs_v3_mul(*beta, bs.weight);
    }
    return 1;
}

/* Shades the hit h of ray `ray` (segment number `bounce`) of path (pixel, sample): adds what the
 * vertex sends to ps->radiance (background, emitter), and may make the path's next ray (returns
 * RS_SHADE_NEXT, *next set, ps->throughput/bsdf_pdf/flags updated) and a shadow ray toward a
 * light (returns RS_SHADE_SHADOW, *shadow set, its contribution in ps->pending if the ray is
 * unoccluded).  `pre`: the vertex's numbers made ahead, pre[0] group RS_DIM_BSDF and pre[1]
 * RS_DIM_LIGHT (rs_path_rand's); NULL: made here, only where the vertex needs them. */
RS_HD_HOT uint32_t rs_path_shade_at(const rs_render_consts *it, uint32_t pixel, uint32_t sample,
                                    uint32_t bounce, const rs_rng_f4 *pre, const rs_ray *ray,
                                    const rs_hit *h, rs_path_state *ps, rs_ray *next,
                                    rs_ray *shadow)
{
    const rs_scene *sc = it->scene;
    rs_ray r = *ray;
    rs_vec3 beta = ps->throughput, wi;
    rs_vertex v;
    rs_material local;
    rs_rng_f4 rb;
    float pdf = 0.0f, fw;
    int specular = 0;
    uint32_t out = 0;

    if (h->prim == RS_NO_HIT) {
        rs_vec3 bg;
        if (rs_env_present(sc)) {
            /* the map is a light: MIS-weighted against sampling it, as an emitter hit is */
            bg = rs_env_radiance(sc, r.d);
            if (it->sampling == RS_SAMPLING_MIS && !(ps->flags & RS_PATH_SPECULAR) &&
                sc->env_pick > 0.0f)
                /* a uniform sky's pdf depends on the vertex the ray left (its normal): kept
                 * from there; a map's on the direction alone */
                bg = rs_v3_scale(bg, rs_power_heuristic(
                                         ps->bsdf_pdf, sc->env_uniform ? ps->env_pdf
                                                                       : sc->env_pick *
                                                                             rs_env_pdf(sc, r.d)));
        } else {
            bg = rs_scene_background(sc, r.d);
        }
        ps->radiance = rs_v3_add(ps->radiance, rs_v3_mul(beta, bg));
        return 0;
    }
    v.prim = h->prim;
    v.m = rs_scene_prim_material(sc, v.prim);
    {
        rs_surface_point sp = rs_surface_at(sc, v.prim, &r, h->t, h->u, h->v);
        v.x = sp.p;
        v.err = sp.err;
        v.ng = sp.ng;
    }
    if (v.m->type == RS_MAT_DIFFUSE_LIGHT) {
        rs_shade_emitter(it, &r, h->t, v.prim, v.m, v.ng, beta, ps);
        return 0; /* emitters reflect nothing */
    }
    if (!rs_v3_is_zero(v.m->sigma_a) && rs_v3_dot(v.ng, r.d) > 0.0f) {
        /* the segment ran inside an absorbing object (KHR_materials_volume): Beer-Lambert */
        float len = h->t * rs_v3_length(r.d);
        beta = rs_v3_mul(beta, rs_v3(rs_expf(-v.m->sigma_a.x * len), rs_expf(-v.m->sigma_a.y * len),
                                     rs_expf(-v.m->sigma_a.z * len)));
    }
    fw = rs_texture_footprint(it, v.m, v.x, v.ng); /* 0 without textures */
    if (v.m->type >= RS_MAT_CONDUCTOR) {
        if (v.m->mr_tex != RS_NO_TEXTURE || v.m->emission_tex != RS_NO_TEXTURE)
            v.m = rs_surface_material(sc, v.m, v.prim, h->u, h->v, v.x, v.ng, fw, &local);
        if (v.m->type == RS_MAT_PBR && !rs_v3_is_zero(v.m->emission)) {
            /* a glTF emissive surface: MIS-weighted against light sampling where that samples
             * it (constant emission), in full where it cannot (a textured one) */
            float w = 1.0f;
            int32_t l = rs_scene_prim_light(sc, v.prim);
            if (it->sampling == RS_SAMPLING_MIS && !(ps->flags & RS_PATH_SPECULAR) && l >= 0) {
                float pick = rs_light_sampler_pmf(sc, it->light_sampler, (uint32_t)l, r.o);
                w = rs_power_heuristic(ps->bsdf_pdf,
                                       rs_light_pdf_hit_pick(sc, (uint32_t)l, pick, r.o, r.time,
                                                             r.d, h->t, v.ng));
            }
            ps->radiance = rs_v3_add(ps->radiance, rs_v3_scale(rs_v3_mul(beta, v.m->emission), w));
        }
    }
    /* The segment after this vertex would be number bounce + 1. */
    if (bounce + 1 >= it->max_depth)
        return out;
    v.front = rs_v3_dot(v.ng, r.d) < 0.0f;
    /* a sign, not a branch: which side a ray meets is unpredictable (a wall's winding), and
     * x * -1 is -x exactly */
    v.n_geo = rs_v3_scale(v.ng, v.front ? 1.0f : -1.0f);
    v.wo = rs_v3_neg(r.d);
    v.n = rs_shading_normal(sc, v.prim, h->u, h->v, v.n_geo, v.wo);
    if (v.m->type >= RS_MAT_CONDUCTOR && v.m->normal_tex != RS_NO_TEXTURE)
        v.n = rs_normal_mapped(sc, v.m, v.prim, h->u, h->v, v.x, v.n, v.front, v.wo, fw);
    v.albedo = rs_surface_albedo(sc, v.m, v.prim, h->u, h->v, v.x, v.ng, fw);
    rb = pre ? pre[0] : rs_path_rand(it, pixel, sample, bounce, RS_DIM_BSDF);

    if (rs_material_is_delta(v.m)) {
        if (!rs_shade_delta(&v, rb, &beta, &wi))
            return out;
        specular = 1;
    } else {
        rs_rng_f4 rl = pre ? pre[1] : rs_path_rand(it, pixel, sample, bounce, RS_DIM_LIGHT);
        v.origin = rs_spawn_origin(v.x, v.err, v.n_geo);
        if (it->sampling == RS_SAMPLING_MIS && rs_scene_has_lights(sc))
            out = rs_shade_next_event(sc, &v, &r, rl, beta, ps, shadow, RS_LIGHTS_ALL,
                                      it->light_sampler);
        else if (it->sampling == RS_SAMPLING_MIXTURE && sc->n_lights > sc->n_area_lights)
            /* the mixture cannot draw a delta light's direction: next-event estimation does,
             * with the same numbers (the mixture's light half uses them only when it picks the
             * light side, and independently of this shadow ray's outcome) */
            out = rs_shade_next_event(sc, &v, &r, rl, beta, ps, shadow, RS_LIGHTS_DELTA,
                                      RS_LIGHT_SAMPLER_POWER);
        if (!rs_shade_direction(it, &v, &r, rb, rl, &beta, &wi, &pdf))
            return out;
        if (!(rs_v3_dot(wi, v.n_geo) > 0.0f)) {
            /* below the real surface: through it for a transmitting material (on the same side
             * of the shading surface too), else a shading-normal artefact that carries nothing */
            if (!rs_vertex_side_ok(&v, wi, rs_v3_dot(wi, v.n), 1))
                return out;
            v.origin = rs_vertex_far_origin(&v);
        }
    }
    /* Russian roulette, then the next segment.  The survival probability follows the path's
     * throughput before this vertex times what the surface reflects on average, not the sampled
     * direction's f cos / pdf: under the mixture pdf a direction toward a small light has a large
     * pdf and so a small f cos / pdf, and a q taken from it killed most of the very paths about
     * to reach the light (and weighted the survivors up by 1 / q): 2.85x the per-sample standard
     * deviation of the same estimator without roulette (docs/sampling.md). */
    if (bounce + 1 >= it->rr_depth) {
        float q = rs_roulette_survival(ps->throughput, v.m, v.albedo);
        if (!(rb.v[3] < q))
            return out;
        beta = rs_v3_scale(beta, 1.0f / q);
    }
    if (rs_v3_is_zero(beta) || !(rs_v3_max_comp(beta) > 0.0f))
        return out;
    next->o = v.origin;
    next->d = wi;
    next->tmin = 0.0f;
    next->tmax = FLT_MAX;
    next->time = r.time;
    ps->throughput = beta;
    ps->bsdf_pdf = pdf;
    ps->env_pdf = sc->env_uniform && !specular ? sc->env_pick * rs_env_pdf_at(sc, v.n, wi) : 0.0f;
    ps->flags = (uint8_t)((ps->flags & RS_PATH_NEGATIVE) | (specular ? RS_PATH_SPECULAR : 0u));
    return out | RS_SHADE_NEXT;
}

/* Rays a megakernel traced. */
typedef struct rs_path_counts {
    uint64_t closest, shadow;
    uint32_t max_bounce;
} rs_path_counts;

/* One path of a megakernel between its traversals (the thesis's recursive radiance(),
 * unrolled).  Shading owns the path; the device owns the loop and its traversal:
 *
 *     rs_path p;
 *     rs_path_start(it, pixel, sample, &p);
 *     for (;;) {
 *         closest hit of p.ray -> h;                        (count closest, max_bounce = p.bounce)
 *         made = rs_path_step(it, &p, &h);
 *         if ((made & RS_SHADE_SHADOW) && !occluded(p.shadow)) (count shadow)
 *             rs_path_unoccluded(&p);
 *         if (!(made & RS_SHADE_NEXT)) break;
 *     }
 *     radiance: rs_path_result(p.ps.radiance, p.ps.flags)
 *
 * Each vertex is shaded as the wavefront shades it and each shadow ray resolved before the next
 * segment, so the radiance is the wavefront's bit for bit (on the same compiler). */
typedef struct rs_path {
    uint32_t pixel, sample;
    uint32_t bounce; /* the segment p.ray is: 0 for the camera ray */
    rs_path_state ps;
    rs_ray ray;    /* the segment to trace next */
    rs_ray shadow; /* valid where rs_path_step returned RS_SHADE_SHADOW */
} rs_path;

/* Path (pixel, sample): its camera ray in p->ray, its state reset. */
RS_HD void rs_path_start(const rs_render_consts *it, uint32_t pixel, uint32_t sample, rs_path *p)
{
    p->pixel = pixel;
    p->sample = sample;
    p->bounce = 0;
    p->ray = rs_path_begin_at(it, pixel, sample, NULL, &p->ps);
    p->shadow = p->ray; /* set by rs_path_step where its flags say: this quiets gcc */
}

/* Shades h, the closest hit of p->ray: returns rs_path_shade_at's RS_SHADE_* flags.  With
 * RS_SHADE_SHADOW, p->shadow is to be tested (rs_path_unoccluded if nothing is in the way);
 * with RS_SHADE_NEXT, p->ray is the next segment and p->bounce its number; without it the path
 * has ended and p->ps.radiance is its radiance (once a pending shadow ray is resolved). */
RS_HD uint32_t rs_path_step(const rs_render_consts *it, rs_path *p, const rs_hit *h)
{
    rs_ray next = p->ray;
    uint32_t made = rs_path_shade_at(it, p->pixel, p->sample, p->bounce, NULL, &p->ray, h, &p->ps,
                                     &next, &p->shadow);
    if (made & RS_SHADE_NEXT) {
        p->ray = next;
        ++p->bounce;
    }
    return made;
}

/* p->shadow reached its light: the light's contribution is added. */
RS_HD void rs_path_unoccluded(rs_path *p)
{
    p->ps.radiance = rs_v3_add(p->ps.radiance, p->ps.pending);
}

#endif
