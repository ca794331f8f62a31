/* scenes/scene_finalize.c — rs_scene_finalize (scenes/scene.h): the checks and tables that turn a
 * scene the loaders filled through rs_scene_add_* into one the renderer reads, as a list of named
 * steps: check_geometry, number_instances, check_materials, build_masks, build_lights,
 * place_environment (the map's distribution, scenes/scene_env.h), the mip pyramids, then the
 * light BVH (scenes/light_bvh.h).  Apart from scene.c so that the scene's own code (creating,
 * adding, destroying) does not include the builders that read the scene: the include graph runs
 * one way, scene_finalize -> light_bvh, scene_env -> scene. */
#include "scenes/scene.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "scenes/light_bvh.h"
#include "scenes/scene_env.h"

static float luminance(rs_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

static float prim_area(const rs_scene *s, uint32_t prim)
{
    if (prim < s->n_spheres) {
        float r = s->spheres[prim].radius;
        return 4.0f * 3.14159265358979f * r * r;
    }
    prim -= s->n_spheres;
    if (prim < s->n_quads)
        return rs_v3_length(rs_v3_cross(s->quads[prim].u, s->quads[prim].v));
    prim -= s->n_quads;
    {
        const rs_tri *t = &s->tris[prim];
        return 0.5f * rs_v3_length(rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0)));
    }
}

static int within(rs_vec3 p, float lim)
{
    return fabsf(p.x) <= lim && fabsf(p.y) <= lim && fabsf(p.z) <= lim;
}

/* Refuses part `part` number `index` with a message; the reader can name it as its file does. */
static rs_status refuse_part(rs_scene *s, uint32_t part, uint32_t index, const char *what)
{
    static const char *const k_names[] = {"",         "sphere",          "quad",
                                          "triangle", "instance",        "material",
                                          "light",    "environment map", "camera"};
    s->bad_part = part;
    s->bad_index = index;
    if (part == RS_PART_ENVIRONMENT || part == RS_PART_CAMERA)
        return rs_error_set(RS_ERR_ARG, "%s: %s", k_names[part], what);
    return rs_error_set(RS_ERR_ARG, "%s %u: %s", k_names[part], index, what);
}

/* The ranges of scene.h (RS_SCENE_MAX_COORD, RS_SCENE_MAX_RADIANCE). */
static rs_status check_ranges(rs_scene *s)
{
    const float lim = RS_SCENE_MAX_COORD, most = RS_SCENE_MAX_RADIANCE;
    char why[160];
    uint32_t i;
    snprintf(why, sizeof why,
             "a point beyond +-%.0e, where the intersection tests' float "
             "arithmetic no longer holds (scale the scene down)",
             (double)lim);
    for (i = 0; i < s->n_spheres; ++i) {
        rs_vec3 c = s->spheres[i].center, r = rs_v3_splat(s->spheres[i].radius);
        rs_vec3 e = s->sphere_motion ? rs_v3_add(c, s->sphere_motion[i]) : c;
        if (!within(rs_v3_add(c, r), lim) || !within(rs_v3_sub(c, r), lim) ||
            !within(rs_v3_add(e, r), lim) || !within(rs_v3_sub(e, r), lim))
            return refuse_part(s, RS_PART_SPHERE, i, why);
    }
    for (i = 0; i < s->n_quads; ++i) {
        const rs_quad *q = &s->quads[i];
        if (!within(q->q, lim) || !within(rs_v3_add(q->q, q->u), lim) ||
            !within(rs_v3_add(q->q, q->v), lim) ||
            !within(rs_v3_add(rs_v3_add(q->q, q->u), q->v), lim))
            return refuse_part(s, RS_PART_QUAD, i, why);
    }
    for (i = 0; i < s->n_tris; ++i)
        if (!within(s->tris[i].v0, lim) || !within(s->tris[i].v1, lim) ||
            !within(s->tris[i].v2, lim))
            return refuse_part(s, RS_PART_TRIANGLE, i, why);
    for (i = 0; i < s->n_instances; ++i)
        if (!within(s->instances[i].box.lo, lim) || !within(s->instances[i].box.hi, lim))
            return refuse_part(s, RS_PART_INSTANCE, i, why);
    if (!within(s->camera.from, lim)) /* the rays' origin */
        return refuse_part(s, RS_PART_CAMERA, 0, why);
    snprintf(why, sizeof why,
             "above %.0e, more than the film holds (a sample beyond 2^48 "
             "would be dropped)",
             (double)most);
    for (i = 0; i < s->n_materials; ++i)
        if (rs_v3_max_comp(s->materials[i].emission) > most) {
            char w[200];
            snprintf(w, sizeof w, "emission %g %s",
                     (double)rs_v3_max_comp(s->materials[i].emission), why);
            return refuse_part(s, RS_PART_MATERIAL, i, w);
        }
    for (i = 0; i < s->n_punctuals; ++i) {
        const rs_punctual *p = &s->punctuals[i];
        char w[200];
        if (rs_v3_max_comp(p->intensity) > most) {
            snprintf(w, sizeof w, "intensity %g %s", (double)rs_v3_max_comp(p->intensity), why);
            return refuse_part(s, RS_PART_LIGHT, i, w);
        }
        if (p->type != RS_PUNCTUAL_DIRECTIONAL && !within(p->pos, lim)) {
            snprintf(w, sizeof w, "a position beyond +-%.0e (scale the scene down)", (double)lim);
            return refuse_part(s, RS_PART_LIGHT, i, w);
        }
    }
    if (s->env_image != RS_NO_TEXTURE && s->env_image < s->n_images) {
        const rs_image *im = &s->images[s->env_image];
        float top = 0, sc = rs_v3_max_comp(s->env_scale);
        size_t k, n = (size_t)im->width * im->height * 3;
        for (k = 0; k < n; ++k)
            if (im->rgb[k] > top)
                top = im->rgb[k];
        if ((double)top * sc > most) {
            char w[240];
            snprintf(w, sizeof w, "its brightest texel times the scale is %g, %s", (double)top * sc,
                     why);
            return refuse_part(s, RS_PART_ENVIRONMENT, 0, w);
        }
    }
    return RS_OK;
}

