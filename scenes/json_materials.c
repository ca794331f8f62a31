/* scenes/json_materials.c — textures and materials of a JSON scene (scenes/json_internal.h;
 * docs/scene-format.md): each definition read, checked and added with rs_scene_add_texture and
 * rs_scene_add_material, and an object's material found by name. */
#include "scenes/json_internal.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/try.h"

rs_status rs_json_read_texture(ctx *c, const cJSON *t, const char *path, const char *name)
{
    static const char *const k_solid[] = {"type", "color", NULL};
    static const char *const k_two[] = {"type", "a", "b", "scale", NULL};
    static const char *const k_image[] = {"type", "file", NULL};
    rs_texture tex;
    const char *type = "";
    uint32_t id;
    memset(&tex, 0, sizeof tex);
    if (!cJSON_IsObject(t))
        return FAIL(c, path, "expected an object");
    RS_TRY(rs_json_get_string(c, t, path, "type", &type));
    if (strcmp(type, "solid") == 0) {
        RS_TRY(rs_json_check_keys(c, t, path, k_solid));
        tex.type = RS_TEX_SOLID;
        RS_TRY(rs_json_get_reflectance(c, t, path, "color", 1, rs_v3(0, 0, 0), &tex.a));
    } else if (strcmp(type, "checker") == 0 || strcmp(type, "stripes") == 0) {
        RS_TRY(rs_json_check_keys(c, t, path, k_two));
        tex.type = type[0] == 'c' ? RS_TEX_CHECKER : RS_TEX_STRIPES;
        RS_TRY(rs_json_get_reflectance(c, t, path, "a", 1, rs_v3(0, 0, 0), &tex.a));
        RS_TRY(rs_json_get_reflectance(c, t, path, "b", 1, rs_v3(0, 0, 0), &tex.b));
        RS_TRY(rs_json_get_num(c, t, path, "scale", 0, type[0] == 'c' ? 1.0 : 10.0, 1e-6, 1e6,
                               &tex.scale));
    } else if (strcmp(type, "image") == 0) {
        const char *file = "";
        char full[1024];
        rs_status st;
        RS_TRY(rs_json_check_keys(c, t, path, k_image));
        RS_TRY(rs_json_get_string(c, t, path, "file", &file));
        rs_json_resolve_path(c, file, full, sizeof full);
        tex.type = RS_TEX_IMAGE;
        rs_error_clear();
        st = rs_scene_load_image(c->scene, full, &tex.image);
        if (st != RS_OK) {
            char msg[400];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            return FAIL(c, path, "%s", msg);
        }
    } else {
        return FAIL(c, path, "unknown texture type '%s' (solid, checker, stripes, image)", type);
    }
    RS_TRY(rs_scene_add_texture(c->scene, &tex, &id));
    c->textures[c->n_textures].name = name;
    c->textures[c->n_textures++].id = id;
    return RS_OK;
}

/* "albedo": [r,g,b] or "texture": "name" (exactly one). */
static rs_status read_albedo(ctx *c, const cJSON *m, const char *path, const char *key,
                             rs_material *mat)
{
    const cJSON *tex = cJSON_GetObjectItemCaseSensitive(m, "texture");
    if (tex) {
        char p[256];
        rs_json_subpath(p, sizeof p, path, "texture");
        if (cJSON_GetObjectItemCaseSensitive(m, key))
            return FAIL(c, path, "give either '%s' or 'texture', not both", key);
        if (!cJSON_IsString(tex) ||
            !rs_json_lookup(c->textures, c->n_textures, tex->valuestring, &mat->albedo_tex))
            return FAIL(c, p, "no texture named %s%s%s", cJSON_IsString(tex) ? "'" : "",
                        cJSON_IsString(tex) ? tex->valuestring : "(not a string)",
                        cJSON_IsString(tex) ? "'" : "");
        mat->albedo = rs_v3_splat(1.0f);
        return RS_OK;
    }
    return rs_json_get_reflectance(c, m, path, key, 0, rs_v3(.5f, .5f, .5f), &mat->albedo);
}

