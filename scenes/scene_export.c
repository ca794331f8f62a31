/* scenes/scene_export.c — see scene_export.h. */
#include "scenes/scene_export.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/file.h"
#include "core/image_io.h"
#include "core/try.h"

static void num(FILE *f, float x) { fprintf(f, "%.9g", (double)x); }

static void vec(FILE *f, rs_vec3 v)
{
    fputc('[', f);
    num(f, v.x);
    fputs(", ", f);
    num(f, v.y);
    fputs(", ", f);
    num(f, v.z);
    fputc(']', f);
}

/* "DIR/STEM-image-N.exr" for image i of the file at `path`, and its name relative to the file
 * (.pfm where the build has no OpenImageIO: both keep the floats exactly). */
static void image_name(const char *path, uint32_t i, char *full, size_t n, char *rel, size_t rn)
{
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path;
    const char *dot = strrchr(base, '.');
    int stem = dot ? (int)(dot - base) : (int)strlen(base);
    snprintf(rel, rn, "%.*s-image-%u.%s", stem, base, i,
             strncmp(rs_image_library_version(), "none", 4) == 0 ? "pfm" : "exr");
    if (slash)
        snprintf(full, n, "%.*s/%s", (int)(slash - path), path, rel);
    else
        snprintf(full, n, "%s", rel);
}

/* Whether pbr material m is what a scene file's "pbr" holds: a base colour (or its texture),
 * metallic and roughness, none of glTF's other textures, emission, cut-outs or layers. */
static int pbr_plain(const rs_material *m)
{
    return m->mr_tex == RS_NO_TEXTURE && m->emission_tex == RS_NO_TEXTURE &&
           m->normal_tex == RS_NO_TEXTURE && rs_v3_is_zero(m->emission) && !m->alpha_mask &&
           m->spec_weight == 1.0f && m->specular.x == 0.04f && m->specular.y == 0.04f &&
           m->specular.z == 0.04f && !(m->coat > 0.0f) && rs_v3_is_zero(m->sheen);
}

/* Material i's type and the parameters of its type; *albedo_key the key its colour goes under,
 * or NULL when the material is written whole (an emitter, a conductor by eta and k). */
static rs_status write_material_type(FILE *f, const rs_material *m, uint32_t i,
                                     const char **albedo_key)
{
    *albedo_key = "albedo";
    switch (m->type) {
    case RS_MAT_LAMBERTIAN: fputs("\"lambertian\"", f); break;
    case RS_MAT_DIFFUSE_UNIFORM: fputs("\"diffuse_uniform\"", f); break;
    case RS_MAT_DISNEY_DIFFUSE:
        fputs("\"disney_diffuse\", \"roughness\": ", f);
        num(f, m->roughness);
        break;
    case RS_MAT_PHONG:
        fputs("\"phong\", \"ks\": ", f);
        vec(f, m->specular);
        fputs(", \"exponent\": ", f);
        num(f, m->exponent);
        *albedo_key = "kd";
        break;
    case RS_MAT_METAL:
        fputs("\"metal\", \"fuzz\": ", f);
        num(f, m->fuzz);
        break;
    case RS_MAT_DIELECTRIC:
        fputs("\"dielectric\", \"ior\": ", f);
        num(f, m->ior);
        if (m->flags & RS_MAT_EXACT_FRESNEL)
            fputs(", \"fresnel\": \"exact\"", f);
        *albedo_key = "tint";
        break;
    case RS_MAT_DIFFUSE_LIGHT:
        fputs("\"light\", \"emission\": ", f);
        vec(f, m->emission);
        if (m->flags & RS_MAT_TWO_SIDED)
            fputs(", \"two_sided\": true", f);
        *albedo_key = NULL;
        return RS_OK;
    case RS_MAT_CONDUCTOR:
        fputs("\"conductor\", \"roughness\": ", f);
        num(f, sqrtf(m->alpha));
        if (m->flags & RS_MAT_F0_COLOR) {
            *albedo_key = "color";
        } else {
            fputs(", \"eta\": ", f);
            vec(f, m->eta);
            fputs(", \"k\": ", f);
            vec(f, m->k);
            *albedo_key = NULL;
            return RS_OK;
        }
        break;
    case RS_MAT_ROUGH_DIELECTRIC:
        if (!rs_v3_is_zero(m->sigma_a))
            return rs_error_set(RS_ERR_ARG, "material %u: a glTF volume's absorption has no place "
                                            "in a scene file", i);
        fputs("\"rough_dielectric\", \"ior\": ", f);
        num(f, m->ior);
        fputs(", \"roughness\": ", f);
        num(f, sqrtf(m->alpha));
        *albedo_key = "tint";
        break;
    case RS_MAT_PBR:
        if (!pbr_plain(m))
            return rs_error_set(RS_ERR_ARG, "material %u: a pbr material's metallic-roughness, "
                                            "emissive and normal textures, alpha cut-outs and "
                                            "glTF specular, clearcoat and sheen layers have "
                                            "no place "
                                            "in a scene file",
                                i);
        fputs("\"pbr\", \"metallic\": ", f);
        num(f, m->metallic);
        fputs(", \"roughness\": ", f);
        num(f, sqrtf(m->alpha));
        *albedo_key = "base_color";
        break;
    default: return rs_error_set(RS_ERR_ARG, "material %u: unknown type %u", i, m->type);
    }
    return RS_OK;
}

