/* scenes/mesh_import.c — reading a mesh file into an Assimp scene (scenes/mesh_assimp.h): every
 * file Assimp opens goes through core/file.h, PLY headers and glTF starts checked before Assimp
 * sees them, triangle-strip PLYs decoded here, and the import with our own checks. */
#define _DEFAULT_SOURCE /* close, fileno */
#include "scenes/mesh_assimp.h"

#include <assimp/cfileio.h>
#include <assimp/cimport.h>
#include <assimp/postprocess.h>
#include <ctype.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/file.h"
#include "scenes/gltf_check.h"
#include "scenes/ply_header.h"
#include "scenes/ply_strips.h"

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

int rs_mesh_ext_is(const char *path, const char *ext)
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

/* The walk over the ascii data's lists, started with the elements and properties a strict
 * parse of the header keeps (a header only the loose parse takes is left to Assimp as before:
 * no elements to walk).  Returns the elements, for the caller to free. */
static rs_ply_elem *walk_start(ply_walk *w, const char *path, const char *buf, size_t n,
                               uint64_t size, size_t data_at)
{
    rs_ply_header strict;
    rs_ply_elem *elems = (rs_ply_elem *)rs_alloc(RS_PLY_WALK_ELEMS, sizeof *elems);
    memset(w, 0, sizeof *w);
    memset(&strict, 0, sizeof strict);
    strict.elems = elems;
    strict.max_elems = elems ? RS_PLY_WALK_ELEMS : 0;
    if (elems && rs_ply_parse_header(path, buf, n, size, 1, &strict) == RS_OK) {
        w->elems = elems;
        w->n_elems = strict.n_elems;
        w->list_left = -1;
        w->line = 1;
        w->max_items = (size - data_at) / 2u + 1u;
        ply_walk_settle(w);
    }
    rs_error_clear();
    return elems;
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
    rs_ply_header h;
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
        if (rs_mesh_ext_is(path, "ply"))
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
    elems = walk_start(&w, path, buf, n, size, h.data_at);
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

/* A file named .gltf must hold JSON (its first non-blank byte '{') and one named .glb the binary
 * container (magic "glTF"): when the glTF reader turns a file down, Assimp offers it to every
 * other reader, and its PLY reader spun for ever on junk that began with "ply" (found by
 * tests/fuzz/fuzz_mesh). */
static rs_status check_gltf_start(const char *path)
{
    unsigned char b[64];
    size_t n, i = 0;
    FILE *f;
    int glb = rs_mesh_ext_is(path, "glb");
    if (!glb && !rs_mesh_ext_is(path, "gltf"))
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

void rs_mesh_release(const struct aiScene *as)
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

void rs_mesh_strips_of(const struct aiScene *as, uint32_t *strips, uint32_t *joins)
{
    if (as->mFlags & OWN_SCENE) {
        *strips = ((const own_scene *)(const void *)as)->strips.strips;
        *joins = ((const own_scene *)(const void *)as)->strips.joins;
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
        rs_mesh_release(&o->scene);
        return rs_error_set(RS_ERR_ARG, "%s: its triangle strips hold no triangle", path);
    }
    o->vertices = (struct aiVector3D *)rs_alloc(o->strips.n_vertices + 1, sizeof *o->vertices);
    o->faces = (struct aiFace *)rs_alloc(o->strips.n_triangles, sizeof *o->faces);
    o->indices = (unsigned int *)rs_alloc(3 * (size_t)o->strips.n_triangles, sizeof *o->indices);
    if (!o->vertices || !o->faces || !o->indices) {
        rs_mesh_release(&o->scene);
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
rs_status rs_mesh_import(const char *path, unsigned int flags, const struct aiScene **out)
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
