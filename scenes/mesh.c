/* scenes/mesh.c — see mesh.h. */
#include "scenes/mesh.h"

#include <assimp/cimport.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"

/* Rotation about x, then y, then z (right-handed, degrees). */
static rs_vec3 rotate_xyz(rs_vec3 p, rs_vec3 deg)
{
    const float k = 0.017453292519943295f;
    float cx = cosf(deg.x * k), sx = sinf(deg.x * k), cy = cosf(deg.y * k), sy = sinf(deg.y * k);
    float cz = cosf(deg.z * k), sz = sinf(deg.z * k);
    rs_vec3 a = rs_v3(p.x, cx * p.y - sx * p.z, sx * p.y + cx * p.z);
    rs_vec3 b = rs_v3(cy * a.x + sy * a.z, a.y, -sy * a.x + cy * a.z);
    return rs_v3(cz * b.x - sz * b.y, sz * b.x + cz * b.y, b.z);
}

static int finite3(rs_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }

/* A scene material for an Assimp material: an emitter if it emits, Phong if it has a specular
 * colour and shininess, else Lambertian; a diffuse texture file becomes an image texture. */
static rs_status add_file_material(rs_scene *s, const struct aiMaterial *am, const char *dir,
                                   uint32_t *id)
{
    struct aiColor4D kd = {0.7f, 0.7f, 0.7f, 1}, ks = {0, 0, 0, 1}, ke = {0, 0, 0, 1};
    ai_real shininess = 0;
    unsigned int max = 1;
    struct aiString tex;
    rs_material m;
    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &kd);
    aiGetMaterialColor(am, AI_MATKEY_COLOR_SPECULAR, &ks);
    aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &ke);
    aiGetMaterialFloatArray(am, AI_MATKEY_SHININESS, &shininess, &max);
    if (ke.r > 0 || ke.g > 0 || ke.b > 0) {
        m = rs_mat_light(rs_v3(ke.r, ke.g, ke.b), 0);
    } else {
        rs_vec3 d =
            rs_v3(fminf(fmaxf(kd.r, 0), 1), fminf(fmaxf(kd.g, 0), 1), fminf(fmaxf(kd.b, 0), 1));
        rs_vec3 sp = rs_v3(fmaxf(ks.r, 0), fmaxf(ks.g, 0), fmaxf(ks.b, 0));
        if (rs_v3_max_comp(sp) > 0 && shininess > 1) {
            /* keep kd + ks <= 1 per channel so the Phong model conserves energy */
            float sum = rs_v3_max_comp(rs_v3_add(d, sp));
            if (sum > 1)
                sp = rs_v3_scale(sp, fmaxf(0.0f, 1.0f - rs_v3_max_comp(d)) / rs_v3_max_comp(sp));
            m = rs_mat_phong(d, sp, (float)shininess);
        } else {
            m = rs_mat_lambertian(d);
        }
        if (aiGetMaterialTexture(am, aiTextureType_DIFFUSE, 0, &tex, NULL, NULL, NULL, NULL, NULL,
                                 NULL) == aiReturn_SUCCESS &&
            tex.length > 0 && tex.data[0] != '*') {
            char path[2048];
            uint32_t image, t;
            rs_texture tx;
            if (tex.data[0] == '/')
                snprintf(path, sizeof path, "%s", tex.data);
            else
                snprintf(path, sizeof path, "%s/%s", dir, tex.data);
            if (rs_scene_load_image(s, path, &image) == RS_OK) {
                memset(&tx, 0, sizeof tx);
                tx.type = RS_TEX_IMAGE;
                tx.image = image;
                if (rs_scene_add_texture(s, &tx, &t) == RS_OK) {
                    m.albedo_tex = t;
                    m.albedo = rs_v3_splat(1.0f);
                }
            } else {
                /* a missing texture file: keep the colour, say so once */
                fprintf(stderr, "raystream: warning: %s\n", rs_error_message());
                rs_error_clear();
            }
        }
    }
    return rs_scene_add_material(s, &m, id);
}

typedef struct placement {
    rs_vec3 scale, rot, translate;
    float fit_scale;
} placement;

static rs_vec3 place(const placement *pl, rs_vec3 p)
{
    return rs_v3_add(rs_v3_scale(rotate_xyz(rs_v3_mul(p, pl->scale), pl->rot), pl->fit_scale),
                     pl->translate);
}

/* Normals transform by the inverse transpose: divide by the scale, then rotate. */
static rs_vec3 place_normal(const placement *pl, rs_vec3 n)
{
    rs_vec3 m = rotate_xyz(rs_v3(n.x / pl->scale.x, n.y / pl->scale.y, n.z / pl->scale.z), pl->rot);
    float l = rs_v3_length(m);
    return l > 0 ? rs_v3_scale(m, 1.0f / l) : rs_v3(0, 0, 0);
}

