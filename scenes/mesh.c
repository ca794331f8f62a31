/* scenes/mesh.c — see mesh.h: a mesh file's triangles placed in a scene (rs_scene_add_mesh).
 * Reading the file is scenes/mesh_import.c, its materials scenes/mesh_materials.c, a whole glTF
 * scene scenes/gltf_scene.c. */
#include "scenes/mesh_assimp.h"

#include <assimp/postprocess.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

/* ---- placement ----------------------------------------------------------------------------
 *
 * A mesh is placed by an rs_xform (scenes/transform.h), the one transform type of scenes: the
 * options' scale, then the rotations about x, y and z (rs_xform_rotate_euler: right-handed
 * degrees in that order), then the fit's uniform scale and translation or the options'
 * translation.  Points go by rs_xform_point and normals by rs_xform_normal (the inverse
 * transpose), in double, rounded to float once; a placement that mirrors (a negative scale)
 * keeps each face's outward side, as the scene file's transforms do.
 *
 * add_faces takes NULL for "as the file has them": a glTF node's meshes (which
 * rs_scene_transform_since moves afterwards) and a mesh placed by the identity.  Those are stored
 * bit for bit as the float placement by the identity (before rs_xform placed meshes) stored
 * them, so that scenes whose meshes are not placed render as they did: it turned a zero
 * coordinate's sign to +0, renormalised normals in float, and left their zeros' signs as the
 * rotations by 0 degrees, written out below, leave them (they matter: core/sampling.h's basis
 * reads the sign of n.z).  The build has no fast-math (CMakeLists.txt), so `x + 0.0f` and
 * `0.0f * x` are not folded away. */

static rs_vec3 as_stored_point(rs_vec3 p) { return rs_v3(p.x + 0.0f, p.y + 0.0f, p.z + 0.0f); }

static rs_vec3 as_stored_normal(rs_vec3 n)
{
    /* about x, y, then z by 0 degrees: cos = 1, sin = +0 (so -sin = -0) */
    rs_vec3 a = rs_v3(n.x, n.y - 0.0f * n.z, 0.0f * n.y + n.z);
    rs_vec3 b = rs_v3(a.x + 0.0f * a.z, a.y, -0.0f * a.x + a.z);
    rs_vec3 m = rs_v3(b.x - 0.0f * b.y, 0.0f * b.x + b.y, b.z);
    float l = rs_v3_length(m);
    return l > 0 ? rs_v3_scale(m, 1.0f / l) : rs_v3(0, 0, 0);
}

/* The options' scale, then their rotations about x, y and z. */
static rs_xform scale_rotate(const rs_mesh_opts *o)
{
    rs_xform sc = rs_xform_scale(o->scale.x, o->scale.y, o->scale.z);
    rs_xform rot = rs_xform_rotate_euler(o->rotate_deg.x, o->rotate_deg.y, o->rotate_deg.z);
    return rs_xform_compose(&rot, &sc);
}

/* sr (scale_rotate's) followed by the fit into o's box, given the bounds `raw` of the vertices
 * sr places (a uniform scale so the largest extent is fit_size, its bottom centre on fit_base),
 * or by the options' translation. */
static rs_xform fit_translate(const rs_mesh_opts *o, const rs_xform *sr, rs_aabb raw)
{
    rs_xform sf, mv, x = *sr;
    if (o->fit) {
        double ex = (double)raw.hi.x - raw.lo.x, ey = (double)raw.hi.y - raw.lo.y;
        double ez = (double)raw.hi.z - raw.lo.z, big = fmax(ex, fmax(ey, ez));
        double f = big > 0 ? o->fit_size / big : 1.0;
        sf = rs_xform_scale(f, f, f);
        x = rs_xform_compose(&sf, &x);
        mv = rs_xform_translate(o->fit_base.x - f * 0.5 * ((double)raw.lo.x + raw.hi.x),
                                o->fit_base.y - f * raw.lo.y,
                                o->fit_base.z - f * 0.5 * ((double)raw.lo.z + raw.hi.z));
    } else {
        mv = rs_xform_translate(o->translate.x, o->translate.y, o->translate.z);
    }
    return rs_xform_compose(&mv, &x);
}

/* The triangles of Assimp mesh m, placed by xf (NULL: as the file has them), with material mat;
 * faces with an index out of range, a placed vertex that is not finite, no placed area, or that
 * are not triangles, are dropped and counted in *info (which also gets the triangles added and
 * their placed bounds). */
