/* scenes/scene_json.c — the JSON scene reader (see scene_json.h and docs/scene-format.md).
 *
 * Every object is checked against the keys it may have; every value against its type and range.
 * Paths in messages are JSON paths: objects[3].radius, materials.glass.ior. */
#include "scenes/scene_json.h"
#include "scenes/sky.h"

#include <cjson/cJSON.h>
#include <float.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/try.h"
#include "scenes/mesh.h"
#include "scenes/transform.h"

#define MAX_NAMES       4096
#define MAX_NESTING     16 /* instances within instances */
#define MAX_OVERRIDES   64 /* a mesh's materials replaced by name */
/* Groups that are not instanced are copied into the scene (and nested groups into their
 * prototype): this bounds what a file of a few lines can make (ten groups of ten instances of each
 * other would be 10^10 primitives).  Placed triangles are bounded by RS_MAX_INST_PRIMS. */
#define MAX_PRIMS       RS_SCENE_MAX_COPIED_PRIMS

typedef struct named {
    const char *name;
    uint32_t id;
} named;

/* A named group of objects that instances place (top-level "groups").  A group of triangles
 * (triangle, mesh and instances of such groups) is instanced at the top level: read once into a
 * prototype that every instance shares (core/geom.h); any other group is copied. */
typedef struct group {
    const char *name;
    const cJSON *objects;
    uint32_t prims; /* primitives one instance makes, once known */
    int known;
    int shape;            /* 0: not yet known, 1: triangles only, -1: copied */
    int made;             /* the prototype is read */
    uint32_t first, n;    /* the prototype's triangles (inst_tris) */
    uint32_t placed;      /* instances of it */
} group;

/* A mesh object's triangles as its file gave them (before any transform), so that a mesh that
 * instances place many times is read once. */
typedef struct mesh_copy {
    const cJSON *node;
    uint32_t n;
    rs_tri *tris;
    uint32_t *mat;
    float *uv, *normal; /* 6 and 9 per triangle, or NULL */
} mesh_copy;

typedef struct ctx {
    mesh_copy *meshes;
    uint32_t n_meshes, cap_meshes;
    const char *label;
    const char *base_dir;
    FILE *log; /* a line per mesh imported, or NULL */
    rs_scene *scene;
    group groups[MAX_NAMES];
    uint32_t n_groups;
    const group *stack[MAX_NESTING]; /* the groups being expanded, outermost first */
    uint32_t depth;
    char instance_path[256]; /* the outermost instance being expanded, for messages */
    named textures[MAX_NAMES];
    uint32_t n_textures;
    named materials[MAX_NAMES];
    uint32_t n_materials;
    /* per top-level object, the scene's spheres, quads, triangles and instances before it: a
     * primitive rs_scene_finalize refuses is named as the object that made it */
    uint32_t (*obj_start)[4];
    uint32_t n_obj;
} ctx;

#define FAIL(c, path, ...) field_error((c), (path), __VA_ARGS__)

static rs_status field_error(const ctx *c, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Control characters (a key may hold an escaped newline) print as '?': one line, always. */
static void one_line(char *s)
{
    for (; *s; ++s)
        if ((unsigned char)*s < 0x20 || *s == 0x7f)
            *s = '?';
}

static rs_status field_error(const ctx *c, const char *path, const char *fmt, ...)
{
    char msg[384], all[1600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(all, sizeof all, "%s: %s: %s", c->label, path, msg);
    one_line(all);
    return rs_error_set(RS_ERR_ARG, "%s", all);
}

/* Edit distance between a and b (optimal string alignment: insertions, deletions,
 * substitutions and swaps of neighbours each cost 1), capped at 99; keys are short. */
static int key_distance(const char *a, const char *b)
{
    enum { N = 48 };
    int d[N + 1][N + 1], i, j, la = (int)strlen(a), lb = (int)strlen(b);
    if (la > N || lb > N)
        return 99;
    for (i = 0; i <= la; ++i)
        d[i][0] = i;
    for (j = 0; j <= lb; ++j)
        d[0][j] = j;
    for (i = 1; i <= la; ++i)
        for (j = 1; j <= lb; ++j) {
            int cost = a[i - 1] != b[j - 1], v = d[i - 1][j - 1] + cost;
            if (d[i - 1][j] + 1 < v)
                v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v)
                v = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

/* Fails on any key of `obj` that is not in the NULL-terminated list `keys`, naming the closest
 * known key when one is within a third of its length (at least 2 edits). */
static rs_status check_keys(const ctx *c, const cJSON *obj, const char *path,
                            const char *const *keys)
{
    const cJSON *it;
    for (it = obj->child; it; it = it->next) {
        int k, known = 0;
        for (k = 0; keys[k]; ++k)
            if (strcmp(it->string, keys[k]) == 0)
                known = 1;
        if (!known) {
            char list[256] = "";
            for (k = 0; keys[k]; ++k) {
                strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, keys[k], sizeof list - strlen(list) - 1);
            }
            {
                int best = -1, best_d = 99, limit = (int)strlen(it->string) / 3;
                if (limit < 2)
                    limit = 2;
                for (k = 0; keys[k]; ++k) {
                    int dk = key_distance(it->string, keys[k]);
                    if (dk < best_d) {
                        best_d = dk;
                        best = k;
                    }
                }
                if (best >= 0 && best_d <= limit)
                    return FAIL(c, path, "unknown key '%s': did you mean '%s'? (allowed: %s)",
                                it->string, keys[best], list);
            }
            return FAIL(c, path, "unknown key '%s' (allowed: %s)", it->string, list);
        }
    }
    return RS_OK;
}

/* out = path.key (key alone at the top level), cut to n - 1 characters. */
static void subpath(char *out, size_t n, const char *path, const char *key)
{
    size_t k = 0;
    const char *parts[3];
    int i;
    parts[0] = path;
    parts[1] = *path ? "." : "";
    parts[2] = key;
    for (i = 0; i < 3; ++i)
        for (const char *q = parts[i]; *q && k + 1 < n; ++q)
            out[k++] = *q;
    out[k] = '\0';
}

/* A number in [lo, hi]; `def` when absent and not required. */
static rs_status get_num(const ctx *c, const cJSON *obj, const char *path, const char *key,
                         int required, double def, double lo, double hi, float *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[256];
    subpath(p, sizeof p, path, key);
    if (!it) {
        if (required)
            return FAIL(c, path, "missing '%s'", key);
        *out = (float)def;
        return RS_OK;
    }
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return FAIL(c, p, "expected a number");
    if (it->valuedouble < lo || it->valuedouble > hi)
        return FAIL(c, p, "%g is out of range [%g, %g]", it->valuedouble, lo, hi);
    *out = (float)it->valuedouble;
    return RS_OK;
}

static rs_status vec3_of(const ctx *c, const cJSON *it, const char *p, rs_vec3 *out)
{
    float v[3];
    int i;
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 3)
        return FAIL(c, p, "expected an array of 3 numbers");
    for (i = 0; i < 3; ++i) {
        const cJSON *e = cJSON_GetArrayItem(it, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
            return FAIL(c, p, "expected an array of 3 finite numbers");
        v[i] = (float)e->valuedouble;
    }
    *out = rs_v3(v[0], v[1], v[2]);
    return RS_OK;
}

static rs_status get_vec3(const ctx *c, const cJSON *obj, const char *path, const char *key,
                          int required, rs_vec3 def, rs_vec3 *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[256];
    subpath(p, sizeof p, path, key);
    if (!it) {
        if (required)
            return FAIL(c, path, "missing '%s'", key);
        *out = def;
        return RS_OK;
    }
    return vec3_of(c, it, p, out);
}

/* A colour: 3 numbers >= 0. */
static rs_status get_color(const ctx *c, const cJSON *obj, const char *path, const char *key,
                           int required, rs_vec3 def, rs_vec3 *out)
{
    char p[256];
    rs_status st = get_vec3(c, obj, path, key, required, def, out);
    subpath(p, sizeof p, path, key);
    if (st == RS_OK && (out->x < 0 || out->y < 0 || out->z < 0))
        return FAIL(c, p, "colour components must be >= 0");
    return st;
}

/* A reflectance (or transmittance): a colour with every component in [0, 1]. */
static rs_status get_reflectance(const ctx *c, const cJSON *obj, const char *path,
                                 const char *key, int required, rs_vec3 def, rs_vec3 *out)
{
    char p[256];
    rs_status st = get_color(c, obj, path, key, required, def, out);
    subpath(p, sizeof p, path, key);
    if (st == RS_OK && (out->x > 1 || out->y > 1 || out->z > 1))
        return FAIL(c, p, "reflectance must be in [0, 1]");
    return st;
}

static rs_status get_bool(const ctx *c, const cJSON *obj, const char *path, const char *key,
                          int def, int *out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[256];
    subpath(p, sizeof p, path, key);
    if (!it) {
        *out = def;
        return RS_OK;
    }
    if (!cJSON_IsBool(it))
        return FAIL(c, p, "expected true or false");
    *out = cJSON_IsTrue(it);
    return RS_OK;
}

static rs_status get_string(const ctx *c, const cJSON *obj, const char *path, const char *key,
                            const char **out)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    char p[256];
    subpath(p, sizeof p, path, key);
    if (!it)
        return FAIL(c, path, "missing '%s'", key);
    if (!cJSON_IsString(it) || !*it->valuestring)
        return FAIL(c, p, "expected a non-empty string");
    *out = it->valuestring;
    return RS_OK;
}

static int lookup(const named *list, uint32_t n, const char *name, uint32_t *id)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (strcmp(list[i].name, name) == 0) {
            *id = list[i].id;
            return 1;
        }
    return 0;
}

