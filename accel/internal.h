/* accel/internal.h — what the BVH builders share; for accel/ only.
 *
 * rs_bvh_build (accel/bvh.c) owns the frame every builder runs in: it computes each primitive's
 * box and centroid, then recurses top-down over ranges of `ids`.  At each node it asks the
 * builder's split function for a split of ids[first, first + count):
 *
 *   returns 0          make a leaf of the whole range (only allowed when count <= max_leaf);
 *   returns m          0 < m < count: the function has reordered the range so that its first m
 *                      ids form the left child and the rest the right child.
 *
 * A split function may reorder only its own range and write only its own range of the scratch
 * arrays, so subtrees can be built by concurrent OpenMP tasks; it must be a pure function of the
 * range's contents and (first, count, depth), so the tree does not depend on the thread count.
 * It never allocates: every buffer is allocated before the recursion starts, so out-of-memory can
 * only happen up front.  The frame enforces the depth bound and computes the node boxes
 * (bottom-up: a leaf's from its primitives, an interior node's as the union of its children). */
#ifndef RS_ACCEL_INTERNAL_H
#define RS_ACCEL_INTERNAL_H

#include "accel/bvh.h"
#include "accel/bvh4.h"
#include "accel/bvh8.h"

/* A sort key and the primitive it belongs to (8 bytes). */
typedef struct rs_bvh_key_id {
    float key;
    uint32_t id;
} rs_bvh_key_id;

typedef struct rs_bvh_ctx {
    const rs_aabb *bounds;   /* per primitive: rs_geom_prim_bounds */
    const rs_vec3 *centroid; /* per primitive: the centre of its box */
    uint32_t *ids;           /* the permutation under construction; becomes prim_ids */
    uint32_t max_leaf;
    uint32_t leaf_block; /* SAH: primitives per block of the leaf cost (>= 1) */
    rs_bvh_builder builder; /* validated, bins filled in */
    rs_bvh_key_id *pairs;   /* n scratch pairs (grid builders and the median fallback) */
    rs_bvh_key_id *pairs2;  /* n more for the merge sort (RS_BVH_PART_SORT only) */
    const uint32_t *codes;  /* LBVH: Morton code of ids[i], sorted ascending */
} rs_bvh_ctx;

/* Ranges at least this long get their linear passes (bounds, binning) split over OpenMP tasks in
 * a fixed number of chunks, merged in chunk order (so the result is the same for any number of
 * threads). */
#define RS_BVH_PAR_RANGE  65536u
#define RS_BVH_PAR_CHUNKS 8u

/* Bounds of the centroids of ids[first, first + count), count >= 1. */
rs_aabb rs_bvh_centroid_bounds(const rs_bvh_ctx *c, uint32_t first, uint32_t count);

/* The split functions (see the contract above).  *fallback is set to 1 when the builder had to
 * split at the middle because its heuristic could not separate the range. */
uint32_t rs_bvh_split_grid(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                           int *fallback);
uint32_t rs_bvh_split_sah(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                          int *fallback);
uint32_t rs_bvh_split_lbvh(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                           int *fallback);
/* The median split (largest centroid extent, quickselect by centroid at count / 2), used by
 * RS_BVH_MEDIAN and as the depth-bound fallback of the SAH builder; count >= 2. */
uint32_t rs_bvh_split_median(const rs_bvh_ctx *c, uint32_t first, uint32_t count);

/* LBVH preparation (accel/bvh_lbvh.c): Morton codes of the centroids, radix-sorted together with
 * ids.  `codes`, `codes_tmp` and `ids_tmp` hold n entries each; on return ids[] is sorted by code
 * (ties in ascending primitive order) and codes[i] is the code of ids[i]. */
void rs_bvh_lbvh_sort(const rs_vec3 *centroid, uint32_t n, uint32_t *ids, uint32_t *codes,
                      uint32_t *codes_tmp, uint32_t *ids_tmp, int threads);

/* ---- collapsing into wide trees (accel/wide.c; used by accel/bvh4.c and accel/bvh8.c) ---- */

/* The binary nodes a wide node of up to `width` lanes holds, starting from binary node `src`: its
 * two children, then opening the interior lane of largest surface area until there are `width`
 * or none is left (for a tree that is one leaf, that leaf alone).  Returns the count. */
