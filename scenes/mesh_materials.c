/* scenes/mesh_materials.c — an Assimp material as a scene material (scenes/mesh_assimp.h):
 * textures (files beside the mesh or embedded in it, glTF's texture transform, alpha cut-outs),
 * glTF's metallic-roughness with its extensions as the pbr material, the classic materials, and
 * the overrides a scene file names. */
#define _DEFAULT_SOURCE /* mkstemps, for a glTF binary's embedded textures */
#include "scenes/mesh_assimp.h"

#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/image_io.h"
#include "core/srgb.h"
#include "core/try.h"

/* How a texture's texels are read: colours are sRGB-decoded, data (normals, metallic-roughness)
 * taken as stored. */
#define TEX_COLOR 0
#define TEX_DATA  1

/* Texture `type` of material am as a scene texture in *id (RS_NO_TEXTURE when the material has
 * none).  A file next to the mesh, or one embedded in it ("*N": a glTF binary's images, written
 * to a temporary file for OpenImageIO).  A texture that is not a regular file of a sane size is
 * an error; a missing or unreadable one is an error when `strict`, else a warning and no
 * texture. */
/* With `alpha`, the texture's alpha channel times alpha->scale against alpha->cutoff becomes an
 * alpha cut-out instead (rs_scene_add_mask; *id a material's alpha_mask; 0 when the texture has
 * no alpha channel: the constant scale decides). */
typedef struct alpha_req {
    float scale, cutoff;
} alpha_req;

/* A mask from the alpha channel of image file `path` (none: the constant). */
static rs_status load_mask_file(rs_scene *s, const char *path, const alpha_req *a, uint32_t *id)
{
    uint32_t w = 0, h = 0;
    float *alpha = NULL;
    rs_status st = rs_image_read_alpha(path, &w, &h, &alpha);
    *id = 0;
    if (st == RS_OK && alpha) /* without an alpha channel the constant decides (the caller) */
        st = rs_scene_add_mask(s, w, h, alpha, a->scale, a->cutoff, id);
    rs_free(alpha);
    return st;
}

static rs_status load_texture_ex(rs_scene *s, const struct aiScene *as,
                                 const struct aiMaterial *am, enum aiTextureType type,
                                 const char *mesh, const char *dir, int data, int strict,
                                 const alpha_req *alpha, uint32_t *id);

/* glTF's KHR_texture_transform on the material's texture of `type` into tx->uv_m (tx->uv_xform
 * set; left unset without one or for the identity, so that such textures look up exactly as
 * before).  The spec maps glTF's UVs (v down from the image's top) by T(offset) R(rotation)
 * S(scale), R turning (x, y) to (c x + s y, -s x + c y): what its example needs to take the
 * lower-left quadrant.  Assimp 5.2's glTF2 importer (it reads the extension only where the
 * file lists it in extensionsUsed) hands over scale as mScaling, -rotation as mRotation, and
 * offset folded into mTranslation for its own centre of rotation and flipped v:
 *     tx = sx/2 (1 - c + s) + ox,   ty = sy/2 (s + c - 1) + 1 - sy - oy
 * which is undone here.  In the renderer's UVs (v = 1 - glTF's v):
 *     u' = c sx u - s sy v + s sy + ox,   v' = s sx u + c sy v + 1 - c sy - oy. */