static rs_status read_camera(ctx *c, const cJSON *cam)
{
    static const char *const keys[] = {"from",           "at",      "up", "vfov", "aperture",
                                       "focus_distance", "shutter", NULL};
    rs_camera_desc *d = &c->scene->camera;
    const cJSON *sh;
    if (!cJSON_IsObject(cam))
        return FAIL(c, "camera", "expected an object");
    RS_TRY(check_keys(c, cam, "camera", keys));
    RS_TRY(get_vec3(c, cam, "camera", "from", 1, rs_v3(0, 0, 0), &d->from));
    RS_TRY(get_vec3(c, cam, "camera", "at", 1, rs_v3(0, 0, 0), &d->at));
    RS_TRY(get_vec3(c, cam, "camera", "up", 0, rs_v3(0, 1, 0), &d->up));
    RS_TRY(get_num(c, cam, "camera", "vfov", 0, 40.0, 1e-3, 179.0, &d->vfov_deg));
    RS_TRY(get_num(c, cam, "camera", "aperture", 0, 0.0, 0.0, 1e30, &d->aperture));
    RS_TRY(get_num(c, cam, "camera", "focus_distance", 0, 0.0, 0.0, 1e30, &d->focus_dist));
    if (rs_v3_length(rs_v3_sub(d->from, d->at)) == 0.0f)
        return FAIL(c, "camera", "'from' and 'at' must differ");
    if (rs_v3_length(rs_v3_cross(d->up, rs_v3_sub(d->from, d->at))) == 0.0f)
        return FAIL(c, "camera.up", "must not be parallel to the viewing direction");
    sh = cJSON_GetObjectItemCaseSensitive(cam, "shutter");
    if (sh) {
        if (!cJSON_IsArray(sh) || cJSON_GetArraySize(sh) != 2 ||
            !cJSON_IsNumber(cJSON_GetArrayItem(sh, 0)) ||
            !cJSON_IsNumber(cJSON_GetArrayItem(sh, 1)) ||
            fabs(cJSON_GetArrayItem(sh, 0)->valuedouble) > 1e30 ||
            fabs(cJSON_GetArrayItem(sh, 1)->valuedouble) > 1e30)
            return FAIL(c, "camera.shutter", "expected [open, close], two finite numbers");
        d->shutter_open = (float)cJSON_GetArrayItem(sh, 0)->valuedouble;
        d->shutter_close = (float)cJSON_GetArrayItem(sh, 1)->valuedouble;
        if (!(d->shutter_close >= d->shutter_open))
            return FAIL(c, "camera.shutter", "close must not be before open");
    }
    return RS_OK;
}

static rs_status read_image_size(ctx *c, const cJSON *img)
{
    static const char *const keys[] = {"width", "height", NULL};
    float w, h;
    if (!cJSON_IsObject(img))
        return FAIL(c, "image", "expected an object");
    RS_TRY(check_keys(c, img, "image", keys));
    RS_TRY(get_num(c, img, "image", "width", 0, 512, 1, 32768, &w));
    RS_TRY(get_num(c, img, "image", "height", 0, 512, 1, 32768, &h));
    if (w != floorf(w) || h != floorf(h))
        return FAIL(c, "image", "width and height must be whole numbers");
    c->scene->width = (uint32_t)w;
    c->scene->height = (uint32_t)h;
    return RS_OK;
}

static rs_status read_rotation(ctx *c, const cJSON *it, const char *q, rs_xform *out);
static rs_status resolve_path(const ctx *c, const char *file, char *out, size_t n);

/* "background": {"map": FILE, "scale": s or [r, g, b], "rotate": ...}: an environment map. */
static rs_status read_envmap(ctx *c, const cJSON *bg)
{
    static const char *const keys[] = {"map", "scale", "rotate", NULL};
    rs_scene *s = c->scene;
    const cJSON *sc = cJSON_GetObjectItemCaseSensitive(bg, "scale");
    const cJSON *rot = cJSON_GetObjectItemCaseSensitive(bg, "rotate");
    const char *file = "";
    char full[1024];
    rs_vec3 scale = rs_v3_splat(1.0f);
    float r[9];
    uint32_t image;
    int i, k;
    RS_TRY(check_keys(c, bg, "background", keys));
    RS_TRY(get_string(c, bg, "background", "map", &file));
    if (sc && cJSON_IsNumber(sc)) {
        if (!(sc->valuedouble >= 0) || sc->valuedouble > 1e30)
            return FAIL(c, "background.scale", "must be >= 0");
        scale = rs_v3_splat((float)sc->valuedouble);
    } else if (sc) {
        RS_TRY(get_color(c, bg, "background", "scale", 1, scale, &scale));
    }
    for (i = 0; i < 9; ++i)
        r[i] = (i % 4 == 0) ? 1.0f : 0.0f;
    if (rot) {
        /* the map turns by `rotate` in the world: directions go back by its inverse */
        rs_xform x;
        RS_TRY(read_rotation(c, rot, "background.rotate", &x));
        for (i = 0; i < 3; ++i)
            for (k = 0; k < 3; ++k)
                r[3 * i + k] = (float)x.m[k][i];
    }
    resolve_path(c, file, full, sizeof full);
    rs_error_clear();
    if (rs_scene_load_image(s, full, &image) != RS_OK) {
        char msg[400];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return FAIL(c, "background.map", "%s", msg);
    }
    {
        const rs_image *im = &s->images[image];
        for (i = 0; i < (int)(3 * im->width * im->height); ++i)
            if (!isfinite(im->rgb[i]) || im->rgb[i] < 0)
                return FAIL(c, "background.map", "%s: texel (%u, %u) is %s (an environment map's "
                            "texels must be finite and >= 0)", full, (unsigned)(i / 3) % im->width,
                            (unsigned)(i / 3) / im->width,
                            isfinite(im->rgb[i]) ? "negative" : "not finite");
    }
    RS_TRY(rs_scene_set_environment(s, image, scale, r));
    return RS_OK;
}

/* "background": {"sky": {"elevation": .., "azimuth": .., "turbidity": .., "intensity": ..,
 * "sun": true}}: the sun and sky of scenes/sky.h (each key optional: its default). */
static rs_status read_sky(ctx *c, const cJSON *bg)
{
    static const char *const keys[] = {"sky", NULL};
    static const char *const sky_keys[] = {"elevation", "azimuth", "turbidity", "intensity", "sun",
                                           NULL};
    const cJSON *sky = cJSON_GetObjectItemCaseSensitive(bg, "sky");
    rs_sky_params p;
    RS_TRY(check_keys(c, bg, "background", keys));
    if (!cJSON_IsObject(sky))
        return FAIL(c, "background.sky", "expected {\"elevation\": .., \"azimuth\": .., ...} or {}");
    RS_TRY(check_keys(c, sky, "background.sky", sky_keys));
    rs_sky_defaults(&p); /* the ranges are scenes/sky.h's */
    RS_TRY(get_num(c, sky, "background.sky", "elevation", 0, p.elevation_deg, 0, 90,
                   &p.elevation_deg));
    RS_TRY(get_num(c, sky, "background.sky", "azimuth", 0, p.azimuth_deg, -360, 360,
                   &p.azimuth_deg));
    RS_TRY(get_num(c, sky, "background.sky", "turbidity", 0, p.turbidity, 2, 10, &p.turbidity));
    RS_TRY(get_num(c, sky, "background.sky", "intensity", 0, p.intensity, 0, 1e6, &p.intensity));
    RS_TRY(get_bool(c, sky, "background.sky", "sun", 1, &p.sun));
    return rs_scene_set_sky(c->scene, &p);
}

static rs_status read_background(ctx *c, const cJSON *bg)
{
    static const char *const keys[] = {"horizon", "zenith", NULL};
    rs_scene *s = c->scene;
    if (cJSON_IsObject(bg) && cJSON_GetObjectItemCaseSensitive(bg, "map"))
        return read_envmap(c, bg);
    if (cJSON_IsObject(bg) && cJSON_GetObjectItemCaseSensitive(bg, "sky"))
        return read_sky(c, bg);
    if (cJSON_IsArray(bg)) {
        RS_TRY(vec3_of(c, bg, "background", &s->background));
        if (s->background.x < 0 || s->background.y < 0 || s->background.z < 0)
            return FAIL(c, "background", "colour components must be >= 0");
        return RS_OK;
    }
    if (!cJSON_IsObject(bg))
        return FAIL(c, "background", "expected [r, g, b] or {\"horizon\": .., \"zenith\": ..}");
    RS_TRY(check_keys(c, bg, "background", keys));
    RS_TRY(get_color(c, bg, "background", "horizon", 1, rs_v3(0, 0, 0), &s->background));
    RS_TRY(get_color(c, bg, "background", "zenith", 1, rs_v3(0, 0, 0), &s->background_top));
    s->background_sky = 1;
    return RS_OK;
}

