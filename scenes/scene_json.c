/* scenes/scene_json.c — the JSON scene reader (see scene_json.h and docs/scene-format.md): the
 * file's checks (no key twice, no number out of range), its camera, image and background, its
 * textures, materials, groups and objects in that order (json_materials.c, json_objects.c, with
 * the fields of json_values.c), and the finalized scene's refusals named by the file's paths.
 *
 * Every object is checked against the keys it may have; every value against its type and range.
 * Paths in messages are JSON paths: objects[3].radius, materials.glass.ior. */
#include "scenes/scene_json.h"
#include "scenes/json_internal.h"
#include "scenes/sky.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/try.h"
#include "scenes/mesh.h"

static rs_status read_camera(ctx *c, const cJSON *cam)
{
    static const char *const keys[] = {"from",           "at",      "up", "vfov", "aperture",
                                       "focus_distance", "shutter", NULL};
    rs_camera_desc cd = c->scene->camera, *d = &cd;
    const cJSON *sh;
    if (!cJSON_IsObject(cam))
        return FAIL(c, "camera", "expected an object");
    RS_TRY(rs_json_check_keys(c, cam, "camera", keys));
    RS_TRY(rs_json_get_vec3(c, cam, "camera", "from", 1, rs_v3(0, 0, 0), &d->from));
    RS_TRY(rs_json_get_vec3(c, cam, "camera", "at", 1, rs_v3(0, 0, 0), &d->at));
    RS_TRY(rs_json_get_vec3(c, cam, "camera", "up", 0, rs_v3(0, 1, 0), &d->up));
    RS_TRY(rs_json_get_num(c, cam, "camera", "vfov", 0, 40.0, 1e-3, 179.0, &d->vfov_deg));
    RS_TRY(rs_json_get_num(c, cam, "camera", "aperture", 0, 0.0, 0.0, 1e30, &d->aperture));
    RS_TRY(rs_json_get_num(c, cam, "camera", "focus_distance", 0, 0.0, 0.0, 1e30, &d->focus_dist));
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
    rs_scene_set_camera(c->scene, d);
    return RS_OK;
}

static rs_status read_image_size(ctx *c, const cJSON *img)
{
    static const char *const keys[] = {"width", "height", NULL};
    float w, h;
    if (!cJSON_IsObject(img))
        return FAIL(c, "image", "expected an object");
    RS_TRY(rs_json_check_keys(c, img, "image", keys));
    RS_TRY(rs_json_get_num(c, img, "image", "width", 0, 512, 1, 32768, &w));
    RS_TRY(rs_json_get_num(c, img, "image", "height", 0, 512, 1, 32768, &h));
    if (w != floorf(w) || h != floorf(h))
        return FAIL(c, "image", "width and height must be whole numbers");
    rs_scene_set_image_size(c->scene, (uint32_t)w, (uint32_t)h);
    return RS_OK;
}


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
    RS_TRY(rs_json_check_keys(c, bg, "background", keys));
    RS_TRY(rs_json_get_string(c, bg, "background", "map", &file));
    if (sc && cJSON_IsNumber(sc)) {
        if (!(sc->valuedouble >= 0) || sc->valuedouble > 1e30)
            return FAIL(c, "background.scale", "must be >= 0");
        scale = rs_v3_splat((float)sc->valuedouble);
    } else if (sc) {
        RS_TRY(rs_json_get_color(c, bg, "background", "scale", 1, scale, &scale));
    }
    for (i = 0; i < 9; ++i)
        r[i] = (i % 4 == 0) ? 1.0f : 0.0f;
    if (rot) {
        /* the map turns by `rotate` in the world: directions go back by its inverse */
        rs_xform x;
        RS_TRY(rs_json_read_rotation(c, rot, "background.rotate", &x));
        for (i = 0; i < 3; ++i)
            for (k = 0; k < 3; ++k)
                r[3 * i + k] = (float)x.m[k][i];
    }
    rs_json_resolve_path(c, file, full, sizeof full);
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
    RS_TRY(rs_json_check_keys(c, bg, "background", keys));
    if (!cJSON_IsObject(sky))
        return FAIL(c, "background.sky",
                    "expected {\"elevation\": .., \"azimuth\": .., ...} or {}");
    RS_TRY(rs_json_check_keys(c, sky, "background.sky", sky_keys));
    rs_sky_defaults(&p); /* the ranges are scenes/sky.h's */
    RS_TRY(rs_json_get_num(c, sky, "background.sky", "elevation", 0, p.elevation_deg, 0, 90,
                           &p.elevation_deg));
    RS_TRY(rs_json_get_num(c, sky, "background.sky", "azimuth", 0, p.azimuth_deg, -360, 360,
                           &p.azimuth_deg));
    RS_TRY(rs_json_get_num(c, sky, "background.sky", "turbidity", 0, p.turbidity, 2, 10,
                           &p.turbidity));
    RS_TRY(rs_json_get_num(c, sky, "background.sky", "intensity", 0, p.intensity, 0, 1e6,
                           &p.intensity));
    RS_TRY(rs_json_get_bool(c, sky, "background.sky", "sun", 1, &p.sun));
    return rs_scene_set_sky(c->scene, &p);
}