static void uv_transform(const struct aiMaterial *am, enum aiTextureType type, rs_texture *tx)
{
    struct aiUVTransform tr;
    unsigned int n = 5;
    double sx, sy, rot, c, sn, ox, oy;
    if (aiGetMaterialFloatArray(am, _AI_MATKEY_UVTRANSFORM_BASE, (unsigned int)type, 0,
                                (ai_real *)&tr, &n) != aiReturn_SUCCESS ||
        n != 5)
        return;
    sx = tr.mScaling.x;
    sy = tr.mScaling.y;
    rot = -(double)tr.mRotation;
    if (!isfinite(sx) || !isfinite(sy) || !isfinite(rot) || !isfinite(tr.mTranslation.x) ||
        !isfinite(tr.mTranslation.y))
        return;
    c = cos(rot);
    sn = sin(rot);
    ox = tr.mTranslation.x - 0.5 * sx * (1.0 - c + sn);
    oy = 0.5 * sy * (sn + c - 1.0) + 1.0 - sy - tr.mTranslation.y;
    if (sx == 1.0 && sy == 1.0 && rot == 0.0 && fabs(ox) < 1e-7 && fabs(oy) < 1e-7)
        return;
    tx->uv_xform = 1;
    tx->uv_m[0] = (float)(c * sx);
    tx->uv_m[1] = (float)(-sn * sy);
    tx->uv_m[2] = (float)(sn * sy + ox);
    tx->uv_m[3] = (float)(sn * sx);
    tx->uv_m[4] = (float)(c * sy);
    tx->uv_m[5] = (float)(1.0 - c * sy - oy);
}

static rs_status load_texture(rs_scene *s, const struct aiScene *as, const struct aiMaterial *am,
                              enum aiTextureType type, const char *mesh, const char *dir,
                              int data, int strict, uint32_t *id)
{
    return load_texture_ex(s, as, am, type, mesh, dir, data, strict, NULL, id);
}

/* Embedded texture t (raw BGRA texels, top row first) as a scene image in *image, or with
 * `alpha` its alpha channel as a mask in *id. */
static rs_status embedded_texels(rs_scene *s, const struct aiTexture *t, const char *name,
                                 const char *mesh, int data, const alpha_req *alpha, uint32_t *id,
                                 uint32_t *image)
{
    float *rgb;
    uint32_t i, n;
    rs_status st;
    if ((uint64_t)t->mWidth * t->mHeight > RS_IMAGE_MAX_PIXELS)
        return rs_error_set(RS_ERR_ARG, "%s: embedded texture %s is too large", mesh, name);
    n = t->mWidth * t->mHeight;
    if (alpha) {
        float *a = (float *)rs_alloc(n ? n : 1, sizeof *a);
        if (!a)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory for a texture", mesh);
        for (i = 0; i < n; ++i)
            a[i] = t->pcData[i].a / 255.0f;
        st = rs_scene_add_mask(s, t->mWidth, t->mHeight, a, alpha->scale, alpha->cutoff, id);
        rs_free(a);
        return st;
    }
    rgb = (float *)rs_alloc((size_t)n * 3, sizeof *rgb);
    if (!rgb)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory for a texture", mesh);
    for (i = 0; i < n; ++i) {
        const struct aiTexel *px = &t->pcData[i];
        rgb[3 * i] = px->r / 255.0f;
        rgb[3 * i + 1] = px->g / 255.0f;
        rgb[3 * i + 2] = px->b / 255.0f;
        if (!data) {
            int c;
            for (c = 0; c < 3; ++c)
                rgb[3 * i + c] = rs_srgb_decode(rgb[3 * i + c]);
        }
    }
    st = rs_scene_add_image(s, t->mWidth, t->mHeight, rgb, image);
    rs_free(rgb);
    return st;
}

/* Embedded texture t's compressed bytes (mWidth of them, a format hint) written to a temporary
 * file, whose name goes in tmp[tmp_n] (for OpenImageIO to read, then unlinked by the caller). */
