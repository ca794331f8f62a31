/* shading/aov.h — the auxiliary images (AOVs) written beside the beauty image as EXR layers:
 * the first hit's albedo, shading normal and distance, what the camera sees emitted, averaged
 * over the pixel's samples, and the samples each pixel got.  What a denoiser (Intel Open Image
 * Denoise, OptiX) takes with the beauty image, and what a compositor wants for depth.
 *
 * They are written by the devices as they render, as Cycles' denoising passes: each path's
 * first vertex (rs_path_aux_at, on every device: the host's stages, the CPU's and the GPU's
 * wavefronts, the megakernels) records what its camera ray showed, and the film adds it to its
 * passes (shading/film.h) with the path's sample, in exact sums.  So they are the render's own
 * samples, the same bits on any device set, under mpirun and for a render resumed from a
 * checkpoint. */
#ifndef RS_SHADING_AOV_H
#define RS_SHADING_AOV_H

#include "accel/bvh_traverse.h"
#include "shading/path.h"

#define RS_AOV_ALBEDO  1u /* layer "albedo" (R, G, B): the first hit's reflectance, textured */
#define RS_AOV_NORMAL  2u /* "normal" (X, Y, Z): the shading normal, world space, toward the eye */
#define RS_AOV_DEPTH   4u /* "depth" (Z): distance from the camera to the first hit; inf: none */
#define RS_AOV_SAMPLES 8u /* "samples" (Y): the samples the pixel got */
#define RS_AOV_ALL     15u

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

/* What the camera ray r of a path (its state ps as rs_path_begin_at left it) showed at its first
 * hit h, for the film's passes: rs_path_aov and rs_path_first_emission together.  Every path
 * step's first vertex calls it where the render keeps passes (it->passes), on every device,
 * before shading moves the path on. */
RS_HD rs_path_aux rs_path_aux_at(const rs_render_consts *it, const rs_ray *r, const rs_hit *h,
                                 const rs_path_state *ps)
{
    rs_path_aux a;
    rs_path_aov(it, r, h, &a.albedo, &a.normal, &a.depth);
    a.emission = rs_path_first_emission(it, r, h, ps);
    return a;
}

/* Camera samples per pixel for rs_aov_refine's better estimate where the direct emission has
 * an edge (an emitter's outline, the horizon against a sky). */
#define RS_AOV_EMISSION_SPP 256u

#ifdef __cplusplus
extern "C" {
#endif
/* The direct emission's better estimate (--denoise keeps it out of the denoiser and adds this
 * back: core/denoise.h rs_denoise_split).  e_render: the emission pass of the render's film
 * (rs_film_resolve_passes: the mean over the very samples the render took, w*h*3 floats); into
 * e_fine (the same size) the same integral estimated better where the direct emission has an
 * edge within the filter's reach (a pixel's neighbourhood of radius ceil(width/2) + 1 whose
 * means differ by more than 5% of its brightest): from RS_AOV_EMISSION_SPP Sobol camera samples
 * of its own (fewer when edges cover much of the image: at most 64 a pixel on average; none
 * where the render took as many, count[p]); elsewhere e_render (a flat emitter, an empty
 * background, geometry that emits nothing: the render's samples already agree).  Camera rays
 * and their first hits only, through `bvh` over `g` (host arrays, attached: rs_bvh_attach) on
 * `threads` host threads: an estimate of its own, with numbers of its own, so the same for any
 * device set.  Returns how many pixels got the better estimate. */
size_t rs_aov_refine(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                     const uint32_t *count, int threads, const float *e_render, float *e_fine);
#ifdef __cplusplus
}
#endif

#endif
