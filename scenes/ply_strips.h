/* scenes/ply_strips.h — PLY files whose faces are triangle strips (`element tristrips`, as the
 * Stanford scans' originals and many scanners write them), which Assimp does not read (it made a
 * single triangle of a whole model, without a word).
 *
 * A strip lists vertex indices; -1 ends one strip and starts the next.  Triangle i of a strip is
 * (s[i], s[i+1], s[i+2]) for even i and (s[i+1], s[i], s[i+2]) for odd i, so that all keep the
 * first one's orientation; triangles with a repeated vertex join strips and are skipped (counted
 * as joins, not as dropped faces).  ascii, binary_little_endian and binary_big_endian; vertices
 * need x, y and z of any numeric type; other elements and properties are read past.  The header
 * is parsed by scenes/ply_header.h in its strict mode (every line understood, counts bounded by
 * the file's size). */
#ifndef RS_SCENES_PLY_STRIPS_H
#define RS_SCENES_PLY_STRIPS_H

#include <stdint.h>

#include "core/status.h"

typedef struct rs_ply_strips {
    float *vertices;    /* 3 per vertex */
    uint32_t n_vertices;
    uint32_t *triangles; /* 3 vertex indices per triangle (an index may be out of range: the
                            caller drops those faces and counts them) */
    uint32_t n_triangles;
    uint32_t strips, joins;
} rs_ply_strips;

#ifdef __cplusplus
extern "C" {
#endif
/* Reads `path`; RS_ERR_ARG naming the file (and the header or data line) for bad content. */
rs_status rs_ply_read_strips(const char *path, rs_ply_strips *out);
void rs_ply_strips_free(rs_ply_strips *s);
#ifdef __cplusplus
}
#endif
#endif
