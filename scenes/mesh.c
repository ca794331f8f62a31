/* scenes/mesh.c — see mesh.h. */
#define _DEFAULT_SOURCE /* mkstemps, for a glTF binary's embedded textures */
#include "scenes/mesh.h"
#include "scenes/gltf.h"
#include "scenes/gltf_check.h"
#include "scenes/ply_header.h"
#include "scenes/ply_strips.h"
#include "scenes/transform.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/GltfMaterial.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
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

/* ---- every file Assimp opens goes through core/file.h ------------------------------------ */

/* Assimp's own file system would open whatever a mesh names (an OBJ's mtllib, a glTF's
 * buffers): a FIFO blocks the open for ever, /dev/zero never ends.  These callbacks open only
 * regular files of a sane size.  A file refused for its kind or size is remembered and fails
 * the whole import, even where Assimp would carry on without it; a missing file is left to
 * Assimp (an OBJ without its MTL still imports, with default materials). */
typedef struct mesh_io {
    struct aiFileIO io;  /* first: Assimp hands this pointer back */
    rs_status refused;   /* RS_OK, or the code of the first refusal */
    char why[1200];      /* its message, "FILE: not a regular file" */
} mesh_io;

typedef struct mesh_file {
    struct aiFile file;  /* first: Assimp hands this pointer back */
    FILE *fp;
    uint64_t size;
} mesh_file;

static size_t mf_read(struct aiFile *f, char *buf, size_t size, size_t count)
{
    return fread(buf, size, count, ((mesh_file *)f)->fp);
}

static size_t mf_write(struct aiFile *f, const char *buf, size_t size, size_t count)
{
    (void)f, (void)buf, (void)size, (void)count;
    return 0; /* opened for reading only */
}

static size_t mf_tell(struct aiFile *f)
{
    off_t at = ftello(((mesh_file *)f)->fp);
    return at < 0 ? 0 : (size_t)at;
}

static size_t mf_size(struct aiFile *f) { return (size_t)((mesh_file *)f)->size; }

static enum aiReturn mf_seek(struct aiFile *f, size_t offset, enum aiOrigin origin)
{
    /* Assimp passes a backwards relative seek as a wrapped-around size_t */
    int whence = origin == aiOrigin_CUR ? SEEK_CUR : origin == aiOrigin_END ? SEEK_END : SEEK_SET;
    return fseeko(((mesh_file *)f)->fp, (off_t)(ptrdiff_t)offset, whence) == 0 ? aiReturn_SUCCESS
                                                                             : aiReturn_FAILURE;
}

static void mf_flush(struct aiFile *f) { (void)f; }

static struct aiFile *mio_open(struct aiFileIO *io, const char *path, const char *mode)
{
    mesh_io *m = (mesh_io *)io;
    mesh_file *mf;
    char msg[1200];
    uint64_t size;
    int fd;
    rs_status st;
    if (!path || !mode || strpbrk(mode, "wa+"))
        return NULL; /* an import never writes */
    st = rs_file_open_quiet(path, RS_FILE_MAX_MESH_BYTES, &fd, &size, msg, sizeof msg);
    if (st != RS_OK) {
        if (st == RS_ERR_ARG && m->refused == RS_OK) {
            m->refused = st;
            snprintf(m->why, sizeof m->why, "%s", msg);
        }
        return NULL;
    }
    mf = (mesh_file *)rs_calloc(1, sizeof *mf);
    if (!mf || !(mf->fp = fdopen(fd, "rb"))) {
        rs_free(mf);
        close(fd);
        return NULL;
    }
    mf->size = size;
    mf->file.ReadProc = mf_read;
    mf->file.WriteProc = mf_write;
    mf->file.TellProc = mf_tell;
    mf->file.FileSizeProc = mf_size;
    mf->file.SeekProc = mf_seek;
    mf->file.FlushProc = mf_flush;
    return &mf->file;
}

static void mio_close(struct aiFileIO *io, struct aiFile *f)
{
    (void)io;
    if (f) {
        fclose(((mesh_file *)f)->fp);
        rs_free(f);
    }
}

/* ---- PLY headers ------------------------------------------------------------------------- */

/* Assimp's PLY reader spins for ever on a header that stops before end_header, and aborts the
 * whole process (an ai_assert in its triangulation, found by tests/fuzz/fuzz_mesh) on an ascii
 * file whose data stops before the elements its header declares.  A file that says it is PLY
 * (by its first line or its extension) must have a header that scenes/ply_header.h accepts
 * (end_header within its first 64 KiB; counts and, in binary, bytes that the data can hold) and,
 * in ascii, a line for every instance of an element that has a property (one instance a line,
 * as the format writes them). */

static int ext_is(const char *path, const char *ext)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    size_t i;
    if (!dot || (slash && dot < slash) || strlen(dot + 1) != strlen(ext))
        return 0;
    for (i = 0; ext[i]; ++i)
        if (tolower((unsigned char)dot[1 + i]) != ext[i])
            return 0;
    return 1;
}

#define RS_PLY_WALK_ELEMS 16 /* elements a strict parse keeps for the walk */

