/* scenes/json_objects.c — the objects of a JSON scene (scenes/json_internal.h;
 * docs/scene-format.md): spheres, quads, triangles, boxes, meshes (read once where instances
 * place them many times), punctual lights, their transforms, and groups placed by instances:
 * groups of triangles instanced, others copied. */
#include "scenes/json_internal.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/try.h"
#include "scenes/mesh.h"

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
    RS_TRY(rs_json_check_keys(c, st, p, keys));
    it = st->child;
    rs_json_subpath(q, sizeof q, p, it->string);
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
        RS_TRY(rs_json_vec3_of(c, it, q, &v));
        *out = rs_xform_translate(v.x, v.y, v.z);
        return RS_OK;
    }
    if (strcmp(it->string, "scale") == 0) {
        if (cJSON_IsNumber(it))
            v = rs_v3_splat((float)it->valuedouble);
        else
            RS_TRY(rs_json_vec3_of(c, it, q, &v));
        if (v.x == 0 || v.y == 0 || v.z == 0)
            return FAIL(c, q, "a scale must not be 0 (it would flatten the object)");
        *out = rs_xform_scale(v.x, v.y, v.z);
        return RS_OK;
    }
    return rs_json_read_rotation(c, it, q, out);
}

/* A rotation: [x, y, z] (degrees about x, then y, then z), {"axis": [x, y, z], "degrees": a},
 * or {"matrix": [9 numbers, row by row]} (orthonormal with determinant 1 to 1e-4). */