/* Complex indices of refraction of some metals at 650, 550 and 450 nm (red, green, blue),
 * from the measured data pbrt and Mitsuba ship (Palik; Rakic et al. 1998). */
static const struct {
    const char *name;
    float eta[3], k[3];
} g_metals[] = {
    {"gold", {0.143f, 0.374f, 1.442f}, {3.983f, 2.385f, 1.603f}},
    {"silver", {0.155f, 0.117f, 0.138f}, {4.828f, 3.122f, 2.147f}},
    {"copper", {0.200f, 0.924f, 1.102f}, {3.912f, 2.452f, 2.142f}},
    {"aluminium", {1.657f, 0.880f, 0.521f}, {9.224f, 6.270f, 4.837f}},
};

/* A conductor by a named metal, by "eta" and "k", or by its colour at normal incidence ("color"
 * or "texture"): exactly one of the three. */
static rs_status read_conductor(ctx *c, const cJSON *m, const char *path, float alpha,
                                rs_material *mat)
{
    const cJSON *metal = cJSON_GetObjectItemCaseSensitive(m, "metal");
    int by_metal = metal != NULL, by_index = cJSON_GetObjectItemCaseSensitive(m, "eta") ||
                                             cJSON_GetObjectItemCaseSensitive(m, "k");
    int by_color = cJSON_GetObjectItemCaseSensitive(m, "color") ||
                   cJSON_GetObjectItemCaseSensitive(m, "texture");
    char p[256];
    size_t i;
    if (by_metal + by_index + by_color != 1)
        return FAIL(c, path, "give one of 'metal' (gold, silver, copper, aluminium), 'eta' and "
                             "'k', or 'color'");
    if (by_metal) {
        rs_json_subpath(p, sizeof p, path, "metal");
        for (i = 0; i < sizeof g_metals / sizeof g_metals[0]; ++i)
            if (cJSON_IsString(metal) && strcmp(metal->valuestring, g_metals[i].name) == 0) {
                const float *e = g_metals[i].eta, *k = g_metals[i].k;
                *mat = rs_mat_conductor(rs_v3(e[0], e[1], e[2]), rs_v3(k[0], k[1], k[2]), alpha);
                return RS_OK;
            }
        return FAIL(c, p, "unknown metal (gold, silver, copper, aluminium)");
    }
    if (by_index) {
        rs_vec3 eta, k;
        RS_TRY(rs_json_get_color(c, m, path, "eta", 1, rs_v3(0, 0, 0), &eta));
        RS_TRY(rs_json_get_color(c, m, path, "k", 1, rs_v3(0, 0, 0), &k));
        rs_json_subpath(p, sizeof p, path, "eta");
        if (!(eta.x > 0 && eta.y > 0 && eta.z > 0))
            return FAIL(c, p, "must be > 0");
        *mat = rs_mat_conductor(eta, k, alpha);
        return RS_OK;
    }
    *mat = rs_mat_conductor_f0(rs_v3_splat(.9f), alpha);
    return read_albedo(c, m, path, "color", mat);
}

/* The diffuse materials: lambertian, diffuse_uniform, disney_diffuse, phong (*known 0 for
 * another type). */