static rs_status resolve_path(const ctx *c, const char *file, char *out, size_t n)
{
    if (file[0] == '/' || !c->base_dir || !*c->base_dir)
        snprintf(out, n, "%s", file);
    else
        snprintf(out, n, "%s/%s", c->base_dir, file);
    return RS_OK;
}

static rs_status read_texture(ctx *c, const cJSON *t, const char *path, const char *name)
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
    RS_TRY(get_string(c, t, path, "type", &type));
    if (strcmp(type, "solid") == 0) {
        RS_TRY(check_keys(c, t, path, k_solid));
        tex.type = RS_TEX_SOLID;
        RS_TRY(get_reflectance(c, t, path, "color", 1, rs_v3(0, 0, 0), &tex.a));
    } else if (strcmp(type, "checker") == 0 || strcmp(type, "stripes") == 0) {
        RS_TRY(check_keys(c, t, path, k_two));
        tex.type = type[0] == 'c' ? RS_TEX_CHECKER : RS_TEX_STRIPES;
        RS_TRY(get_reflectance(c, t, path, "a", 1, rs_v3(0, 0, 0), &tex.a));
        RS_TRY(get_reflectance(c, t, path, "b", 1, rs_v3(0, 0, 0), &tex.b));
        RS_TRY(get_num(c, t, path, "scale", 0, type[0] == 'c' ? 1.0 : 10.0, 1e-6, 1e6, &tex.scale));
    } else if (strcmp(type, "image") == 0) {
        const char *file = "";
        char full[1024];
        rs_status st;
        RS_TRY(check_keys(c, t, path, k_image));
        RS_TRY(get_string(c, t, path, "file", &file));
        resolve_path(c, file, full, sizeof full);
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
        subpath(p, sizeof p, path, "texture");
        if (cJSON_GetObjectItemCaseSensitive(m, key))
            return FAIL(c, path, "give either '%s' or 'texture', not both", key);
        if (!cJSON_IsString(tex) ||
            !lookup(c->textures, c->n_textures, tex->valuestring, &mat->albedo_tex))
            return FAIL(c, p, "no texture named %s%s%s", cJSON_IsString(tex) ? "'" : "",
                        cJSON_IsString(tex) ? tex->valuestring : "(not a string)",
                        cJSON_IsString(tex) ? "'" : "");
        mat->albedo = rs_v3_splat(1.0f);
        return RS_OK;
    }
    return get_reflectance(c, m, path, key, 0, rs_v3(.5f, .5f, .5f), &mat->albedo);
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
        subpath(p, sizeof p, path, "metal");
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
        RS_TRY(get_color(c, m, path, "eta", 1, rs_v3(0, 0, 0), &eta));
        RS_TRY(get_color(c, m, path, "k", 1, rs_v3(0, 0, 0), &k));
        subpath(p, sizeof p, path, "eta");
        if (!(eta.x > 0 && eta.y > 0 && eta.z > 0))
            return FAIL(c, p, "must be > 0");
        *mat = rs_mat_conductor(eta, k, alpha);
        return RS_OK;
    }
    *mat = rs_mat_conductor_f0(rs_v3_splat(.9f), alpha);
    return read_albedo(c, m, path, "color", mat);
}

static rs_status read_material(ctx *c, const cJSON *m, const char *path, const char *name)
{
    static const char *const k_diffuse[] = {"type", "albedo", "texture", "importance_sampling",
                                            NULL};
    static const char *const k_disney[] = {
        "type", "albedo", "texture", "roughness", "importance_sampling", NULL};
    static const char *const k_phong[] = {
        "type", "kd", "texture", "ks", "exponent", "importance_sampling", NULL};
    static const char *const k_metal[] = {"type", "albedo", "fuzz", NULL};
    static const char *const k_glass[] = {"type", "ior", "tint", "fresnel", NULL};
    static const char *const k_cond[] = {"type",    "metal",     "eta", "k", "color",
                                         "texture", "roughness", NULL};
    static const char *const k_rglass[] = {"type", "ior", "tint", "roughness", NULL};
    static const char *const k_pbr[] = {"type", "base_color", "texture", "metallic", "roughness",
                                        NULL};
    static const char *const k_light[] = {"type", "emission", "two_sided", NULL};
    rs_material mat;
    const char *type = "";
    int is_ok = 1, two = 0;
    uint32_t id;
    if (!cJSON_IsObject(m))
        return FAIL(c, path, "expected an object");
    RS_TRY(get_string(c, m, path, "type", &type));
    if (strcmp(type, "lambertian") == 0 || strcmp(type, "diffuse_uniform") == 0) {
        mat = type[0] == 'l' ? rs_mat_lambertian(rs_v3_splat(.5f))
                             : rs_mat_diffuse_uniform(rs_v3_splat(.5f));
        RS_TRY(check_keys(c, m, path, k_diffuse));
        RS_TRY(read_albedo(c, m, path, "albedo", &mat));
    } else if (strcmp(type, "disney_diffuse") == 0) {
        mat = rs_mat_disney_diffuse(rs_v3_splat(.5f), 0.5f);
        RS_TRY(check_keys(c, m, path, k_disney));
        RS_TRY(read_albedo(c, m, path, "albedo", &mat));
        RS_TRY(get_num(c, m, path, "roughness", 0, 0.5, 0.0, 1.0, &mat.roughness));
    } else if (strcmp(type, "phong") == 0) {
        mat = rs_mat_phong(rs_v3_splat(.5f), rs_v3_splat(.5f), 50.0f);
        RS_TRY(check_keys(c, m, path, k_phong));
        RS_TRY(read_albedo(c, m, path, "kd", &mat));
        RS_TRY(get_reflectance(c, m, path, "ks", 0, rs_v3_splat(.25f), &mat.specular));
        RS_TRY(get_num(c, m, path, "exponent", 0, 50.0, 0.0, 1e6, &mat.exponent));
    } else if (strcmp(type, "metal") == 0) {
        mat = rs_mat_metal(rs_v3_splat(.8f), 0.0f);
        RS_TRY(check_keys(c, m, path, k_metal));
        RS_TRY(get_reflectance(c, m, path, "albedo", 0, rs_v3_splat(.8f), &mat.albedo));
        RS_TRY(get_num(c, m, path, "fuzz", 0, 0.0, 0.0, 1.0, &mat.fuzz));
    } else if (strcmp(type, "dielectric") == 0) {
        mat = rs_mat_dielectric(1.5f);
        RS_TRY(check_keys(c, m, path, k_glass));
        RS_TRY(get_num(c, m, path, "ior", 0, 1.5, 1e-3, 100.0, &mat.ior));
        RS_TRY(get_reflectance(c, m, path, "tint", 0, rs_v3_splat(1.0f), &mat.albedo));
        {
            const cJSON *fr = cJSON_GetObjectItemCaseSensitive(m, "fresnel");
            char p[256];
            subpath(p, sizeof p, path, "fresnel");
            if (fr && (!cJSON_IsString(fr) || (strcmp(fr->valuestring, "schlick") != 0 &&
                                               strcmp(fr->valuestring, "exact") != 0)))
                return FAIL(c, p, "expected \"schlick\" (the default) or \"exact\"");
            if (fr && strcmp(fr->valuestring, "exact") == 0)
                mat.flags |= RS_MAT_EXACT_FRESNEL;
        }
    } else if (strcmp(type, "conductor") == 0) {
        float r;
        RS_TRY(check_keys(c, m, path, k_cond));
        RS_TRY(get_num(c, m, path, "roughness", 0, 0.3, 0.0, 1.0, &r));
        RS_TRY(read_conductor(c, m, path, r * r, &mat));
    } else if (strcmp(type, "rough_dielectric") == 0) {
        float r, ior;
        RS_TRY(check_keys(c, m, path, k_rglass));
        RS_TRY(get_num(c, m, path, "ior", 0, 1.5, 1e-3, 100.0, &ior));
        RS_TRY(get_num(c, m, path, "roughness", 0, 0.3, 0.0, 1.0, &r));
        mat = rs_mat_rough_dielectric(ior, r * r);
        RS_TRY(get_reflectance(c, m, path, "tint", 0, rs_v3_splat(1.0f), &mat.albedo));
    } else if (strcmp(type, "pbr") == 0) {
        float r, metal;
        RS_TRY(check_keys(c, m, path, k_pbr));
        RS_TRY(get_num(c, m, path, "metallic", 0, 0.0, 0.0, 1.0, &metal));
        RS_TRY(get_num(c, m, path, "roughness", 0, 0.5, 0.0, 1.0, &r));
        mat = rs_mat_pbr(rs_v3_splat(.8f), metal, r);
        RS_TRY(read_albedo(c, m, path, "base_color", &mat));
    } else if (strcmp(type, "light") == 0) {
        mat = rs_mat_light(rs_v3_splat(1.0f), 0);
        RS_TRY(check_keys(c, m, path, k_light));
        RS_TRY(get_color(c, m, path, "emission", 1, rs_v3(0, 0, 0), &mat.emission));
        RS_TRY(get_bool(c, m, path, "two_sided", 0, &two));
        mat.flags = two ? RS_MAT_TWO_SIDED : 0u;
    } else {
        return FAIL(c, path,
                    "unknown material type '%s' (lambertian, diffuse_uniform, disney_diffuse, "
                    "phong, metal, dielectric, conductor, rough_dielectric, pbr, light)",
                    type);
    }
    RS_TRY(get_bool(c, m, path, "importance_sampling", 1, &is_ok));
    if (!is_ok)
        mat.flags |= RS_MAT_UNIFORM_SAMPLING;
    RS_TRY(rs_scene_add_material(c->scene, &mat, &id));
    c->materials[c->n_materials].name = name;
    c->materials[c->n_materials++].id = id;
    return RS_OK;
}

