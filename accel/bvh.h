/* accel/bvh.h — the bounding volume hierarchy: one flat node layout shared by host and device,
 * the host builders (median, the thesis's axis/partition/comparator grid, binned SAH, LBVH; see
 * accel/bvh.c for the invariants every one keeps), and the RS_HD traversal kernels that the CPU
 * device, the CUDA kernels and the CUDA fallback all call.
 *
 * Node layout (32 bytes, two per 64-byte cache line):
 *   lo, hi       12 B each  bounds
 *   left_first   4 B        interior: index of the left child; the right child is left_first + 1
 *                           leaf:     index of the first entry in prim_ids
 *   count        4 B        0 for an interior node, else the number of primitives in the leaf
 * Node 0 is the root.  An empty scene has no nodes and every ray misses. */
#ifndef RS_ACCEL_BVH_H
#define RS_ACCEL_BVH_H

#include <stddef.h>

#include "core/geom.h"
#include "core/status.h"

typedef struct rs_bvh_node {
    rs_vec3 lo;
    uint32_t left_first;
    rs_vec3 hi;
    uint32_t count;
} rs_bvh_node;

/* What traversal needs: pointers (host or device) and counts.  Plain data, copied by value. */
typedef struct rs_bvh_view {
    const rs_bvh_node *nodes;
    const uint32_t *prim_ids;
    uint32_t n_nodes;
} rs_bvh_view;

/* Deepest stack traversal uses.  Every builder keeps depth <= RS_BVH_MAX_DEPTH = 63 nodes: the
 * closest-hit stack then holds at most depth - 1 entries and the any-hit stack depth + 1. */
#define RS_BVH_STACK 64

/* Traversal counters (the thesis's "ray-object intersection tests" metric): compiled in only in
 * a translation unit that defines RS_COUNTERS before including this header (a benchmark's
 * counting pass), as that unit's thread-local tallies.  Everywhere else RS_COUNT is empty, so
 * the traversal the devices run pays nothing. */
#if defined(RS_COUNTERS) && !defined(__CUDACC__)
typedef struct rs_trace_counters {
    uint64_t rays, nodes, box_tests, prim_tests;
} rs_trace_counters;
static _Thread_local rs_trace_counters rs_counters;
#  define RS_COUNT(field, n) (rs_counters.field += (uint64_t)(n))
#else
#  define RS_COUNT(field, n) ((void)0)
#endif

RS_HD rs_vec3 rs_bvh_inv_dir(rs_vec3 d) { return rs_v3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z); }

/* Traversal's box tests are conservative by a relative margin: a box passes when the ray's
 * interval [tn, tf] inside it, clipped to [tmin, tmax], satisfies tn <= tf * RS_BVH_SLACK.  The
 * slab distances (bound - o) / d and a primitive test's t each carry rounding errors of a few
 * ulps; without the margin a primitive hit exactly on its box's face (a ray through a mesh
 * vertex, a point on an axis-aligned wall) could be culled by one ancestor box and found through
 * another, so that the answer would depend on the order of the visit. */
#define RS_BVH_SLACK (1.0f + 0x1.0p-16f)

/* The slab test (rs_isect_aabb) with the margin. */
RS_HD int rs_bvh_slab(const rs_aabb *b, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                      float *t_entry)
{
    float tn = tmin, tf = tmax;
    rs_slab((b->lo.x - o.x) * inv_d.x, (b->hi.x - o.x) * inv_d.x, &tn, &tf);
    rs_slab((b->lo.y - o.y) * inv_d.y, (b->hi.y - o.y) * inv_d.y, &tn, &tf);
    rs_slab((b->lo.z - o.z) * inv_d.z, (b->hi.z - o.z) * inv_d.z, &tn, &tf);
    *t_entry = tn;
    return tn <= tf * RS_BVH_SLACK;
}

/* The node's box test, with the ray/box algorithm the geometry names (g->aabb_algo; the slab
 * test with the margin by default; the other algorithms, benchmark options, get the margin on
 * tmax only).  The id is loop-invariant, so the branch is predicted perfectly. */
RS_HD int rs_bvh_node_hit(const rs_bvh_node *n, uint32_t algo, rs_vec3 o, rs_vec3 inv_d, float tmin,
                          float tmax, float *t_entry)
{
    rs_aabb b;
    b.lo = n->lo;
    b.hi = n->hi;
    if (algo == 0)
        return rs_bvh_slab(&b, o, inv_d, tmin, tmax, t_entry);
    return rs_isect_aabb_by(algo, &b, o, inv_d, tmin, tmax * RS_BVH_SLACK, t_entry);
}

/* The next float above t (for t >= 0, the common case, the next bit pattern): a bound that lets
 * a primitive hit at exactly t through the primitive tests' strict t < tmax. */
RS_HD float rs_float_next_up(float t)
{
    union {
        float f;
        uint32_t u;
    } x;
    x.f = t;
    if (t == 0.0f)
        x.u = 1u; /* the smallest denormal, also above -0 */
    else if (t > 0.0f && x.u < 0x7f800000u)
        x.u++;
    else if (t < 0.0f)
        x.u--;
    return x.f;
}

/* Which closest hit a traversal reports, whatever order it visits the primitives in: the smallest
 * t, and of primitives hit at exactly that t the lowest-numbered (what a brute-force loop over
 * the primitives in order keeps).  After a hit at t, a traversal keeps searching up to
 * rs_float_next_up(t) so that ties are seen, and takes a candidate (t', prim') when this says so
 * (before any hit, best->t is the ray's tmax and best->prim RS_NO_HIT).  So the binary and the
 * 4-wide traversals (accel/bvh4.h), on any device, agree bit for bit. */
