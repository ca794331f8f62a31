/* accel/bvh8.h — the CPU's 8-wide BVH: the binary tree collapsed so that each node holds up to
 * eight children's boxes side by side, tested against one ray with AVX2 (Embree's BVH8; Wald et
 * al. 2014).  Host only, like the 4-wide tree (accel/bvh4.h) it extends: the CUDA kernels and the
 * GPU fallback keep the binary tree.  The traversal (accel/bvh8_avx2.c) is compiled for AVX2 alone
 * and chosen at run time: rs_bvh8_supported() says whether this machine and build can run it;
 * where it cannot, the CPU device uses the 4-wide tree.
 *
 * Same answers as the binary and 4-wide traversals, bit for bit, for the reasons accel/bvh4.h
 * gives: the nodes hold the binary tree's own boxes, the leaves its primitive ranges (triangle
 * and parallelogram leaves packed eight to a block, tri8 and quad8, and tested eight at once with
 * the scalar tests' operations lane by lane, as the 4-wide tree's tri4 and quad4 blocks are; so
 * are leaves of static spheres with the algebraic test, sphere8, sqrt and division being correctly
 * rounded in both), and the
 * closest hit follows rs_hit_better.  The box test picks each axis's near and far plane by the sign
 * of the ray's direction instead of taking min / max of the two slab distances: for a finite
 * 1 / d the rounded (bound - o) * (1 / d) is monotone in the bound, so the near plane's distance
 * is exactly the min the slab test takes and the far plane's the max, and each box passes exactly
 * when rs_bvh_slab passes it.  Rays with a zero (or NaN, or denormal) direction component, whose
 * 1 / d is not finite, take the slab test's min / max form with its NaN rule.
 *
 * Node layout (256 bytes, four cache lines, 64-byte aligned):
 *   b[6][8]     the children's boxes by plane: lo.x, lo.y, lo.z, hi.x, hi.y, hi.z of all eight
 *               lanes (so the near plane of axis a is row a or a + 3)
 *   child[8]    interior lane: index of the child node; leaf lane: first prim_ids entry, or for a
 *               packed leaf the first of its blocks
 *   count[8]    0 for an interior lane, else the leaf's primitive count, or for a packed leaf
 *               RS_WIDE_PACKED | its number of blocks (with RS_WIDE_QUADS for quad8 blocks,
 *               RS_WIDE_SPHERES for sphere8 blocks)
 *   n_lanes     lanes in use (1 to 8), packed from lane 0; unused lanes hold an empty box */
#ifndef RS_ACCEL_BVH8_H
#define RS_ACCEL_BVH8_H

#include "accel/bvh4.h"

typedef struct rs_bvh8_node {
    float b[6][8];
    uint32_t child[8];
    uint16_t count[8];
    uint32_t n_lanes;
    uint32_t leaf_mask; /* bit i: lane i is a leaf (count[i] != 0) */
    uint32_t pad_[2];
} rs_bvh8_node;

/* Packed leaves' blocks: rs_bvh4_tri4 and rs_bvh4_quad4 with eight lanes (320 and 416 bytes). */
typedef struct rs_bvh8_tri8 {
    float v0[3][8], e1[3][8], e2[3][8];
    uint32_t prim[8]; /* global primitive numbers; RS_NO_HIT in unused lanes */
} rs_bvh8_tri8;

typedef struct rs_bvh8_quad8 {
    float q[3][8], u[3][8], v[3][8], w[3][8];
    uint32_t prim[8];
} rs_bvh8_quad8;

/* Spheres (static, with the algebraic test), eight to a block (160 bytes); unused lanes have a
 * NaN radius, which no ray hits. */
typedef struct rs_bvh8_sphere8 {
    float c[3][8], r[8];
    uint32_t prim[8];
} rs_bvh8_sphere8;

typedef struct rs_bvh8 {
    rs_bvh8_node *nodes;      /* node 0 is the root; none for an empty scene */
    rs_bvh8_tri8 *tri8;       /* the packed leaves' triangles */
    rs_bvh8_quad8 *quad8;     /* the packed leaves' parallelograms */
    rs_bvh8_sphere8 *sphere8; /* the packed leaves' spheres */
    const uint32_t *prim_ids; /* the binary BVH's, borrowed: it must outlive this tree */
    uint32_t *inst_root;      /* per instance: its prototype's bottom level, collapsed like the
                                 top tree into nodes after the top tree's; NULL without instances */
    uint32_t n_nodes, n_tri8, n_quad8, n_sphere8;
    uint32_t depth;    /* in nodes; at most the binary tree's */
    uint32_t n_packed; /* leaves packed as blocks */
} rs_bvh8;

/* Stack entries and leaf flags: accel/wide.h (leaf entries RS_WIDE_LEAF | node << 3 | lane). */
#define RS_BVH8_MAX_NODES (1u << 28)
/* Each level pushes at most 7 entries (closest) or 8 (any hit). */
#define RS_BVH8_STACK (8 * RS_BVH_STACK)

#ifdef __cplusplus
extern "C" {
#endif
/* Collapses `b`, built over `g`, into an 8-wide tree (each node opens the interior child of
 * largest surface area until it has eight; triangle and parallelogram leaves packed eight to a block where rs_bvh4_build packs them four).
 * RS_ERR_ARG for a leaf of more than 32767 primitives or a tree of more than 2^28 nodes,
 * RS_ERR_NOMEM when memory runs out (*out is NULL then).  Builds on any machine. */
rs_status rs_bvh8_build(const rs_bvh *b, const rs_geom *g, rs_bvh8 **out);
void rs_bvh8_destroy(rs_bvh8 *b);

/* The leaf size that suits the CPU device's wide tree over `g`, as rs_bvh_build_opts.leaf_block
 * and .max_leaf: the tree's block width (8 for bvh_width 8, or 0 where rs_bvh8_supported(); 4 for
 * width 4 or without AVX2) when at least 90% of the primitives are of a kind that tree packs
 * into blocks (triangles with the Möller-Trumbore test, parallelograms, and for 8 wide static
 * spheres with the algebraic test); else 0, the classic SAH leaves (also for the binary kernel,
 * width 2): a leaf the tree cannot pack is tested one primitive at a time. */
uint32_t rs_bvh_wide_leaf_size(uint32_t bvh_width, const rs_geom *g);

/* Whether the traversal below can run here: built for x86-64 with GCC or Clang, and the CPU has
 * AVX2.  The functions below must not be called where it says 0. */
int rs_bvh8_supported(void);

/* Closest hit, as rs_bvh_closest (1 and *hit on a hit, else hit->prim = RS_NO_HIT and 0), and any
 * hit inside (tmin, tmax), as rs_bvh_occluded. */
int rs_bvh8_closest(const rs_bvh8 *b, const rs_geom *g, rs_ray ray, rs_hit *hit);
int rs_bvh8_occluded(const rs_bvh8 *b, const rs_geom *g, rs_ray ray);

/* rs_trace_one (accel/trace.h) on rays [begin, end) of `batch`. */
void rs_bvh8_trace(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                   uint32_t begin, uint32_t end);

/* The same answers, bit for bit, with the rays walked eight at a time as packets (consecutive
 * rays of the batch together): faster where neighbours are coherent. */
void rs_bvh8_trace_packets(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                           uint32_t begin, uint32_t end);
#ifdef __cplusplus
}
#endif

#endif