static rs_status object_material(ctx *c, const cJSON *o, const char *path, uint32_t *id)
{
    const char *name = "";
    char p[256];
    RS_TRY(get_string(c, o, path, "material", &name));
    subpath(p, sizeof p, path, "material");
    if (!lookup(c->materials, c->n_materials, name, id))
        return FAIL(c, p, "no material named '%s'", name);
    return RS_OK;
}

/* One step of a transform: {"matrix": [16 numbers, row-major]}, {"translate": [x, y, z]},
 * {"scale": s or [x, y, z]}, {"rotate": [x, y, z] (degrees about x, then y, then z)} or
 * {"rotate": {"axis": [x, y, z], "degrees": a}}. */
static rs_status read_xform_step(ctx *c, const cJSON *st, const char *p, rs_xform *out)
{
    static const char *const keys[] = {"matrix", "translate", "rotate", "scale", NULL};
    const cJSON *it;
    char q[256];
    rs_vec3 v;
    if (!cJSON_IsObject(st) || !st->child || st->child->next)
        return FAIL(c, p, "a transform step is an object of one key: matrix, translate, rotate "
                          "or scale");
    RS_TRY(check_keys(c, st, p, keys));
    it = st->child;
    subpath(q, sizeof q, p, it->string);
    if (strcmp(it->string, "matrix") == 0) {
        double m[16];
        int i;
        if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 16)
            return FAIL(c, q, "expected 16 numbers (a 4x4 matrix, row by row)");
        for (i = 0; i < 16; ++i) {
            const cJSON *e = cJSON_GetArrayItem(it, i);
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
                return FAIL(c, q, "expected 16 finite numbers");
            m[i] = e->valuedouble;
        }
        if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1)
            return FAIL(c, q, "the last row must be [0, 0, 0, 1] (an affine transform)");
        for (i = 0; i < 3; ++i) {
            out->m[i][0] = m[4 * i];
            out->m[i][1] = m[4 * i + 1];
            out->m[i][2] = m[4 * i + 2];
            out->t[i] = m[4 * i + 3];
        }
        return RS_OK;
    }
    if (strcmp(it->string, "translate") == 0) {
        RS_TRY(vec3_of(c, it, q, &v));
        *out = rs_xform_translate(v.x, v.y, v.z);
        return RS_OK;
    }
    if (strcmp(it->string, "scale") == 0) {
        if (cJSON_IsNumber(it))
            v = rs_v3_splat((float)it->valuedouble);
        else
            RS_TRY(vec3_of(c, it, q, &v));
        if (v.x == 0 || v.y == 0 || v.z == 0)
            return FAIL(c, q, "a scale must not be 0 (it would flatten the object)");
        *out = rs_xform_scale(v.x, v.y, v.z);
        return RS_OK;
    }
    return read_rotation(c, it, q, out);
}

/* A rotation: [x, y, z] (degrees about x, then y, then z), {"axis": [x, y, z], "degrees": a},
 * or {"matrix": [9 numbers, row by row]} (orthonormal with determinant 1 to 1e-4). */
static rs_status read_rotation(ctx *c, const cJSON *it, const char *q, rs_xform *out)
{
    static const char *const k_axis[] = {"axis", "degrees", NULL};
    static const char *const k_mat[] = {"matrix", NULL};
    rs_vec3 v;
    if (cJSON_IsObject(it) && cJSON_GetObjectItemCaseSensitive(it, "matrix")) {
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(it, "matrix");
        char mp[300];
        double scale;
        int i;
        RS_TRY(check_keys(c, it, q, k_mat));
        subpath(mp, sizeof mp, q, "matrix");
        if (!cJSON_IsArray(m) || cJSON_GetArraySize(m) != 9)
            return FAIL(c, mp, "expected 9 numbers (a 3x3 rotation, row by row)");
        *out = rs_xform_identity();
        for (i = 0; i < 9; ++i) {
            const cJSON *e = cJSON_GetArrayItem(m, i);
            if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble))
                return FAIL(c, mp, "expected 9 finite numbers");
            out->m[i / 3][i % 3] = e->valuedouble;
        }
        if (!rs_xform_is_similarity(out, &scale) || fabs(scale - 1.0) > 1e-4 ||
            rs_xform_det(out) < 0)
            return FAIL(c, mp, "not a rotation (rows must be orthonormal, determinant 1)");
        return RS_OK;
    }
    if (cJSON_IsObject(it)) {
        double axis[3];
        float deg;
        char ap[300];
        RS_TRY(check_keys(c, it, q, k_axis));
        RS_TRY(get_vec3(c, it, q, "axis", 1, rs_v3(0, 0, 0), &v));
        RS_TRY(get_num(c, it, q, "degrees", 1, 0, -1e6, 1e6, &deg));
        subpath(ap, sizeof ap, q, "axis");
        if (rs_v3_is_zero(v))
            return FAIL(c, ap, "the axis must not be zero");
        axis[0] = v.x, axis[1] = v.y, axis[2] = v.z;
        *out = rs_xform_rotate_axis(axis, deg);
        return RS_OK;
    }
    if (!cJSON_IsArray(it))
        return FAIL(c, q, "expected [x, y, z] (Euler angles in degrees) or {\"axis\": [x, y, z], "
                          "\"degrees\": a}");
    RS_TRY(vec3_of(c, it, q, &v));
    if (fabsf(v.x) > 1e6f || fabsf(v.y) > 1e6f || fabsf(v.z) > 1e6f)
        return FAIL(c, q, "angles must lie within +-1e6 degrees");
    *out = rs_xform_rotate_euler(v.x, v.y, v.z);
    return RS_OK;
}

/* An object's "transform": one step, or an array of steps applied in order (the first to the
 * object first).  The identity when absent. */
static rs_status read_transform(ctx *c, const cJSON *o, const char *path, rs_xform *out)
{
    const cJSON *tr = cJSON_GetObjectItemCaseSensitive(o, "transform"), *it;
    char p[256];
    const char *why;
    int i = 0;
    *out = rs_xform_identity();
    if (!tr)
        return RS_OK;
    subpath(p, sizeof p, path, "transform");
    if (cJSON_IsObject(tr)) {
        RS_TRY(read_xform_step(c, tr, p, out));
    } else if (cJSON_IsArray(tr)) {
        for (it = tr->child; it; it = it->next, ++i) {
            rs_xform step, all;
            char sp[280];
            snprintf(sp, sizeof sp, "%s[%d]", p, i);
            RS_TRY(read_xform_step(c, it, sp, &step));
            all = rs_xform_compose(&step, out);
            *out = all;
        }
    } else {
        return FAIL(c, p, "expected a step ({\"translate\": [x, y, z]}, ...) or an array of steps");
    }
    why = rs_xform_invalid(out);
    if (why)
        return FAIL(c, p, "%s", why);
    return RS_OK;
}

/* Keeps the triangles from `first` on (a mesh just imported, not yet transformed). */
static rs_status keep_mesh(ctx *c, const cJSON *node, uint32_t first)
{
    const rs_scene *s = c->scene;
    uint32_t n = s->n_tris - first;
    mesh_copy m;
    memset(&m, 0, sizeof m);
    if (c->n_meshes == c->cap_meshes) {
        uint32_t cap = c->cap_meshes ? 2 * c->cap_meshes : 8;
        mesh_copy *g = (mesh_copy *)rs_alloc(cap, sizeof *g);
        if (!g)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", c->label);
        if (c->n_meshes)
            memcpy(g, c->meshes, c->n_meshes * sizeof *g);
        rs_free(c->meshes);
        c->meshes = g;
        c->cap_meshes = cap;
    }
    m.node = node;
    m.n = n;
    m.tris = (rs_tri *)rs_alloc(n, sizeof *m.tris);
    m.mat = (uint32_t *)rs_alloc(n, sizeof *m.mat);
    m.uv = s->tri_uv ? (float *)rs_alloc(6 * (size_t)n, sizeof *m.uv) : NULL;
    m.normal = s->tri_normal ? (float *)rs_alloc(9 * (size_t)n, sizeof *m.normal) : NULL;
    if (!m.tris || !m.mat || (s->tri_uv && !m.uv) || (s->tri_normal && !m.normal)) {
        rs_free(m.tris), rs_free(m.mat), rs_free(m.uv), rs_free(m.normal);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", c->label);
    }
    memcpy(m.tris, s->tris + first, (size_t)n * sizeof *m.tris);
    memcpy(m.mat, s->tri_mat + first, (size_t)n * sizeof *m.mat);
    if (m.uv)
        memcpy(m.uv, s->tri_uv + 6 * (size_t)first, 6 * (size_t)n * sizeof *m.uv);
    if (m.normal)
        memcpy(m.normal, s->tri_normal + 9 * (size_t)first, 9 * (size_t)n * sizeof *m.normal);
    c->meshes[c->n_meshes++] = m;
    return RS_OK;
}