rs_status rs_scene_add_mesh(rs_scene *s, const char *path, const rs_mesh_opts *o,
                            rs_mesh_info *info)
{
    const struct aiScene *as;
    struct aiPropertyStore *props;
    struct stat sb;
    placement pl;
    uint32_t *mat_of = NULL, mi, k;
    char dir[1024];
    const char *slash = strrchr(path, '/');
    rs_status st = RS_OK;
    rs_aabb raw;
    memset(info, 0, sizeof *info);
    if (stat(path, &sb) != 0)
        return rs_error_set(RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (!S_ISREG(sb.st_mode))
        return rs_error_set(RS_ERR_IO, "%s: not a regular file", path);
    if (sb.st_size == 0)
        return rs_error_set(RS_ERR_ARG, "%s: empty file", path);
    if (o->scale.x == 0 || o->scale.y == 0 || o->scale.z == 0 || !finite3(o->scale))
        return rs_error_set(RS_ERR_ARG, "%s: scale must be finite and non-zero", path);
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");

    props = aiCreatePropertyStore();
    /* Drop points and lines (a truncated OBJ face is a line); keep triangles.  Assimp's own
     * structure validation is off: it rejects a whole file for one bad face, while the loop
     * below checks every index and coordinate and drops just the bad faces. */
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE,
                               aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    as = aiImportFileExWithProperties(path,
                                      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                          aiProcess_SortByPType | aiProcess_PreTransformVertices |
                                          aiProcess_GenSmoothNormals |
                                          aiProcess_ValidateDataStructure,
                                      NULL, props);
    aiReleasePropertyStore(props);
    if (!as || !as->mRootNode) {
        st = rs_error_set(RS_ERR_ARG, "%s: cannot import mesh: %s", path, aiGetErrorString());
        if (as)
            aiReleaseImport(as);
        return st;
    }
    if (as->mNumMeshes == 0) {
        aiReleaseImport(as);
        return rs_error_set(RS_ERR_ARG, "%s: no triangles in the file", path);
    }

    /* placement: the raw bounds of the transformed (unfitted) vertices decide a fit */
    pl.scale = o->scale;
    pl.rot = o->rotate_deg;
    pl.translate = rs_v3(0, 0, 0);
    pl.fit_scale = 1.0f;
    raw.lo = rs_v3_splat(FLT_MAX);
    raw.hi = rs_v3_splat(-FLT_MAX);
    for (mi = 0; mi < as->mNumMeshes; ++mi) {
        const struct aiMesh *m = as->mMeshes[mi];
        if (!m->mVertices)
            continue;
        for (k = 0; k < m->mNumVertices; ++k) {
            rs_vec3 p = place(&pl, rs_v3(m->mVertices[k].x, m->mVertices[k].y, m->mVertices[k].z));
            if (!finite3(p))
                continue;
            raw.lo = rs_v3_min(raw.lo, p);
            raw.hi = rs_v3_max(raw.hi, p);
        }
    }
    if (!(raw.lo.x <= raw.hi.x)) {
        aiReleaseImport(as);
        return rs_error_set(RS_ERR_ARG, "%s: no finite vertex in the file", path);
    }
    if (o->fit) {
        rs_vec3 ext = rs_v3_sub(raw.hi, raw.lo);
        float big = rs_v3_max_comp(ext);
        pl.fit_scale = big > 0 ? o->fit_size / big : 1.0f;
        pl.translate = rs_v3_sub(
            o->fit_base,
            rs_v3_scale(rs_v3((raw.lo.x + raw.hi.x) * 0.5f, raw.lo.y, (raw.lo.z + raw.hi.z) * 0.5f),
                        pl.fit_scale));
    } else {
        pl.translate = o->translate;
    }

    if (o->material == RS_MESH_FILE_MATERIALS) {
        mat_of = (uint32_t *)rs_alloc(as->mNumMaterials ? as->mNumMaterials : 1, sizeof *mat_of);
        if (!mat_of) {
            aiReleaseImport(as);
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
        }
        for (k = 0; k < as->mNumMaterials && st == RS_OK; ++k) {
            st = add_file_material(s, as->mMaterials[k], dir, &mat_of[k]);
            info->materials++;
        }
        if (st == RS_OK && as->mNumMaterials == 0) {
            rs_material def = rs_mat_lambertian(rs_v3_splat(0.7f));
            st = rs_scene_add_material(s, &def, &mat_of[0]);
        }
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
        for (k = 0; k < m->mNumFaces && st == RS_OK; ++k) {
            const struct aiFace *f = &m->mFaces[k];
            rs_vec3 v[3];
            float uv[6], nrm[9];
            int c, ok = f->mNumIndices == 3;
            for (c = 0; c < 3 && ok; ++c) {
                unsigned int idx = f->mIndices[c];
                if (idx >= m->mNumVertices) {
                    ok = 0;
                    break;
                }
                v[c] = place(&pl,
                             rs_v3(m->mVertices[idx].x, m->mVertices[idx].y, m->mVertices[idx].z));
                ok = finite3(v[c]);
                if (m->mTextureCoords[0]) {
                    uv[2 * c] = m->mTextureCoords[0][idx].x;
                    uv[2 * c + 1] = m->mTextureCoords[0][idx].y;
                }
                if (m->mNormals) {
                    rs_vec3 n = place_normal(
                        &pl, rs_v3(m->mNormals[idx].x, m->mNormals[idx].y, m->mNormals[idx].z));
                    if (!finite3(n))
                        n = rs_v3(0, 0, 0);
                    nrm[3 * c] = n.x;
                    nrm[3 * c + 1] = n.y;
                    nrm[3 * c + 2] = n.z;
                }
            }
            if (ok && rs_v3_is_zero(rs_v3_cross(rs_v3_sub(v[1], v[0]), rs_v3_sub(v[2], v[0]))))
                ok = 0; /* zero area */
            if (!ok) {
                info->dropped++;
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
    }
    rs_free(mat_of);
    aiReleaseImport(as);
    if (st == RS_OK && info->triangles == 0)
        st = rs_error_set(RS_ERR_ARG, "%s: no usable triangles (%u faces dropped)", path,
                          info->dropped);
    return st;
}