/* Image i's mip pyramid (docs/textures.md): the levels below level 0, each from the one above
 * by core/image_io.h's rs_image_downsample (OpenImageIO's resize, a box one texel of the new
 * level wide), max(1, floor(w / 2)) x max(1, floor(h / 2)) down to 1x1, stored after level 0 in
 * one block so that a device copy stays one buffer.  An image that has them already is left. */
static rs_status build_pyramid(rs_image *im)
{
    uint32_t levels = 1, w = im->width, h = im->height, k;
    size_t total, off = 0;
    float *rgb;
    rs_status st;
    if (im->levels > 1)
        return RS_OK;
    while (w > 1 || h > 1) {
        w = w > 1 ? w / 2 : 1;
        h = h > 1 ? h / 2 : 1;
        ++levels;
    }
    im->levels = 1;
    if (levels == 1)
        return RS_OK;
    total = rs_image_levels_floats(im->width, im->height, levels);
    rgb = (float *)rs_alloc(total, sizeof *rgb);
    if (!rgb)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the mip levels of a %ux%u image",
                            im->width, im->height);
    memcpy(rgb, im->rgb, 3 * (size_t)im->width * im->height * sizeof *rgb);
    w = im->width;
    h = im->height;
    for (k = 1; k < levels; ++k) {
        uint32_t w2 = w > 1 ? w / 2 : 1, h2 = h > 1 ? h / 2 : 1;
        size_t next = off + 3 * (size_t)w * h;
        if ((st = rs_image_downsample(rgb + off, w, h, rgb + next, w2, h2)) != RS_OK) {
            rs_free(rgb);
            return st;
        }
        off = next;
        w = w2;
        h = h2;
    }
    rs_free(im->rgb);
    im->rgb = rgb;
    im->levels = levels;
    return RS_OK;
}

static _Thread_local struct {
    int light_bvh, pyramids;
} g_extras = {1, 1}; /* per thread: the library's renders on several threads each set theirs */

void rs_scene_set_extras(int light_bvh, int pyramids)
{
    g_extras.light_bvh = light_bvh != 0;
    g_extras.pyramids = pyramids != 0;
}

/* Pyramids for every image an image texture uses (an image used only as the environment map
 * keeps one level: shading/envmap.h samples its texels).  A build without OpenImageIO has no
 * resampler: its images keep one level, and their lookups stay bilinear. */
static rs_status build_pyramids(rs_scene *s)
{
    uint32_t i;
    rs_status st;
    if (!rs_image_can_downsample() || !g_extras.pyramids)
        return RS_OK;
    for (i = 0; i < s->n_textures; ++i)
        if (s->textures[i].type == RS_TEX_IMAGE && s->textures[i].image < s->n_images &&
            (st = build_pyramid(&s->images[s->textures[i].image])) != RS_OK)
            return st;
    return RS_OK;
}

/* ---- rs_scene_finalize's steps, in order ---- */

/* Every primitive's numbers finite and its shape not degenerate; a prototype triangle's material
 * exists and emits nothing. */