/* The triangles of a mesh read before, added again as they came from the file. */
static rs_status copy_mesh(ctx *c, const mesh_copy *m)
{
    uint32_t i;
    for (i = 0; i < m->n; ++i) {
        rs_vec3 v[3];
        v[0] = m->tris[i].v0, v[1] = m->tris[i].v1, v[2] = m->tris[i].v2;
        RS_TRY(rs_scene_add_triangle_full(c->scene, v, m->uv ? m->uv + 6 * (size_t)i : NULL,
                                          m->normal ? m->normal + 9 * (size_t)i : NULL, m->mat[i]));
    }
    return RS_OK;
}

/* `n` finite numbers (|x| <= 1e30) from array `a` into out. */
static rs_status read_floats(ctx *c, const cJSON *a, const char *p, int n, const char *what,
                             float *out)
{
    int i;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n)
        return FAIL(c, p, "expected %d numbers %s", n, what);
    for (i = 0; i < n; ++i) {
        const cJSON *e = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
            return FAIL(c, p, "expected %d finite numbers %s", n, what);
        out[i] = (float)e->valuedouble;
    }
    return RS_OK;
}

/* point_light {position, intensity}, spot_light {position, direction, intensity, inner, outer
 * (degrees)}, directional_light {direction, irradiance}: delta lights, as glTF's. */
static rs_status add_punctual(ctx *c, const cJSON *o, const char *path, const char *type)
{
    static const char *const k_point[] = {"type", "position", "intensity", "transform", NULL};
    static const char *const k_spot[] = {"type",  "position", "direction", "intensity",
                                         "inner", "outer",    "transform", NULL};
    static const char *const k_dir[] = {"type", "direction", "irradiance", "transform", NULL};
    rs_punctual p;
    memset(&p, 0, sizeof p);
    if (type[0] == 'p') {
        p.type = RS_PUNCTUAL_POINT;
        RS_TRY(check_keys(c, o, path, k_point));
        RS_TRY(get_vec3(c, o, path, "position", 1, rs_v3(0, 0, 0), &p.pos));
        RS_TRY(get_color(c, o, path, "intensity", 1, rs_v3(0, 0, 0), &p.intensity));
    } else if (type[0] == 's') {
        float inner, outer;
        char q[256];
        p.type = RS_PUNCTUAL_SPOT;
        RS_TRY(check_keys(c, o, path, k_spot));
        RS_TRY(get_vec3(c, o, path, "position", 1, rs_v3(0, 0, 0), &p.pos));
        RS_TRY(get_vec3(c, o, path, "direction", 1, rs_v3(0, 0, 0), &p.dir));
        RS_TRY(get_color(c, o, path, "intensity", 1, rs_v3(0, 0, 0), &p.intensity));
        RS_TRY(get_num(c, o, path, "inner", 0, 0.0, 0.0, 90.0, &inner));
        RS_TRY(get_num(c, o, path, "outer", 0, 45.0, 0.0, 90.0, &outer));
        subpath(q, sizeof q, path, "outer");
        if (outer < inner)
            return FAIL(c, q, "the outer cone must not be narrower than the inner");
        /* 90 degrees in float radians is a little past pi/2: its cosf is -4.4e-8, held at 0 */
        p.cos_inner = fmaxf(0.0f, cosf(inner * 0.017453292519943295f));
        p.cos_outer = fmaxf(0.0f, cosf(outer * 0.017453292519943295f));
    } else {
        p.type = RS_PUNCTUAL_DIRECTIONAL;
        RS_TRY(check_keys(c, o, path, k_dir));
        RS_TRY(get_vec3(c, o, path, "direction", 1, rs_v3(0, 0, 0), &p.dir));
        RS_TRY(get_color(c, o, path, "irradiance", 1, rs_v3(0, 0, 0), &p.intensity));
    }
    if (p.type != RS_PUNCTUAL_POINT && rs_v3_is_zero(p.dir)) {
        char q[256];
        subpath(q, sizeof q, path, "direction");
        return FAIL(c, q, "must not be zero");
    }
    if (rs_scene_add_punctual(c->scene, &p) != RS_OK) {
        char msg[300];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return FAIL(c, path, "%s", msg); /* the file and the object named */
    }
    return RS_OK;
}

/* A mesh file through Assimp: its own materials, one scene material for all of it ("material"),
 * or some of its materials replaced by name ("materials": {"file's name": "scene's name"}). */
static rs_status add_mesh(ctx *c, const cJSON *o, const char *path)
{
    static const char *const keys[] = {"type",  "file",   "material", "materials", "scale",
                                       "rotate", "fit",   "transform", NULL};
    static const char *const k_fit[] = {"size", "base", NULL};
    const char *file = "", *names[MAX_OVERRIDES];
    const cJSON *ov = cJSON_GetObjectItemCaseSensitive(o, "materials");
    const cJSON *fit = cJSON_GetObjectItemCaseSensitive(o, "fit");
    uint32_t ids[MAX_OVERRIDES], n = 0, k, first;
    char full[1024], p[256];
    rs_mesh_opts mo = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    rs_mesh_info info;
    rs_status st;
    mo.strict_textures = 1; /* a scene file's textures must be there */
    RS_TRY(check_keys(c, o, path, keys));
    RS_TRY(get_string(c, o, path, "file", &file));
    if (cJSON_GetObjectItemCaseSensitive(o, "material")) {
        if (ov)
            return FAIL(c, path, "give either 'material' or 'materials', not both");
        RS_TRY(object_material(c, o, path, &mo.material));
    }
    if (ov) {
        const cJSON *it;
        subpath(p, sizeof p, path, "materials");
        if (!cJSON_IsObject(ov))
            return FAIL(c, p, "expected {\"file's material\": \"scene material\", ...}");
        for (it = ov->child; it; it = it->next) {
            char q[300];
            snprintf(q, sizeof q, "%s.%s", p, it->string);
            if (n >= MAX_OVERRIDES)
                return FAIL(c, p, "more than %d materials replaced", MAX_OVERRIDES);
            if (!cJSON_IsString(it) || !lookup(c->materials, c->n_materials, it->valuestring, &ids[n]))
                return FAIL(c, q, "no material named %s%s%s", cJSON_IsString(it) ? "'" : "",
                            cJSON_IsString(it) ? it->valuestring : "(not a string)",
                            cJSON_IsString(it) ? "'" : "");
            names[n++] = it->string;
        }
        mo.override_names = names;
        mo.override_ids = ids;
        mo.n_overrides = n;
    }
    /* the thesis's placement, applied to the file's coordinates before the fit: a scale per
     * axis, then rotations about x, y and z (degrees) */
    RS_TRY(get_vec3(c, o, path, "scale", 0, rs_v3(1, 1, 1), &mo.scale));
    subpath(p, sizeof p, path, "scale");
    if (mo.scale.x == 0 || mo.scale.y == 0 || mo.scale.z == 0)
        return FAIL(c, p, "a scale must not be 0 (it would flatten the mesh)");
    RS_TRY(get_vec3(c, o, path, "rotate", 0, rs_v3(0, 0, 0), &mo.rotate_deg));
    if (fit) {
        subpath(p, sizeof p, path, "fit");
        if (!cJSON_IsObject(fit))
            return FAIL(c, p, "expected {\"size\": s, \"base\": [x, y, z]}");
        RS_TRY(check_keys(c, fit, p, k_fit));
        mo.fit = 1;
        RS_TRY(get_num(c, fit, p, "size", 1, 1, 1e-30, 1e30, &mo.fit_size));
        RS_TRY(get_vec3(c, fit, p, "base", 0, rs_v3(0, 0, 0), &mo.fit_base));
    }
    for (k = 0; k < c->n_meshes; ++k)
        if (c->meshes[k].node == o)
            return copy_mesh(c, &c->meshes[k]);
    resolve_path(c, file, full, sizeof full);
    rs_error_clear();
    first = c->scene->n_tris;
    st = rs_scene_add_mesh(c->scene, full, &mo, &info);
    if (st != RS_OK) {
        char msg[600];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return FAIL(c, path, "%s", msg);
    }
    if (c->log) {
        char why[160], mats[160];
        if (mo.material != RS_MESH_FILE_MATERIALS)
            snprintf(mats, sizeof mats, "material '%s'",
                     cJSON_GetObjectItemCaseSensitive(o, "material")->valuestring);
        else
            snprintf(mats, sizeof mats, "%u material%s from the file%s", info.materials,
                     info.materials == 1 ? "" : "s", n ? " and the scene's replacements" : "");
        char strips[64] = "";
        if (info.strips)
            snprintf(strips, sizeof strips, " (from %u triangle strips)", info.strips);
        fprintf(c->log, "raystream: %s: %u triangles%s, %s%s%s\n", full, info.triangles, strips,
                mats, info.dropped ? "; " : "", rs_mesh_dropped_text(&info, why, sizeof why));
    }
    return keep_mesh(c, o, first);
}

