/* accel/bvh.h — the bounding volume hierarchy's host side: the builders (median, the thesis's
 * axis/partition/comparator grid, binned SAH, LBVH; see accel/bvh.c for the invariants every one
 * keeps), their options and names, the rs_bvh that owns the node and primitive-id arrays, its
 * SAH cost and destroy.  The node layout, the view and the RS_HD traversal that host and CUDA
 * both compile are accel/bvh_traverse.h's, included here. */
#ifndef RS_ACCEL_BVH_H
#define RS_ACCEL_BVH_H

#include <stddef.h>

#include "accel/bvh_traverse.h"
#include "core/geom.h"
#include "core/status.h"

/* How a builder chooses its splits.  Stored as uint32_t fields (fixed width in C and CUDA C++).
 * A zeroed rs_bvh_builder is RS_BVH_MEDIAN, the builder this project always had. */
typedef enum rs_bvh_method {
    RS_BVH_MEDIAN = 0, /* largest centroid extent, quickselect at the middle, by centroid */
    RS_BVH_GRID = 1,   /* the thesis's grid (§5.7): split axis x partition x comparator */
    RS_BVH_SAH = 2,    /* binned surface area heuristic (Wald 2007) */
    RS_BVH_LBVH = 3    /* Morton-code linear BVH (Lauterbach et al. 2009, Karras 2012) */
} rs_bvh_method;

/* RS_BVH_GRID: which axis a node is split on. */
typedef enum rs_bvh_axis {
    RS_BVH_AXIS_RANDOM = 0,     /* uniform over x, y, z from a fixed-seed hash of the node */
    RS_BVH_AXIS_ROTATIONAL = 1, /* (depth - 1) mod 3: x at the root, then y, z, x, ... */
    RS_BVH_AXIS_LARGEST = 2     /* the largest extent of the node's centroid bounds */
} rs_bvh_axis;

/* RS_BVH_GRID: how the node's range is split at its middle (the thesis's std:: calls). */
typedef enum rs_bvh_partition {
    RS_BVH_PART_SORT = 0,    /* full sort of the range (std::sort; here a stable merge sort) */
    RS_BVH_PART_PARTIAL = 1, /* sort of the lower half only (std::partial_sort; heap select) */
    RS_BVH_PART_NTH = 2      /* quickselect of the middle element (std::nth_element) */
} rs_bvh_partition;

/* RS_BVH_GRID: what primitives are compared by on the split axis. */
typedef enum rs_bvh_key {
    RS_BVH_KEY_MIN = 0,     /* the min corner of the primitive's box */
    RS_BVH_KEY_MAX = 1,     /* the max corner */
    RS_BVH_KEY_CENTROID = 2 /* the box's centre */
} rs_bvh_key;

#define RS_BVH_SAH_BINS_DEFAULT 16u
#define RS_BVH_SAH_BINS_MIN     2u
#define RS_BVH_SAH_BINS_MAX     32u
#define RS_BVH_N_VARIANTS       30u
/* Deepest leaf any builder makes, in nodes (root = 1): traversal's stacks hold RS_BVH_STACK. */
#define RS_BVH_MAX_DEPTH (RS_BVH_STACK - 1)
/* Cost constants of the SAH (MacDonald & Booth 1990): one node visit (a ray/box test) and one
 * ray/primitive test cost the same.  The binned-SAH builder and rs_bvh_sah_cost both use them. */
#define RS_BVH_COST_TRAV  1.0
#define RS_BVH_COST_ISECT 1.0

/* A builder: the method and its parameters.  Fields that the method does not use are ignored. */
typedef struct rs_bvh_builder {
    uint32_t method;    /* rs_bvh_method */
    uint32_t axis;      /* RS_BVH_GRID: rs_bvh_axis */
    uint32_t partition; /* RS_BVH_GRID: rs_bvh_partition */
    uint32_t key;       /* RS_BVH_GRID: rs_bvh_key */
    uint32_t bins;      /* RS_BVH_SAH: bins per axis, RS_BVH_SAH_BINS_MIN..MAX; 0 means 16 */
} rs_bvh_builder;

typedef struct rs_bvh {
    rs_bvh_node *nodes;
    uint32_t *prim_ids;
    uint32_t n_nodes;
    uint32_t n_prims;
    uint32_t depth; /* longest root-to-leaf path, in nodes (< RS_BVH_STACK) */
    /* build statistics (build time is measured by the caller) */
    rs_bvh_builder builder;  /* what built it: defaults filled in, unused fields zeroed */
    uint32_t n_leaves;       /* n_nodes = 2 n_leaves - 1 (none for an empty scene) */
    uint32_t max_leaf_count; /* primitives in the fullest leaf */
    uint32_t n_fallback;     /* interior nodes split at the middle because the heuristic could not
                                split them (identical centroids or Morton codes) or because its
                                split would have broken the depth bound; 0 for median and grid */
    /* Instances (core/geom.h): the bottom levels, one per prototype, in one pool (node indices
     * and prim ids absolute), and a copy of the geometry's instance table with each root set.
     * NULL / 0 without instances.  rs_bvh_attach points a geometry at them. */
    rs_instance *instances;
    rs_bvh_node *blas_nodes;
    uint32_t *blas_prim_ids;
    uint32_t n_blas_nodes;
} rs_bvh;