static rs_status check_geometry(rs_scene *s)
{
    uint32_t i;
    for (i = 0; i < s->n_spheres; ++i)
        if (!rs_v3_is_finite(s->spheres[i].center) || !isfinite(s->spheres[i].radius) ||
            !(s->spheres[i].radius > 0.0f))
            return refuse_part(s, RS_PART_SPHERE, i, "non-finite centre or radius <= 0");
    for (i = 0; i < s->n_quads; ++i)
        if (!rs_v3_is_finite(s->quads[i].q) || !rs_v3_is_finite(s->quads[i].w) ||
            rs_v3_is_zero(rs_v3_cross(s->quads[i].u, s->quads[i].v)))
            return refuse_part(s, RS_PART_QUAD, i, "non-finite or degenerate (zero area)");
    for (i = 0; i < s->n_tris; ++i)
        if (!rs_v3_is_finite(s->tris[i].v0) || !rs_v3_is_finite(s->tris[i].v1) ||
            !rs_v3_is_finite(s->tris[i].v2))
            return refuse_part(s, RS_PART_TRIANGLE, i, "non-finite vertex");
    for (i = 0; i < s->n_inst_tris; ++i) {
        const rs_material *m;
        if (!rs_v3_is_finite(s->inst_tris[i].v0) || !rs_v3_is_finite(s->inst_tris[i].v1) ||
            !rs_v3_is_finite(s->inst_tris[i].v2))
            return rs_error_set(RS_ERR_ARG, "prototype triangle %u: non-finite vertex", i);
        if (s->inst_tri_mat[i] >= s->n_materials)
            return rs_error_set(RS_ERR_ARG, "prototype triangle %u: no material %u", i,
                                s->inst_tri_mat[i]);
        m = &s->materials[s->inst_tri_mat[i]];
        if (rs_material_is_light(m))
            return rs_error_set(RS_ERR_ARG,
                                "prototype triangle %u emits light: emitters are "
                                "copied, never instanced",
                                i);
    }
    s->bad_part = RS_PART_NONE;
    return RS_OK;
}

/* Instances' triangles are numbered after the scene's own n primitives, in instance order. */
static rs_status number_instances(rs_scene *s, uint32_t n)
{
    uint64_t base = (uint64_t)n;
    uint32_t i;
    for (i = 0; i < s->n_instances; ++i) {
        s->instances[i].prim_base = (uint32_t)base;
        base += s->instances[i].n_tris;
    }
    if (base > 0x7fffffffu)
        return rs_error_set(RS_ERR_ARG, "the scene has %llu primitives, at most 2^31 - 1",
                            (unsigned long long)base);
    return RS_OK;
}

/* Every material's parameters in their ranges. */
static rs_status check_materials(rs_scene *s)
{
    uint32_t i;
    for (i = 0; i < s->n_materials; ++i) {
        const rs_material *m = &s->materials[i];
        if (m->type > RS_MAT_TYPE_LAST)
            return rs_error_set(RS_ERR_ARG, "material %u: unknown type %u", i, m->type);
        if ((m->type == RS_MAT_CONDUCTOR || m->type == RS_MAT_ROUGH_DIELECTRIC ||
             m->type == RS_MAT_PBR) &&
            !(m->alpha >= 0.0f && m->alpha <= 1.0f && m->metallic >= 0.0f && m->metallic <= 1.0f))
            return refuse_part(s, RS_PART_MATERIAL, i, "alpha and metallic must be in [0, 1]");
        if (m->type == RS_MAT_CONDUCTOR && !(m->flags & RS_MAT_F0_COLOR) &&
            !(m->eta.x > 0 && m->eta.y > 0 && m->eta.z > 0 && m->k.x >= 0 && m->k.y >= 0 &&
              m->k.z >= 0 && rs_v3_is_finite(m->eta) && rs_v3_is_finite(m->k)))
            return refuse_part(s, RS_PART_MATERIAL, i, "a conductor's eta must be > 0, k >= 0");
        if (m->type == RS_MAT_ROUGH_DIELECTRIC && !(m->ior > 0.0f && isfinite(m->ior)))
            return refuse_part(s, RS_PART_MATERIAL, i, "index of refraction must be > 0");
        if (!rs_v3_is_finite(m->albedo) || !rs_v3_is_finite(m->emission) ||
            !rs_v3_is_finite(m->specular) || m->albedo.x < 0 || m->albedo.y < 0 ||
            m->albedo.z < 0 || m->emission.x < 0 || m->emission.y < 0 || m->emission.z < 0)
            return refuse_part(s, RS_PART_MATERIAL, i, "colours must be finite and >= 0");
        if (m->type == RS_MAT_DIELECTRIC && !(m->ior > 0.0f && isfinite(m->ior)))
            return refuse_part(s, RS_PART_MATERIAL, i, "index of refraction must be > 0");
        if (m->type == RS_MAT_PHONG && !(m->exponent >= 0.0f && isfinite(m->exponent)))
            return refuse_part(s, RS_PART_MATERIAL, i, "Phong exponent must be >= 0");
        if (m->type == RS_MAT_METAL && !(m->fuzz >= 0.0f && m->fuzz <= 1.0f))
            return refuse_part(s, RS_PART_MATERIAL, i, "metal fuzz must be in [0, 1]");
        if (m->type == RS_MAT_DISNEY_DIFFUSE && !(m->roughness >= 0.0f && m->roughness <= 1.0f))
            return refuse_part(s, RS_PART_MATERIAL, i, "roughness must be in [0, 1]");
        if (m->alpha_mask > s->n_masks)
            return rs_error_set(RS_ERR_ARG, "material %u: no alpha mask %u", i, m->alpha_mask);
    }
    return RS_OK;
}