rs_status rs_json_read_rotation(ctx *c, const cJSON *it, const char *q, rs_xform *out)
{
    static const char *const k_axis[] = {"axis", "degrees", NULL};
    static const char *const k_mat[] = {"matrix", NULL};
    rs_vec3 v;
    if (cJSON_IsObject(it) && cJSON_GetObjectItemCaseSensitive(it, "matrix")) {
        const cJSON *m = cJSON_GetObjectItemCaseSensitive(it, "matrix");
        char mp[300];
        double scale;
        int i;
        RS_TRY(rs_json_check_keys(c, it, q, k_mat));
        rs_json_subpath(mp, sizeof mp, q, "matrix");
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
        RS_TRY(rs_json_check_keys(c, it, q, k_axis));
        RS_TRY(rs_json_get_vec3(c, it, q, "axis", 1, rs_v3(0, 0, 0), &v));
        RS_TRY(rs_json_get_num(c, it, q, "degrees", 1, 0, -1e6, 1e6, &deg));
        rs_json_subpath(ap, sizeof ap, q, "axis");
        if (rs_v3_is_zero(v))
            return FAIL(c, ap, "the axis must not be zero");
        axis[0] = v.x, axis[1] = v.y, axis[2] = v.z;
        *out = rs_xform_rotate_axis(axis, deg);
        return RS_OK;
    }
    if (!cJSON_IsArray(it))
        return FAIL(c, q, "expected [x, y, z] (Euler angles in degrees) or {\"axis\": [x, y, z], "
                          "\"degrees\": a}");
    RS_TRY(rs_json_vec3_of(c, it, q, &v));
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
    rs_json_subpath(p, sizeof p, path, "transform");
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
        RS_TRY(rs_json_check_keys(c, o, path, k_point));
        RS_TRY(rs_json_get_vec3(c, o, path, "position", 1, rs_v3(0, 0, 0), &p.pos));
        RS_TRY(rs_json_get_color(c, o, path, "intensity", 1, rs_v3(0, 0, 0), &p.intensity));
    } else if (type[0] == 's') {
        float inner, outer;
        char q[256];
        p.type = RS_PUNCTUAL_SPOT;
        RS_TRY(rs_json_check_keys(c, o, path, k_spot));
        RS_TRY(rs_json_get_vec3(c, o, path, "position", 1, rs_v3(0, 0, 0), &p.pos));
        RS_TRY(rs_json_get_vec3(c, o, path, "direction", 1, rs_v3(0, 0, 0), &p.dir));
        RS_TRY(rs_json_get_color(c, o, path, "intensity", 1, rs_v3(0, 0, 0), &p.intensity));
        RS_TRY(rs_json_get_num(c, o, path, "inner", 0, 0.0, 0.0, 90.0, &inner));
        RS_TRY(rs_json_get_num(c, o, path, "outer", 0, 45.0, 0.0, 90.0, &outer));
        rs_json_subpath(q, sizeof q, path, "outer");
        if (outer < inner)
            return FAIL(c, q, "the outer cone must not be narrower than the inner");
        /* 90 degrees in float radians is a little past pi/2: its cosf is -4.4e-8, held at 0 */
        p.cos_inner = fmaxf(0.0f, cosf(inner * 0.017453292519943295f));
        p.cos_outer = fmaxf(0.0f, cosf(outer * 0.017453292519943295f));
    } else {
        p.type = RS_PUNCTUAL_DIRECTIONAL;
        RS_TRY(rs_json_check_keys(c, o, path, k_dir));
        RS_TRY(rs_json_get_vec3(c, o, path, "direction", 1, rs_v3(0, 0, 0), &p.dir));
        RS_TRY(rs_json_get_color(c, o, path, "irradiance", 1, rs_v3(0, 0, 0), &p.intensity));
    }
    if (p.type != RS_PUNCTUAL_POINT && rs_v3_is_zero(p.dir)) {
        char q[256];
        rs_json_subpath(q, sizeof q, path, "direction");
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
/* A mesh object's "materials": the file's materials replaced by scene materials, by name. */
static rs_status mesh_overrides(ctx *c, const cJSON *ov, const char *path, const char **names,
                                uint32_t *ids, uint32_t *n_out)
{
    const cJSON *it;
    char p[256];
    uint32_t n = 0;
    rs_json_subpath(p, sizeof p, path, "materials");
    if (!cJSON_IsObject(ov))
        return FAIL(c, p, "expected {\"file's material\": \"scene material\", ...}");
    for (it = ov->child; it; it = it->next) {
        char q[300];
        snprintf(q, sizeof q, "%s.%s", p, it->string);
        if (n >= MAX_OVERRIDES)
            return FAIL(c, p, "more than %d materials replaced", MAX_OVERRIDES);
        if (!cJSON_IsString(it) ||
            !rs_json_lookup(c->materials, c->n_materials, it->valuestring, &ids[n]))
            return FAIL(c, q, "no material named %s%s%s", cJSON_IsString(it) ? "'" : "",
                        cJSON_IsString(it) ? it->valuestring : "(not a string)",
                        cJSON_IsString(it) ? "'" : "");
        names[n++] = it->string;
    }
    *n_out = n;
    return RS_OK;
}

/* The thesis's placement, applied to the file's coordinates before the fit: a scale per axis,
 * then rotations about x, y and z (degrees); and the fit, where asked for. */
static rs_status mesh_placement(ctx *c, const cJSON *o, const char *path, rs_mesh_opts *mo)
{
    static const char *const k_fit[] = {"size", "base", NULL};
    const cJSON *fit = cJSON_GetObjectItemCaseSensitive(o, "fit");
    char p[256];
    RS_TRY(rs_json_get_vec3(c, o, path, "scale", 0, rs_v3(1, 1, 1), &mo->scale));
    rs_json_subpath(p, sizeof p, path, "scale");
    if (mo->scale.x == 0 || mo->scale.y == 0 || mo->scale.z == 0)
        return FAIL(c, p, "a scale must not be 0 (it would flatten the mesh)");
    RS_TRY(rs_json_get_vec3(c, o, path, "rotate", 0, rs_v3(0, 0, 0), &mo->rotate_deg));
    if (fit) {
        rs_json_subpath(p, sizeof p, path, "fit");
        if (!cJSON_IsObject(fit))
            return FAIL(c, p, "expected {\"size\": s, \"base\": [x, y, z]}");
        RS_TRY(rs_json_check_keys(c, fit, p, k_fit));
        mo->fit = 1;
        RS_TRY(rs_json_get_num(c, fit, p, "size", 1, 1, 1e-30, 1e30, &mo->fit_size));
        RS_TRY(rs_json_get_vec3(c, fit, p, "base", 0, rs_v3(0, 0, 0), &mo->fit_base));
    }
    return RS_OK;
}

/* The line for c->log about mesh file `full` as read (n_overrides of its materials replaced). */
static void mesh_log(const ctx *c, const cJSON *o, const char *full, const rs_mesh_opts *mo,
                     const rs_mesh_info *info, uint32_t n_overrides)
{
    char why[160], mats[160], strips[64] = "";
    if (mo->material != RS_MESH_FILE_MATERIALS)
        snprintf(mats, sizeof mats, "material '%s'",
                 cJSON_GetObjectItemCaseSensitive(o, "material")->valuestring);
    else
        snprintf(mats, sizeof mats, "%u material%s from the file%s", info->materials,
                 info->materials == 1 ? "" : "s",
                 n_overrides ? " and the scene's replacements" : "");
    if (info->strips)
        snprintf(strips, sizeof strips, " (from %u triangle strips)", info->strips);
    fprintf(c->log, "raystream: %s: %u triangles%s, %s%s%s\n", full, info->triangles, strips,
            mats, info->dropped ? "; " : "", rs_mesh_dropped_text(info, why, sizeof why));
}

static rs_status add_mesh(ctx *c, const cJSON *o, const char *path)
{
    static const char *const keys[] = {"type",  "file",   "material", "materials", "scale",
                                       "rotate", "fit",   "transform", NULL};
    const char *file = "", *names[MAX_OVERRIDES];
    const cJSON *ov = cJSON_GetObjectItemCaseSensitive(o, "materials");
    uint32_t ids[MAX_OVERRIDES], n = 0, k, first;
    char full[1024];
    rs_mesh_opts mo = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    rs_mesh_info info;
    rs_status st;
    mo.strict_textures = 1; /* a scene file's textures must be there */
    RS_TRY(rs_json_check_keys(c, o, path, keys));
    RS_TRY(rs_json_get_string(c, o, path, "file", &file));
    if (cJSON_GetObjectItemCaseSensitive(o, "material")) {
        if (ov)
            return FAIL(c, path, "give either 'material' or 'materials', not both");
        RS_TRY(rs_json_object_material(c, o, path, &mo.material));
    }
    if (ov) {
        RS_TRY(mesh_overrides(c, ov, path, names, ids, &n));
        mo.override_names = names;
        mo.override_ids = ids;
        mo.n_overrides = n;
    }
    RS_TRY(mesh_placement(c, o, path, &mo));
    for (k = 0; k < c->n_meshes; ++k)
        if (c->meshes[k].node == o)
            return copy_mesh(c, &c->meshes[k]);
    rs_json_resolve_path(c, file, full, sizeof full);
    rs_error_clear();
    first = c->scene->n_tris;
    st = rs_scene_add_mesh(c->scene, full, &mo, &info);
    if (st != RS_OK) {
        char msg[600];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return FAIL(c, path, "%s", msg);
    }
    if (c->log)
        mesh_log(c, o, full, &mo, &info, n);
    return keep_mesh(c, o, first);
}

/* A sphere, still or moving (to `moving_to` over the shutter, or at `velocity`). */
static rs_status add_sphere(ctx *c, const cJSON *o, const char *path)
{
    static const char *const k_sphere[] = {"type",     "center",    "radius",    "material",
                                           "moving_to", "velocity", "transform", NULL};
    rs_scene *s = c->scene;
    uint32_t mat;
    rs_vec3 center, to;
    float r;
    RS_TRY(rs_json_check_keys(c, o, path, k_sphere));
    RS_TRY(rs_json_get_vec3(c, o, path, "center", 1, rs_v3(0, 0, 0), &center));
    RS_TRY(rs_json_get_num(c, o, path, "radius", 1, 0, 1e-30, 1e30, &r));
    RS_TRY(rs_json_object_material(c, o, path, &mat));
    if (cJSON_GetObjectItemCaseSensitive(o, "moving_to") &&
        cJSON_GetObjectItemCaseSensitive(o, "velocity"))
        return FAIL(c, path, "give either 'moving_to' or 'velocity', not both");
    if (cJSON_GetObjectItemCaseSensitive(o, "moving_to")) {
        /* the centre moves linearly from `center` at time 0 to `moving_to` at time 1 */
        RS_TRY(rs_json_get_vec3(c, o, path, "moving_to", 1, center, &to));
        return rs_scene_add_moving_sphere(s, center, 0.0f, to, 1.0f, r, mat);
    }
    if (cJSON_GetObjectItemCaseSensitive(o, "velocity")) {
        /* the centre at time t is center + t velocity (what `raystream export` writes: the
         * stored motion exactly) */
        rs_vec3 vel;
        RS_TRY(rs_json_get_vec3(c, o, path, "velocity", 1, center, &vel));
        return rs_scene_add_sphere_velocity(s, center, vel, r, mat);
    }
    return rs_scene_add_sphere(s, center, r, mat);
}

/* A parallelogram q + a u + b v. */
static rs_status add_quad(ctx *c, const cJSON *o, const char *path)
{
    static const char *const k_quad[] = {"type", "q", "u", "v", "material", "transform", NULL};
    rs_scene *s = c->scene;
    uint32_t mat;
    rs_vec3 q, u, v;
    RS_TRY(rs_json_check_keys(c, o, path, k_quad));
    RS_TRY(rs_json_get_vec3(c, o, path, "q", 1, rs_v3(0, 0, 0), &q));
    RS_TRY(rs_json_get_vec3(c, o, path, "u", 1, rs_v3(0, 0, 0), &u));
    RS_TRY(rs_json_get_vec3(c, o, path, "v", 1, rs_v3(0, 0, 0), &v));
    if (rs_v3_is_zero(rs_v3_cross(u, v)))
        return FAIL(c, path, "u and v must span a parallelogram (u x v = 0)");
    RS_TRY(rs_json_object_material(c, o, path, &mat));
    return rs_scene_add_quad(s, q, u, v, mat);
}

/* A triangle, with UVs and vertex normals where given. */
static rs_status add_triangle(ctx *c, const cJSON *o, const char *path)
{
    static const char *const k_tri[] = {"type", "vertices", "uv", "normals", "material",
                                        "transform", NULL};
    rs_scene *s = c->scene;
    uint32_t mat;
    const cJSON *vs = cJSON_GetObjectItemCaseSensitive(o, "vertices");
    const cJSON *uv = cJSON_GetObjectItemCaseSensitive(o, "uv");
    const cJSON *nrm = cJSON_GetObjectItemCaseSensitive(o, "normals");
    rs_vec3 p[3];
    float uvs[6], ns[9];
    char sp[256];
    int i;
    RS_TRY(rs_json_check_keys(c, o, path, k_tri));
    rs_json_subpath(sp, sizeof sp, path, "vertices");
    if (!cJSON_IsArray(vs) || cJSON_GetArraySize(vs) != 3)
        return FAIL(c, vs ? sp : path, vs ? "expected 3 vertices" : "missing 'vertices'");
    for (i = 0; i < 3; ++i)
        RS_TRY(rs_json_vec3_of(c, cJSON_GetArrayItem(vs, i), sp, &p[i]));
    RS_TRY(rs_json_object_material(c, o, path, &mat));
    if (!uv && !nrm)
        return rs_scene_add_triangle(s, p[0], p[1], p[2], mat);
    if (uv) {
        rs_json_subpath(sp, sizeof sp, path, "uv");
        RS_TRY(rs_json_read_floats(c, uv, sp, 6, "(u0, v0, u1, v1, u2, v2)", uvs));
    }
    if (nrm) {
        /* unit vertex normals (zeros: the face's), as `raystream export` writes a mesh's */
        rs_json_subpath(sp, sizeof sp, path, "normals");
        RS_TRY(rs_json_read_floats(c, nrm, sp, 9, "(three normals)", ns));
    }
    if (!nrm)
        return rs_scene_add_triangle_uv(s, p[0], p[1], p[2], uvs, mat);
    return rs_scene_add_triangle_full(s, p, uv ? uvs : NULL, ns, mat);
}

/* RTIOW's box: six parallelograms, turned about y and moved. */
static rs_status add_box(ctx *c, const cJSON *o, const char *path)
{
    static const char *const k_box[] = {"type",      "min",      "max",       "rotate_y",
                                        "translate", "material", "transform", NULL};
    rs_scene *s = c->scene;
    uint32_t mat;
    rs_vec3 lo, hi, t;
    float rot;
    RS_TRY(rs_json_check_keys(c, o, path, k_box));
    RS_TRY(rs_json_get_vec3(c, o, path, "min", 1, rs_v3(0, 0, 0), &lo));
    RS_TRY(rs_json_get_vec3(c, o, path, "max", 1, rs_v3(0, 0, 0), &hi));
    if (!(hi.x > lo.x && hi.y > lo.y && hi.z > lo.z))
        return FAIL(c, path, "'max' must exceed 'min' on every axis");
    RS_TRY(rs_json_get_num(c, o, path, "rotate_y", 0, 0.0, -1e6, 1e6, &rot));
    RS_TRY(rs_json_get_vec3(c, o, path, "translate", 0, rs_v3(0, 0, 0), &t));
    RS_TRY(rs_json_object_material(c, o, path, &mat));
    return rs_scene_add_box(s, lo, hi, rot, t, mat);
}

static rs_status add_primitive(ctx *c, const cJSON *o, const char *path, const char *type)
{
    if (strcmp(type, "sphere") == 0)
        return add_sphere(c, o, path);
    if (strcmp(type, "quad") == 0)
        return add_quad(c, o, path);
    if (strcmp(type, "triangle") == 0)
        return add_triangle(c, o, path);
    if (strcmp(type, "box") == 0)
        return add_box(c, o, path);
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
            RS_TRY(rs_json_read_object(c, it, q, &id));
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
    RS_TRY(rs_json_check_keys(c, o, path, keys));
    RS_TRY(rs_json_get_string(c, o, path, "group", &name));
    rs_json_subpath(p, sizeof p, path, "group");
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
        RS_TRY(rs_json_read_object(c, it, q, xf));
        if (rs_scene_prim_count(c->scene) > MAX_PRIMS)
            return FAIL(c, path,
                        "the scene would pass %u primitives (this group is copied, not instanced)",
                        MAX_PRIMS);
    }
    c->depth--;
    g->prims = rs_scene_prim_count(c->scene) - before;
    g->known = 1;
    return RS_OK;
}

rs_status rs_json_read_object(ctx *c, const cJSON *o, const char *path, const rs_xform *parent)
{
    const char *type = "";
    rs_scene_mark mark = rs_scene_mark_now(c->scene);
    rs_xform own, xf;
    if (!cJSON_IsObject(o))
        return FAIL(c, path, "expected an object");
    RS_TRY(rs_json_get_string(c, o, path, "type", &type));
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
        rs_json_subpath(p, sizeof p, path, "transform");
        return FAIL(c, p, "%s", msg);
    }
    return RS_OK;
}