/* The ascii data's lists, walked token by token over the elements a strict header parse kept
 * (chunk by chunk: ply_walk_chunk): Assimp reads a list's length from its leading digits as a
 * 32-bit number whatever the header's length type, and reserves that many values before it reads
 * them (a fuzzed "4555555555t" asked for 30 GiB).  A length above what the rest of the file could
 * hold (two bytes an item: a digit and a blank) is refused with its line. */
typedef struct ply_walk {
    const rs_ply_elem *elems;
    int n_elems, e, p;  /* the element and the property the next token belongs to */
    uint64_t inst;      /* the instance (line) of element e */
    int64_t list_left;  /* items left in the current list; -1: at a property's first token */
    uint64_t value;     /* the token's leading digits so far (capped) */
    int in_tok, digits; /* inside a token; its leading digits still running */
    uint64_t line, max_items;
} ply_walk;

/* Steps past elements without a property (they take no line) and finished ones. */
static void ply_walk_settle(ply_walk *w)
{
    while (w->e < w->n_elems &&
           (w->elems[w->e].n_props == 0 || w->inst >= w->elems[w->e].count)) {
        w->e++;
        w->inst = 0;
    }
}

/* One whole token of the data; 0 when it is a list length too long for the file. */
static int ply_walk_token(ply_walk *w)
{
    const rs_ply_elem *el;
    if (w->e >= w->n_elems || w->p >= w->elems[w->e].n_props)
        return 1; /* past the declared data, or extra tokens on a line: Assimp's to judge */
    el = &w->elems[w->e];
    if (w->list_left > 0) {
        if (--w->list_left == 0) {
            w->list_left = -1;
            w->p++;
        }
        return 1;
    }
    if (el->props[w->p].len_type == RS_PLY_NONE) {
        w->p++;
        return 1;
    }
    if (w->value > w->max_items)
        return 0;
    w->list_left = (int64_t)w->value;
    if (w->list_left == 0) {
        w->list_left = -1;
        w->p++;
    }
    return 1;
}

static rs_status ply_list_error(const ply_walk *w, const char *path)
{
    if (w->value >= (1ull << 40))
        return rs_error_set(RS_ERR_ARG,
                            "%s: PLY data line %llu: a list of over 10^12 items (the file holds "
                            "%llu bytes)",
                            path, (unsigned long long)w->line,
                            (unsigned long long)(2u * (w->max_items - 1u)));
    return rs_error_set(RS_ERR_ARG,
                        "%s: PLY data line %llu: a list of %llu items, more than the file's "
                        "data could hold",
                        path, (unsigned long long)w->line, (unsigned long long)w->value);
}

static rs_status ply_walk_chunk(ply_walk *w, const char *path, const char *buf, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        char c = buf[i];
        if (c == ' ' || c == '\t' || c == '\r' || c == '\n') {
            if (w->in_tok && !ply_walk_token(w))
                return ply_list_error(w, path);
            w->in_tok = 0;
            if (c == '\n') {
                w->line++;
                w->p = 0;
                w->list_left = -1;
                if (w->e < w->n_elems) {
                    w->inst++;
                    ply_walk_settle(w);
                }
            }
        } else if (!w->in_tok) {
            w->in_tok = 1;
            w->value = c >= '0' && c <= '9' ? (uint64_t)(c - '0') : 0;
            w->digits = (c >= '0' && c <= '9') || c == '+';
        } else if (w->digits && c >= '0' && c <= '9') {
            if (w->value < (1ull << 40))
                w->value = w->value * 10u + (uint64_t)(c - '0');
        } else {
            w->digits = 0;
        }
    }
    return RS_OK;
}

/* Checks a file that says it is PLY (*is_ply set: 1, or 2 for one of triangle strips, which
 * Assimp does not read: a stripped model came out as one triangle; scenes/ply_strips.h does);
 * any other file passes. */
