/* scenes/ply_header.c — the one PLY header parser (see ply_header.h). */
#include "scenes/ply_header.h"

#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "core/try.h"

/* A header line's first blank-separated words (a line has at most MAX_WORDS that matter: "count"
 * stops there). */
#define MAX_WORDS 6

typedef struct words {
    const char *w[MAX_WORDS];
    size_t n[MAX_WORDS];
    int count;
} words;

static int blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

static void split(const char *p, const char *eol, words *ws)
{
    ws->count = 0;
    while (ws->count < MAX_WORDS) {
        while (p < eol && blank(*p))
            ++p;
        if (p >= eol)
            break;
        ws->w[ws->count] = p;
        while (p < eol && !blank(*p))
            ++p;
        ws->n[ws->count] = (size_t)(p - ws->w[ws->count]);
        ws->count++;
    }
}

static int word_is(const words *ws, int i, const char *s)
{
    return i < ws->count && ws->n[i] == strlen(s) && memcmp(ws->w[i], s, ws->n[i]) == 0;
}

/* Word i, at most 63 characters of it, NUL-terminated in buf[64] (empty if there is none). */
static const char *word(const words *ws, int i, char buf[64])
{
    size_t n = i < ws->count ? ws->n[i] : 0;
    if (n > 63)
        n = 63;
    if (n)
        memcpy(buf, ws->w[i], n);
    buf[n] = '\0';
    return buf;
}

static rs_ply_type type_of(const words *ws, int i)
{
    static const struct {
        const char *name;
        rs_ply_type t;
    } k[] = {{"char", RS_PLY_I8},    {"int8", RS_PLY_I8},     {"uchar", RS_PLY_U8},
             {"uint8", RS_PLY_U8},   {"short", RS_PLY_I16},   {"int16", RS_PLY_I16},
             {"ushort", RS_PLY_U16}, {"uint16", RS_PLY_U16},  {"int", RS_PLY_I32},
             {"int32", RS_PLY_I32},  {"uint", RS_PLY_U32},    {"uint32", RS_PLY_U32},
             {"float", RS_PLY_F32},  {"float32", RS_PLY_F32}, {"double", RS_PLY_F64},
             {"float64", RS_PLY_F64}};
    size_t j;
    for (j = 0; j < sizeof k / sizeof k[0]; ++j)
        if (word_is(ws, i, k[j].name))
            return k[j].t;
    return RS_PLY_NONE;
}

size_t rs_ply_type_size(rs_ply_type t)
{
    static const size_t sz[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return (unsigned)t < sizeof sz / sizeof sz[0] ? sz[t] : 0;
}

int rs_ply_is_ply(const char *text, size_t n)
{
    return n >= 4 && memcmp(text, "ply", 3) == 0 && (text[3] == '\n' || text[3] == '\r');
}

static uint64_t add_sat(uint64_t a, uint64_t b) { return a + b < a ? UINT64_MAX : a + b; }

static uint64_t mul_sat(uint64_t a, uint64_t b)
{
    return a && b > UINT64_MAX / a ? UINT64_MAX : a * b;
}

/* An "element NAME COUNT" line: its count in *count; kept in h->elems when `strict`. */
static rs_status element_line(const char *path, unsigned line, const words *ws, int strict,
                              rs_ply_header *h, uint64_t *count)
{
    size_t i;
    int ok = ws->count == 3;
    if (word_is(ws, 1, "tristrips"))
        h->tristrips = 1;
    for (i = 0; ok && i < ws->n[2]; ++i) {
        ok = isdigit((unsigned char)ws->w[2][i]);
        *count = *count > UINT32_MAX ? *count : 10 * *count + (uint64_t)(ws->w[2][i] - '0');
    }
    if (!ok || *count > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u is not 'element NAME COUNT'",
                            path, line);
    if (strict) {
        rs_ply_elem *e;
        if (h->n_elems >= h->max_elems)
            return rs_error_set(RS_ERR_ARG, "%s: PLY header: more than %d elements", path,
                                h->max_elems);
        e = &h->elems[h->n_elems++];
        memset(e, 0, sizeof *e);
        word(ws, 1, e->name);
        e->count = *count;
    }
    return RS_OK;
}

/* A "property TYPE NAME" or "property list LEN_TYPE TYPE NAME" line: its fixed bytes added to
 * *inst_bytes (a list's length; an unknown type 1 byte, which Assimp refuses itself); kept in the
 * last element when `strict`. */
static rs_status property_line(const char *path, unsigned line, const words *ws, int strict,
                               rs_ply_header *h, uint64_t *inst_bytes)
{
    char b[64];
    int list = word_is(ws, 1, "list");
    rs_ply_type t = type_of(ws, list ? 2 : 1);
    rs_ply_elem *e;
    rs_ply_prop *pr;
    *inst_bytes = add_sat(*inst_bytes, t == RS_PLY_NONE ? 1 : rs_ply_type_size(t));
    list = list && ws->count >= 4; /* else a scalar, of the unknown type "list" */
    if (!strict)
        return RS_OK;
    e = &h->elems[h->n_elems - 1];
    if (e->n_props >= RS_PLY_MAX_PROPS)
        return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: too many properties", path,
                            line);
    pr = &e->props[e->n_props++];
    memset(pr, 0, sizeof *pr);
    if (list) {
        /* "property list LEN_TYPE TYPE NAME" */
        pr->len_type = t;
        pr->type = type_of(ws, 3);
        word(ws, 4, pr->name);
        if (pr->len_type == RS_PLY_NONE || pr->type == RS_PLY_NONE || pr->len_type >= RS_PLY_F32)
            return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: bad list property", path,
                                line);
    } else if (ws->count == 3) {
        pr->type = type_of(ws, 1);
        word(ws, 2, pr->name);
        if (pr->type == RS_PLY_NONE)
            return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unknown type '%s'", path,
                                line, word(ws, 1, b));
    } else {
        return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: bad property", path, line);
    }
    return RS_OK;
}