static rs_status read_diffuse(ctx *c, const cJSON *m, const char *path, const char *type,
                              rs_material *mat, int *known)
{
    static const char *const k_diffuse[] = {"type", "albedo", "texture", "importance_sampling",
                                            NULL};
    static const char *const k_disney[] = {
        "type", "albedo", "texture", "roughness", "importance_sampling", NULL};
    static const char *const k_phong[] = {
        "type", "kd", "texture", "ks", "exponent", "importance_sampling", NULL};
    *known = 1;
    if (strcmp(type, "lambertian") == 0 || strcmp(type, "diffuse_uniform") == 0) {
        *mat = type[0] == 'l' ? rs_mat_lambertian(rs_v3_splat(.5f))
                             : rs_mat_diffuse_uniform(rs_v3_splat(.5f));
        RS_TRY(rs_json_check_keys(c, m, path, k_diffuse));
        RS_TRY(read_albedo(c, m, path, "albedo", mat));
    } else if (strcmp(type, "disney_diffuse") == 0) {
        *mat = rs_mat_disney_diffuse(rs_v3_splat(.5f), 0.5f);
        RS_TRY(rs_json_check_keys(c, m, path, k_disney));
        RS_TRY(read_albedo(c, m, path, "albedo", mat));
        RS_TRY(rs_json_get_num(c, m, path, "roughness", 0, 0.5, 0.0, 1.0, &mat->roughness));
    } else if (strcmp(type, "phong") == 0) {
        *mat = rs_mat_phong(rs_v3_splat(.5f), rs_v3_splat(.5f), 50.0f);
        RS_TRY(rs_json_check_keys(c, m, path, k_phong));
        RS_TRY(read_albedo(c, m, path, "kd", mat));
        RS_TRY(rs_json_get_reflectance(c, m, path, "ks", 0, rs_v3_splat(.25f), &mat->specular));
        RS_TRY(rs_json_get_num(c, m, path, "exponent", 0, 50.0, 0.0, 1e6, &mat->exponent));
    } else {
        *known = 0;
    }
    return RS_OK;
}

/* The specular materials: metal, dielectric, conductor, rough_dielectric (*known 0 for another
 * type). */
static rs_status read_specular(ctx *c, const cJSON *m, const char *path, const char *type,
                               rs_material *mat, int *known)
{
    static const char *const k_metal[] = {"type", "albedo", "fuzz", NULL};
    static const char *const k_glass[] = {"type", "ior", "tint", "fresnel", NULL};
    static const char *const k_cond[] = {"type",    "metal",     "eta", "k", "color",
                                         "texture", "roughness", NULL};
    static const char *const k_rglass[] = {"type", "ior", "tint", "roughness", NULL};
    *known = 1;
    if (strcmp(type, "metal") == 0) {
        *mat = rs_mat_metal(rs_v3_splat(.8f), 0.0f);
        RS_TRY(rs_json_check_keys(c, m, path, k_metal));
        RS_TRY(rs_json_get_reflectance(c, m, path, "albedo", 0, rs_v3_splat(.8f), &mat->albedo));
        RS_TRY(rs_json_get_num(c, m, path, "fuzz", 0, 0.0, 0.0, 1.0, &mat->fuzz));
    } else if (strcmp(type, "dielectric") == 0) {
        *mat = rs_mat_dielectric(1.5f);
        RS_TRY(rs_json_check_keys(c, m, path, k_glass));
        RS_TRY(rs_json_get_num(c, m, path, "ior", 0, 1.5, 1e-3, 100.0, &mat->ior));
        RS_TRY(rs_json_get_reflectance(c, m, path, "tint", 0, rs_v3_splat(1.0f), &mat->albedo));
        {
            const cJSON *fr = cJSON_GetObjectItemCaseSensitive(m, "fresnel");
            char p[256];
            rs_json_subpath(p, sizeof p, path, "fresnel");
            if (fr && (!cJSON_IsString(fr) || (strcmp(fr->valuestring, "schlick") != 0 &&
                                               strcmp(fr->valuestring, "exact") != 0)))
                return FAIL(c, p, "expected \"schlick\" (the default) or \"exact\"");
            if (fr && strcmp(fr->valuestring, "exact") == 0)
                mat->flags |= RS_MAT_EXACT_FRESNEL;
        }
    } else if (strcmp(type, "conductor") == 0) {
        float r;
        RS_TRY(rs_json_check_keys(c, m, path, k_cond));
        RS_TRY(rs_json_get_num(c, m, path, "roughness", 0, 0.3, 0.0, 1.0, &r));
        RS_TRY(read_conductor(c, m, path, r * r, mat));
    } else if (strcmp(type, "rough_dielectric") == 0) {
        float r, ior;
        RS_TRY(rs_json_check_keys(c, m, path, k_rglass));
        RS_TRY(rs_json_get_num(c, m, path, "ior", 0, 1.5, 1e-3, 100.0, &ior));
        RS_TRY(rs_json_get_num(c, m, path, "roughness", 0, 0.3, 0.0, 1.0, &r));
        *mat = rs_mat_rough_dielectric(ior, r * r);
        RS_TRY(rs_json_get_reflectance(c, m, path, "tint", 0, rs_v3_splat(1.0f), &mat->albedo));
    } else {
        *known = 0;
    }
    return RS_OK;
}