static rs_status embedded_to_file(const struct aiTexture *t, const char *name, const char *mesh,
                                  char *tmp, size_t tmp_n)
{
    size_t bytes = t->mWidth;
    FILE *f;
    int fd;
    snprintf(tmp, tmp_n, "/tmp/raystream-tex-XXXXXX.%.8s",
             t->achFormatHint[0] ? t->achFormatHint : "png");
    fd = mkstemps(tmp, (int)strlen(strrchr(tmp, '.')));
    if (fd < 0) {
        *tmp = 0;
        return rs_error_set(RS_ERR_IO, "%s: cannot write embedded texture %s to /tmp", mesh, name);
    }
    f = fdopen(fd, "wb");
    if (!f || fwrite(t->pcData, 1, bytes, f) != bytes) {
        if (f)
            fclose(f);
        else
            close(fd);
        unlink(tmp);
        *tmp = 0;
        return rs_error_set(RS_ERR_IO, "%s: cannot write embedded texture %s to /tmp", mesh, name);
    }
    fclose(f);
    return RS_OK;
}

/* Image file `path` (tex: as the material names it) as a scene image in *image, or with `alpha`
 * its alpha channel as a mask in *id.  A texture that is not a regular file of a sane size (a
 * FIFO, /dev/zero, a folder) is refused outright, as is one that is there but unusable (a texel
 * NaN, infinite or negative); a missing or unreadable one fails only a strict import, else warns
 * (*loaded 0: keep the colour). */
static rs_status texture_file(rs_scene *s, const char *path, const char *tex, const char *mesh,
                              int data, int strict, const alpha_req *alpha, uint32_t *id,
                              uint32_t *image, int *loaded)
{
    char why[1200];
    rs_status st;
    int fd;
    *loaded = 0;
    st = rs_file_open_quiet(path, RS_FILE_MAX_IMAGE_BYTES, &fd, NULL, why, sizeof why);
    if (st == RS_ERR_ARG)
        return rs_error_set(st, "%s: %s", mesh, why);
    if (st == RS_OK)
        close(fd);
    rs_error_clear();
    st = alpha ? load_mask_file(s, path, alpha, id)
         : data ? rs_scene_load_image_data(s, path, image)
                : rs_scene_load_image(s, path, image);
    if (st != RS_OK) {
        if (strict || st == RS_ERR_ARG) {
            char msg[1200];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            return rs_error_set(st, "%s: texture %s: %s", mesh, tex, msg);
        }
        /* a missing texture file: keep the colour, say so once */
        fprintf(stderr, "raystream: warning: %s\n", rs_error_message());
        rs_error_clear();
        return RS_OK;
    }
    *loaded = 1;
    return RS_OK;
}

static rs_status load_texture_ex(rs_scene *s, const struct aiScene *as,
                                 const struct aiMaterial *am, enum aiTextureType type,
                                 const char *mesh, const char *dir, int data, int strict,
                                 const alpha_req *alpha, uint32_t *id)
{
    struct aiString tex;
    char path[2048], tmp[64] = "";
    uint32_t image = 0;
    rs_texture tx;
    rs_status st;
    int loaded = 0;
    *id = alpha ? 0 : RS_NO_TEXTURE;
    if (aiGetMaterialTexture(am, type, 0, &tex, NULL, NULL, NULL, NULL, NULL, NULL) !=
            aiReturn_SUCCESS ||
        tex.length == 0)
        return RS_OK;
    if (tex.data[0] == '*') {
        /* embedded: compressed bytes (mHeight 0, mWidth bytes, a format hint), or raw texels */
        long k = strtol(tex.data + 1, NULL, 10);
        const struct aiTexture *t;
        if (!as || k < 0 || (unsigned long)k >= as->mNumTextures || !as->mTextures[k])
            return rs_error_set(RS_ERR_ARG, "%s: a material names embedded texture %s, which "
                                            "the file does not have", mesh, tex.data);
        t = as->mTextures[k];
        if (t->mHeight != 0) {
            st = embedded_texels(s, t, tex.data, mesh, data, alpha, id, &image);
            if (st != RS_OK || alpha)
                return st;
            loaded = 1;
        } else {
            RS_TRY(embedded_to_file(t, tex.data, mesh, tmp, sizeof tmp));
            snprintf(path, sizeof path, "%s", tmp);
        }
    } else if (tex.data[0] == '/') {
        snprintf(path, sizeof path, "%s", tex.data);
    } else {
        snprintf(path, sizeof path, "%s/%s", dir, tex.data);
    }
    if (!loaded) {
        st = texture_file(s, path, tex.data, mesh, data, strict, alpha, id, &image, &loaded);
        if (*tmp)
            unlink(tmp);
        if (st != RS_OK || !loaded || alpha)
            return st; /* an error, a missing texture's warning, or the mask made */
    }
    memset(&tx, 0, sizeof tx);
    tx.type = RS_TEX_IMAGE;
    tx.image = image;
    uv_transform(am, type, &tx);
    return rs_scene_add_texture(s, &tx, id);
}

