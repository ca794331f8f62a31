/* scenes/gltf_scene.c — a glTF file as a whole scene (scenes/gltf.h): its node tree's meshes,
 * lights and first camera, through the mesh code's import, materials and faces
 * (scenes/mesh_assimp.h). */
#include "scenes/gltf.h"
#include "scenes/mesh_assimp.h"

#include <assimp/postprocess.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

/* ---- glTF scenes (scenes/gltf.h) ---------------------------------------------------------- */


typedef struct gltf_ctx {
    rs_scene *s;
    const struct aiScene *as;
    const char *path;
    uint32_t *mat_of;
    rs_mesh_info info;
    const struct aiNode *camera_node; /* the camera's node, once found */
    const struct aiCamera *camera;
    rs_xform camera_xf;
    uint32_t lights;
    rs_gltf_ext ext; /* the file's extensions (scenes/gltf_check.h) */
} gltf_ctx;

/* Assimp's row-major 4x4 (a1..a4 the first row) as an affine transform. */
static rs_xform xform_of(const struct aiMatrix4x4 *m)
{
    rs_xform x;
    x.m[0][0] = m->a1, x.m[0][1] = m->a2, x.m[0][2] = m->a3, x.t[0] = m->a4;
    x.m[1][0] = m->b1, x.m[1][1] = m->b2, x.m[1][2] = m->b3, x.t[1] = m->b4;
    x.m[2][0] = m->c1, x.m[2][1] = m->c2, x.m[2][2] = m->c3, x.t[2] = m->c4;
    return x;
}

static rs_vec3 ai_v3(struct aiVector3D v) { return rs_v3(v.x, v.y, v.z); }

static rs_status gltf_light(gltf_ctx *g, const struct aiLight *l, const rs_xform *xf)
{
    rs_punctual p;
    memset(&p, 0, sizeof p);
    if (l->mType == aiLightSource_POINT)
        p.type = RS_PUNCTUAL_POINT;
    else if (l->mType == aiLightSource_SPOT)
        p.type = RS_PUNCTUAL_SPOT;
    else if (l->mType == aiLightSource_DIRECTIONAL)
        p.type = RS_PUNCTUAL_DIRECTIONAL;
    else
        return rs_error_set(RS_ERR_ARG, "%s: light '%s' is of a kind glTF does not have", g->path,
                            l->mName.data);
    p.pos = rs_xform_point(xf, ai_v3(l->mPosition));
    p.dir = rs_xform_vector(xf, ai_v3(l->mDirection));
    p.intensity = rs_v3(l->mColorDiffuse.r, l->mColorDiffuse.g, l->mColorDiffuse.b);
    if (p.type == RS_PUNCTUAL_SPOT) {
        float inner = fminf(fmaxf(l->mAngleInnerCone, 0.0f), 1.5707963f);
        float outer = fminf(fmaxf(l->mAngleOuterCone, inner), 1.5707963f);
        p.cos_inner = cosf(inner);
        p.cos_outer = cosf(outer);
    }
    if (rs_scene_add_punctual(g->s, &p) != RS_OK) {
        char msg[400];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        return rs_error_set(RS_ERR_ARG, "%s: light '%s': %s", g->path, l->mName.data, msg);
    }
    g->lights++;
    return RS_OK;
}

/* Node nd and its children under the parent's transform: their meshes, and the camera and the
 * lights that name them. */