/* Build options.  A zeroed struct (or NULL) gives the median builder with 4-primitive leaves and
 * the default OpenMP thread count, the behaviour rs_bvh_build always had. */
typedef struct rs_bvh_build_opts {
    uint32_t max_leaf;      /* most primitives in a leaf (>= 1); 0 means the default, 4 */
    rs_bvh_builder builder; /* which builder; zeroed: RS_BVH_MEDIAN */
    uint32_t threads;       /* OpenMP threads for the build; 0: the default.  The tree does not
                               depend on it. */
    /* SAH only: a leaf's cost counts its primitives in blocks of this many, the width of the
     * leaf test that tests them together (the CPU's wide trees test a leaf's triangles or
     * parallelograms 4 or 8 at a time: rs_bvh_wide_leaf_size, accel/bvh8.h); 0 or 1: one by one,
     * as MacDonald and Booth count them.  Shapes the tree only: every tree gives the same hits. */
    uint32_t leaf_block;
    /* LBVH only: where the Morton codes are computed and sorted (the GPU: gpu/gpu_device.h's
     * rs_gpu_lbvh_sort); NULL: on the host.  It must write codes[i] = rs_morton3(centroid[i],
     * lo, scale) (accel/morton.h) for i < n and sort the pairs (codes[i], ids[i] = i) stably by
     * code, so that the tree is the host builder's, bit for bit. */
    rs_status (*lbvh_sort)(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                           const float scale[3], uint32_t *ids, uint32_t *codes);
    void *lbvh_sort_user;
} rs_bvh_build_opts;

/* The Morton frame of the LBVH builder: the centroids' bounds as an origin and a scale per axis
 * (1024 / extent; 0 for an axis without extent). */
void rs_bvh_lbvh_frame(const rs_vec3 *centroid, uint32_t n, int threads, float lo[3],
                       float scale[3]);

/* Builds a BVH over every primitive of `g` (each instance one primitive, and a bottom level per
 * prototype: see rs_bvh.instances) with the builder and leaf size in `opts` (NULL: the
 * defaults above).  The result owns its arrays; the same inputs give the same tree, bit for bit,
 * for any thread count.  RS_ERR_ARG for an invalid builder, RS_ERR_NOMEM when memory runs out
 * (nothing leaks, *out is NULL).  Every builder keeps the invariants listed in accel/bvh.c. */
#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_bvh_build(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out);
/* Points g's instance table and bottom levels at b's (a no-op without instances): the geometry
 * that traversal reads, on the host and in device copies, must be attached to its BVH. */
void rs_bvh_attach(const rs_bvh *b, rs_geom *g);
/* Frees `b` and its arrays; NULL is a no-op. */
void rs_bvh_destroy(rs_bvh *b);
/* What traversal reads of `b` (accel/bvh_traverse.h): its host arrays, borrowed. */
rs_bvh_view rs_bvh_view_of(const rs_bvh *b);
/* The SAH cost of the finished tree (MacDonald & Booth 1990; Wald 2007, eq. 1), in units of
 * ray/primitive tests for a ray that hits the root box:
 *     sum over interior nodes n of C_trav A(n) / A(root)
 *   + sum over leaves n of C_isect N(n) A(n) / A(root)
 * with C_trav = RS_BVH_COST_TRAV, C_isect = RS_BVH_COST_ISECT (both 1), A a box's surface area
 * and N a leaf's primitive count.  0 for an empty tree; if the root box has no area every node
 * weighs 1. */
double rs_bvh_sah_cost(const rs_bvh *b);

/* Parses a --bvh name: "median", "sah" or "sah:BINS" (BINS in 2..32, default 16), "lbvh", or the
 * thesis grid "AXIS-PARTITION-COMPARATOR" with AXIS random|rotational|largest, PARTITION
 * sort|partial|nth and COMPARATOR min|max|centroid (e.g. "rotational-nth-centroid").
 * RS_ERR_ARG with a message naming the valid forms if `name` is none of them. */
rs_status rs_bvh_builder_parse(const char *name, rs_bvh_builder *out);
/* The canonical name of `b` (parse(name(b)) == b, with bins filled in), written into buf[n] and
 * returned; "?" for an invalid builder. */
const char *rs_bvh_builder_name(const rs_bvh_builder *b, char *buf, size_t n);
/* RS_OK if `b` names a valid builder, else RS_ERR_ARG with a message. */
rs_status rs_bvh_builder_check(const rs_bvh_builder *b);
/* The standard variants, in table order: median, the 27 grid combinations (axis major, then
 * partition, then comparator), sah (16 bins), lbvh.  Writes at most `cap` of them to `out` (which
 * may be NULL when cap is 0) and returns how many there are (RS_BVH_N_VARIANTS). */
uint32_t rs_bvh_builder_variants(rs_bvh_builder *out, uint32_t cap);
/* Bounds of global primitive `prim`. */
rs_aabb rs_geom_prim_bounds(const rs_geom *g, uint32_t prim);
#ifdef __cplusplus
}
#endif

#endif