static rs_vec3 clamp01(rs_vec3 c)
{
    return rs_v3(fminf(fmaxf(c.x, 0), 1), fminf(fmaxf(c.y, 0), 1), fminf(fmaxf(c.z, 0), 1));
}

/* KHR_materials_transmission (mostly transmitting): rough glass of the material's index
 * (KHR_materials_ior, else 1.5), tinted by the base colour; the transmission texture is not
 * read.  KHR_materials_volume's attenuation as the glass's absorption. */
static rs_status add_pbr_glass(rs_scene *s, const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                               struct aiColor4D base, ai_real rough, uint32_t *id)
{
    rs_material m;
    unsigned int one;
    ai_real ior = 1.5f;
    float r = fminf(fmaxf(rough, 0), 1);
    int c;
    one = 1;
    aiGetMaterialFloatArray(am, AI_MATKEY_REFRACTI, &ior, &one);
    if (x->ior != 1.5f)
        ior = x->ior; /* our reading of KHR_materials_ior (checked) */
    m = rs_mat_rough_dielectric(isfinite(ior) && ior > 1e-3f && ior < 100 ? ior : 1.5f, r * r);
    m.albedo = clamp01(rs_v3(base.r, base.g, base.b));
    if (isfinite(x->attenuation_distance)) {
        /* KHR_materials_volume: what is left after attenuationDistance is attenuationColor
         * (a channel of 0 taken as 1e-6, so that the coefficient stays finite) */
        float sig[3];
        for (c = 0; c < 3; ++c)
            sig[c] = (float)(-log(fmax((double)x->attenuation_color[c], 1e-6)) /
                             x->attenuation_distance);
        m.sigma_a = rs_v3(sig[0], sig[1], sig[2]);
    }
    return rs_scene_add_material(s, &m, id);
}

/* The pbr material's emission (times KHR_materials_emissive_strength) and its layers: the
 * dielectric one (KHR_materials_ior, KHR_materials_specular), sheen and clearcoat. */
static void pbr_layers(rs_material *mp, const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                       struct aiColor4D ke)
{
    rs_material m = *mp;
    ai_real strength = 1;
    unsigned int one;
    m.emission = rs_v3(fmaxf(ke.r, 0), fmaxf(ke.g, 0), fmaxf(ke.b, 0));
    one = 1;
    if (x->emissive_strength != 1.0f)
        m.emission = rs_v3_scale(m.emission, x->emissive_strength); /* ours (Assimp 5.2 drops it) */
    else if (aiGetMaterialFloatArray(am, AI_MATKEY_EMISSIVE_INTENSITY, &strength, &one) ==
                 aiReturn_SUCCESS &&
             strength >= 0 && isfinite(strength))
        m.emission = rs_v3_scale(m.emission, strength); /* KHR_materials_emissive_strength */
    {
        /* the dielectric layer: F0 from KHR_materials_ior and KHR_materials_specular's colour
         * (in double, so that the defaults give exactly rs_mat_pbr's 0.04f), its weight */
        double f = ((double)x->ior - 1.0) / ((double)x->ior + 1.0);
        m.specular = rs_v3((float)fmin(f * f * x->specular_color[0], 1.0),
                           (float)fmin(f * f * x->specular_color[1], 1.0),
                           (float)fmin(f * f * x->specular_color[2], 1.0));
        m.spec_weight = x->specular;
    }
    /* KHR_materials_sheen (its textures not read) */
    m.sheen = rs_v3(x->sheen_color[0], x->sheen_color[1], x->sheen_color[2]);
    m.sheen_rough = x->sheen_roughness;
    if (x->clearcoat > 0.0f) { /* KHR_materials_clearcoat (its textures and normal not read) */
        float a = x->clearcoat_roughness * x->clearcoat_roughness;
        m.coat = x->clearcoat;
        m.coat_alpha = a < RS_GGX_DELTA_ALPHA ? RS_GGX_DELTA_ALPHA : a;
    }
    *mp = m;
}