/* The triangles' cut-outs, for traversal (none on a prototype's triangles). */
static rs_status build_masks(rs_scene *s)
{
    uint32_t i;
    int any = 0;
    rs_free(s->tri_mask);
    s->tri_mask = NULL;
    for (i = 0; i < s->n_tris && !any; ++i)
        any = s->materials[s->tri_mat[i]].alpha_mask != 0;
    if (any) {
        s->tri_mask = (uint32_t *)rs_alloc(s->n_tris, sizeof *s->tri_mask);
        if (!s->tri_mask)
            return rs_error_set(RS_ERR_NOMEM, "out of memory preparing alpha masks");
        for (i = 0; i < s->n_tris; ++i)
            s->tri_mask[i] = s->materials[s->tri_mat[i]].alpha_mask;
    }
    for (i = 0; i < s->n_inst_tris; ++i)
        if (s->materials[s->inst_tri_mat[i]].alpha_mask)
            return rs_error_set(RS_ERR_ARG,
                                "prototype triangle %u has an alpha cut-out: "
                                "cut-outs are copied, never instanced",
                                i);
    return RS_OK;
}

/* The light table over the scene's n own primitives (every one with an emissive material, by
 * area: spheres sampled by the cone they subtend, quads and triangles by area) and its punctual
 * lights, each picked in proportion to its power: s->lights, light_cdf, n_area_lights (n_lights
 * is set by the caller from *n_lights); *total, their summed power.  s->prim_light (allocated by
 * the caller) maps a primitive to its light or -1. */
/* A punctual light's power: 4 pi I for a point, the cone's solid angle (to the middle of the
 * falloff) times I for a spot, pi R^2 E for a directional light over a scene of radius R. */
static double punctual_power(const rs_punctual *p, double radius)
{
    double lum = luminance(p->intensity);
    if (p->type == RS_PUNCTUAL_POINT)
        return 4.0 * 3.14159265358979 * lum;
    if (p->type == RS_PUNCTUAL_SPOT)
        return 2.0 * 3.14159265358979 * (1.0 - 0.5 * (p->cos_inner + p->cos_outer)) * lum;
    return 3.14159265358979 * radius * radius * lum;
}