static rs_status write_material(FILE *f, const rs_material *m, uint32_t i)
{
    const char *albedo_key;
    fprintf(f, "    \"m%u\": { \"type\": ", i);
    RS_TRY(write_material_type(f, m, i, &albedo_key));
    if (!albedo_key) {
        fputs(" }", f);
        return RS_OK;
    }
    if (m->flags & RS_MAT_UNIFORM_SAMPLING)
        fputs(", \"importance_sampling\": false", f);
    if (m->albedo_tex != RS_NO_TEXTURE && m->type != RS_MAT_METAL &&
        m->type != RS_MAT_DIELECTRIC && m->type != RS_MAT_ROUGH_DIELECTRIC) {
        fprintf(f, ", \"texture\": \"t%u\" }", m->albedo_tex);
    } else {
        fprintf(f, ", \"%s\": ", albedo_key);
        vec(f, m->albedo);
        fputs(" }", f);
    }
    return RS_OK;
}

/* The camera and the image size. */
static void write_camera(FILE *f, const rs_scene *s)
{
    const rs_camera_desc *c = &s->camera;
    fputs("{\n  \"camera\": { \"from\": ", f);
    vec(f, c->from);
    fputs(", \"at\": ", f);
    vec(f, c->at);
    fputs(", \"up\": ", f);
    vec(f, c->up);
    fputs(", \"vfov\": ", f);
    num(f, c->vfov_deg);
    if (c->aperture > 0) {
        fputs(", \"aperture\": ", f);
        num(f, c->aperture);
    }
    if (c->focus_dist > 0) {
        fputs(", \"focus_distance\": ", f);
        num(f, c->focus_dist);
    }
    if (c->shutter_open != 0 || c->shutter_close != 0) {
        fputs(", \"shutter\": [", f);
        num(f, c->shutter_open);
        fputs(", ", f);
        num(f, c->shutter_close);
        fputc(']', f);
    }
    fprintf(f, " },\n  \"image\": { \"width\": %u, \"height\": %u },\n", s->width, s->height);
}

/* Every image as an EXR (a PFM without OpenImageIO) beside the file. */
static rs_status write_images(const rs_scene *s, const char *path)
{
    uint32_t i;
    rs_status st = RS_OK;
    for (i = 0; i < s->n_images && st == RS_OK; ++i) {
        char full[1024], rel[512];
        image_name(path, i, full, sizeof full, rel, sizeof rel);
        st = rs_image_write(full, s->images[i].width, s->images[i].height, s->images[i].rgb);
    }
    return st;
}

