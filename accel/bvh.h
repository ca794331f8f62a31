/* accel/bvh.h — the bounding volume hierarchy: one flat node layout shared by host and device,
 * the host builder, and the RS_HD traversal kernels that the CPU device, the CUDA kernels and
 * the CUDA fallback all call.
 *
 * Node layout (32 bytes, two per 64-byte cache line):
 *   lo, hi       12 B each  bounds
 *   left_first   4 B        interior: index of the left child; the right child is left_first + 1
 *                           leaf:     index of the first entry in prim_ids
 *   count        4 B        0 for an interior node, else the number of primitives in the leaf
 * Node 0 is the root.  An empty scene has no nodes and every ray misses. */
#ifndef RS_ACCEL_BVH_H
#define RS_ACCEL_BVH_H

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

/* Deepest stack traversal uses.  The builders keep trees shallower than this (median splits
 * halve the primitive count, so depth <= log2(n) + 1). */
#define RS_BVH_STACK 64

RS_HD rs_vec3 rs_bvh_inv_dir(rs_vec3 d) { return rs_v3(1.0f / d.x, 1.0f / d.y, 1.0f / d.z); }

RS_HD int rs_bvh_node_hit(const rs_bvh_node *n, rs_vec3 o, rs_vec3 inv_d, float tmin, float tmax,
                          float *t_entry)
{
    rs_aabb b;
    b.lo = n->lo;
    b.hi = n->hi;
    return rs_isect_aabb(&b, o, inv_d, tmin, tmax, t_entry);
}

/* Closest hit along `ray` (ordered, stack-based traversal: the nearer child first, the other
 * pushed).  Returns 1 and fills *hit on a hit; on a miss sets hit->prim = RS_NO_HIT, returns 0. */
RS_HD int rs_bvh_closest(const rs_bvh_view *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    uint32_t stack[RS_BVH_STACK];
    uint32_t sp = 0, node = 0;
    rs_vec3 inv_d = rs_bvh_inv_dir(ray.d);
    float te;
    hit->prim = RS_NO_HIT;
    hit->t = ray.tmax;
    hit->u = hit->v = 0.0f;
    if (b->n_nodes == 0 || !rs_bvh_node_hit(&b->nodes[0], ray.o, inv_d, ray.tmin, ray.tmax, &te))
        return 0;
    for (;;) {
        const rs_bvh_node *n = &b->nodes[node];
        if (n->count > 0) {
            uint32_t i;
            for (i = 0; i < n->count; ++i) {
                uint32_t prim = b->prim_ids[n->left_first + i];
                float t, u, v;
                if (rs_geom_intersect(g, prim, &ray, &t, &u, &v)) {
                    ray.tmax = t;
                    hit->t = t;
                    hit->u = u;
                    hit->v = v;
                    hit->prim = prim;
                }
            }
        } else {
            uint32_t l = n->left_first, r = l + 1;
            float tl, tr;
            int hl = rs_bvh_node_hit(&b->nodes[l], ray.o, inv_d, ray.tmin, ray.tmax, &tl);
            int hr = rs_bvh_node_hit(&b->nodes[r], ray.o, inv_d, ray.tmin, ray.tmax, &tr);
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
            if (rs_bvh_node_hit(&b->nodes[node], ray.o, inv_d, ray.tmin, ray.tmax, &te))
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
    if (b->n_nodes == 0)
        return 0;
    stack[sp++] = 0;
    while (sp > 0) {
        const rs_bvh_node *n;
        node = stack[--sp];
        n = &b->nodes[node];
        if (!rs_bvh_node_hit(n, ray.o, inv_d, ray.tmin, ray.tmax, &te))
            continue;
        if (n->count > 0) {
            uint32_t i;
            for (i = 0; i < n->count; ++i) {
                float t, u, v;
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

typedef struct rs_bvh {
    rs_bvh_node *nodes;
    uint32_t *prim_ids;
    uint32_t n_nodes;
    uint32_t n_prims;
    uint32_t depth; /* longest root-to-leaf path, in nodes */
} rs_bvh;

typedef struct rs_bvh_build_opts {
    uint32_t max_leaf; /* most primitives in a leaf (>= 1); 0 means the default, 4 */
} rs_bvh_build_opts;

/* Builds a BVH over every primitive of `g` by median split on the axis of largest centroid
 * extent (quickselect partition).  `opts` may be NULL.  The result owns its arrays. */
#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_bvh_build(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out);
void rs_bvh_destroy(rs_bvh *b);
rs_bvh_view rs_bvh_view_of(const rs_bvh *b);
/* Bounds of global primitive `prim`. */
rs_aabb rs_geom_prim_bounds(const rs_geom *g, uint32_t prim);
#ifdef __cplusplus
}
#endif

#endif
