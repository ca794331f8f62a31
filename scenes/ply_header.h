/* scenes/ply_header.h — the one PLY header parser, for the mesh import's check before Assimp
 * (scenes/mesh_import.c) and for the triangle-strip reader (scenes/ply_strips.h).
 *
 * A header must reach end_header within its first RS_PLY_MAX_HEADER bytes (Assimp's PLY reader
 * spins for ever on a header cut before it), and every "element NAME COUNT" line must be exactly
 * that, COUNT a whole number below 2^32 (Assimp read a mangled count as 2^32 - 1 and asked for
 * 64 GiB).  What the header declares is checked against the bytes after end_header: every
 * element instance counts against them (Assimp allocates each one), and in binary the instances'
 * fixed-size properties (a list counts its length field only) must fit.  An ascii body's lines
 * are counted by the caller against `need_lines` (scenes/mesh_import.c reads the file in pieces).
 *
 * Two modes: a loose one that leaves what it does not know to Assimp (unknown keywords, types and
 * formats), and a strict one for our own reader, which also keeps every element and property
 * and refuses any line it would not understand. */
#ifndef RS_SCENES_PLY_HEADER_H
#define RS_SCENES_PLY_HEADER_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

#define RS_PLY_MAX_HEADER (64u << 10)
#define RS_PLY_MAX_PROPS  64

typedef enum rs_ply_type {
    RS_PLY_NONE, /* unknown (loose mode: 1 byte), or a scalar's list length type */
    RS_PLY_I8,
    RS_PLY_U8,
    RS_PLY_I16,
    RS_PLY_U16,
    RS_PLY_I32,
    RS_PLY_U32,
    RS_PLY_F32,
    RS_PLY_F64
} rs_ply_type;

typedef struct rs_ply_prop {
    char name[64];
    rs_ply_type type;     /* the value's type (a list's items) */
    rs_ply_type len_type; /* a list's length type, RS_PLY_NONE for a scalar */
} rs_ply_prop;

typedef struct rs_ply_elem {
    char name[64];
    uint64_t count;
    rs_ply_prop props[RS_PLY_MAX_PROPS];
    int n_props;
} rs_ply_elem;

typedef struct rs_ply_header {
    /* in: where a strict parse keeps the elements (NULL and 0 in loose mode) */
    rs_ply_elem *elems;
    int max_elems;
    /* out */
    int n_elems;         /* strict: elements kept */
    int ascii, big;      /* the format: ascii, else binary, big-endian when `big` */
    int tristrips;       /* an element named "tristrips" (which Assimp does not read) */
    size_t data_at;      /* the data's offset: the byte after end_header's line */
    uint64_t total;      /* element instances declared, over all elements */
    uint64_t need_lines; /* ascii: instances of elements with a property (one line each) */
    uint64_t need_bytes; /* binary: the least bytes those instances take */
} rs_ply_header;

#ifdef __cplusplus
extern "C" {
#endif
/* Whether text[0, n) begins with the line "ply". */
int rs_ply_is_ply(const char *text, size_t n);
/* Bytes of a PLY scalar type in binary; 0 for RS_PLY_NONE. */
size_t rs_ply_type_size(rs_ply_type t);
/* Parses the header at the start of text[0, n) (n <= the file's `file_size` bytes; only the
 * first RS_PLY_MAX_HEADER are looked at), with `strict` as above, into *h (its elems and
 * max_elems set by the caller).  RS_ERR_ARG naming `path` (and the header line) for a bad
 * header, or one that declares more data than the file's bytes after it could hold. */
rs_status rs_ply_parse_header(const char *path, const char *text, size_t n, uint64_t file_size,
                              int strict, rs_ply_header *h);
#ifdef __cplusplus
}
#endif
#endif