/* The environment map, the RTIOW sky or the constant background. */
static void write_background(FILE *f, const rs_scene *s, const char *path)
{
    uint32_t i;
    if (s->env_image != RS_NO_TEXTURE) {
        char full[1024], rel[512];
        const float *r = s->env_rot;
        image_name(path, s->env_image, full, sizeof full, rel, sizeof rel);
        fprintf(f, "  \"background\": { \"map\": \"%s\", \"scale\": ", rel);
        vec(f, s->env_scale);
        /* the map's rotation in the world is the transpose of world -> map */
        fputs(", \"rotate\": { \"matrix\": [", f);
        for (i = 0; i < 9; ++i) {
            num(f, r[3 * (i % 3) + i / 3]);
            fputs(i < 8 ? ", " : "", f);
        }
        fputs("] } },\n", f);
    } else if (s->background_sky) {
        fputs("  \"background\": { \"horizon\": ", f);
        vec(f, s->background);
        fputs(", \"zenith\": ", f);
        vec(f, s->background_top);
        fputs(" },\n", f);
    } else {
        fputs("  \"background\": ", f);
        vec(f, s->background);
        fputs(",\n", f);
    }
}

static void write_textures(FILE *f, const rs_scene *s, const char *path)
{
    uint32_t i;
    if (s->n_textures) {
        fputs("  \"textures\": {\n", f);
        for (i = 0; i < s->n_textures; ++i) {
            const rs_texture *t = &s->textures[i];
            fprintf(f, "    \"t%u\": { \"type\": ", i);
            if (t->type == RS_TEX_SOLID) {
                fputs("\"solid\", \"color\": ", f);
                vec(f, t->a);
            } else if (t->type == RS_TEX_CHECKER || t->type == RS_TEX_STRIPES) {
                fprintf(f, "\"%s\", \"a\": ", t->type == RS_TEX_CHECKER ? "checker" : "stripes");
                vec(f, t->a);
                fputs(", \"b\": ", f);
                vec(f, t->b);
                fputs(", \"scale\": ", f);
                num(f, t->scale);
            } else {
                char full[1024], rel[512];
                image_name(path, t->image, full, sizeof full, rel, sizeof rel);
                fprintf(f, "\"image\", \"file\": \"%s\"", rel);
            }
            fprintf(f, " }%s\n", i + 1 < s->n_textures ? "," : "");
        }
        fputs("  },\n", f);
    }
}

static rs_status write_materials(FILE *f, const rs_scene *s)
{
    uint32_t i;
    rs_status st = RS_OK;
    fputs("  \"materials\": {\n", f);
    for (i = 0; i < s->n_materials && st == RS_OK; ++i) {
        st = write_material(f, &s->materials[i], i);
        fputs(i + 1 < s->n_materials ? ",\n" : "\n", f);
    }
    return st;
}

/* The spheres and parallelograms, each after a comma unless *first. */
static void write_spheres_quads(FILE *f, const rs_scene *s, uint32_t *first_io)
{
    uint32_t i, first = *first_io;
    for (i = 0; i < s->n_spheres; ++i, first = 0) {
        fprintf(f, "%s    { \"type\": \"sphere\", \"center\": ", first ? "" : ",\n");
        vec(f, s->spheres[i].center);
        fputs(", \"radius\": ", f);
        num(f, s->spheres[i].radius);
        if (s->sphere_motion && !rs_v3_is_zero(s->sphere_motion[i])) {
            fputs(", \"velocity\": ", f);
            vec(f, s->sphere_motion[i]);
        }
        fprintf(f, ", \"material\": \"m%u\" }", s->sphere_mat[i]);
    }
    for (i = 0; i < s->n_quads; ++i, first = 0) {
        fprintf(f, "%s    { \"type\": \"quad\", \"q\": ", first ? "" : ",\n");
        vec(f, s->quads[i].q);
        fputs(", \"u\": ", f);
        vec(f, s->quads[i].u);
        fputs(", \"v\": ", f);
        vec(f, s->quads[i].v);
        fprintf(f, ", \"material\": \"m%u\" }", s->quad_mat[i]);
    }
    *first_io = first;
}

