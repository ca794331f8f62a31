/* scenes/ply_strips.c — PLY files whose faces are triangle strips (see ply_strips.h). */
#include "scenes/ply_strips.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/try.h"
#include "core/file.h"
#include "scenes/ply_header.h"

typedef struct reader {
    const char *path;
    const unsigned char *p, *end; /* the data after end_header */
    int ascii, big;
    unsigned line; /* ascii: the current line, for messages */
} reader;

/* The next value of type t as a double; 0 at the end of the data or on a bad number. */
static int read_value(reader *r, rs_ply_type t, double *out)
{
    if (r->ascii) {
        char *e;
        while (r->p < r->end && isspace(*r->p)) {
            r->line += *r->p == '\n';
            ++r->p;
        }
        if (r->p >= r->end)
            return 0;
        {
            /* strtod on a bounded copy: the data is not NUL-terminated */
            char tmp[64];
            size_t n = 0;
            while (r->p + n < r->end && !isspace(r->p[n]) && n < sizeof tmp - 1)
                ++n;
            memcpy(tmp, r->p, n);
            tmp[n] = '\0';
            *out = strtod(tmp, &e);
            if (e != tmp + n)
                return 0;
            r->p += n;
        }
        return 1;
    }
    {
        size_t n = rs_ply_type_size(t), i;
        unsigned char b[8];
        if ((size_t)(r->end - r->p) < n)
            return 0;
        for (i = 0; i < n; ++i)
            b[i] = r->p[r->big ? n - 1 - i : i];
        r->p += n;
        switch (t) {
        case RS_PLY_I8: *out = (int8_t)b[0]; break;
        case RS_PLY_U8: *out = b[0]; break;
        case RS_PLY_I16: {
            int16_t v;
            memcpy(&v, b, 2);
            *out = v;
            break;
        }
        case RS_PLY_U16: {
            uint16_t v;
            memcpy(&v, b, 2);
            *out = v;
            break;
        }
        case RS_PLY_I32: {
            int32_t v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case RS_PLY_U32: {
            uint32_t v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case RS_PLY_F32: {
            float v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case RS_PLY_F64: {
            double v;
            memcpy(&v, b, 8);
            *out = v;
            break;
        }
        default: return 0;
        }
        return 1;
    }
}

static rs_status cut(const reader *r, const char *what)
{
    if (r->ascii)
        return rs_error_set(RS_ERR_ARG, "%s: PLY data line %u: %s", r->path, r->line, what);
    return rs_error_set(RS_ERR_ARG, "%s: PLY data: %s", r->path, what);
}

void rs_ply_strips_free(rs_ply_strips *s)
{
    rs_free(s->vertices);
    rs_free(s->triangles);
    memset(s, 0, sizeof *s);
}

/* Appends the triangles of one strip: alternate ones reversed, so that every triangle keeps the
 * first one's orientation; those with a repeated vertex (the joins of stitched strips) are
 * skipped as the format means them. */
static rs_status strip_triangles(rs_ply_strips *out, const uint32_t *idx, size_t n, size_t *cap)
{
    size_t i;
    for (i = 2; i < n; ++i) {
        uint32_t a = idx[i - 2], b = idx[i - 1], c = idx[i], t;
        if (a == b || b == c || a == c) {
            out->joins++;
            continue;
        }
        if ((i - 2) & 1)
            t = a, a = b, b = t;
        if (out->n_triangles == *cap) {
            size_t nc = *cap ? 2 * *cap : 1024;
            uint32_t *g = (uint32_t *)rs_alloc(3 * nc, sizeof *g);
            if (!g)
                return rs_error_set(RS_ERR_NOMEM, "out of memory decoding strips");
            if (out->triangles)
                memcpy(g, out->triangles, 3 * out->n_triangles * sizeof *g);
            rs_free(out->triangles);
            out->triangles = g;
            *cap = nc;
        }
        out->triangles[3 * out->n_triangles] = a;
        out->triangles[3 * out->n_triangles + 1] = b;
        out->triangles[3 * out->n_triangles + 2] = c;
        out->n_triangles++;
    }
    return RS_OK;
}

/* The decoding's buffers: the strip being read and the triangles' capacity. */
typedef struct strip_buf {
    uint32_t *idx;
    size_t cap;     /* of idx */
    size_t tri_cap; /* of out->triangles, in triangles */
} strip_buf;

/* One list property's values; where it is the strips' list (`strips`), decoded into out's
 * triangles, a value of -1 restarting the strip. */
static rs_status read_list(reader *r, const rs_ply_prop *pr, int strips, rs_ply_strips *out,
                           strip_buf *sb)
{
    double cnt, v;
    uint64_t j, n;
    size_t run = 0;
    rs_status st = RS_OK;
    if (!read_value(r, pr->len_type, &cnt) || !(cnt >= 0) || cnt > 1e9)
        return cut(r, "a list's length is missing or absurd (a cut file?)");
    n = (uint64_t)cnt;
    if (strips && n > sb->cap) {
        uint32_t *g = (uint32_t *)rs_alloc((size_t)n, sizeof *g);
        if (!g)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", r->path);
        rs_free(sb->idx);
        sb->idx = g;
        sb->cap = (size_t)n;
    }
    for (j = 0; j < n; ++j) {
        if (!read_value(r, pr->type, &v))
            return cut(r, "a list ends early (a cut file?)");
        if (!strips)
            continue;
        if (v == -1.0) {
            /* a restart: the strip so far is done */
            st = strip_triangles(out, sb->idx, run, &sb->tri_cap);
            out->strips++;
            run = 0;
            if (st != RS_OK)
                return st;
            continue;
        }
        sb->idx[run++] = v >= 0 && v < 4294967295.0 ? (uint32_t)v : UINT32_MAX;
    }
    if (strips && run > 0) {
        st = strip_triangles(out, sb->idx, run, &sb->tri_cap);
        out->strips++;
    }
    return st;
}

/* Every instance of element el: a vertex element's x, y and z into out->vertices (allocated
 * here), a tristrips element's first list decoded, every other value read past. */
static rs_status read_element(reader *r, const rs_ply_elem *el, rs_ply_strips *out,
                              strip_buf *sb, int *have_xyz)
{
    int is_vertex = strcmp(el->name, "vertex") == 0;
    int is_strips = strcmp(el->name, "tristrips") == 0;
    int px = -1, py = -1, pz = -1, pl = -1, k;
    uint64_t i;
    for (k = 0; k < el->n_props; ++k) {
        const rs_ply_prop *pr = &el->props[k];
        if (is_vertex && pr->len_type == RS_PLY_NONE) {
            if (strcmp(pr->name, "x") == 0)
                px = k;
            else if (strcmp(pr->name, "y") == 0)
                py = k;
            else if (strcmp(pr->name, "z") == 0)
                pz = k;
        }
        if (is_strips && pr->len_type != RS_PLY_NONE && pl < 0)
            pl = k;
    }
    if (is_vertex) {
        if (px < 0 || py < 0 || pz < 0)
            return rs_error_set(RS_ERR_ARG, "%s: PLY vertices have no x, y and z", r->path);
        /* the header's count is bounded by the file's size (rs_ply_parse_header) */
        out->vertices = (float *)rs_alloc(3 * (size_t)el->count + 3, sizeof *out->vertices);
        if (!out->vertices)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", r->path);
        out->n_vertices = (uint32_t)el->count;
        *have_xyz = 1;
    }
    if (is_strips && pl < 0)
        return rs_error_set(RS_ERR_ARG, "%s: PLY tristrips have no list of vertex indices",
                            r->path);
    for (i = 0; i < el->count; ++i)
        for (k = 0; k < el->n_props; ++k) {
            const rs_ply_prop *pr = &el->props[k];
            double v;
            if (pr->len_type != RS_PLY_NONE) {
                RS_TRY(read_list(r, pr, is_strips && k == pl, out, sb));
                continue;
            }
            if (!read_value(r, pr->type, &v))
                return cut(r, "the data ends before the elements the header declares");
            if (is_vertex && (k == px || k == py || k == pz))
                out->vertices[3 * i + (k == px ? 0 : k == py ? 1 : 2)] = (float)v;
        }
    return RS_OK;
}

rs_status rs_ply_read_strips(const char *path, rs_ply_strips *out)
{
    enum { MAX_ELEMS = 16 };
    rs_ply_elem elems[MAX_ELEMS];
    rs_ply_header h;
    int e, have_xyz = 0;
    size_t len;
    char *text;
    reader r;
    strip_buf sb;
    rs_status st;
    memset(out, 0, sizeof *out);
    memset(&sb, 0, sizeof sb);
    st = rs_file_read(path, RS_FILE_MAX_MESH_BYTES, &text, &len);
    if (st != RS_OK)
        return st;
    memset(&h, 0, sizeof h);
    h.elems = elems;
    h.max_elems = MAX_ELEMS;
    st = rs_ply_parse_header(path, text, len, len, 1, &h);
    if (st != RS_OK) {
        rs_free(text);
        return st;
    }
    r.path = path;
    r.p = (const unsigned char *)text + h.data_at;
    r.end = (const unsigned char *)text + len;
    r.ascii = h.ascii;
    r.big = h.big;
    r.line = 1;
    for (e = 0; e < h.n_elems && st == RS_OK; ++e)
        st = read_element(&r, &elems[e], out, &sb, &have_xyz);
    rs_free(sb.idx);
    rs_free(text);
    if (st == RS_OK && !have_xyz)
        st = rs_error_set(RS_ERR_ARG, "%s: PLY file has no vertex element", path);
    if (st != RS_OK)
        rs_ply_strips_free(out);
    return st;
}