static rs_status gltf_node(gltf_ctx *g, const struct aiNode *nd, const rs_xform *parent,
                           int depth, const char *want_camera)
{
    rs_xform local = xform_of(&nd->mTransformation), xf = rs_xform_compose(parent, &local);
    const char *why = rs_xform_invalid(&xf);
    uint32_t k;
    rs_status st;
    if (depth > RS_GLTF_MAX_DEPTH)
        return rs_error_set(RS_ERR_ARG, "%s: nodes nested more than %d deep", g->path,
                            RS_GLTF_MAX_DEPTH);
    if (nd->mNumMeshes && why)
        return rs_error_set(RS_ERR_ARG, "%s: node '%s': %s", g->path, nd->mName.data, why);
    for (k = 0; k < nd->mNumMeshes; ++k) {
        const struct aiMesh *m;
        rs_scene_mark mark = rs_scene_mark_now(g->s);
        if (nd->mMeshes[k] >= g->as->mNumMeshes)
            return rs_error_set(RS_ERR_ARG, "%s: node '%s' names mesh %u of %u", g->path,
                                nd->mName.data, nd->mMeshes[k], g->as->mNumMeshes);
        m = g->as->mMeshes[nd->mMeshes[k]];
        if (!m->mVertices || !m->mFaces)
            continue;
        st = rs_mesh_add_faces(
            g->s, m, NULL,
            g->mat_of[m->mMaterialIndex < g->as->mNumMaterials ? m->mMaterialIndex : 0], &g->info);
        if (st == RS_OK && !rs_xform_is_identity(&xf))
            st = rs_scene_transform_since(g->s, &mark, &xf);
        if (st != RS_OK) {
            char msg[400];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            return rs_error_set(st, "%s: node '%s': %s", g->path, nd->mName.data, msg);
        }
    }
    for (k = 0; k < g->as->mNumCameras; ++k) {
        const struct aiCamera *c = g->as->mCameras[k];
        if (!g->camera && strcmp(c->mName.data, nd->mName.data) == 0 &&
            (!want_camera || strcmp(want_camera, c->mName.data) == 0) && c->mHorizontalFOV > 0) {
            g->camera = c;
            g->camera_node = nd;
            g->camera_xf = xf;
        }
    }
    for (k = 0; k < g->as->mNumLights; ++k)
        if (strcmp(g->as->mLights[k]->mName.data, nd->mName.data) == 0) {
            st = gltf_light(g, g->as->mLights[k], &xf);
            if (st != RS_OK)
                return st;
        }
    for (k = 0; k < nd->mNumChildren; ++k) {
        st = gltf_node(g, nd->mChildren[k], &xf, depth + 1, want_camera);
        if (st != RS_OK)
            return st;
    }
    return RS_OK;
}

/* The camera: the glTF camera found (its node's transform applied to looking down -z with +y
 * up; Assimp gives yfov times the aspect ratio as the horizontal field of view), else one that
 * frames the model's bounding sphere from the front, a little above. */
static void gltf_camera(gltf_ctx *g)
{
    rs_camera_desc cd = g->s->camera, *d = &cd;
    if (g->camera) {
        const struct aiCamera *c = g->camera;
        float aspect = c->mAspect > 0 ? c->mAspect : 1.0f;
        float yfov = c->mHorizontalFOV / aspect * 57.29577951f;
        rs_vec3 look = rs_xform_vector(&g->camera_xf, ai_v3(c->mLookAt));
        rs_vec3 up = rs_xform_vector(&g->camera_xf, ai_v3(c->mUp));
        d->from = rs_xform_point(&g->camera_xf, rs_v3(0, 0, 0));
        d->at = rs_v3_add(d->from, rs_v3_normalize(look));
        d->up = rs_v3_is_zero(up) ? rs_v3(0, 1, 0) : up;
        d->vfov_deg = fminf(fmaxf(yfov, 1.0f), 170.0f);
        if (c->mAspect > 0) {
            float w = roundf(512.0f * c->mAspect);
            rs_scene_set_image_size(g->s, (uint32_t)fminf(fmaxf(w, 1.0f), 32768.0f), 512);
        }
    } else {
        rs_aabb b = g->info.bounds;
        rs_vec3 c = rs_v3_scale(rs_v3_add(b.lo, b.hi), 0.5f);
        float r = 0.5f * rs_v3_length(rs_v3_sub(b.hi, b.lo)), dist;
        d->vfov_deg = 40.0f;
        dist = (r > 0 ? r : 1.0f) / sinf(0.5f * 40.0f * 0.017453293f) * 1.05f;
        d->at = c;
        d->from = rs_v3_add(c, rs_v3_scale(rs_v3_normalize(rs_v3(0.3f, 0.35f, 1.0f)), dist));
        d->up = rs_v3(0, 1, 0);
    }
    d->aperture = 0;
    d->focus_dist = 0;
    rs_scene_set_camera(g->s, d);
}