/* The base colour texture (glTF's, else a diffuse one), the factor baked into its texels. */
static rs_status pbr_base_texture(rs_scene *s, const struct aiScene *as,
                                  const struct aiMaterial *am, const char *mesh, const char *dir,
                                  int strict, rs_material *m)
{
    uint32_t t;
    if (load_texture(s, as, am, aiTextureType_BASE_COLOR, mesh, dir, TEX_COLOR, strict, &t) !=
        RS_OK)
        return RS_ERR_ARG;
    if (t == RS_NO_TEXTURE &&
        load_texture(s, as, am, aiTextureType_DIFFUSE, mesh, dir, TEX_COLOR, strict, &t) != RS_OK)
        return RS_ERR_ARG;
    if (t != RS_NO_TEXTURE) {
        /* glTF multiplies the texture by the factor: bake the factor into the texels */
        RS_TRY(rs_scene_scale_image(s, s->textures[t].image, m->albedo));
        m->albedo_tex = t;
        m->albedo = rs_v3_splat(1.0f);
    }
    return RS_OK;
}

/* glTF's alpha cut-out: MASK at its alphaCutoff, BLEND taken as a mask at 0.5 (no partial
 * transparency); the base colour texture's alpha times the factor's (base_a). */
static rs_status pbr_alpha(rs_scene *s, const struct aiScene *as, const struct aiMaterial *am,
                           const char *mesh, const char *dir, int strict, ai_real base_a,
                           uint32_t *alpha_mask)
{
    struct aiString mode;
    ai_real cutoff = 0.5f;
    if (aiGetMaterialString(am, AI_MATKEY_GLTF_ALPHAMODE, &mode) == aiReturn_SUCCESS &&
        (strcmp(mode.data, "MASK") == 0 || strcmp(mode.data, "BLEND") == 0)) {
        alpha_req ar;
        unsigned int one = 1;
        if (strcmp(mode.data, "MASK") == 0)
            aiGetMaterialFloatArray(am, AI_MATKEY_GLTF_ALPHACUTOFF, &cutoff, &one);
        ar.scale = isfinite(base_a) ? fminf(fmaxf(base_a, 0), 1) : 1.0f;
        ar.cutoff = isfinite(cutoff) ? cutoff : 0.5f;
        if (load_texture_ex(s, as, am, aiTextureType_BASE_COLOR, mesh, dir, TEX_DATA, strict,
                            &ar, alpha_mask) != RS_OK)
            return RS_ERR_ARG;
        /* no alpha texels: the factor alone, all or nothing */
        if (!*alpha_mask && ar.scale < ar.cutoff &&
            rs_scene_add_mask(s, 1, 1, NULL, ar.scale, ar.cutoff, alpha_mask) != RS_OK)
            return RS_ERR_ARG;
    }
    return RS_OK;
}

/* KHR_materials_unlit: the base colour (its texture's too), emitted; nothing reflected. */
static void pbr_unlit(rs_material *m)
{
    m->emission = m->albedo;
    m->emission_tex = m->albedo_tex;
    m->albedo = rs_v3_splat(0.0f);
    m->albedo_tex = RS_NO_TEXTURE;
    m->metallic = 0.0f;
    m->spec_weight = 0.0f;
    m->coat = 0.0f;
    m->sheen = rs_v3_splat(0.0f);
    m->mr_tex = m->normal_tex = RS_NO_TEXTURE;
}