static rs_status add_primitive(ctx *c, const cJSON *o, const char *path, const char *type)
{
    static const char *const k_sphere[] = {"type",     "center",    "radius",    "material",
                                           "moving_to", "velocity", "transform", NULL};
    static const char *const k_quad[] = {"type", "q", "u", "v", "material", "transform", NULL};
    static const char *const k_tri[] = {"type", "vertices", "uv", "normals", "material",
                                        "transform", NULL};
    static const char *const k_box[] = {"type",      "min",      "max",       "rotate_y",
                                        "translate", "material", "transform", NULL};
    rs_scene *s = c->scene;
    uint32_t mat;
    if (strcmp(type, "sphere") == 0) {
        rs_vec3 center, to;
        float r;
        RS_TRY(check_keys(c, o, path, k_sphere));
        RS_TRY(get_vec3(c, o, path, "center", 1, rs_v3(0, 0, 0), &center));
        RS_TRY(get_num(c, o, path, "radius", 1, 0, 1e-30, 1e30, &r));
        RS_TRY(object_material(c, o, path, &mat));
        if (cJSON_GetObjectItemCaseSensitive(o, "moving_to") &&
            cJSON_GetObjectItemCaseSensitive(o, "velocity"))
            return FAIL(c, path, "give either 'moving_to' or 'velocity', not both");
        if (cJSON_GetObjectItemCaseSensitive(o, "moving_to")) {
            /* the centre moves linearly from `center` at time 0 to `moving_to` at time 1 */
            RS_TRY(get_vec3(c, o, path, "moving_to", 1, center, &to));
            return rs_scene_add_moving_sphere(s, center, 0.0f, to, 1.0f, r, mat);
        }
        if (cJSON_GetObjectItemCaseSensitive(o, "velocity")) {
            /* the centre at time t is center + t velocity (what `raystream export` writes: the
             * stored motion exactly) */
            rs_vec3 vel;
            RS_TRY(get_vec3(c, o, path, "velocity", 1, center, &vel));
            RS_TRY(
                rs_scene_add_moving_sphere(s, center, 0.0f, rs_v3_add(center, vel), 1.0f, r, mat));
            s->sphere_motion[s->n_spheres - 1] = vel;
            return RS_OK;
        }
        return rs_scene_add_sphere(s, center, r, mat);
    }
    if (strcmp(type, "quad") == 0) {
        rs_vec3 q, u, v;
        RS_TRY(check_keys(c, o, path, k_quad));
        RS_TRY(get_vec3(c, o, path, "q", 1, rs_v3(0, 0, 0), &q));
        RS_TRY(get_vec3(c, o, path, "u", 1, rs_v3(0, 0, 0), &u));
        RS_TRY(get_vec3(c, o, path, "v", 1, rs_v3(0, 0, 0), &v));
        if (rs_v3_is_zero(rs_v3_cross(u, v)))
            return FAIL(c, path, "u and v must span a parallelogram (u x v = 0)");
        RS_TRY(object_material(c, o, path, &mat));
        return rs_scene_add_quad(s, q, u, v, mat);
    }
    if (strcmp(type, "triangle") == 0) {
        const cJSON *vs = cJSON_GetObjectItemCaseSensitive(o, "vertices");
        const cJSON *uv = cJSON_GetObjectItemCaseSensitive(o, "uv");
        const cJSON *nrm = cJSON_GetObjectItemCaseSensitive(o, "normals");
        rs_vec3 p[3];
        float uvs[6], ns[9];
        char sp[256];
        int i;
        RS_TRY(check_keys(c, o, path, k_tri));
        subpath(sp, sizeof sp, path, "vertices");
        if (!cJSON_IsArray(vs) || cJSON_GetArraySize(vs) != 3)
            return FAIL(c, vs ? sp : path, vs ? "expected 3 vertices" : "missing 'vertices'");
        for (i = 0; i < 3; ++i)
            RS_TRY(vec3_of(c, cJSON_GetArrayItem(vs, i), sp, &p[i]));
        RS_TRY(object_material(c, o, path, &mat));
        if (!uv && !nrm)
            return rs_scene_add_triangle(s, p[0], p[1], p[2], mat);
        if (uv) {
            subpath(sp, sizeof sp, path, "uv");
            RS_TRY(read_floats(c, uv, sp, 6, "(u0, v0, u1, v1, u2, v2)", uvs));
        }
        if (nrm) {
            /* unit vertex normals (zeros: the face's), as `raystream export` writes a mesh's */
            subpath(sp, sizeof sp, path, "normals");
            RS_TRY(read_floats(c, nrm, sp, 9, "(three normals)", ns));
        }
        if (!nrm)
            return rs_scene_add_triangle_uv(s, p[0], p[1], p[2], uvs, mat);
        return rs_scene_add_triangle_full(s, p, uv ? uvs : NULL, ns, mat);
    }
    if (strcmp(type, "box") == 0) {
        rs_vec3 lo, hi, t;
        float rot;
        RS_TRY(check_keys(c, o, path, k_box));
        RS_TRY(get_vec3(c, o, path, "min", 1, rs_v3(0, 0, 0), &lo));
        RS_TRY(get_vec3(c, o, path, "max", 1, rs_v3(0, 0, 0), &hi));
        if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
            return FAIL(c, path, "'max' must exceed 'min' on every axis");
        RS_TRY(get_num(c, o, path, "rotate_y", 0, 0.0, -1e6, 1e6, &rot));
        RS_TRY(get_vec3(c, o, path, "translate", 0, rs_v3(0, 0, 0), &t));
        RS_TRY(object_material(c, o, path, &mat));
        return rs_scene_add_box(s, lo, hi, rot, t, mat);
    }
    if (strcmp(type, "mesh") == 0)
        return add_mesh(c, o, path);
    if (strcmp(type, "point_light") == 0 || strcmp(type, "spot_light") == 0 ||
        strcmp(type, "directional_light") == 0)
        return add_punctual(c, o, path, type);
    return FAIL(c, path,
                "unknown object type '%s' (sphere, quad, triangle, box, mesh, instance, "
                "point_light, spot_light, directional_light)",
                type);
}

static rs_status read_object(ctx *c, const cJSON *o, const char *path, const rs_xform *parent);

static const group *find_group(const ctx *c, const char *name)
{
    uint32_t i;
    for (i = 0; i < c->n_groups; ++i)
        if (strcmp(c->groups[i].name, name) == 0)
            return &c->groups[i];
    return NULL;
}

/* Whether group g holds only triangles (triangle and mesh objects, and instances of groups that
 * do): such a group can be instanced.  Unknown groups and cycles answer no (and are reported
 * when the group is copied). */
static int group_of_triangles(ctx *c, group *g, uint32_t depth)
{
    const cJSON *it;
    if (g->shape)
        return g->shape > 0;
    if (depth >= MAX_NESTING)
        return 0;
    g->shape = -1; /* until shown otherwise: also what a cycle finds */
    for (it = g->objects->child; it; it = it->next) {
        const cJSON *t = cJSON_GetObjectItemCaseSensitive(it, "type");
        const char *type = cJSON_IsString(t) ? t->valuestring : "";
        if (strcmp(type, "triangle") == 0 || strcmp(type, "mesh") == 0)
            continue;
        if (strcmp(type, "instance") == 0) {
            const cJSON *gn = cJSON_GetObjectItemCaseSensitive(it, "group");
            group *inner = cJSON_IsString(gn) ? (group *)find_group(c, gn->valuestring) : NULL;
            if (inner && inner != g && group_of_triangles(c, inner, depth + 1))
                continue;
        }
        return 0;
    }
    g->shape = 1;
    return 1;
}

/* A top-level instance of a group of triangles: the group read once (the first time) into a
 * prototype, then placed by xf.  A group whose triangles emit light is copied instead (*copied
 * set): emitters are lights, one per placed triangle. */