static rs_status build_lights(rs_scene *s, uint32_t n, uint32_t *n_lights, double *total)
{
    uint32_t i, nl = 0;
    double acc = 0.0;
    *total = 0.0;
    for (i = 0; i < n; ++i) {
        const rs_material *m = rs_scene_prim_material(s, i);
        s->prim_light[i] = -1;
        /* a glTF material's constant emission is sampled too (two-sided); a textured one is
         * left to the paths that hit it */
        if (rs_material_is_light(m))
            s->prim_light[i] = (int32_t)nl++;
    }
    s->n_area_lights = nl;
    nl += s->n_punctuals;
    *n_lights = nl;
    if (nl == 0)
        return RS_OK;
    {
        double radius = s->n_punctuals ? rs_scene_bound_radius(s) : 1.0;
        uint64_t need = (uint64_t)nl * (sizeof *s->lights + sizeof *s->light_cdf);
        uint64_t budget = rs_memory_budget();
        if (budget && need > budget) /* before the allocation: a small file can copy millions */
            return rs_error_set(RS_ERR_NOMEM,
                                "%u lights take %.0f MB of light tables, more than the %.0f MB "
                                "this process may use",
                                nl, (double)need / 1048576.0, (double)budget / 1048576.0);
        s->lights = (rs_light *)rs_alloc(nl, sizeof *s->lights);
        s->light_cdf = (float *)rs_alloc(nl + 1, sizeof *s->light_cdf);
        if (!s->lights || !s->light_cdf)
            return rs_error_set(RS_ERR_NOMEM, "out of memory preparing %u lights", nl);
        for (i = 0; i < s->n_punctuals; ++i) {
            rs_light *lt = &s->lights[s->n_area_lights + i];
            double pw = punctual_power(&s->punctuals[i], radius);
            lt->prim = RS_LIGHT_PUNCTUAL | i;
            lt->area = 0.0f;
            lt->power = (float)pw;
            *total += pw;
        }
    }
    for (i = 0; i < n && s->n_area_lights; ++i) {
        int32_t l = s->prim_light[i];
        const rs_material *m;
        if (l < 0)
            continue;
        m = rs_scene_prim_material(s, i);
        s->lights[l].prim = i;
        s->lights[l].area = prim_area(s, i);
        s->lights[l].power = 3.14159265f * s->lights[l].area * luminance(m->emission) *
                             ((m->flags & RS_MAT_TWO_SIDED) || m->type == RS_MAT_PBR ? 2.0f : 1.0f);
        *total += s->lights[l].power;
    }
    s->light_cdf[0] = 0.0f;
    for (i = 0; i < nl; ++i) {
        s->lights[i].pick_pdf = (float)(s->lights[i].power / *total);
        acc += s->lights[i].power;
        s->light_cdf[i + 1] = (float)(acc / *total);
    }
    s->light_cdf[nl] = 1.0f;
    if (!(*total > 0)) {
        /* black lights only: nothing to pick (never a 0/0 pick probability) */
        rs_free(s->lights);
        rs_free(s->light_cdf);
        s->lights = NULL;
        s->light_cdf = NULL;
        for (i = 0; i < n; ++i)
            s->prim_light[i] = -1;
        *n_lights = 0;
        s->n_area_lights = 0;
    }
    return RS_OK;
}

/* The environment map's distribution; light sampling picks it or an emitter in proportion to
 * their powers (`total`: the emitters' and punctual lights'), the map's kept within [0.1, 0.9]
 * when both are there (a map seen through a window is mostly occluded; emitters inside a sky's
 * dome may be small). */
static rs_status place_environment(rs_scene *s, double total)
{
    double env_power = 0;
    uint32_t i, nl = s->n_lights;
    rs_status st = rs_scene_env_build(s, &env_power);
    if (st != RS_OK)
        return st;
    if (env_power > 0) {
        double pick = nl ? env_power / (env_power + total) : 1.0;
        if (nl)
            pick = pick < 0.1 ? 0.1 : pick > 0.9 ? 0.9 : pick;
        s->env_pick = (float)pick;
        for (i = 0; i < nl; ++i)
            s->lights[i].pick_pdf *= 1.0f - s->env_pick;
    }
    /* what the mixture's light half may pick: the map and the emitters, not the delta lights */
    s->area_mass = s->n_lights > s->n_area_lights
                       ? s->env_pick + (1.0f - s->env_pick) * s->light_cdf[s->n_area_lights]
                       : 1.0f;
    return RS_OK;
}

rs_status rs_scene_finalize(rs_scene *s)
{
    uint32_t n = rs_scene_prim_count(s), nl = 0;
    double total = 0.0;
    rs_status st;
    if ((st = check_geometry(s)) != RS_OK || (st = check_ranges(s)) != RS_OK ||
        (st = build_pyramids(s)) != RS_OK || (st = number_instances(s, n)) != RS_OK)
        return st;
    rs_free(s->lights);
    rs_free(s->light_cdf);
    rs_free(s->prim_light);
    s->lights = NULL;
    s->light_cdf = NULL;
    s->n_lights = 0;
    s->prim_light = (int32_t *)rs_alloc(n ? n : 1, sizeof *s->prim_light);
    if (!s->prim_light)
        return rs_error_set(RS_ERR_NOMEM, "out of memory preparing lights");
    if ((st = check_materials(s)) != RS_OK || (st = build_masks(s)) != RS_OK ||
        (st = build_lights(s, n, &nl, &total)) != RS_OK)
        return st;
    s->n_lights = nl;
    if ((st = place_environment(s, total)) != RS_OK)
        return st;
    /* --light-sampler bvh (scenes/light_bvh.h), where the render may use it */
    s->light_bvh_built = 0;
    if (g_extras.light_bvh && (st = rs_scene_build_light_bvh(s)) != RS_OK)
        return st;
    s->finalized = 1;
    return RS_OK;
}