/* The materials the file's meshes use (in the file's order), or a default; *emissive counts
 * those that emit. */
static rs_status gltf_materials(gltf_ctx *g, const char *dir, uint32_t *emissive)
{
    rs_status st = RS_OK;
    uint32_t k;
    *emissive = 0;
    for (k = 0; k < g->as->mNumMaterials && st == RS_OK; ++k) {
        uint32_t mi;
        int used = 0;
        for (mi = 0; mi < g->as->mNumMeshes && !used; ++mi)
            used = g->as->mMeshes[mi]->mMaterialIndex == k;
        if (!used)
            continue;
        st = rs_mesh_add_file_material(g->s, g->as, g->as->mMaterials[k],
                                       rs_mesh_material_ext(&g->ext, k), g->path, dir, 1,
                                       &g->mat_of[k]);
        if (st == RS_OK) {
            g->info.materials++;
            *emissive += !rs_v3_is_zero(g->s->materials[g->mat_of[k]].emission);
        }
    }
    if (st == RS_OK && g->as->mNumMaterials == 0) {
        rs_material def = rs_mat_pbr(rs_v3_splat(1.0f), 0.0f, 1.0f);
        st = rs_scene_add_material(g->s, &def, &g->mat_of[0]);
    }
    return st;
}

/* The camera the options named, not found among the nodes: why (orthographic, a field of view of
 * 0, or no such name, with the names the file has). */
static rs_status gltf_camera_missing(const gltf_ctx *g, const char *name)
{
    char have[512] = "";
    uint32_t k;
    for (k = 0; k < g->as->mNumCameras; ++k) {
        const struct aiCamera *c = g->as->mCameras[k];
        if (strcmp(c->mName.data, name) != 0)
            continue;
        /* there, but not a camera raystream can look through */
        if (c->mOrthographicWidth > 0)
            return rs_error_set(RS_ERR_ARG,
                                "%s: camera '%s' is orthographic; raystream's cameras are "
                                "perspective (give the file a perspective camera)",
                                g->path, name);
        return rs_error_set(RS_ERR_ARG,
                            "%s: camera '%s' has a field of view of 0 (its yfov must be "
                            "above 0)",
                            g->path, name);
    }
    for (k = 0; k < g->as->mNumCameras; ++k)
        if (strlen(have) + g->as->mCameras[k]->mName.length + 5 < sizeof have) {
            strcat(have, *have ? ", '" : "'");
            strcat(have, g->as->mCameras[k]->mName.data);
            strcat(have, "'");
        }
    return rs_error_set(RS_ERR_ARG, "%s: no camera named '%s' (the file has: %s)", g->path, name,
                        *have ? have : "none");
}

/* The loaded scene completed: refused if most of its faces were dropped; else its placed bounds,
 * its camera (the file's or one framing the model), a white sky where nothing lights it, and
 * rs_scene_finalize (its refusal named with the file). */