rs_status rs_mesh_add_faces(rs_scene *s, const struct aiMesh *m, const rs_xform *xf, uint32_t mat,
                            rs_mesh_info *info)
{
    rs_status st = RS_OK;
    uint32_t k;
    int mirror = xf && rs_xform_det(xf) < 0;
    for (k = 0; k < m->mNumFaces && st == RS_OK; ++k) {
        const struct aiFace *f = &m->mFaces[k];
        rs_vec3 v[3];
        float uv[6], nrm[9];
        int c, ok = f->mNumIndices == 3;
        uint32_t *why = &info->dropped_shape;
        for (c = 0; c < 3 && ok; ++c) {
            /* a mirror takes the corners 0, 2, 1: the face keeps its outward side */
            unsigned int idx = f->mIndices[mirror && c ? 3 - c : c];
            rs_vec3 p;
            if (idx >= m->mNumVertices) {
                ok = 0;
                why = &info->dropped_index;
                break;
            }
            p = rs_v3(m->mVertices[idx].x, m->mVertices[idx].y, m->mVertices[idx].z);
            v[c] = xf ? rs_xform_point(xf, p) : as_stored_point(p);
            ok = rs_v3_is_finite(v[c]);
            if (!ok)
                why = &info->dropped_nonfinite;
            if (m->mTextureCoords[0]) {
                uv[2 * c] = m->mTextureCoords[0][idx].x;
                uv[2 * c + 1] = m->mTextureCoords[0][idx].y;
            }
            if (m->mNormals) {
                rs_vec3 n = rs_v3(m->mNormals[idx].x, m->mNormals[idx].y, m->mNormals[idx].z);
                n = xf ? rs_xform_normal(xf, n) : as_stored_normal(n);
                if (!rs_v3_is_finite(n))
                    n = rs_v3(0, 0, 0);
                nrm[3 * c] = n.x;
                nrm[3 * c + 1] = n.y;
                nrm[3 * c + 2] = n.z;
            }
        }
        if (ok && rs_v3_is_zero(rs_v3_cross(rs_v3_sub(v[1], v[0]), rs_v3_sub(v[2], v[0])))) {
            ok = 0;
            why = &info->dropped_area;
        }
        if (!ok) {
            info->dropped++;
            ++*why;
            continue;
        }
        st = rs_scene_add_triangle_full(s, v, m->mTextureCoords[0] ? uv : NULL,
                                        m->mNormals ? nrm : NULL, mat);
        if (st != RS_OK)
            break;
        info->triangles++;
        for (c = 0; c < 3; ++c) {
            info->bounds.lo = rs_v3_min(info->bounds.lo, v[c]);
            info->bounds.hi = rs_v3_max(info->bounds.hi, v[c]);
        }
    }
    return st;
}

rs_status rs_mesh_file_extensions(const char *path, rs_gltf_ext *e)
{
    rs_status st = RS_OK;
    memset(e, 0, sizeof *e);
    if (rs_mesh_ext_is(path, "glb") || rs_mesh_ext_is(path, "gltf"))
        st = rs_gltf_read_ext(path, rs_mesh_ext_is(path, "glb"), e);
    if (st == RS_OK && e->unread[0])
        fprintf(stderr,
                "raystream: warning: %s uses %s, which raystream does not read: rendered "
                "without %s\n",
                path, e->unread, strchr(e->unread, ',') ? "them" : "it");
    return st;
}

/* Material k's extensions (NULL: none, or not a glTF file). */
const rs_gltf_mat_ext *rs_mesh_material_ext(const rs_gltf_ext *e, uint32_t k)
{
    return k < e->n_materials ? &e->materials[k] : NULL;
}

/* The bounds of the finite vertices of every mesh of `as` placed by xf. */
static rs_aabb placed_bounds(const struct aiScene *as, const rs_xform *xf)
{
    rs_aabb raw;
    uint32_t mi, k;
    raw.lo = rs_v3_splat(FLT_MAX);
    raw.hi = rs_v3_splat(-FLT_MAX);
    for (mi = 0; mi < as->mNumMeshes; ++mi) {
        const struct aiMesh *m = as->mMeshes[mi];
        if (!m->mVertices)
            continue;
        for (k = 0; k < m->mNumVertices; ++k) {
            rs_vec3 p = rs_xform_point(
                xf, rs_v3(m->mVertices[k].x, m->mVertices[k].y, m->mVertices[k].z));
            if (!rs_v3_is_finite(p))
                continue;
            raw.lo = rs_v3_min(raw.lo, p);
            raw.hi = rs_v3_max(raw.hi, p);
        }
    }
    return raw;
}