uint32_t rs_bvh_wide_lanes(const rs_bvh_node *bn, uint32_t src, uint32_t width, uint32_t *lanes);

/* Copies leaves of triangles into triangle blocks and leaves of parallelograms into
 * parallelogram blocks of `width` lanes (4: rs_bvh4_tri4 / quad4, accel/bvh4.h; 8: rs_bvh8_tri8 /
 * quad8, accel/bvh8.h), in SSE builds only; triangles only with the Möller-Trumbore test, whose
 * arithmetic the blocks' test repeats; leaves of static spheres with the algebraic test into
 * rs_bvh8_sphere8 blocks, width 8 only. */
typedef struct rs_leaf_packer {
    const rs_geom *g;
    const uint32_t *prim_ids;
    uint32_t width;
    void *tri;  /* cap_tri triangle blocks, allocated by the caller */
    void *quad; /* cap_quad parallelogram blocks */
    rs_bvh8_sphere8 *sphere; /* cap_sphere sphere blocks (width 8 only) */
    uint32_t n_tri, cap_tri, n_quad, cap_quad, n_sphere, cap_sphere;
    int pack_tris, pack_quads, pack_spheres;
} rs_leaf_packer;

void rs_leaf_packer_init(rs_leaf_packer *p, const rs_bvh *b, const rs_geom *g, uint32_t width);
/* A wide node's lane for binary leaf `l`: its blocks packed where they can be, *child and *count
 * set as the node layouts say (accel/bvh4.h).  Returns 1 when the leaf was packed. */
int rs_leaf_lane(rs_leaf_packer *p, const rs_bvh_node *l, uint32_t *child, uint16_t *count);

/* Checks that `b` fits a wide tree (`what` names it in the message) of at most `max_nodes` nodes
 * and leaves of at most 32767 primitives; sets p->cap_tri, p->cap_quad and *cap_nodes, the
 * blocks and nodes to allocate. */
rs_status rs_bvh_wide_plan(const rs_bvh *b, rs_leaf_packer *p, const char *what,
                           uint32_t max_nodes, uint32_t *cap_nodes);

/* A wide tree's node layout, for the collapse below: bytes per node, where its child[width],
 * count[width], n_lanes and leaf_mask fields lie, and how a lane's box is written (l NULL: an
 * unused lane, which no ray may enter); the block sizes of its triangle and parallelogram
 * blocks. */
#define RS_WIDE_MAX 8u
typedef struct rs_wide_layout {
    const char *what; /* "4-wide BVH", for messages */
    uint32_t width, max_nodes;
    size_t node_size, child_offset, count_offset, n_lanes_offset, leaf_mask_offset;
    size_t tri_size, quad_size;
    void (*set_box)(void *node, uint32_t lane, const rs_bvh_node *l);
} rs_wide_layout;

/* The collapsed tree's arrays (rs_bvh4 and rs_bvh8 take them over). */
typedef struct rs_wide_tree {
    void *nodes, *tri, *quad;
    rs_bvh8_sphere8 *sphere;
    uint32_t *inst_root; /* per instance of b: the wide root of its bottom level; NULL without */
    uint32_t n_nodes, n_tri, n_quad, n_sphere, depth, n_packed;
} rs_wide_tree;

/* Collapses `b`, built over `g`, into the wide tree `L` describes: each node takes its binary
 * node's two children and keeps opening the interior child of largest surface area until it has
 * `width` (rs_bvh_wide_lanes); leaf lanes packed by rs_leaf_lane; nodes in depth-first order from
 * the root at 0.  Then, with instances, each prototype's bottom level (b->blas_nodes from an
 * instance's root) the same way into the nodes that follow, once per prototype, its leaves never
 * packed (a lane's child indexes b->blas_prim_ids); out->inst_root[i] is instance i's.
 * RS_ERR_ARG or RS_ERR_NOMEM (with a message naming L->what; *out holds nothing
 * then); an empty tree has no nodes. */
rs_status rs_wide_build(const rs_bvh *b, const rs_geom *g, const rs_wide_layout *L,
                        rs_wide_tree *out);
void rs_wide_free(rs_wide_tree *t);

#endif