static rs_status gltf_finish(gltf_ctx *g, uint32_t emissive)
{
    rs_status st;
    uint32_t k;
    if (g->info.triangles == 0 || g->info.dropped > g->info.triangles) {
        char why[160];
        return rs_error_set(RS_ERR_ARG, "%s: %s of %u, %u triangles left: the mesh is broken",
                            g->path, rs_mesh_dropped_text(&g->info, why, sizeof why),
                            g->info.dropped + g->info.triangles, g->info.triangles);
    }
    g->info.bounds.lo = rs_v3_splat(FLT_MAX);
    g->info.bounds.hi = rs_v3_splat(-FLT_MAX);
    for (k = 0; k < g->s->n_tris; ++k) {
        const rs_tri *t = &g->s->tris[k];
        g->info.bounds.lo = rs_v3_min(g->info.bounds.lo, rs_v3_min(t->v0, rs_v3_min(t->v1, t->v2)));
        g->info.bounds.hi = rs_v3_max(g->info.bounds.hi, rs_v3_max(t->v0, rs_v3_max(t->v1, t->v2)));
    }
    gltf_camera(g);
    if (g->lights == 0 && emissive == 0)
        rs_scene_set_background(g->s, rs_v3_splat(1.0f)); /* nothing lights it: a white sky */
    st = rs_scene_finalize(g->s);
    if (st != RS_OK) {
        char msg[400];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        st = rs_error_set(st, "%s: %s", g->path, msg);
    }
    return st;
}

/* What was loaded, a line to opts->log, and the extensions read into opts->extensions. */
static void gltf_report(const gltf_ctx *g, const rs_gltf_opts *opts)
{
    if (opts && opts->log) {
        char why[160];
        fprintf(opts->log,
                "raystream: %s: %u triangles, %u materials, %u lights, camera %s%s%s%s%s%s%s\n",
                g->path, g->info.triangles, g->info.materials, g->lights,
                g->camera ? "'" : "(framing the model)", g->camera ? g->camera->mName.data : "",
                g->camera ? "'" : "", g->info.dropped ? "; " : "",
                rs_mesh_dropped_text(&g->info, why, sizeof why),
                g->ext.used[0] ? "; extensions: " : "", g->ext.used);
    }
    if (opts && opts->extensions && opts->extensions_n)
        snprintf(opts->extensions, opts->extensions_n, "%s", g->ext.used);
}

rs_status rs_scene_load_gltf(const char *path, const rs_gltf_opts *opts, rs_scene **out)
{
    gltf_ctx g;
    rs_xform id = rs_xform_identity();
    char dir[1024];
    const char *slash = strrchr(path, '/');
    const char *camera = opts ? opts->camera : NULL;
    rs_status st;
    uint32_t emissive = 0;
    *out = NULL;
    memset(&g, 0, sizeof g);
    g.path = path;
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    st = rs_mesh_import(path,
                        aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                            aiProcess_SortByPType | aiProcess_GenSmoothNormals |
                            aiProcess_ValidateDataStructure,
                        &g.as);
    if (st != RS_OK)
        return st;
    st = rs_scene_create(path, &g.s);
    g.info.bounds.lo = rs_v3_splat(FLT_MAX);
    g.info.bounds.hi = rs_v3_splat(-FLT_MAX);
    if (st == RS_OK) {
        g.mat_of = (uint32_t *)rs_calloc(g.as->mNumMaterials ? g.as->mNumMaterials : 1,
                                         sizeof *g.mat_of);
        if (!g.mat_of)
            st = rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    }
    if (st == RS_OK)
        st = rs_mesh_file_extensions(path, &g.ext);
    if (st == RS_OK)
        st = gltf_materials(&g, dir, &emissive);
    if (st == RS_OK)
        st = gltf_node(&g, g.as->mRootNode, &id, 0, camera);
    if (st == RS_OK && camera && !g.camera)
        st = gltf_camera_missing(&g, camera);
    if (st == RS_OK)
        st = gltf_finish(&g, emissive);
    if (st == RS_OK)
        gltf_report(&g, opts);
    rs_gltf_ext_free(&g.ext);
    rs_free(g.mat_of);
    rs_mesh_release(g.as);
    if (st != RS_OK) {
        rs_scene_destroy(g.s);
        return st;
    }
    *out = g.s;
    return RS_OK;
}
