/* shading/aov.h — the auxiliary images (AOVs) written beside the beauty image as EXR layers:
 * the first hit's albedo, shading normal and distance, averaged over the pixel's first samples
 * (the very camera rays the render traced first), and the samples each pixel got.  What a
 * denoiser (Intel Open Image Denoise, OptiX) takes with the beauty image, and what a compositor
 * wants for depth.
 *
 * They are made in a pass of their own after the render, on host threads, with the host BVH:
 * camera rays and their first hits only, so a few percent of one sample's work.  Being a
 * function of the scene, the settings and the seed only, they are the same for any device set,
 * and for a render resumed from a checkpoint. */
#ifndef RS_SHADING_AOV_H
#define RS_SHADING_AOV_H

#include "accel/bvh_traverse.h"
#include "shading/path.h"

#define RS_AOV_ALBEDO  1u /* layer "albedo" (R, G, B): the first hit's reflectance, textured */
#define RS_AOV_NORMAL  2u /* "normal" (X, Y, Z): the shading normal, world space, toward the eye */
#define RS_AOV_DEPTH   4u /* "depth" (Z): distance from the camera to the first hit; inf: none */
#define RS_AOV_SAMPLES 8u /* "samples" (Y): the samples the pixel got */
#define RS_AOV_ALL     15u

/* Samples per pixel the albedo, normal and depth average over (at most the render's spp). */
#define RS_AOV_SPP 16u

/* What the first hit of camera ray r (hit h) gives: the material's albedo there (an emitter's
 * emission held to [0, 1]; the background's radiance, held likewise, for a miss), the shading
 * normal turned toward the ray's origin (zero for a miss), and the distance t |d| (a miss:
 * infinity). */
RS_HD void rs_path_aov(const rs_render_consts *it, const rs_ray *r, const rs_hit *h,
                       rs_vec3 *albedo, rs_vec3 *normal, float *depth)
{
    const rs_scene *sc = it->scene;
    rs_vec3 x, ng, n_geo, wo;
    const rs_material *m;
    float fw;
    if (h->prim == RS_NO_HIT) {
        rs_vec3 bg = rs_env_present(sc) ? rs_env_radiance(sc, r->d) : rs_scene_background(sc, r->d);
        *albedo = rs_v3(rs_fminf(bg.x, 1.0f), rs_fminf(bg.y, 1.0f), rs_fminf(bg.z, 1.0f));
        *normal = rs_v3_splat(0.0f);
        *depth = INFINITY;
        return;
    }
    m = rs_scene_prim_material(sc, h->prim);
    {
        rs_surface_point sp = rs_surface_at(sc, h->prim, r, h->t, h->u, h->v); /* as shading */
        x = sp.p;
        ng = sp.ng;
    }
    wo = rs_v3_neg(r->d);
    n_geo = rs_v3_dot(ng, r->d) < 0.0f ? ng : rs_v3_neg(ng);
    *depth = h->t * rs_v3_length(r->d);
    if (m->type == RS_MAT_DIFFUSE_LIGHT) {
        *albedo = rs_v3(rs_fminf(m->emission.x, 1.0f), rs_fminf(m->emission.y, 1.0f),
                        rs_fminf(m->emission.z, 1.0f));
        *normal = n_geo;
        return;
    }
    fw = rs_texture_footprint(it, m, x, ng); /* the lookups' footprint, as shading takes it */
    *normal = rs_shading_normal(sc, h->prim, h->u, h->v, n_geo, wo);
    if (m->type >= RS_MAT_CONDUCTOR && m->normal_tex != RS_NO_TEXTURE)
        *normal = rs_normal_mapped(sc, m, h->prim, h->u, h->v, x, *normal,
                                   rs_v3_dot(ng, r->d) < 0.0f, wo, fw);
    *albedo = rs_surface_albedo(sc, m, h->prim, h->u, h->v, x, ng, fw);
}