/* glTF's metallic-roughness material (Assimp sets a metallic factor for it): base colour and
 * its texture, metallic and roughness and their texture, emission and its texture, the normal
 * map. */
static rs_status add_pbr_material(rs_scene *s, const struct aiScene *as,
                                  const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                                  const char *mesh, const char *dir, int strict, uint32_t *id)
{
    struct aiColor4D base = {1, 1, 1, 1}, ke = {0, 0, 0, 1};
    ai_real metal = 1, rough = 1, scale = 1, trans = 0;
    unsigned int one = 1;
    rs_material m;
    rs_gltf_mat_ext none = rs_gltf_mat_ext_default();
    if (!x)
        x = &none;
    aiGetMaterialColor(am, AI_MATKEY_BASE_COLOR, &base);
    aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &ke);
    aiGetMaterialFloatArray(am, AI_MATKEY_METALLIC_FACTOR, &metal, &one);
    one = 1;
    aiGetMaterialFloatArray(am, AI_MATKEY_ROUGHNESS_FACTOR, &rough, &one);
    one = 1;
    if (aiGetMaterialFloatArray(am, AI_MATKEY_TRANSMISSION_FACTOR, &trans, &one) ==
            aiReturn_SUCCESS &&
        trans >= 0.5f && metal < 0.5f)
        return add_pbr_glass(s, am, x, base, rough, id);
    m = rs_mat_pbr(clamp01(rs_v3(base.r, base.g, base.b)), fminf(fmaxf(metal, 0), 1),
                   fminf(fmaxf(rough, 0), 1));
    pbr_layers(&m, am, x, ke);
    if (!isfinite(m.emission.x + m.emission.y + m.emission.z))
        return rs_error_set(RS_ERR_ARG, "%s: a material's emissive factor is not finite", mesh);
    if (pbr_base_texture(s, as, am, mesh, dir, strict, &m) != RS_OK ||
        pbr_alpha(s, as, am, mesh, dir, strict, base.a, &m.alpha_mask) != RS_OK)
        return RS_ERR_ARG;
    if (load_texture(s, as, am, aiTextureType_UNKNOWN, mesh, dir, TEX_DATA, strict,
                     &m.mr_tex) != RS_OK ||
        load_texture(s, as, am, aiTextureType_EMISSIVE, mesh, dir, TEX_COLOR, strict,
                     &m.emission_tex) != RS_OK ||
        load_texture(s, as, am, aiTextureType_NORMALS, mesh, dir, TEX_DATA, strict,
                     &m.normal_tex) != RS_OK)
        return RS_ERR_ARG;
    if (m.emission_tex != RS_NO_TEXTURE && rs_v3_is_zero(m.emission))
        m.emission_tex = RS_NO_TEXTURE; /* a texture times a zero factor */
    if (x->unlit)
        pbr_unlit(&m);
    one = 1;
    if (m.normal_tex != RS_NO_TEXTURE &&
        aiGetMaterialFloatArray(am, "$tex.scale", aiTextureType_NORMALS, 0, &scale, &one) ==
            aiReturn_SUCCESS &&
        isfinite(scale))
        m.normal_scale = scale;
    return rs_scene_add_material(s, &m, id);
}

/* A scene material for an Assimp material: glTF's metallic-roughness as the pbr material; else an
 * emitter if it emits, Phong if it has a specular colour and shininess, Lambertian otherwise; a
 * diffuse texture file becomes an image texture. */
