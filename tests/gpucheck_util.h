/* tests/gpucheck_util.h — what render_gpucheck_test (any machine) and gpu_trace_test (a CUDA
 * device) share about builtin:gpucheck: the render settings each compares over, the check that
 * the scene still holds every feature it exists for, and a bitwise image comparison that says
 * where two images first differ.  Test-only helper. */
#ifndef RS_TESTS_GPUCHECK_UTIL_H
#define RS_TESTS_GPUCHECK_UTIL_H

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "render_util.h"

#define GC_W   64
#define GC_H   40
#define GC_SPP 8

/* The sampling modes (MIS, the mixture, BSDF only, uniform: each shades through other
 * functions) with the three samplers between them. */
typedef struct gc_case {
    const char *name;
    rs_sampling sampling;
    rs_sampler sampler;
} gc_case;

static const gc_case gc_cases[] = {
    {"mis/sobol", RS_SAMPLING_MIS, RS_SAMPLER_SOBOL},
    {"mixture/independent", RS_SAMPLING_MIXTURE, RS_SAMPLER_INDEPENDENT},
    {"bsdf/zsobol", RS_SAMPLING_BSDF, RS_SAMPLER_ZSOBOL},
    {"uniform/sobol", RS_SAMPLING_UNIFORM, RS_SAMPLER_SOBOL},
};
#define GC_N_CASES ((int)(sizeof gc_cases / sizeof gc_cases[0]))

/* builtin:many-lights with the light BVH picking the lights (48x48, 4 spp, 2 threads): what the
 * device comparisons render besides gpucheck. */
static inline rt_args gc_many_lights_bvh_args(void)
{
    rt_args a = rt_defaults("many-lights", 48, 4);
    a.threads = 2;
    a.sampler = RS_SAMPLER_SOBOL;
    a.light_sampler = RS_LIGHT_SAMPLER_BVH;
    return a;
}

/* Adaptive sampling on the Cornell box (40x40, at most 32 spp, 2 threads): plans over some
 * pixels; its statistics into *st. */
static inline rt_args gc_adaptive_args(rs_adaptive_stats *st)
{
    rt_args a = rt_defaults("cornell", 40, 32);
    a.threads = 2;
    a.sampler = RS_SAMPLER_SOBOL;
    a.adaptive.threshold = 0.05f;
    a.adaptive.min_spp = 4;
    a.adaptive_out = st;
    return a;
}

static inline rt_args gc_args(const gc_case *c)
{
    rt_args a = rt_defaults("gpucheck", GC_W, GC_SPP);
    a.height = GC_H;
    a.threads = 2;
    a.sampling = c->sampling;
    a.sampler = c->sampler;
    return a;
}

/* NULL if scene s (builtin:gpucheck, finalized) holds every feature the GPU check is for; else
 * the first one missing. */
static inline const char *gc_scene_missing(const rs_scene *s)
{
    int mat[RS_MAT_TYPE_LAST + 1], tex[4], punct[3], mirrored = 0, oblique = 0, normal_map = 0,
                                                     mr_map = 0, emit_tex = 0, masked = 0;
    uint32_t i;
    memset(mat, 0, sizeof mat);
    memset(tex, 0, sizeof tex);
    memset(punct, 0, sizeof punct);
    for (i = 0; i < s->n_materials; ++i) {
        const rs_material *m = &s->materials[i];
        mat[m->type] = 1;
        normal_map |= m->normal_tex != RS_NO_TEXTURE;
        mr_map |= m->mr_tex != RS_NO_TEXTURE;
        emit_tex |= m->emission_tex != RS_NO_TEXTURE;
        masked |= m->alpha_mask != 0;
    }
    for (i = 0; i <= RS_MAT_TYPE_LAST; ++i)
        if (!mat[i])
            return "a material type";
    for (i = 0; i < s->n_textures; ++i)
        tex[s->textures[i].type] = 1;
    if (!tex[RS_TEX_SOLID] || !tex[RS_TEX_CHECKER] || !tex[RS_TEX_STRIPES] || !tex[RS_TEX_IMAGE])
        return "a texture type";
    for (i = 0; i < s->n_punctuals; ++i)
        punct[s->punctuals[i].type] = 1;
    if (!punct[RS_PUNCTUAL_POINT] || !punct[RS_PUNCTUAL_SPOT] || !punct[RS_PUNCTUAL_DIRECTIONAL])
        return "a point, spot or directional light";
    for (i = 0; i < s->n_instances; ++i) {
        const double *m = s->instances[i].m;
        mirrored |= s->instances[i].mirror != 0;
        /* an off-diagonal linear part: not a scale and translation only */
        oblique |= m[1] != 0 && m[4] != 0 && m[6] != 0;
    }
    if (!mirrored || !oblique)
        return "a mirrored and an obliquely turned instance";
    if (!s->tri_uv || !s->tri_normal || !s->inst_tri_uv || !s->inst_tri_normal)
        return "triangles (own and instanced) with UVs and vertex normals";
    if (!normal_map || !mr_map || !emit_tex)
        return "a pbr material with a normal map, a metallic-roughness map, a textured emission";
    if (!masked || !s->tri_mask || s->n_masks == 0)
        return "an alpha cut-out";
    if (s->env_image == RS_NO_TEXTURE || s->env_uniform || !s->env_marg_cdf)
        return "an importance-sampled (not uniform) environment map";
    if (!s->sphere_motion || !(s->camera.shutter_close > s->camera.shutter_open))
        return "a moving sphere under an open shutter";
    if (!(s->camera.aperture > 0.0f))
        return "a thin lens";
    if (s->n_quads == 0 || s->n_spheres == 0 || s->n_tris == 0)
        return "spheres, quads and triangles";
    if (s->n_area_lights < 3)
        return "sphere, quad and triangle emitters";
    return NULL;
}

/* Pixels (of w * h RGB floats) where a and b differ in any bit; prints the first one. */
static inline uint32_t gc_diff_pixels(const char *what, const float *a, const float *b, uint32_t w,
                                      uint32_t h)
{
    uint32_t i, n = 0;
    for (i = 0; i < w * h; ++i)
        if (memcmp(&a[3 * i], &b[3 * i], 3 * sizeof(float)) != 0 && n++ == 0)
            printf("%s: first differing pixel (%u, %u): %.9g %.9g %.9g vs %.9g %.9g %.9g\n", what,
                   i % w, i / w, a[3 * i], a[3 * i + 1], a[3 * i + 2], b[3 * i], b[3 * i + 1],
                   b[3 * i + 2]);
    printf("%s: %u of %u pixels differ in any bit\n", what, n, w * h);
    return n;
}

/* 1 if every value is finite and >= 0 and their mean is above 0. */
static inline int gc_image_sane(const float *rgb, uint32_t w, uint32_t h)
{
    double sum = 0.0;
    uint32_t i;
    for (i = 0; i < 3 * w * h; ++i) {
        if (!isfinite(rgb[i]) || rgb[i] < 0.0f)
            return 0;
        sum += rgb[i];
    }
    return sum > 0.0;
}

#endif