/* The pbr material and the emitter (*known 0 for another type). */
static rs_status read_pbr_light(ctx *c, const cJSON *m, const char *path, const char *type,
                                rs_material *mat, int *known)
{
    static const char *const k_pbr[] = {"type", "base_color", "texture", "metallic", "roughness",
                                        NULL};
    static const char *const k_light[] = {"type", "emission", "two_sided", NULL};
    int two = 0;
    *known = 1;
    if (strcmp(type, "pbr") == 0) {
        float r, metal;
        RS_TRY(rs_json_check_keys(c, m, path, k_pbr));
        RS_TRY(rs_json_get_num(c, m, path, "metallic", 0, 0.0, 0.0, 1.0, &metal));
        RS_TRY(rs_json_get_num(c, m, path, "roughness", 0, 0.5, 0.0, 1.0, &r));
        *mat = rs_mat_pbr(rs_v3_splat(.8f), metal, r);
        RS_TRY(read_albedo(c, m, path, "base_color", mat));
    } else if (strcmp(type, "light") == 0) {
        *mat = rs_mat_light(rs_v3_splat(1.0f), 0);
        RS_TRY(rs_json_check_keys(c, m, path, k_light));
        RS_TRY(rs_json_get_color(c, m, path, "emission", 1, rs_v3(0, 0, 0), &mat->emission));
        RS_TRY(rs_json_get_bool(c, m, path, "two_sided", 0, &two));
        mat->flags = two ? RS_MAT_TWO_SIDED : 0u;
    } else {
        *known = 0;
    }
    return RS_OK;
}

rs_status rs_json_read_material(ctx *c, const cJSON *m, const char *path, const char *name)
{
    rs_material mat;
    const char *type = "";
    int is_ok = 1, known = 0;
    uint32_t id;
    if (!cJSON_IsObject(m))
        return FAIL(c, path, "expected an object");
    RS_TRY(rs_json_get_string(c, m, path, "type", &type));
    RS_TRY(read_diffuse(c, m, path, type, &mat, &known));
    if (!known)
        RS_TRY(read_specular(c, m, path, type, &mat, &known));
    if (!known)
        RS_TRY(read_pbr_light(c, m, path, type, &mat, &known));
    if (!known)
        return FAIL(c, path,
                    "unknown material type '%s' (lambertian, diffuse_uniform, disney_diffuse, "
                    "phong, metal, dielectric, conductor, rough_dielectric, pbr, light)",
                    type);
    RS_TRY(rs_json_get_bool(c, m, path, "importance_sampling", 1, &is_ok));
    if (!is_ok)
        mat.flags |= RS_MAT_UNIFORM_SAMPLING;
    RS_TRY(rs_scene_add_material(c->scene, &mat, &id));
    c->materials[c->n_materials].name = name;
    c->materials[c->n_materials++].id = id;
    return RS_OK;
}

rs_status rs_json_object_material(ctx *c, const cJSON *o, const char *path, uint32_t *id)
{
    const char *name = "";
    char p[256];
    RS_TRY(rs_json_get_string(c, o, path, "material", &name));
    rs_json_subpath(p, sizeof p, path, "material");
    if (!rs_json_lookup(c->materials, c->n_materials, name, id))
        return FAIL(c, p, "no material named '%s'", name);
    return RS_OK;
}