static rs_status check_ply_header(const char *path, int *is_ply_out)
{
    FILE *f;
    uint64_t size, lines = 0;
    char *buf;
    size_t n, i;
    int last_nl;
    rs_ply_header h, strict;
    rs_ply_elem *elems;
    ply_walk w;
    rs_status st = rs_file_open(path, RS_FILE_MAX_MESH_BYTES, &f, &size);
    *is_ply_out = 0;
    if (st != RS_OK)
        return st;
    buf = (char *)rs_alloc(RS_PLY_MAX_HEADER + 1, 1);
    if (!buf) {
        fclose(f);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    }
    n = fread(buf, 1, RS_PLY_MAX_HEADER, f);
    buf[n] = '\0';
    if (!rs_ply_is_ply(buf, n)) {
        fclose(f);
        rs_free(buf);
        if (ext_is(path, "ply"))
            return rs_error_set(RS_ERR_ARG, "%s: not a PLY file (its first line is not 'ply')",
                                path);
        return RS_OK;
    }
    memset(&h, 0, sizeof h);
    st = rs_ply_parse_header(path, buf, n, size, 0, &h);
    *is_ply_out = h.tristrips ? 2 : 1;
    if (st != RS_OK || !h.ascii) {
        fclose(f);
        rs_free(buf);
        return st;
    }
    /* the elements and properties, to walk the lists (a header only the loose parse takes is
     * left to Assimp as before) */
    memset(&w, 0, sizeof w);
    elems = (rs_ply_elem *)rs_alloc(RS_PLY_WALK_ELEMS, sizeof *elems);
    memset(&strict, 0, sizeof strict);
    strict.elems = elems;
    strict.max_elems = elems ? RS_PLY_WALK_ELEMS : 0;
    if (elems && rs_ply_parse_header(path, buf, n, size, 1, &strict) == RS_OK) {
        w.elems = elems;
        w.n_elems = strict.n_elems;
        w.list_left = -1;
        w.line = 1;
        w.max_items = (size - h.data_at) / 2u + 1u;
        ply_walk_settle(&w);
    }
    rs_error_clear();
    /* the ascii data's lines: every newline, and a last line without one */
    for (i = h.data_at; i < n; ++i)
        lines += buf[i] == '\n';
    last_nl = n == h.data_at || buf[n - 1] == '\n';
    st = ply_walk_chunk(&w, path, buf + h.data_at, n - h.data_at);
    while (st == RS_OK && (n = fread(buf, 1, RS_PLY_MAX_HEADER, f)) > 0) {
        for (i = 0; i < n; ++i)
            lines += buf[i] == '\n';
        last_nl = buf[n - 1] == '\n';
        if (w.e < w.n_elems)
            st = ply_walk_chunk(&w, path, buf, n);
        else if (lines >= h.need_lines)
            break;
    }
    if (st == RS_OK && w.in_tok && !ply_walk_token(&w)) /* a last token without a newline */
        st = ply_list_error(&w, path);
    lines += !last_nl;
    fclose(f);
    rs_free(buf);
    rs_free(elems);
    if (st != RS_OK)
        return st;
    if (lines < h.need_lines)
        return rs_error_set(RS_ERR_ARG,
                            "%s: PLY header declares %llu elements, but its ascii data has only "
                            "%llu lines (a cut file?)",
                            path, (unsigned long long)h.need_lines, (unsigned long long)lines);
    return RS_OK;
}

/* 1 when a mesh of `as` has a face without any index.  Assimp's PLY reader makes such faces
 * from face lines it cannot read (or "0"), and its post-processing then crashes the process
 * (SortByPType: SIGBUS; found by tests/fuzz/fuzz_mesh).  Post-processing a scene read without
 * it is no way out: where a step fails, aiApplyPostProcessing crashes releasing the scene. */
static int has_empty_face(const struct aiScene *as)
{
    unsigned int mi, k;
    for (mi = 0; mi < as->mNumMeshes; ++mi) {
        const struct aiMesh *m = as->mMeshes[mi];
        for (k = 0; m && m->mFaces && k < m->mNumFaces; ++k)
            if (m->mFaces[k].mNumIndices == 0 || !m->mFaces[k].mIndices)
                return 1;
    }
    return 0;
}

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