rs_status rs_mesh_add_file_material(rs_scene *s, const struct aiScene *as,
                                    const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                                    const char *mesh, const char *dir, int strict, uint32_t *id)
{
    struct aiColor4D kd = {0.7f, 0.7f, 0.7f, 1}, ks = {0, 0, 0, 1}, ke = {0, 0, 0, 1};
    ai_real shininess = 0, metal;
    unsigned int max = 1;
    rs_material m;
    if (aiGetMaterialFloatArray(am, AI_MATKEY_METALLIC_FACTOR, &metal, &max) == aiReturn_SUCCESS)
        return add_pbr_material(s, as, am, x, mesh, dir, strict, id);
    max = 1;
    aiGetMaterialColor(am, AI_MATKEY_COLOR_DIFFUSE, &kd);
    aiGetMaterialColor(am, AI_MATKEY_COLOR_SPECULAR, &ks);
    aiGetMaterialColor(am, AI_MATKEY_COLOR_EMISSIVE, &ke);
    aiGetMaterialFloatArray(am, AI_MATKEY_SHININESS, &shininess, &max);
    if (ke.r > 0 || ke.g > 0 || ke.b > 0) {
        m = rs_mat_light(rs_v3(ke.r, ke.g, ke.b), 0);
    } else {
        rs_vec3 d = clamp01(rs_v3(kd.r, kd.g, kd.b));
        rs_vec3 sp = rs_v3(fmaxf(ks.r, 0), fmaxf(ks.g, 0), fmaxf(ks.b, 0));
        uint32_t t;
        if (rs_v3_max_comp(sp) > 0 && shininess > 1) {
            /* keep kd + ks <= 1 per channel so the Phong model conserves energy */
            float sum = rs_v3_max_comp(rs_v3_add(d, sp));
            if (sum > 1)
                sp = rs_v3_scale(sp, fmaxf(0.0f, 1.0f - rs_v3_max_comp(d)) / rs_v3_max_comp(sp));
            m = rs_mat_phong(d, sp, (float)shininess);
        } else {
            m = rs_mat_lambertian(d);
        }
        if (load_texture(s, as, am, aiTextureType_DIFFUSE, mesh, dir, TEX_COLOR, strict, &t) !=
            RS_OK)
            return RS_ERR_ARG;
        if (t != RS_NO_TEXTURE) {
            m.albedo_tex = t;
            m.albedo = rs_v3_splat(1.0f);
        }
    }
    return rs_scene_add_material(s, &m, id);
}

/* The override for file material am (its index in o->override_names), or -1. */
int rs_mesh_override_of(const struct aiMaterial *am, const rs_mesh_opts *o)
{
    struct aiString name;
    uint32_t k;
    if (!o->n_overrides || aiGetMaterialString(am, AI_MATKEY_NAME, &name) != aiReturn_SUCCESS)
        return -1;
    for (k = 0; k < o->n_overrides; ++k)
        if (strcmp(name.data, o->override_names[k]) == 0)
            return (int)k;
    return -1;
}

/* Every override must name a material of the file: a misspelt name would otherwise be ignored
 * without a word. */
rs_status rs_mesh_check_overrides(const struct aiScene *as, const char *path, const rs_mesh_opts *o)
{
    uint32_t k, j;
    for (k = 0; k < o->n_overrides; ++k) {
        int found = 0;
        char have[512] = "";
        for (j = 0; j < as->mNumMaterials && !found; ++j) {
            struct aiString name;
            if (aiGetMaterialString(as->mMaterials[j], AI_MATKEY_NAME, &name) != aiReturn_SUCCESS)
                continue;
            found = strcmp(name.data, o->override_names[k]) == 0;
            if (strlen(have) + name.length + 5 < sizeof have) {
                strcat(have, *have ? ", '" : "'");
                strcat(have, name.data);
                strcat(have, "'");
            }
        }
        if (!found)
            return rs_error_set(RS_ERR_ARG, "%s: the file has no material named '%s' (it has: %s)",
                                path, o->override_names[k], *have ? have : "none");
    }
    return RS_OK;
}