/* What the first vertex of a camera path adds to its pixel (rs_path_shade_at's share at bounce
 * 0, ps being rs_path_begin_at's state: its filter weight and sign included): the emission of
 * an emitter or a glTF emissive surface it hits, the background's radiance when it misses, zero
 * on anything else.  The path takes these unweighted by MIS (nothing could have sampled them
 * from the camera), so a render with max_depth 1 is exactly this, averaged (tests/
 * shading_aov_test.c). */
RS_HD rs_vec3 rs_path_first_emission(const rs_render_consts *it, const rs_ray *r, const rs_hit *h,
                                     const rs_path_state *ps)
{
    const rs_scene *sc = it->scene;
    rs_vec3 le = rs_v3_splat(0.0f);
    if (h->prim == RS_NO_HIT) {
        le = rs_env_present(sc) ? rs_env_radiance(sc, r->d) : rs_scene_background(sc, r->d);
    } else {
        const rs_material *m = rs_scene_prim_material(sc, h->prim);
        if (m->type == RS_MAT_DIFFUSE_LIGHT || m->type == RS_MAT_PBR) {
            rs_surface_point sp = rs_surface_at(sc, h->prim, r, h->t, h->u, h->v);
            rs_material local;
            if (m->type == RS_MAT_DIFFUSE_LIGHT) {
                le = rs_emitted(m, sp.ng, r->d);
            } else {
                if (m->mr_tex != RS_NO_TEXTURE || m->emission_tex != RS_NO_TEXTURE)
                    m = rs_surface_material(sc, m, h->prim, h->u, h->v, sp.p, sp.ng,
                                            rs_texture_footprint(it, m, sp.p, sp.ng), &local);
                le = m->emission;
            }
        }
    }
    return rs_path_result(rs_v3_mul(ps->throughput, le), ps->flags);
}

/* Camera samples per pixel for rs_aov_emission's better estimate where the direct emission has
 * an edge (an emitter's outline, the horizon against a sky). */
#define RS_AOV_EMISSION_SPP 256u

#ifdef __cplusplus
extern "C" {
#endif
/* The AOVs `which` (RS_AOV_* but SAMPLES) of the render whose constants are `it`, traced through
 * `bvh` over `g` (host arrays, attached: rs_bvh_attach) on `threads` host threads: each pixel's
 * first min(spp, RS_AOV_SPP) camera rays.  albedo and normal: 3 floats a pixel, depth: 1 (each
 * may be NULL when not asked for); row-major from the top-left. */
void rs_aov_render(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                   uint32_t spp, int threads, float *albedo, float *normal, float *depth);

/* The direct emission of a render (rs_path_first_emission: what the camera sees emitted, the
 * background included), per pixel, two ways (w*h*3 floats each, row-major from the top-left):
 *   e_render: the mean over the very samples the render took: samples 0 .. count[p]-1 of pixel p
 *     (count: the film's per-pixel counts; NULL: spp for every pixel).  Up to rounding, the share
 *     of the beauty image its camera rays' first hits added, so beauty - e_render is the light
 *     that arrived by reflection.
 *   e_fine: the same integral estimated better: where the direct emission has an edge within
 *     the filter's reach (a pixel's neighbourhood of radius ceil(width/2) + 1 holds samples that
 *     differ by more than 5% of its brightest), from RS_AOV_EMISSION_SPP Sobol camera samples of
 *     its own (fewer when edges cover much of the image: at most 64 a pixel on average; none
 *     when the render took as many); elsewhere e_render (a flat emitter, an empty background,
 *     geometry that emits nothing: the render's samples already agree).
 * Only camera rays and their first hits (with the host BVH, on `threads` host threads), as
 * rs_aov_render.  Returns how many pixels got the better estimate.  --denoise keeps both out of
 * the denoiser: core/denoise.h rs_denoise_split. */
size_t rs_aov_emission(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                       const uint32_t *count, uint32_t spp, int threads, float *e_render,
                       float *e_fine);
#ifdef __cplusplus
}
#endif

#endif