static rs_status load_texture_ex(rs_scene *s, const struct aiScene *as,
                                 const struct aiMaterial *am, enum aiTextureType type,
                                 const char *mesh, const char *dir, int data, int strict,
                                 const alpha_req *alpha, uint32_t *id)
{
    struct aiString tex;
    char path[2048], why[1200], tmp[64] = "";
    uint32_t image;
    rs_texture tx;
    rs_status st;
    int fd;
    *id = alpha ? 0 : RS_NO_TEXTURE;
    if (aiGetMaterialTexture(am, type, 0, &tex, NULL, NULL, NULL, NULL, NULL, NULL) !=
            aiReturn_SUCCESS ||
        tex.length == 0)
        return RS_OK;
    if (tex.data[0] == '*') {
        /* embedded: compressed bytes (mHeight 0, mWidth bytes, a format hint), or raw texels */
        long k = strtol(tex.data + 1, NULL, 10);
        const struct aiTexture *t;
        FILE *f;
        size_t bytes;
        if (!as || k < 0 || (unsigned long)k >= as->mNumTextures || !as->mTextures[k])
            return rs_error_set(RS_ERR_ARG, "%s: a material names embedded texture %s, which "
                                            "the file does not have", mesh, tex.data);
        t = as->mTextures[k];
        if (t->mHeight != 0) {
            /* raw BGRA texels, top row first */
            float *rgb;
            uint32_t i, n;
            if ((uint64_t)t->mWidth * t->mHeight > RS_IMAGE_MAX_PIXELS)
                return rs_error_set(RS_ERR_ARG, "%s: embedded texture %s is too large", mesh,
                                    tex.data);
            n = t->mWidth * t->mHeight;
            if (alpha) {
                float *a = (float *)rs_alloc(n ? n : 1, sizeof *a);
                if (!a)
                    return rs_error_set(RS_ERR_NOMEM, "%s: out of memory for a texture", mesh);
                for (i = 0; i < n; ++i)
                    a[i] = t->pcData[i].a / 255.0f;
                st = rs_scene_add_mask(s, t->mWidth, t->mHeight, a, alpha->scale, alpha->cutoff,
                                       id);
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
            st = rs_scene_add_image(s, t->mWidth, t->mHeight, rgb, &image);
            rs_free(rgb);
            if (st != RS_OK)
                return st;
            goto made;
        }
        bytes = t->mWidth;
        snprintf(tmp, sizeof tmp, "/tmp/raystream-tex-XXXXXX.%.8s",
                 t->achFormatHint[0] ? t->achFormatHint : "png");
        fd = mkstemps(tmp, (int)strlen(strrchr(tmp, '.')));
        if (fd < 0)
            return rs_error_set(RS_ERR_IO, "%s: cannot write embedded texture %s to /tmp", mesh,
                                tex.data);
        f = fdopen(fd, "wb");
        if (!f || fwrite(t->pcData, 1, bytes, f) != bytes) {
            if (f)
                fclose(f);
            else
                close(fd);
            unlink(tmp);
            return rs_error_set(RS_ERR_IO, "%s: cannot write embedded texture %s to /tmp", mesh,
                                tex.data);
        }
        fclose(f);
        snprintf(path, sizeof path, "%s", tmp);
    } else if (tex.data[0] == '/') {
        snprintf(path, sizeof path, "%s", tex.data);
    } else {
        snprintf(path, sizeof path, "%s/%s", dir, tex.data);
    }
    /* a texture that is not a regular file of a sane size (a FIFO, /dev/zero, a folder) is
     * refused outright; a missing or unreadable one fails only a strict import */
    st = rs_file_open_quiet(path, RS_FILE_MAX_IMAGE_BYTES, &fd, NULL, why, sizeof why);
    if (st == RS_ERR_ARG) {
        if (*tmp)
            unlink(tmp);
        return rs_error_set(st, "%s: %s", mesh, why);
    }
    if (st == RS_OK)
        close(fd);
    rs_error_clear();
    st = alpha ? load_mask_file(s, path, alpha, id)
         : data ? rs_scene_load_image_data(s, path, &image)
                : rs_scene_load_image(s, path, &image);
    if (*tmp)
        unlink(tmp);
    if (st != RS_OK) {
        /* a texture that is there but unusable (a texel NaN, infinite or negative) is refused
         * even where a missing one only warns */
        if (strict || st == RS_ERR_ARG) {
            char msg[1200];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            return rs_error_set(st, "%s: texture %s: %s", mesh, tex.data, msg);
        }
        /* a missing texture file: keep the colour, say so once */
        fprintf(stderr, "raystream: warning: %s\n", rs_error_message());
        rs_error_clear();
        return RS_OK;
    }
    if (alpha)
        return RS_OK; /* the mask is made */
made:
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

/* glTF's metallic-roughness material (Assimp sets a metallic factor for it): base colour and
 * its texture, metallic and roughness and their texture, emission and its texture, the normal
 * map. */
static rs_status add_pbr_material(rs_scene *s, const struct aiScene *as,
                                  const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                                  const char *mesh, const char *dir, int strict, uint32_t *id)
{
    struct aiColor4D base = {1, 1, 1, 1}, ke = {0, 0, 0, 1};
    ai_real metal = 1, rough = 1, scale = 1, trans = 0, strength = 1;
    unsigned int one = 1;
    rs_material m;
    uint32_t t;
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
        trans >= 0.5f && metal < 0.5f) {
        /* KHR_materials_transmission (mostly transmitting): rough glass of the material's index
         * (KHR_materials_ior, else 1.5), tinted by the base colour; the transmission texture
         * is not read */
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
    m = rs_mat_pbr(clamp01(rs_v3(base.r, base.g, base.b)), fminf(fmaxf(metal, 0), 1),
                   fminf(fmaxf(rough, 0), 1));
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
    if (!isfinite(m.emission.x + m.emission.y + m.emission.z))
        return rs_error_set(RS_ERR_ARG, "%s: a material's emissive factor is not finite", mesh);
    if (load_texture(s, as, am, aiTextureType_BASE_COLOR, mesh, dir, TEX_COLOR, strict, &t) !=
        RS_OK)
        return RS_ERR_ARG;
    if (t == RS_NO_TEXTURE &&
        load_texture(s, as, am, aiTextureType_DIFFUSE, mesh, dir, TEX_COLOR, strict, &t) != RS_OK)
        return RS_ERR_ARG;
    if (t != RS_NO_TEXTURE) {
        /* glTF multiplies the texture by the factor: bake the factor into the texels */
        rs_image *im = &s->images[s->textures[t].image];
        size_t i, n = (size_t)im->width * im->height;
        for (i = 0; i < n; ++i) {
            im->rgb[3 * i] *= m.albedo.x;
            im->rgb[3 * i + 1] *= m.albedo.y;
            im->rgb[3 * i + 2] *= m.albedo.z;
        }
        m.albedo_tex = t;
        m.albedo = rs_v3_splat(1.0f);
    }
    {
        /* glTF's alpha cut-out: MASK at its alphaCutoff, BLEND taken as a mask at 0.5 (no
         * partial transparency); the base colour texture's alpha times the factor's */
        struct aiString mode;
        ai_real cutoff = 0.5f;
        if (aiGetMaterialString(am, AI_MATKEY_GLTF_ALPHAMODE, &mode) == aiReturn_SUCCESS &&
            (strcmp(mode.data, "MASK") == 0 || strcmp(mode.data, "BLEND") == 0)) {
            alpha_req ar;
            one = 1;
            if (strcmp(mode.data, "MASK") == 0)
                aiGetMaterialFloatArray(am, AI_MATKEY_GLTF_ALPHACUTOFF, &cutoff, &one);
            ar.scale = isfinite(base.a) ? fminf(fmaxf(base.a, 0), 1) : 1.0f;
            ar.cutoff = isfinite(cutoff) ? cutoff : 0.5f;
            if (load_texture_ex(s, as, am, aiTextureType_BASE_COLOR, mesh, dir, TEX_DATA, strict,
                                &ar, &m.alpha_mask) != RS_OK)
                return RS_ERR_ARG;
            /* no alpha texels: the factor alone, all or nothing */
            if (!m.alpha_mask && ar.scale < ar.cutoff &&
                rs_scene_add_mask(s, 1, 1, NULL, ar.scale, ar.cutoff, &m.alpha_mask) != RS_OK)
                return RS_ERR_ARG;
        }
    }
    if (load_texture(s, as, am, aiTextureType_UNKNOWN, mesh, dir, TEX_DATA, strict,
                     &m.mr_tex) != RS_OK ||
        load_texture(s, as, am, aiTextureType_EMISSIVE, mesh, dir, TEX_COLOR, strict,
                     &m.emission_tex) != RS_OK ||
        load_texture(s, as, am, aiTextureType_NORMALS, mesh, dir, TEX_DATA, strict,
                     &m.normal_tex) != RS_OK)
        return RS_ERR_ARG;
    if (m.emission_tex != RS_NO_TEXTURE && rs_v3_is_zero(m.emission))
        m.emission_tex = RS_NO_TEXTURE; /* a texture times a zero factor */
    if (x->unlit) {
        /* KHR_materials_unlit: the base colour (its texture's too), emitted; nothing reflected */
        m.emission = m.albedo;
        m.emission_tex = m.albedo_tex;
        m.albedo = rs_v3_splat(0.0f);
        m.albedo_tex = RS_NO_TEXTURE;
        m.metallic = 0.0f;
        m.spec_weight = 0.0f;
        m.coat = 0.0f;
        m.sheen = rs_v3_splat(0.0f);
        m.mr_tex = m.normal_tex = RS_NO_TEXTURE;
    }
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
static rs_status add_file_material(rs_scene *s, const struct aiScene *as,
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
static int override_of(const struct aiMaterial *am, const rs_mesh_opts *o)
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
static rs_status check_overrides(const struct aiScene *as, const char *path, const rs_mesh_opts *o)
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
static rs_status add_faces(rs_scene *s, const struct aiMesh *m, const rs_xform *xf, uint32_t mat,
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

/* A file named .gltf must hold JSON (its first non-blank byte '{') and one named .glb the binary
 * container (magic "glTF"): when the glTF reader turns a file down, Assimp offers it to every
 * other reader, and its PLY reader spun for ever on junk that began with "ply" (found by
 * tests/fuzz/fuzz_mesh). */
static rs_status check_gltf_start(const char *path)
{
    unsigned char b[64];
    size_t n, i = 0;
    FILE *f;
    int glb = ext_is(path, "glb");
    if (!glb && !ext_is(path, "gltf"))
        return RS_OK;
    if (rs_file_open(path, RS_FILE_MAX_MESH_BYTES, &f, NULL) != RS_OK)
        return RS_ERR_IO;
    n = fread(b, 1, sizeof b, f);
    fclose(f);
    if (glb) {
        if (n < 12 || memcmp(b, "glTF", 4) != 0)
            return rs_error_set(RS_ERR_ARG, "%s: not a glTF binary (no 'glTF' magic)", path);
        return rs_gltf_preflight(path, 1);
    }
    if (n >= 3 && b[0] == 0xEF && b[1] == 0xBB && b[2] == 0xBF)
        i = 3; /* a UTF-8 byte order mark */
    while (i < n && (b[i] == ' ' || b[i] == '\t' || b[i] == '\n' || b[i] == '\r'))
        ++i;
    if (i >= n || b[i] != '{')
        return rs_error_set(RS_ERR_ARG, "%s: not a glTF file (it does not start with a JSON object)",
                            path);
    return rs_gltf_preflight(path, 0);
}

/* A scene of our own making (a PLY of triangle strips) carries this flag; release_scene frees
 * it (Assimp's flags stop at 0x20). */
#define OWN_SCENE 0x40000000u

typedef struct own_scene {
    struct aiScene scene;
    struct aiNode root;
    struct aiMesh mesh, *meshes[1];
    struct aiVector3D *vertices;
    struct aiFace *faces;
    unsigned int *indices;
    rs_ply_strips strips;
} own_scene;

static void release_scene(const struct aiScene *as)
{
    if (as && (as->mFlags & OWN_SCENE)) {
        own_scene *o = (own_scene *)(void *)as;
        rs_free(o->vertices);
        rs_free(o->faces);
        rs_free(o->indices);
        rs_ply_strips_free(&o->strips);
        rs_free(o);
    } else if (as) {
        aiReleaseImport(as);
    }
}

/* A PLY of triangle strips decoded into a one-mesh scene, as Assimp would hand it over. */
static rs_status strips_scene(const char *path, const struct aiScene **out)
{
    own_scene *o = (own_scene *)rs_calloc(1, sizeof *o);
    uint32_t i;
    rs_status st;
    if (!o)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    /* first: release_scene tells our scene from Assimp's by it (tests/fuzz/fuzz_mesh found a
     * strip file without triangles handed to Assimp's release before this was set) */
    o->scene.mFlags = OWN_SCENE;
    st = rs_ply_read_strips(path, &o->strips);
    if (st != RS_OK) {
        rs_free(o);
        return st;
    }
    if (o->strips.n_triangles == 0) {
        release_scene(&o->scene);
        return rs_error_set(RS_ERR_ARG, "%s: its triangle strips hold no triangle", path);
    }
    o->vertices = (struct aiVector3D *)rs_alloc(o->strips.n_vertices + 1, sizeof *o->vertices);
    o->faces = (struct aiFace *)rs_alloc(o->strips.n_triangles, sizeof *o->faces);
    o->indices = (unsigned int *)rs_alloc(3 * (size_t)o->strips.n_triangles, sizeof *o->indices);
    if (!o->vertices || !o->faces || !o->indices) {
        release_scene(&o->scene);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    }
    for (i = 0; i < o->strips.n_vertices; ++i) {
        o->vertices[i].x = o->strips.vertices[3 * i];
        o->vertices[i].y = o->strips.vertices[3 * i + 1];
        o->vertices[i].z = o->strips.vertices[3 * i + 2];
    }
    for (i = 0; i < 3 * o->strips.n_triangles; ++i)
        o->indices[i] = o->strips.triangles[i];
    for (i = 0; i < o->strips.n_triangles; ++i) {
        o->faces[i].mNumIndices = 3;
        o->faces[i].mIndices = &o->indices[3 * i];
    }
    o->mesh.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    o->mesh.mNumVertices = o->strips.n_vertices;
    o->mesh.mVertices = o->vertices;
    o->mesh.mNumFaces = o->strips.n_triangles;
    o->mesh.mFaces = o->faces;
    o->meshes[0] = &o->mesh;
    o->scene.mNumMeshes = 1;
    o->scene.mMeshes = o->meshes;
    o->scene.mRootNode = &o->root;
    *out = &o->scene;
    return RS_OK;
}

/* Imports `path` through core/file.h with Assimp's `flags` (points and lines dropped, our own
 * checks instead of Assimp's validation; see rs_scene_add_mesh) into *out: a scene with at least
 * one mesh and a root node, or an error (set) and *out NULL. */
static rs_status import_file(const char *path, unsigned int flags, const struct aiScene **out)
{
    const struct aiScene *as;
    struct aiPropertyStore *props;
    mesh_io mio;
    uint64_t size;
    int is_ply = 0;
    rs_status st = rs_file_check(path, RS_FILE_MAX_MESH_BYTES, &size);
    *out = NULL;
    if (st != RS_OK)
        return st;
    if (size == 0)
        return rs_error_set(RS_ERR_ARG, "%s: empty file", path);
    st = check_gltf_start(path);
    if (st != RS_OK)
        return st;
    st = check_ply_header(path, &is_ply);
    if (st != RS_OK)
        return st;
    if (is_ply == 2)
        return strips_scene(path, out);
    memset(&mio, 0, sizeof mio);
    mio.io.OpenProc = mio_open;
    mio.io.CloseProc = mio_close;
    props = aiCreatePropertyStore();
    /* Drop points and lines (a truncated OBJ face is a line); keep triangles.  Assimp's own
     * structure validation is off: it rejects a whole file for one bad face, while the loop
     * below checks every index and coordinate and drops just the bad faces. */
    aiSetImportPropertyInteger(props, AI_CONFIG_PP_SBP_REMOVE,
                               aiPrimitiveType_POINT | aiPrimitiveType_LINE);
    if (is_ply) {
        /* a PLY is read once without post-processing first: faces without indices are refused
         * before the steps that crash on them see them (has_empty_face) */
        as = aiImportFileEx(path, 0, &mio.io);
        if (as && mio.refused == RS_OK && has_empty_face(as)) {
            aiReleaseImport(as);
            aiReleasePropertyStore(props);
            return rs_error_set(RS_ERR_ARG,
                                "%s: a PLY face has no vertex indices (a malformed face line?)",
                                path);
        }
        if (as)
            aiReleaseImport(as);
    }
    as = mio.refused != RS_OK ? NULL : aiImportFileExWithProperties(path, flags, &mio.io, props);
    aiReleasePropertyStore(props);
    if (mio.refused != RS_OK) {
        /* a file the mesh names was refused: fail even if Assimp carried on without it */
        if (as)
            aiReleaseImport(as);
        if (strncmp(mio.why, path, strlen(path)) == 0 && mio.why[strlen(path)] == ':')
            return rs_error_set(mio.refused, "%s", mio.why);
        return rs_error_set(mio.refused, "%s: %s", path, mio.why);
    }
    if (!as || !as->mRootNode) {
        st = rs_error_set(RS_ERR_ARG, "%s: cannot import: %s", path, aiGetErrorString());
        if (as)
            aiReleaseImport(as);
        return st;
    }
    if (as->mNumMeshes == 0) {
        aiReleaseImport(as);
        return rs_error_set(RS_ERR_ARG, "%s: no triangles in the file", path);
    }
    *out = as;
    return RS_OK;
}

/* The extensions of `path` when it is a glTF file (none otherwise), with the one warning line
 * naming those the file uses that raystream does not read. */
static rs_status file_extensions(const char *path, rs_gltf_ext *e)
{
    rs_status st = RS_OK;
    memset(e, 0, sizeof *e);
    if (ext_is(path, "glb") || ext_is(path, "gltf"))
        st = rs_gltf_read_ext(path, ext_is(path, "glb"), e);
    if (st == RS_OK && e->unread[0])
        fprintf(stderr, "raystream: warning: %s uses %s, which raystream does not read: rendered "
                        "without %s\n",
                path, e->unread, strchr(e->unread, ',') ? "them" : "it");
    return st;
}

/* Material k's extensions (NULL: none, or not a glTF file). */
static const rs_gltf_mat_ext *material_extensions(const rs_gltf_ext *e, uint32_t k)
{
    return k < e->n_materials ? &e->materials[k] : NULL;
}

rs_status rs_scene_add_mesh(rs_scene *s, const char *path, const rs_mesh_opts *o,
                            rs_mesh_info *info)
{
    const struct aiScene *as;
    rs_xform xf;
    uint32_t *mat_of = NULL, mi, k;
    char dir[1024];
    const char *slash = strrchr(path, '/');
    rs_status st = RS_OK;
    rs_aabb raw;
    memset(info, 0, sizeof *info);
    if (o->scale.x == 0 || o->scale.y == 0 || o->scale.z == 0 || !rs_v3_is_finite(o->scale))
        return rs_error_set(RS_ERR_ARG, "%s: scale must be finite and non-zero", path);
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    st = import_file(path,
                     aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_SortByPType | aiProcess_PreTransformVertices |
                         aiProcess_GenSmoothNormals | aiProcess_ValidateDataStructure,
                     &as);
    if (st != RS_OK)
        return st;

    /* placement: the bounds of the scaled and rotated (unfitted) vertices decide a fit */
    xf = scale_rotate(o);
    raw.lo = rs_v3_splat(FLT_MAX);
    raw.hi = rs_v3_splat(-FLT_MAX);
    for (mi = 0; mi < as->mNumMeshes; ++mi) {
        const struct aiMesh *m = as->mMeshes[mi];
        if (!m->mVertices)
            continue;
        for (k = 0; k < m->mNumVertices; ++k) {
            rs_vec3 p = rs_xform_point(
                &xf, rs_v3(m->mVertices[k].x, m->mVertices[k].y, m->mVertices[k].z));
            if (!rs_v3_is_finite(p))
                continue;
            raw.lo = rs_v3_min(raw.lo, p);
            raw.hi = rs_v3_max(raw.hi, p);
        }
    }
    if (!(raw.lo.x <= raw.hi.x)) {
        release_scene(as);
        return rs_error_set(RS_ERR_ARG, "%s: no finite vertex in the file", path);
    }
    xf = fit_translate(o, &xf, raw);

    if (o->material == RS_MESH_FILE_MATERIALS) {
        rs_gltf_ext ext;
        mat_of = (uint32_t *)rs_alloc(as->mNumMaterials ? as->mNumMaterials : 1, sizeof *mat_of);
        if (!mat_of) {
            release_scene(as);
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
        }
        st = check_overrides(as, path, o);
        if (st == RS_OK)
            st = file_extensions(path, &ext);
        else
            memset(&ext, 0, sizeof ext);
        for (k = 0; k < as->mNumMaterials && st == RS_OK; ++k) {
            int ov = override_of(as->mMaterials[k], o), used = 0;
            for (mi = 0; mi < as->mNumMeshes && !used; ++mi)
                used = as->mMeshes[mi]->mMaterialIndex == k;
            mat_of[k] = 0;
            if (!used)
                continue; /* (Assimp's unused default material, say): not added */
            if (ov >= 0) {
                mat_of[k] = o->override_ids[ov];
                continue;
            }
            st = add_file_material(s, as, as->mMaterials[k], material_extensions(&ext, k), path,
                                   dir, o->strict_textures, &mat_of[k]);
            info->materials++;
        }
        rs_gltf_ext_free(&ext);
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
        st = add_faces(s, m, rs_xform_is_identity(&xf) ? NULL : &xf, mat, info);
    }
    rs_free(mat_of);
    if (as->mFlags & OWN_SCENE) {
        info->strips = ((const own_scene *)(const void *)as)->strips.strips;
        info->joins = ((const own_scene *)(const void *)as)->strips.joins;
    }
    release_scene(as);
    if (st == RS_OK && (info->triangles == 0 || info->dropped > info->triangles)) {
        char why[160];
        st = rs_error_set(RS_ERR_ARG, "%s: %s of %u, %u triangles left: the mesh is broken", path,
                          rs_mesh_dropped_text(info, why, sizeof why),
                          info->dropped + info->triangles, info->triangles);
    }
    return st;
}

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
        st = add_faces(g->s, m, NULL,
                       g->mat_of[m->mMaterialIndex < g->as->mNumMaterials ? m->mMaterialIndex : 0],
                       &g->info);
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
    rs_camera_desc *d = &g->s->camera;
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
            g->s->height = 512;
            g->s->width = (uint32_t)fminf(fmaxf(w, 1.0f), 32768.0f);
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
}

rs_status rs_scene_load_gltf(const char *path, const rs_gltf_opts *opts, rs_scene **out)
{
    gltf_ctx g;
    rs_xform id = rs_xform_identity();
    char dir[1024];
    const char *slash = strrchr(path, '/');
    rs_status st;
    uint32_t k, emissive = 0;
    *out = NULL;
    memset(&g, 0, sizeof g);
    g.path = path;
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    st = import_file(path,
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
        st = file_extensions(path, &g.ext);
    for (k = 0; k < g.as->mNumMaterials && st == RS_OK; ++k) {
        uint32_t mi;
        int used = 0;
        for (mi = 0; mi < g.as->mNumMeshes && !used; ++mi)
            used = g.as->mMeshes[mi]->mMaterialIndex == k;
        if (!used)
            continue;
        st = add_file_material(g.s, g.as, g.as->mMaterials[k], material_extensions(&g.ext, k),
                               path, dir, 1, &g.mat_of[k]);
        if (st == RS_OK) {
            g.info.materials++;
            emissive += !rs_v3_is_zero(g.s->materials[g.mat_of[k]].emission);
        }
    }
    if (st == RS_OK && g.as->mNumMaterials == 0) {
        rs_material def = rs_mat_pbr(rs_v3_splat(1.0f), 0.0f, 1.0f);
        st = rs_scene_add_material(g.s, &def, &g.mat_of[0]);
    }
    if (st == RS_OK)
        st = gltf_node(&g, g.as->mRootNode, &id, 0, opts ? opts->camera : NULL);
    if (st == RS_OK && opts && opts->camera && !g.camera) {
        for (k = 0; k < g.as->mNumCameras && st == RS_OK; ++k) {
            const struct aiCamera *c = g.as->mCameras[k];
            if (strcmp(c->mName.data, opts->camera) != 0)
                continue;
            /* there, but not a camera raystream can look through */
            if (c->mOrthographicWidth > 0)
                st = rs_error_set(RS_ERR_ARG,
                                  "%s: camera '%s' is orthographic; raystream's cameras are "
                                  "perspective (give the file a perspective camera)",
                                  path, opts->camera);
            else
                st = rs_error_set(RS_ERR_ARG,
                                  "%s: camera '%s' has a field of view of 0 (its yfov must be "
                                  "above 0)",
                                  path, opts->camera);
        }
    }
    if (st == RS_OK && opts && opts->camera && !g.camera) {
        char have[512] = "";
        for (k = 0; k < g.as->mNumCameras; ++k)
            if (strlen(have) + g.as->mCameras[k]->mName.length + 5 < sizeof have) {
                strcat(have, *have ? ", '" : "'");
                strcat(have, g.as->mCameras[k]->mName.data);
                strcat(have, "'");
            }
        st = rs_error_set(RS_ERR_ARG, "%s: no camera named '%s' (the file has: %s)", path,
                          opts->camera, *have ? have : "none");
    }
    if (st == RS_OK && (g.info.triangles == 0 || g.info.dropped > g.info.triangles)) {
        char why[160];
        st = rs_error_set(RS_ERR_ARG, "%s: %s of %u, %u triangles left: the mesh is broken", path,
                          rs_mesh_dropped_text(&g.info, why, sizeof why),
                          g.info.dropped + g.info.triangles, g.info.triangles);
    }
    if (st == RS_OK) {
        /* the placed bounds, for a framing camera */
        g.info.bounds.lo = rs_v3_splat(FLT_MAX);
        g.info.bounds.hi = rs_v3_splat(-FLT_MAX);
        for (k = 0; k < g.s->n_tris; ++k) {
            const rs_tri *t = &g.s->tris[k];
            g.info.bounds.lo = rs_v3_min(g.info.bounds.lo, rs_v3_min(t->v0, rs_v3_min(t->v1, t->v2)));
            g.info.bounds.hi = rs_v3_max(g.info.bounds.hi, rs_v3_max(t->v0, rs_v3_max(t->v1, t->v2)));
        }
        gltf_camera(&g);
        if (g.lights == 0 && emissive == 0)
            g.s->background = rs_v3_splat(1.0f); /* nothing lights it: a white sky does */
        st = rs_scene_finalize(g.s);
        if (st != RS_OK) {
            char msg[400];
            snprintf(msg, sizeof msg, "%s", rs_error_message());
            rs_error_clear();
            st = rs_error_set(st, "%s: %s", path, msg);
        }
    }
    if (st == RS_OK && opts && opts->log) {
        char why[160];
        fprintf(opts->log,
                "raystream: %s: %u triangles, %u materials, %u lights, camera %s%s%s%s%s%s%s\n",
                path, g.info.triangles, g.info.materials, g.lights,
                g.camera ? "'" : "(framing the model)", g.camera ? g.camera->mName.data : "",
                g.camera ? "'" : "", g.info.dropped ? "; " : "",
                rs_mesh_dropped_text(&g.info, why, sizeof why),
                g.ext.used[0] ? "; extensions: " : "", g.ext.used);
    }
    if (st == RS_OK && opts && opts->extensions && opts->extensions_n)
        snprintf(opts->extensions, opts->extensions_n, "%s", g.ext.used);
    rs_gltf_ext_free(&g.ext);
    rs_free(g.mat_of);
    release_scene(g.as);
    if (st != RS_OK) {
        rs_scene_destroy(g.s);
        return st;
    }
    *out = g.s;
    return RS_OK;
}