static rs_status place_instance(ctx *c, group *g, const char *path, const rs_xform *xf,
                                int *copied)
{
    double m[12];
    int i, j;
    *copied = 0;
    if (!g->made) {
        const cJSON *it;
        rs_xform id = rs_xform_identity();
        rs_scene_mark before = rs_scene_mark_now(c->scene);
        uint32_t from = c->scene->n_tris, k;
        int emits = 0;
        c->stack[c->depth++] = g;
        for (it = g->objects->child, i = 0; it; it = it->next, ++i) {
            char q[300];
            snprintf(q, sizeof q, "groups.%s[%d]", g->name, i);
            RS_TRY(read_object(c, it, q, &id));
            if (rs_scene_prim_count(c->scene) > MAX_PRIMS)
                return FAIL(c, path, "the scene would pass %u primitives", MAX_PRIMS);
        }
        c->depth--;
        /* emitters (lights, one per placed triangle) and cut-outs are copied, as is anything
         * that is not a triangle (a mesh file's lights, should one bring them) */
        for (k = from; k < c->scene->n_tris && !emits; ++k)
            emits = rs_material_is_light(&c->scene->materials[c->scene->tri_mat[k]]) ||
                    c->scene->materials[c->scene->tri_mat[k]].alpha_mask;
        emits |= c->scene->n_spheres != before.n_spheres || c->scene->n_quads != before.n_quads ||
                 c->scene->n_punctuals != before.n_punctuals;
        if (emits) {
            g->shape = -1;
            *copied = 1;
            if (!rs_xform_is_identity(xf) &&
                rs_scene_transform_since(c->scene, &before, xf) != RS_OK) {
                char msg[400];
                snprintf(msg, sizeof msg, "%s", rs_error_message());
                rs_error_clear();
                return FAIL(c, path, "%s", msg);
            }
            return RS_OK;
        }
        if (rs_scene_make_prototype(c->scene, from, &g->first, &g->n) != RS_OK)
            return FAIL(c, path, "out of memory");
        g->made = 1;
    }
    if (g->n == 0)
        return RS_OK; /* an empty group places nothing */
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j)
            m[4 * i + j] = xf->m[i][j];
        m[4 * i + 3] = xf->t[i];
    }
    if (rs_scene_add_instance(c->scene, g->first, g->n, m) != RS_OK) {
        char msg[400];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return FAIL(c, path, "%s", msg);
    }
    g->placed++;
    return RS_OK;
}

/* An instance of a group: at the top level, a group of triangles is placed (place_instance);
 * otherwise the group's objects, each under its own transform and then this one's (xf), are
 * copied into the scene. */
static rs_status read_instance(ctx *c, const cJSON *o, const char *path, const rs_xform *xf)
{
    static const char *const keys[] = {"type", "group", "transform", NULL};
    const char *name = "";
    const cJSON *it;
    group *g;
    uint32_t k, before = rs_scene_prim_count(c->scene);
    char p[256];
    int i = 0;
    RS_TRY(check_keys(c, o, path, keys));
    RS_TRY(get_string(c, o, path, "group", &name));
    subpath(p, sizeof p, path, "group");
    g = (group *)find_group(c, name);
    if (!g)
        return FAIL(c, p, "no group named '%s'", name);
    for (k = 0; k < c->depth; ++k)
        if (c->stack[k] == g) {
            char chain[512] = "";
            for (; k < c->depth; ++k)
                snprintf(chain + strlen(chain), sizeof chain - strlen(chain), "%s -> ",
                         c->stack[k]->name);
            return FAIL(c, p, "instances form a cycle: %s%s", chain, name);
        }
    if (c->depth >= MAX_NESTING)
        return FAIL(c, p, "instances nested more than %d deep", MAX_NESTING);
    if (g->known && (uint64_t)before + g->prims > MAX_PRIMS)
        return FAIL(c, path, "the scene would pass %u primitives (this group is copied, not instanced)",
                    MAX_PRIMS);
    if (c->depth == 0)
        snprintf(c->instance_path, sizeof c->instance_path, "%s", path);
    if (c->depth == 0 && group_of_triangles(c, g, 0)) {
        int copied;
        RS_TRY(place_instance(c, g, path, xf, &copied));
        if (!copied)
            return RS_OK;
        g->prims = rs_scene_prim_count(c->scene) - before;
        g->known = 1;
        return RS_OK;
    }
    c->stack[c->depth++] = g;
    for (it = g->objects->child; it; it = it->next, ++i) {
        char q[300];
        snprintf(q, sizeof q, "groups.%s[%d]", g->name, i);
        RS_TRY(read_object(c, it, q, xf));
        if (rs_scene_prim_count(c->scene) > MAX_PRIMS)
            return FAIL(c, path, "the scene would pass %u primitives (this group is copied, not instanced)",
                        MAX_PRIMS);
    }
    c->depth--;
    g->prims = rs_scene_prim_count(c->scene) - before;
    g->known = 1;
    return RS_OK;
}

static rs_status read_object(ctx *c, const cJSON *o, const char *path, const rs_xform *parent)
{
    const char *type = "";
    rs_scene_mark mark = rs_scene_mark_now(c->scene);
    rs_xform own, xf;
    if (!cJSON_IsObject(o))
        return FAIL(c, path, "expected an object");
    RS_TRY(get_string(c, o, path, "type", &type));
    RS_TRY(read_transform(c, o, path, &own));
    xf = rs_xform_compose(parent, &own);
    if (strcmp(type, "instance") == 0)
        return read_instance(c, o, path, &xf);
    RS_TRY(add_primitive(c, o, path, type));
    if (!rs_xform_is_identity(&xf) && rs_scene_transform_since(c->scene, &mark, &xf) != RS_OK) {
        char msg[400], p[256];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        if (c->depth)
            return FAIL(c, path, "%s (placed by the instance at %s)", msg, c->instance_path);
        subpath(p, sizeof p, path, "transform");
        return FAIL(c, p, "%s", msg);
    }
    return RS_OK;
}

/* Reads a name -> definition map (textures, materials) in file order. */
static rs_status read_map(ctx *c, const cJSON *root, const char *key,
                          rs_status (*read)(ctx *, const cJSON *, const char *, const char *),
                          uint32_t *count)
{
    const cJSON *map = cJSON_GetObjectItemCaseSensitive(root, key), *it;
    if (!map)
        return RS_OK;
    if (!cJSON_IsObject(map))
        return FAIL(c, key, "expected an object of named definitions");
    for (it = map->child; it; it = it->next) {
        char p[256];
        uint32_t dummy;
        snprintf(p, sizeof p, "%s.%s", key, it->string);
        if (!*it->string)
            return FAIL(c, key, "names must not be empty");
        if (*count >= MAX_NAMES)
            return FAIL(c, key, "more than %d definitions", MAX_NAMES);
        if ((read == read_material && lookup(c->materials, c->n_materials, it->string, &dummy)) ||
            (read == read_texture && lookup(c->textures, c->n_textures, it->string, &dummy)))
            return FAIL(c, p, "defined twice");
        RS_TRY(read(c, it, p, it->string));
    }
    return RS_OK;
}

/* Checks the whole tree before it is read: no key twice in one object (cJSON would keep both
 * and the reader see only the first) and no number that is not finite (cJSON reads 1e999 as
 * inf) or beyond a float's range, wherever they are. */
static rs_status check_tree(const ctx *c, const cJSON *it, const char *path)
{
    const cJSON *a, *b;
    int i = 0;
    if (cJSON_IsNumber(it)) {
        if (!isfinite(it->valuedouble) || fabs(it->valuedouble) > FLT_MAX)
            return FAIL(c, *path ? path : "(top level)", "number out of range (not finite)");
        return RS_OK;
    }
    if (!cJSON_IsObject(it) && !cJSON_IsArray(it))
        return RS_OK;
    for (a = it->child; a; a = a->next, ++i) {
        char p[256];
        if (cJSON_IsObject(it)) {
            for (b = it->child; b != a; b = b->next)
                if (strcmp(a->string, b->string) == 0)
                    return FAIL(c, *path ? path : "(top level)", "key '%s' appears twice",
                                a->string);
            subpath(p, sizeof p, path, a->string);
        } else {
            snprintf(p, sizeof p, "%s[%d]", path, i);
        }
        RS_TRY(check_tree(c, a, p));
    }
    return RS_OK;
}

/* The file's name for what rs_scene_finalize refused (scene->bad_part, bad_index): the object
 * that made the primitive (objects[3]), the material's name, the background.  0 if none. */
static int part_path(const ctx *c, char *out, size_t n)
{
    const rs_scene *s = c->scene;
    uint32_t k = 0, i;
    switch (s->bad_part) {
    case RS_PART_SPHERE: k = 0; break;
    case RS_PART_QUAD: k = 1; break;
    case RS_PART_TRIANGLE: k = 2; break;
    case RS_PART_INSTANCE: k = 3; break;
    case RS_PART_MATERIAL:
        for (i = 0; i < c->n_materials; ++i)
            if (c->materials[i].id == s->bad_index) {
                snprintf(out, n, "materials.%s", c->materials[i].name);
                return 1;
            }
        return 0;
    case RS_PART_ENVIRONMENT: snprintf(out, n, "background.map"); return 1;
    case RS_PART_CAMERA: snprintf(out, n, "camera.from"); return 1;
    default: return 0;
    }
    for (i = c->n_obj; i-- > 0;)
        if (c->obj_start[i][k] <= s->bad_index) {
            snprintf(out, n, "objects[%u]", i);
            return 1;
        }
    return 0;
}