/* The header read to its end: what it declares must fit in the file's data. */
static rs_status check_sizes(const char *path, uint64_t file_size, const rs_ply_header *h)
{
    uint64_t data = file_size > h->data_at ? file_size - h->data_at : 0;
    if (h->total > data)
        return rs_error_set(RS_ERR_ARG,
                            "%s: PLY header declares %llu elements, more than its %llu bytes of "
                            "data could hold",
                            path, (unsigned long long)h->total, (unsigned long long)data);
    if (!h->ascii && h->need_bytes > data)
        return rs_error_set(RS_ERR_ARG,
                            "%s: PLY header declares elements of at least %llu bytes, but its "
                            "binary data has only %llu (a cut file?)",
                            path, (unsigned long long)h->need_bytes, (unsigned long long)data);
    return RS_OK;
}

rs_status rs_ply_parse_header(const char *path, const char *text, size_t n, uint64_t file_size,
                              int strict, rs_ply_header *h)
{
    const char *p = text, *end = text + (n < RS_PLY_MAX_HEADER ? n : RS_PLY_MAX_HEADER);
    unsigned line = 0;
    /* the element being read: its count, whether it has a property, an instance's fixed bytes */
    uint64_t count = 0, inst_bytes = 0;
    int has_prop = 0;
    char a[64], b[64];
    h->n_elems = 0;
    h->ascii = 1;
    h->big = 0;
    h->tristrips = 0;
    h->data_at = 0;
    h->total = h->need_lines = h->need_bytes = 0;
    while (p < end) {
        const char *eol = (const char *)memchr(p, '\n', (size_t)(end - p));
        words ws;
        int is_elem, is_end;
        if (!eol)
            break; /* the header's last line is cut */
        ++line;
        if (!strict && blank(*p)) {
            /* loose: a keyword starts its line (as Assimp reads them); this one is left to it */
            p = eol + 1;
            continue;
        }
        split(p, eol, &ws);
        p = eol + 1;
        /* "element" and a blank: a bare "element" is no element line (loose: left to Assimp) */
        is_elem = word_is(&ws, 0, "element") && (ws.w[0][7] == ' ' || ws.w[0][7] == '\t');
        is_end = word_is(&ws, 0, "end_header");
        if (is_elem || is_end) {
            /* the element before is complete: every instance counts against the data's size
             * (Assimp allocates each one, with or without properties); only those with
             * properties take a line or bytes */
            h->total = add_sat(h->total, count);
            if (has_prop) {
                h->need_lines = add_sat(h->need_lines, count);
                h->need_bytes = add_sat(h->need_bytes, mul_sat(count, inst_bytes));
            }
            has_prop = 0;
            count = inst_bytes = 0;
        }
        if (ws.count == 0 || word_is(&ws, 0, "ply") || word_is(&ws, 0, "comment") ||
            word_is(&ws, 0, "obj_info")) {
            continue;
        } else if (is_elem) {
            RS_TRY(element_line(path, line, &ws, strict, h, &count));
        } else if (word_is(&ws, 0, "property") && (!strict || h->n_elems > 0)) {
            has_prop = 1;
            RS_TRY(property_line(path, line, &ws, strict, h, &inst_bytes));
        } else if (word_is(&ws, 0, "format") && (!strict || ws.count >= 2)) {
            h->ascii = word_is(&ws, 1, "ascii");
            h->big = word_is(&ws, 1, "binary_big_endian");
            if (strict && !h->ascii && !h->big && !word_is(&ws, 1, "binary_little_endian"))
                return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unknown format '%s'", path,
                                    line, word(&ws, 1, b));
        } else if (is_end) {
            h->data_at = (size_t)(p - text);
            return check_sizes(path, file_size, h);
        } else if (strict) {
            return rs_error_set(RS_ERR_ARG, "%s: PLY header line %u: unexpected '%s'", path, line,
                                word(&ws, 0, a));
        }
    }
    return rs_error_set(RS_ERR_ARG, "%s: PLY header has no end_header (within its first %u KiB)",
                        path, RS_PLY_MAX_HEADER >> 10);
}