static void write_triangles(FILE *f, const rs_scene *s, uint32_t *first_io)
{
    uint32_t i, first = *first_io;
    for (i = 0; i < s->n_tris; ++i, first = 0) {
        fprintf(f, "%s    { \"type\": \"triangle\", \"vertices\": [", first ? "" : ",\n");
        vec(f, s->tris[i].v0);
        fputs(", ", f);
        vec(f, s->tris[i].v1);
        fputs(", ", f);
        vec(f, s->tris[i].v2);
        fputc(']', f);
        if (s->tri_uv) {
            int k;
            fputs(", \"uv\": [", f);
            for (k = 0; k < 6; ++k) {
                num(f, s->tri_uv[6 * (size_t)i + k]);
                fputs(k < 5 ? ", " : "]", f);
            }
        }
        if (s->tri_normal) {
            int k;
            fputs(", \"normals\": [", f);
            for (k = 0; k < 9; ++k) {
                num(f, s->tri_normal[9 * (size_t)i + k]);
                fputs(k < 8 ? ", " : "]", f);
            }
        }
        fprintf(f, ", \"material\": \"m%u\" }", s->tri_mat[i]);
    }
    *first_io = first;
}

static void write_punctuals(FILE *f, const rs_scene *s, uint32_t first)
{
    uint32_t i;
    for (i = 0; i < s->n_punctuals; ++i, first = 0) {
        const rs_punctual *p = &s->punctuals[i];
        static const char *const kind[] = {"point_light", "spot_light", "directional_light"};
        fprintf(f, "%s    { \"type\": \"%s\"", first ? "" : ",\n", kind[p->type]);
        if (p->type != RS_PUNCTUAL_DIRECTIONAL) {
            fputs(", \"position\": ", f);
            vec(f, p->pos);
        }
        if (p->type != RS_PUNCTUAL_POINT) {
            fputs(", \"direction\": ", f);
            vec(f, p->dir);
        }
        fputs(p->type == RS_PUNCTUAL_DIRECTIONAL ? ", \"irradiance\": " : ", \"intensity\": ", f);
        vec(f, p->intensity);
        if (p->type == RS_PUNCTUAL_SPOT) {
            fputs(", \"inner\": ", f);
            num(f, acosf(p->cos_inner) * 57.2957795f);
            fputs(", \"outer\": ", f);
            num(f, acosf(p->cos_outer) * 57.2957795f);
        }
        fputs(" }", f);
    }
}

static rs_status write_all(FILE *f, const rs_scene *s, const char *path)
{
    uint32_t first = 1;
    write_camera(f, s);
    RS_TRY(write_images(s, path));
    write_background(f, s, path);
    write_textures(f, s, path);
    RS_TRY(write_materials(f, s));
    fputs("  },\n  \"objects\": [\n", f);
    write_spheres_quads(f, s, &first);
    write_triangles(f, s, &first);
    write_punctuals(f, s, first);
    fputs("\n  ]\n}\n", f);
    return RS_OK;
}

rs_status rs_scene_export_json(const rs_scene *s, const char *path)
{
    char tmp[1100];
    FILE *f;
    rs_status st;
    if (!rs_file_temp_name(path, tmp, sizeof tmp))
        return rs_error_set(RS_ERR_IO, "%s: path too long", path);
    f = fopen(tmp, "w");
    if (!f)
        return rs_error_set(RS_ERR_IO, "%s: cannot write", path);
    st = write_all(f, s, path);
    if (fclose(f) != 0 && st == RS_OK)
        st = rs_error_set(RS_ERR_IO, "%s: cannot write", path);
    if (st == RS_OK && rename(tmp, path) != 0)
        st = rs_error_set(RS_ERR_IO, "%s: cannot write", path);
    if (st != RS_OK) {
        unlink(tmp);
        if (!strstr(rs_error_message(), path)) {
            char msg[600];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            rs_error_set(st, "%s: %s", path, msg);
        }
    }
    return st;
}