static rs_status build(ctx *c, const cJSON *root)
{
    static const char *const keys[] = {"camera",    "image",   "background", "textures",
                                       "materials", "groups",  "objects",    NULL};
    const cJSON *objs, *it, *groups;
    rs_xform id = rs_xform_identity();
    int i = 0;
    if (!cJSON_IsObject(root))
        return rs_error_set(RS_ERR_ARG, "%s: the scene must be a JSON object", c->label);
    RS_TRY(check_tree(c, root, ""));
    RS_TRY(check_keys(c, root, "(top level)", keys));
    if (!cJSON_GetObjectItemCaseSensitive(root, "camera"))
        return FAIL(c, "(top level)", "missing 'camera'");
    RS_TRY(read_camera(c, cJSON_GetObjectItemCaseSensitive(root, "camera")));
    if (cJSON_GetObjectItemCaseSensitive(root, "image"))
        RS_TRY(read_image_size(c, cJSON_GetObjectItemCaseSensitive(root, "image")));
    if (cJSON_GetObjectItemCaseSensitive(root, "background"))
        RS_TRY(read_background(c, cJSON_GetObjectItemCaseSensitive(root, "background")));
    RS_TRY(read_map(c, root, "textures", read_texture, &c->n_textures));
    RS_TRY(read_map(c, root, "materials", read_material, &c->n_materials));
    groups = cJSON_GetObjectItemCaseSensitive(root, "groups");
    if (groups) {
        if (!cJSON_IsObject(groups))
            return FAIL(c, "groups", "expected an object of named groups: {\"name\": [objects]}");
        for (it = groups->child; it; it = it->next) {
            char p[256];
            snprintf(p, sizeof p, "groups.%s", it->string);
            if (!*it->string)
                return FAIL(c, "groups", "names must not be empty");
            if (c->n_groups >= MAX_NAMES)
                return FAIL(c, "groups", "more than %d groups", MAX_NAMES);
            if (!cJSON_IsArray(it))
                return FAIL(c, p, "expected an array of objects");
            c->groups[c->n_groups].name = it->string;
            c->groups[c->n_groups++].objects = it;
        }
    }
    objs = cJSON_GetObjectItemCaseSensitive(root, "objects");
    if (!objs)
        return FAIL(c, "(top level)", "missing 'objects'");
    if (!cJSON_IsArray(objs))
        return FAIL(c, "objects", "expected an array");
    c->obj_start = (uint32_t(*)[4])rs_calloc((size_t)cJSON_GetArraySize(objs) + 1,
                                             sizeof *c->obj_start);
    if (!c->obj_start)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", c->label);
    for (it = objs->child; it; it = it->next, ++i) {
        char p[64];
        const rs_scene *sc = c->scene;
        uint32_t *st = c->obj_start[c->n_obj++];
        st[0] = sc->n_spheres, st[1] = sc->n_quads, st[2] = sc->n_tris, st[3] = sc->n_instances;
        snprintf(p, sizeof p, "objects[%d]", i);
        RS_TRY(read_object(c, it, p, &id));
    }
    if (c->log) {
        uint32_t g;
        for (g = 0; g < c->n_groups; ++g)
            if (c->groups[g].made && c->groups[g].placed)
                fprintf(c->log,
                        "raystream: %s: group '%s': %u triangles placed %u time%s (instanced: "
                        "one copy in memory)\n",
                        c->label, c->groups[g].name, c->groups[g].n, c->groups[g].placed,
                        c->groups[g].placed == 1 ? "" : "s");
    }
    return RS_OK;
}

/* The bytes of a scene file before cJSON reads them: UTF-8 throughout, no control byte but
 * tab, newline and carriage return (cJSON took NUL and others for white space), and no NUL
 * character in a string, escaped or not (cJSON cut "w\u0000junk" to "w").  Line numbers in the
 * message. */
static rs_status check_text(const char *label, const char *text, size_t len)
{
    const unsigned char *b = (const unsigned char *)text;
    size_t i = 0, line = 1;
    if (len >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF)
        i = 3; /* a byte order mark */
    while (i < len) {
        unsigned c = b[i];
        size_t k, n = c < 0x80 ? 1 : (c & 0xE0) == 0xC0 ? 2 : (c & 0xF0) == 0xE0 ? 3
                                   : (c & 0xF8) == 0xF0 ? 4 : 0;
        unsigned cp = n == 1 ? c : n == 2 ? c & 0x1F : n == 3 ? c & 0x0F : c & 0x07;
        if (c == '\n')
            ++line;
        if (c < 0x20 && c != '\t' && c != '\n' && c != '\r')
            return rs_error_set(RS_ERR_ARG,
                                "%s:%zu: a control byte (0x%02x) in the text: a scene file is "
                                "UTF-8 text",
                                label, line, c);
        if (c == 0x7f)
            return rs_error_set(RS_ERR_ARG, "%s:%zu: a control byte (0x7f) in the text", label,
                                line);
        if (c == '\\' && i + 5 < len && b[i + 1] == 'u' && b[i + 2] == '0' && b[i + 3] == '0' &&
            b[i + 4] == '0' && b[i + 5] == '0')
            return rs_error_set(RS_ERR_ARG, "%s:%zu: a NUL character (\\u0000) in a string",
                                label, line);
        if (c == '\\' && i + 1 < len) { /* an escape: its next byte is not a new escape */
            i += 2;
            continue;
        }
        for (k = 1; n && k < n; ++k) {
            if (i + k >= len || (b[i + k] & 0xC0) != 0x80) {
                n = 0;
                break;
            }
            cp = cp << 6 | (b[i + k] & 0x3F);
        }
        /* overlong forms, surrogates and code points past U+10FFFF are not UTF-8 either */
        if (!n || (n == 2 && cp < 0x80) || (n == 3 && cp < 0x800) || (n == 4 && cp < 0x10000) ||
            (cp >= 0xD800 && cp <= 0xDFFF) || cp > 0x10FFFF)
            return rs_error_set(RS_ERR_ARG,
                                "%s:%zu: not UTF-8 (byte 0x%02x): save the scene file as UTF-8",
                                label, line, c);
        i += n;
    }
    return RS_OK;
}

rs_status rs_scene_parse_json(const char *text, size_t len, const char *label, const char *base_dir,
                              rs_scene **out)
{
    return rs_scene_parse_json_ex(text, len, label, base_dir, NULL, out);
}

rs_status rs_scene_parse_json_ex(const char *text, size_t len, const char *label,
                                 const char *base_dir, FILE *log, rs_scene **out)
{
    const char *end = NULL;
    cJSON *root;
    ctx *c;
    rs_status st;
    *out = NULL;
    if ((st = check_text(label, text, len)) != RS_OK)
        return st;
    root = cJSON_ParseWithLengthOpts(text, len, &end, 0);
    if (!root) {
        /* the line of the syntax error: count newlines up to where parsing stopped */
        size_t line = 1, i,
               stop = end && end >= text && end <= text + len ? (size_t)(end - text) : len;
        for (i = 0; i < stop; ++i)
            line += text[i] == '\n';
        return rs_error_set(RS_ERR_ARG, "%s:%zu: JSON syntax error", label, line);
    }
    if (end && end >= text && end <= text + len) {
        /* one JSON value and nothing after it but white space */
        const char *p = end;
        while (p < text + len && (*p == ' ' || *p == '\t' || *p == '\n' || *p == '\r'))
            ++p;
        if (p < text + len) {
            size_t line = 1, i;
            for (i = 0; i < (size_t)(p - text); ++i)
                line += text[i] == '\n';
            cJSON_Delete(root);
            return rs_error_set(RS_ERR_ARG, "%s:%zu: unexpected content after the JSON value",
                                label, line);
        }
    }
    c = (ctx *)rs_calloc(1, sizeof *c);
    if (!c) {
        cJSON_Delete(root);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", label);
    }
    c->label = label;
    c->base_dir = base_dir;
    c->log = log;
    st = rs_scene_create(label, &c->scene);
    if (st == RS_OK)
        st = build(c, root);
    if (st == RS_OK) {
        st = rs_scene_finalize(c->scene);
        if (st != RS_OK) {
            /* finalize names the primitive or material as the scene holds it; name it as the
             * file does, and prefix the file */
            char msg[400], where[160];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            if (part_path(c, where, sizeof where)) {
                const char *why = strstr(msg, ": "); /* after the scene's own name for it */
                st = rs_error_set(st, "%s: %s: %s", label, where, why ? why + 2 : msg);
            } else {
                st = rs_error_set(st, "%s: %s", label, msg);
            }
        }
    }
    if (st == RS_OK)
        *out = c->scene;
    else
        rs_scene_destroy(c->scene);
    cJSON_Delete(root);
    {
        uint32_t k;
        for (k = 0; k < c->n_meshes; ++k) {
            rs_free(c->meshes[k].tris), rs_free(c->meshes[k].mat);
            rs_free(c->meshes[k].uv), rs_free(c->meshes[k].normal);
        }
        rs_free(c->meshes);
    }
    rs_free(c->obj_start);
    rs_free(c);
    return st;
}

rs_status rs_scene_load_json(const char *path, rs_scene **out)
{
    return rs_scene_load_json_ex(path, NULL, out);
}

rs_status rs_scene_load_json_ex(const char *path, FILE *log, rs_scene **out)
{
    char *text, dir[1024];
    const char *slash;
    size_t n;
    rs_status st;
    *out = NULL;
    /* a regular file of a sane size only: a FIFO or /dev/zero would never end */
    st = rs_file_read(path, RS_FILE_MAX_SCENE_BYTES, &text, &n);
    if (st != RS_OK)
        return st;
    slash = strrchr(path, '/');
    if (slash)
        snprintf(dir, sizeof dir, "%.*s", (int)(slash - path), path);
    else
        snprintf(dir, sizeof dir, ".");
    st = rs_scene_parse_json_ex(text, n, path, dir, log, out);
    rs_free(text);
    return st;
}
