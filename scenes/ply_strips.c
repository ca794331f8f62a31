/* scenes/ply_strips.c — PLY files whose faces are triangle strips (see ply_strips.h). */
#include "scenes/ply_strips.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"

#define MAX_PROPS 64

typedef enum { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 } ply_type;

typedef struct ply_prop {
    char name[64];
    ply_type type;     /* the value's type (a list's items) */
    ply_type len_type; /* a list's length type, T_NONE for a scalar */
} ply_prop;

typedef struct ply_elem {
    char name[64];
    uint64_t count;
    ply_prop props[MAX_PROPS];
    int n_props;
} ply_elem;

typedef struct reader {
    const char *path;
    const unsigned char *p, *end; /* the data after end_header */
    int ascii, big;
    unsigned line; /* ascii: the current line, for messages */
} reader;

static ply_type type_of(const char *w)
{
    static const struct {
        const char *name;
        ply_type t;
    } k[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},  {"uint8", T_U8},
             {"short", T_I16},  {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
             {"int", T_I32},    {"int32", T_I32},   {"uint", T_U32},  {"uint32", T_U32},
             {"float", T_F32},  {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
    size_t i;
    for (i = 0; i < sizeof k / sizeof k[0]; ++i)
        if (strcmp(w, k[i].name) == 0)
            return k[i].t;
    return T_NONE;
}

static size_t type_size(ply_type t)
{
    static const size_t sz[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return sz[t];
}

/* The next value of type t as a double; 0 at the end of the data or on a bad number. */
static int read_value(reader *r, ply_type t, double *out)
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
        size_t n = type_size(t), i;
        unsigned char b[8];
        if ((size_t)(r->end - r->p) < n)
            return 0;
        for (i = 0; i < n; ++i)
            b[i] = r->p[r->big ? n - 1 - i : i];
        r->p += n;
        switch (t) {
        case T_I8: *out = (int8_t)b[0]; break;
        case T_U8: *out = b[0]; break;
        case T_I16: {
            int16_t v;
            memcpy(&v, b, 2);
            *out = v;
            break;
        }
        case T_U16: {
            uint16_t v;
            memcpy(&v, b, 2);
            *out = v;
            break;
        }
        case T_I32: {
            int32_t v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case T_U32: {
            uint32_t v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case T_F32: {
            float v;
            memcpy(&v, b, 4);
            *out = v;
            break;
        }
        case T_F64: {
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

/* Parses the header in text[0, n): elements, format; *data_at = the offset after end_header. */
static rs_status parse_header(const char *path, const char *text, size_t n, ply_elem *elems,
                              int *n_elems, int max_elems, int *ascii, int *big, size_t *data_at)
{
    const char *p = text, *end = text + n;
    unsigned line = 0;
    *n_elems = 0;
    *ascii = 1;
    *big = 0;
    while (p < end) {
        const char *eol = (const char *)memchr(p, '\n', (size_t)(end - p));
        char ln[256], a[64], b[64], c[64], d[64];
        int k;
        size_t len;
        if (!eol)
            break;
        ++line;
        len = (size_t)(eol - p) < sizeof ln - 1 ? (size_t)(eol - p) : sizeof ln - 1;
        memcpy(ln, p, len);
        ln[len] = '\0';
        if (len && ln[len - 1] == '\r')
            ln[len - 1] = '\0';
        k = sscanf(ln, "%63s %63s %63s %63s", a, b, c, d);
        p = eol + 1;
        if (k <= 0 || strcmp(a, "ply") == 0 || strcmp(a, "comment") == 0 ||
            strcmp(a, "obj_info") == 0)
            continue;
        if (strcmp(a, "format") == 0 && k >= 2) {
            *ascii = strcmp(b, "ascii") == 0;
            *big = strcmp(b, "binary_big_endian") == 0;
            if (!*ascii && !*big && strcmp(b, "binary_little_endian") != 0)
                return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unknown format '%s'",
                                    path, line, b);
        } else if (strcmp(a, "element") == 0 && k == 3) {
            ply_elem *e;
            char *ce;
            if (*n_elems >= max_elems)
                return rs_error_set(RS_ERR_ARG, "%s: PLY header: more than %d elements", path,
                                    max_elems);
            e = &elems[(*n_elems)++];
            memset(e, 0, sizeof *e);
            snprintf(e->name, sizeof e->name, "%s", b);
            e->count = strtoull(c, &ce, 10);
            if (*ce || !isdigit((unsigned char)c[0]) || e->count > UINT32_MAX)
                return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u is not 'element NAME "
                                                "COUNT'", path, line);
        } else if (strcmp(a, "property") == 0 && *n_elems > 0) {
            ply_elem *e = &elems[*n_elems - 1];
            ply_prop *pr;
            if (e->n_props >= MAX_PROPS)
                return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: too many properties",
                                    path, line);
            pr = &e->props[e->n_props++];
            memset(pr, 0, sizeof *pr);
            if (strcmp(b, "list") == 0 && k == 4) {
                /* "property list LEN_TYPE TYPE NAME": the name is the fifth word */
                char name[64] = "";
                sscanf(ln, "%*s %*s %*s %*s %63s", name);
                pr->len_type = type_of(c);
                pr->type = type_of(d);
                snprintf(pr->name, sizeof pr->name, "%s", name);
                if (pr->len_type == T_NONE || pr->type == T_NONE || pr->len_type >= T_F32)
                    return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: bad list property",
                                        path, line);
            } else if (k == 3) {
                pr->type = type_of(b);
                snprintf(pr->name, sizeof pr->name, "%s", c);
                if (pr->type == T_NONE)
                    return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unknown type '%s'",
                                        path, line, b);
            } else {
                return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: bad property", path,
                                    line);
            }
        } else if (strcmp(a, "end_header") == 0) {
            *data_at = (size_t)(p - text);
            return RS_OK;
        } else {
            return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unexpected '%s'", path, line,
                                a);
        }
    }
    return rs_error_set(RS_ERR_ARG, "%s: PLY header has no end_header", path);
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

rs_status rs_ply_read_strips(const char *path, rs_ply_strips *out)
{
    enum { MAX_ELEMS = 16 };
    ply_elem elems[MAX_ELEMS];
    int n_elems, ascii, big, e, have_xyz = 0;
    size_t len, data_at = 0, cap = 0;
    char *text;
    reader r;
    uint32_t *strip = NULL;
    size_t strip_cap = 0;
    rs_status st;
    memset(out, 0, sizeof *out);
    st = rs_file_read(path, RS_FILE_MAX_MESH_BYTES, &text, &len);
    if (st != RS_OK)
        return st;
    st = parse_header(path, text, len, elems, &n_elems, MAX_ELEMS, &ascii, &big, &data_at);
    if (st != RS_OK) {
        rs_free(text);
        return st;
    }
    r.path = path;
    r.p = (const unsigned char *)text + data_at;
    r.end = (const unsigned char *)text + len;
    r.ascii = ascii;
    r.big = big;
    r.line = 1;
    for (e = 0; e < n_elems && st == RS_OK; ++e) {
        ply_elem *el = &elems[e];
        int is_vertex = strcmp(el->name, "vertex") == 0;
        int is_strips = strcmp(el->name, "tristrips") == 0;
        int px = -1, py = -1, pz = -1, pl = -1, k;
        uint64_t i;
        for (k = 0; k < el->n_props; ++k) {
            const ply_prop *pr = &el->props[k];
            if (is_vertex && pr->len_type == T_NONE) {
                if (strcmp(pr->name, "x") == 0)
                    px = k;
                else if (strcmp(pr->name, "y") == 0)
                    py = k;
                else if (strcmp(pr->name, "z") == 0)
                    pz = k;
            }
            if (is_strips && pr->len_type != T_NONE && pl < 0)
                pl = k;
        }
        if (is_vertex) {
            if (px < 0 || py < 0 || pz < 0) {
                st = rs_error_set(RS_ERR_ARG, "%s: PLY vertices have no x, y and z", path);
                break;
            }
            /* the header's count is bounded by check_ply_header against the file's size */
            out->vertices = (float *)rs_alloc(3 * (size_t)el->count + 3, sizeof *out->vertices);
            if (!out->vertices) {
                st = rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
                break;
            }
            out->n_vertices = (uint32_t)el->count;
            have_xyz = 1;
        }
        if (is_strips && pl < 0) {
            st = rs_error_set(RS_ERR_ARG, "%s: PLY tristrips have no list of vertex indices",
                              path);
            break;
        }
        for (i = 0; i < el->count && st == RS_OK; ++i) {
            for (k = 0; k < el->n_props; ++k) {
                const ply_prop *pr = &el->props[k];
                double v;
                if (pr->len_type != T_NONE) {
                    double cnt;
                    uint64_t j, n;
                    if (!read_value(&r, pr->len_type, &cnt) || !(cnt >= 0) || cnt > 1e9) {
                        st = cut(&r, "a list's length is missing or absurd (a cut file?)");
                        break;
                    }
                    n = (uint64_t)cnt;
                    if (is_strips && k == pl && n > strip_cap) {
                        uint32_t *g = (uint32_t *)rs_alloc((size_t)n, sizeof *g);
                        if (!g) {
                            st = rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
                            break;
                        }
                        rs_free(strip);
                        strip = g;
                        strip_cap = (size_t)n;
                    }
                    {
                        size_t run = 0;
                        for (j = 0; j < n; ++j) {
                            if (!read_value(&r, pr->type, &v)) {
                                st = cut(&r, "a list ends early (a cut file?)");
                                break;
                            }
                            if (!(is_strips && k == pl))
                                continue;
                            if (v == -1.0) {
                                /* a restart: the strip so far is done */
                                st = strip_triangles(out, strip, run, &cap);
                                out->strips++;
                                run = 0;
                                if (st != RS_OK)
                                    break;
                                continue;
                            }
                            strip[run++] = v >= 0 && v < 4294967295.0 ? (uint32_t)v : UINT32_MAX;
                        }
                        if (st == RS_OK && is_strips && k == pl && run > 0) {
                            st = strip_triangles(out, strip, run, &cap);
                            out->strips++;
                        }
                    }
                    if (st != RS_OK)
                        break;
                    continue;
                }
                if (!read_value(&r, pr->type, &v)) {
                    st = cut(&r, "the data ends before the elements the header declares");
                    break;
                }
                if (is_vertex && (k == px || k == py || k == pz))
                    out->vertices[3 * i + (k == px ? 0 : k == py ? 1 : 2)] = (float)v;
            }
        }
    }
    rs_free(strip);
    rs_free(text);
    if (st == RS_OK && !have_xyz)
        st = rs_error_set(RS_ERR_ARG, "%s: PLY file has no vertex element", path);
    if (st != RS_OK)
        rs_ply_strips_free(out);
    return st;
}