static rs_status read_background(ctx *c, const cJSON *bg)
{
    static const char *const keys[] = {"horizon", "zenith", NULL};
    rs_vec3 horizon, zenith;
    if (cJSON_IsObject(bg) && cJSON_GetObjectItemCaseSensitive(bg, "map"))
        return read_envmap(c, bg);
    if (cJSON_IsObject(bg) && cJSON_GetObjectItemCaseSensitive(bg, "sky"))
        return read_sky(c, bg);
    if (cJSON_IsArray(bg)) {
        RS_TRY(rs_json_vec3_of(c, bg, "background", &horizon));
        if (horizon.x < 0 || horizon.y < 0 || horizon.z < 0)
            return FAIL(c, "background", "colour components must be >= 0");
        rs_scene_set_background(c->scene, horizon);
        return RS_OK;
    }
    if (!cJSON_IsObject(bg))
        return FAIL(c, "background", "expected [r, g, b] or {\"horizon\": .., \"zenith\": ..}");
    RS_TRY(rs_json_check_keys(c, bg, "background", keys));
    RS_TRY(rs_json_get_color(c, bg, "background", "horizon", 1, rs_v3(0, 0, 0), &horizon));
    RS_TRY(rs_json_get_color(c, bg, "background", "zenith", 1, rs_v3(0, 0, 0), &zenith));
    rs_scene_set_background_gradient(c->scene, horizon, zenith);
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
        if ((read == rs_json_read_material &&
             rs_json_lookup(c->materials, c->n_materials, it->string, &dummy)) ||
            (read == rs_json_read_texture &&
             rs_json_lookup(c->textures, c->n_textures, it->string, &dummy)))
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
            rs_json_subpath(p, sizeof p, path, a->string);
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
    RS_TRY(rs_json_check_keys(c, root, "(top level)", keys));
    if (!cJSON_GetObjectItemCaseSensitive(root, "camera"))
        return FAIL(c, "(top level)", "missing 'camera'");
    RS_TRY(read_camera(c, cJSON_GetObjectItemCaseSensitive(root, "camera")));
    if (cJSON_GetObjectItemCaseSensitive(root, "image"))
        RS_TRY(read_image_size(c, cJSON_GetObjectItemCaseSensitive(root, "image")));
    if (cJSON_GetObjectItemCaseSensitive(root, "background"))
        RS_TRY(read_background(c, cJSON_GetObjectItemCaseSensitive(root, "background")));
    RS_TRY(read_map(c, root, "textures", rs_json_read_texture, &c->n_textures));
    RS_TRY(read_map(c, root, "materials", rs_json_read_material, &c->n_materials));
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
        RS_TRY(rs_json_read_object(c, it, p, &id));
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

/* A context over `s` for one JSON value of the API's (a material, a light): rs_free it. */
static rs_status one_value(rs_scene *s, const char *text, const char *label, cJSON **v, ctx **c)
{
    *c = NULL;
    if (!text || !*text)
        return rs_error_set(RS_ERR_ARG, "%s: expected a JSON object, not an empty text", label);
    if (!(*v = cJSON_Parse(text)))
        return rs_error_set(RS_ERR_ARG, "%s: JSON syntax error", label);
    if (!(*c = (ctx *)rs_calloc(1, sizeof **c))) {
        cJSON_Delete(*v);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", label);
    }
    (*c)->label = label;
    (*c)->scene = s;
    return RS_OK;
}

rs_status rs_scene_add_material_json(rs_scene *s, const char *text, const char *label, uint32_t *id)
{
    cJSON *m = NULL;
    ctx *c;
    rs_status st = one_value(s, text, label, &m, &c);
    if (st != RS_OK)
        return st;
    st = rs_json_read_material(c, m, "material", "");
    if (st == RS_OK)
        *id = c->materials[0].id;
    cJSON_Delete(m);
    rs_free(c);
    return st;
}

rs_status rs_scene_add_light_json(rs_scene *s, const char *text, const char *label)
{
    static const char *const types[] = {"point_light", "spot_light", "directional_light", NULL};
    const cJSON *type;
    cJSON *o = NULL;
    ctx *c;
    rs_xform id = rs_xform_identity();
    rs_status st = one_value(s, text, label, &o, &c);
    int i, known = 0;
    if (st != RS_OK)
        return st;
    type = cJSON_GetObjectItemCaseSensitive(o, "type");
    for (i = 0; types[i] && cJSON_IsString(type); ++i)
        known |= strcmp(type->valuestring, types[i]) == 0;
    st = known ? rs_json_read_object(c, o, "light", &id)
               : FAIL(c, "light.type", "expected point_light, spot_light or directional_light");
    cJSON_Delete(o);
    rs_free(c);
    return st;
}