/* The file's materials that its meshes use, in mat_of[k] (the override a scene file names for
 * material k, else a material made from it; a default one where the file has none). */
static rs_status file_materials(rs_scene *s, const struct aiScene *as, const char *path,
                                const char *dir, const rs_mesh_opts *o, uint32_t *mat_of,
                                rs_mesh_info *info)
{
    rs_gltf_ext ext;
    uint32_t mi, k;
    rs_status st = rs_mesh_check_overrides(as, path, o);
    if (st == RS_OK)
        st = rs_mesh_file_extensions(path, &ext);
    else
        memset(&ext, 0, sizeof ext);
    for (k = 0; k < as->mNumMaterials && st == RS_OK; ++k) {
        int ov = rs_mesh_override_of(as->mMaterials[k], o), used = 0;
        for (mi = 0; mi < as->mNumMeshes && !used; ++mi)
            used = as->mMeshes[mi]->mMaterialIndex == k;
        mat_of[k] = 0;
        if (!used)
            continue; /* (Assimp's unused default material, say): not added */
        if (ov >= 0) {
            mat_of[k] = o->override_ids[ov];
            continue;
        }
        st = rs_mesh_add_file_material(s, as, as->mMaterials[k], rs_mesh_material_ext(&ext, k),
                                       path, dir, o->strict_textures, &mat_of[k]);
        info->materials++;
    }
    rs_gltf_ext_free(&ext);
    if (st == RS_OK && as->mNumMaterials == 0) {
        rs_material def = rs_mat_lambertian(rs_v3_splat(0.7f));
        st = rs_scene_add_material(s, &def, &mat_of[0]);
    }
    return st;
}

rs_status rs_scene_add_mesh(rs_scene *s, const char *path, const rs_mesh_opts *o,
                            rs_mesh_info *info)
{
    const struct aiScene *as;
    rs_xform xf;
    uint32_t *mat_of = NULL, mi;
    char dir[1024];
    const char *slash = strrchr(path, '/');
    rs_status st = RS_OK;
    rs_aabb raw;
    memset(info, 0, sizeof *info);
    if (o->scale.x == 0 || o->scale.y == 0 || o->scale.z == 0 || !rs_v3_is_finite(o->scale))
        return rs_error_set(RS_ERR_ARG, "%s: scale must be finite and non-zero", path);
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    st = rs_mesh_import(path,
                        aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                            aiProcess_SortByPType | aiProcess_PreTransformVertices |
                            aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure,
                        &as);
    if (st != RS_OK)
        return st;

    /* placement: the bounds of the scaled and rotated (unfitted) vertices decide a fit */
    xf = scale_rotate(o);
    raw = placed_bounds(as, &xf);
    if (!(raw.lo.x <= raw.hi.x)) {
        rs_mesh_release(as);
        return rs_error_set(RS_ERR_ARG, "%s: no finite vertex in the file", path);
    }
    xf = fit_translate(o, &xf, raw);

    if (o->material == RS_MESH_FILE_MATERIALS) {
        mat_of = (uint32_t *)rs_alloc(as->mNumMaterials ? as->mNumMaterials : 1, sizeof *mat_of);
        if (!mat_of) {
            rs_mesh_release(as);
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
        }
        st = file_materials(s, as, path, dir, o, mat_of, info);
    }

    info->bounds.lo = rs_v3_splat(FLT_MAX);
    info->bounds.hi = rs_v3_splat(-FLT_MAX);
    for (mi = 0; mi < as->mNumMeshes && st == RS_OK; ++mi) {
        const struct aiMesh *m = as->mMeshes[mi];
        uint32_t mat = o->material;
        if (!m->mVertices || !m->mFaces)
            continue;
        if (mat == RS_MESH_FILE_MATERIALS)
            mat = as->mNumMaterials
                      ? mat_of[m->mMaterialIndex < as->mNumMaterials ? m->mMaterialIndex : 0]
                      : mat_of[0];
        st = rs_mesh_add_faces(s, m, rs_xform_is_identity(&xf) ? NULL : &xf, mat, info);
    }
    rs_free(mat_of);
    rs_mesh_strips_of(as, &info->strips, &info->joins);
    rs_mesh_release(as);
    if (st == RS_OK && (info->triangles == 0 || info->dropped > info->triangles)) {
        char why[160];
        st = rs_error_set(RS_ERR_ARG, "%s: %s of %u, %u triangles left: the mesh is broken", path,
                          rs_mesh_dropped_text(info, why, sizeof why),
                          info->dropped + info->triangles, info->triangles);
    }
    return st;
}