RS_HD int rs_hit_better(float t, uint32_t prim, const rs_hit *best)
{
    return t < best->t || (t == best->t && prim < best->prim);
}

/* Closest hit along `ray` (ordered, stack-based traversal: the nearer child first, the other
 * pushed).  Returns 1 and fills *hit on a hit; on a miss sets hit->prim = RS_NO_HIT, returns 0.
 * Ties go to the lowest primitive number (rs_hit_better). */
RS_HD int rs_bvh_closest(const rs_bvh_view *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    uint32_t stack[RS_BVH_STACK];
    uint32_t sp = 0, node = 0;
    rs_vec3 inv_d = rs_bvh_inv_dir(ray.d);
    float te;
    hit->prim = RS_NO_HIT;
    hit->t = ray.tmax;
    hit->u = hit->v = 0.0f;
    RS_COUNT(rays, 1);
    RS_COUNT(box_tests, b->n_nodes > 0);
    if (b->n_nodes == 0 ||
        !rs_bvh_node_hit(&b->nodes[0], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &te))
        return 0;
    for (;;) {
        const rs_bvh_node *n = &b->nodes[node];
        RS_COUNT(nodes, 1);
        if (n->count > 0) {
            uint32_t i;
            RS_COUNT(prim_tests, n->count);
            for (i = 0; i < n->count; ++i) {
                uint32_t prim = b->prim_ids[n->left_first + i];
                float t, u, v;
                if (rs_geom_intersect(g, prim, &ray, &t, &u, &v) && rs_hit_better(t, prim, hit)) {
                    ray.tmax = rs_float_next_up(t);
                    hit->t = t;
                    hit->u = u;
                    hit->v = v;
                    hit->prim = prim;
                }
            }
        } else {
            uint32_t l = n->left_first, r = l + 1;
            float tl = 0.0f, tr = 0.0f;
            int hl;
            RS_COUNT(box_tests, 2);
            hl = rs_bvh_node_hit(&b->nodes[l], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &tl);
            int hr =
                rs_bvh_node_hit(&b->nodes[r], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &tr);
            if (hl && hr) {
                if (tr < tl) {
                    uint32_t tmp = l;
                    l = r;
                    r = tmp;
                }
                RS_ASSERT(sp < RS_BVH_STACK);
                stack[sp++] = r;
                node = l;
                continue;
            }
            if (hl) {
                node = l;
                continue;
            }
            if (hr) {
                node = r;
                continue;
            }
        }
        /* pop the next subtree that can still hold a closer hit */
        for (;;) {
            if (sp == 0)
                return hit->prim != RS_NO_HIT;
            node = stack[--sp];
            RS_COUNT(box_tests, 1);
            if (rs_bvh_node_hit(&b->nodes[node], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax,
                                &te))
                break;
        }
    }
}

/* Any hit inside (tmin, tmax): the shadow-ray query.  Returns 1 if something blocks the ray. */
RS_HD int rs_bvh_occluded(const rs_bvh_view *b, const rs_geom *g, rs_ray ray)
{
    uint32_t stack[RS_BVH_STACK];
    uint32_t sp = 0, node = 0;
    rs_vec3 inv_d = rs_bvh_inv_dir(ray.d);
    float te;
    RS_COUNT(rays, 1);
    if (b->n_nodes == 0)
        return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const rs_bvh_node *n;
        node = stack[--sp];
        n = &b->nodes[node];
        RS_COUNT(box_tests, 1);
        if (!rs_bvh_node_hit(n, g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &te))
            continue;
        RS_COUNT(nodes, 1);
        if (n->count > 0) {
            uint32_t i;
            for (i = 0; i < n->count; ++i) {
                float t, u, v;
                RS_COUNT(prim_tests, 1);
                if (rs_geom_intersect(g, b->prim_ids[n->left_first + i], &ray, &t, &u, &v))
                    return 1;
            }
        } else {
            RS_ASSERT(sp + 2 <= RS_BVH_STACK);
            stack[sp++] = n->left_first + 1;
            stack[sp++] = n->left_first;
        }
    }
    return 0;
}

/* ---- host side ---------------------------------------------------------------------------- */

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
} rs_bvh;

/* Every array of rs_bvh that its view (rs_bvh_view, the same field names) holds, with its
 * element count (`b` a pointer to the rs_bvh).  A device's copy of the BVH
 * (scheduler/device_copy.h) is made from this list: a new array of the view goes here. */
#define RS_BVH_ARRAYS(X, b)                                                                        \
  X(nodes, (size_t)(b)->n_nodes)                                                                   \
  X(prim_ids, (size_t)(b)->n_prims)

/* Build options.  A zeroed struct (or NULL) gives the median builder with 4-primitive leaves and
 * the default OpenMP thread count, the behaviour rs_bvh_build always had. */
typedef struct rs_bvh_build_opts {
    uint32_t max_leaf;      /* most primitives in a leaf (>= 1); 0 means the default, 4 */
    rs_bvh_builder builder; /* which builder; zeroed: RS_BVH_MEDIAN */
    uint32_t threads;       /* OpenMP threads for the build; 0: the default.  The tree does not
                               depend on it. */
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

/* Builds a BVH over every primitive of `g` with the builder and leaf size in `opts` (NULL: the
 * defaults above).  The result owns its arrays; the same inputs give the same tree, bit for bit,
 * for any thread count.  RS_ERR_ARG for an invalid builder, RS_ERR_NOMEM when memory runs out
 * (nothing leaks, *out is NULL).  Every builder keeps the invariants listed in accel/bvh.c. */
#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_bvh_build(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out);
void rs_bvh_destroy(rs_bvh *b);
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
