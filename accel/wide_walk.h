/* accel/wide_walk.h — the wide trees' closest-hit and any-hit walks, written once for any width
 * (Embree's BVHN traverser, one source for BVH4 and BVH8).  No include guard: accel/bvh4.h
 * includes it for the 4-wide tree (SSE, or scalar lanes without SSE) and accel/bvh8_avx2.c for
 * the 8-wide one (AVX2), each after defining its width and its per-width primitives:
 *
 *   RS_WIDE_W, RS_WIDE_SHIFT    the width and its log2 (a leaf stack entry holds node << SHIFT)
 *   RS_WIDE_TREE, RS_WIDE_NODE  the tree (nodes, n_nodes, prim_ids and the block arrays) and its
 *                               node (child[W], count[W])
 *   RS_WIDE_STACK               stack entries a walk needs (W per level of the binary tree)
 *   RS_WIDE_FN(x)               the generated and the per-width functions' names (prefix ## x)
 *   RS_WIDE_RAY, RS_WIDE_TN     the ray broadcast to W lanes; W entry distances in registers
 *   FN(ray_init)(RAY *, o, d)   the broadcast ray
 *   FN(lanes)(node, RAY *, tmin, tmax, TN *)
 *                               the box test of the node's lanes: the mask of lanes hit (bit i
 *                               for lane i, unused lanes never) and their entry distances
 *   FN(tn_store)(float[W], const TN *)
 *   RS_WIDE_TRIS(b), RS_WIDE_TRI_HIT(block, RAY *, tmin, tmax, t, u, v) and RS_WIDE_QUADS_OF(b),
 *   RS_WIDE_QUAD_HIT(...)       where the tree packs leaves: the block arrays and the blocks'
 *                               tests (the mask of lanes hit inside (tmin, tmax), t, u, v per
 *                               lane); optionally RS_WIDE_SPHERES_OF(b) and
 *                               RS_WIDE_SPHERE_HIT(block, RAY *, tmin, tmax, t)
 *
 * It defines FN(packed_closest) and FN(packed_occluded) (where the tree packs leaves),
 * FN(closest) and FN(occluded), and undefines every parameter above.
 *
 * Same answers as the binary walk (accel/bvh_traverse.h), bit for bit, at any width: a wide node
 * holds the binary tree's own boxes, its leaves the binary leaves' primitives, and the closest
 * hit follows rs_hit_better whatever order the lanes are visited in (see accel/bvh4.h).  The
 * order is still fixed (lanes by entry distance, ties by lane number), so a walk is
 * deterministic too. */

#include "accel/wide.h"

#if !defined(RS_WIDE_W) || !defined(RS_WIDE_SHIFT) || !defined(RS_WIDE_TREE) ||                  \
    !defined(RS_WIDE_NODE) || !defined(RS_WIDE_STACK) || !defined(RS_WIDE_FN) ||                  \
    !defined(RS_WIDE_RAY) || !defined(RS_WIDE_TN)
#  error "accel/wide_walk.h: define the width's parameters first"
#endif

/* The stack entry for lane `lane` of node `n`, number `node`. */
#define RS_WIDE_REF(n, node, lane)                                                                 \
  ((n)->count[lane] ? RS_WIDE_LEAF | (node) << RS_WIDE_SHIFT | (lane) : (n)->child[lane])

#ifdef RS_WIDE_TRI_HIT
/* A packed leaf (`count` has RS_WIDE_PACKED) for closest hit: each block's hits taken as
 * rs_bvh_leaf_closest takes them (rs_hit_better; the ray cut just past the best). */
static inline void RS_WIDE_FN(packed_closest)(const RS_WIDE_TREE *b, uint32_t first,
                                              uint32_t count, const RS_WIDE_RAY *r, rs_ray *ray,
                                              rs_hit *hit)
{
    uint32_t i, n = count & RS_WIDE_BLOCKS;
    for (i = 0; i < n; ++i) {
        float t[RS_WIDE_W], u[RS_WIDE_W], v[RS_WIDE_W];
        const uint32_t *prim;
        uint32_t m;
#  ifdef RS_WIDE_SPHERE_HIT
        if (count & RS_WIDE_SPHERES) {
            m = RS_WIDE_SPHERE_HIT(&RS_WIDE_SPHERES_OF(b)[first + i], r, ray->tmin, ray->tmax, t);
            memset(u, 0, sizeof u); /* rs_geom_intersect's u, v for a sphere */
            memset(v, 0, sizeof v);
            prim = RS_WIDE_SPHERES_OF(b)[first + i].prim;
        } else
#  endif
            if (count & RS_WIDE_QUADS) {
            m = RS_WIDE_QUAD_HIT(&RS_WIDE_QUADS_OF(b)[first + i], r, ray->tmin, ray->tmax, t, u, v);
            prim = RS_WIDE_QUADS_OF(b)[first + i].prim;
        } else {
            m = RS_WIDE_TRI_HIT(&RS_WIDE_TRIS(b)[first + i], r, ray->tmin, ray->tmax, t, u, v);
            prim = RS_WIDE_TRIS(b)[first + i].prim;
        }
        while (m) {
            uint32_t l = (uint32_t)__builtin_ctz(m);
            m &= m - 1;
            if (rs_hit_better(t[l], prim[l], hit)) {
                ray->tmax = rs_float_next_up(t[l]);
                hit->t = t[l];
                hit->u = u[l];
                hit->v = v[l];
                hit->prim = prim[l];
            }
        }
    }
}

/* A packed leaf for any hit: 1 when some primitive is hit inside (tmin, tmax). */
static inline int RS_WIDE_FN(packed_occluded)(const RS_WIDE_TREE *b, uint32_t first,
                                              uint32_t count, const RS_WIDE_RAY *r,
                                              const rs_ray *ray)
{
    uint32_t i, n = count & RS_WIDE_BLOCKS;
    for (i = 0; i < n; ++i) {
        float t[RS_WIDE_W], u[RS_WIDE_W], v[RS_WIDE_W];
        uint32_t m;
#  ifdef RS_WIDE_SPHERE_HIT
        if (count & RS_WIDE_SPHERES)
            m = RS_WIDE_SPHERE_HIT(&RS_WIDE_SPHERES_OF(b)[first + i], r, ray->tmin, ray->tmax, t);
        else
#  endif
            m = count & RS_WIDE_QUADS ? RS_WIDE_QUAD_HIT(&RS_WIDE_QUADS_OF(b)[first + i], r,
                                                         ray->tmin, ray->tmax, t, u, v)
                                      : RS_WIDE_TRI_HIT(&RS_WIDE_TRIS(b)[first + i], r,
                                                        ray->tmin, ray->tmax, t, u, v);
        if (m)
            return 1;
    }
    return 0;
}
#endif

/* Closest hit, as rs_bvh_closest: 1 and *hit on a hit, else hit->prim = RS_NO_HIT and 0.
 * Ordered: the nearest lane hit is visited next and the others pushed far to near with their
 * entry distances (one lane: no sort; two: one compare; more: insertion sort); a popped entry
 * that starts beyond the closest hit so far is dropped without touching its node. */
static inline int RS_WIDE_FN(closest)(const RS_WIDE_TREE *b, const rs_geom *g, rs_ray ray,
                                      rs_hit *hit)
{
    uint32_t stack[RS_WIDE_STACK];
    float stack_t[RS_WIDE_STACK];
    uint32_t sp = 0, ref = 0;
    RS_WIDE_RAY r;
    hit->prim = RS_NO_HIT;
    hit->t = ray.tmax;
    hit->u = hit->v = 0.0f;
    if (b->n_nodes == 0)
        return 0;
    RS_WIDE_FN(ray_init)(&r, ray.o, ray.d);
    for (;;) {
        if (!(ref & RS_WIDE_LEAF)) {
            const RS_WIDE_NODE *n = &b->nodes[ref];
            RS_WIDE_TN tnv;
            uint32_t mask = RS_WIDE_FN(lanes)(n, &r, ray.tmin, ray.tmax, &tnv);
            if (mask != 0) {
                float tn[RS_WIDE_W];
                uint32_t first = (uint32_t)__builtin_ctz(mask), second;
                mask &= mask - 1;
                if (mask == 0) {
                    ref = RS_WIDE_REF(n, ref, first);
                    continue;
                }
                RS_WIDE_FN(tn_store)(tn, &tnv);
                second = (uint32_t)__builtin_ctz(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    /* two lanes: the nearer next, the other pushed */
                    if (tn[second] < tn[first]) {
                        uint32_t s = first;
                        first = second;
                        second = s;
                    }
                    RS_ASSERT(sp < RS_WIDE_STACK);
                    stack[sp] = RS_WIDE_REF(n, ref, second);
                    stack_t[sp++] = tn[second];
                    ref = RS_WIDE_REF(n, ref, first);
                    continue;
                } else {
                    /* three or more: insertion sort by entry distance, pushed far to near */
                    uint32_t lanes[RS_WIDE_W], k = 2, i, j;
                    if (tn[second] < tn[first]) {
                        lanes[0] = second;
                        lanes[1] = first;
                    } else {
                        lanes[0] = first;
                        lanes[1] = second;
                    }
                    while (mask) {
                        uint32_t l = (uint32_t)__builtin_ctz(mask);
                        mask &= mask - 1;
                        for (j = k; j > 0 && tn[lanes[j - 1]] > tn[l]; --j)
                            lanes[j] = lanes[j - 1];
                        lanes[j] = l;
                        ++k;
                    }
                    for (i = k - 1; i > 0; --i) {
                        RS_ASSERT(sp < RS_WIDE_STACK);
                        stack[sp] = RS_WIDE_REF(n, ref, lanes[i]);
                        stack_t[sp++] = tn[lanes[i]];
                    }
                    ref = RS_WIDE_REF(n, ref, lanes[0]);
                    continue;
                }
            }
        } else {
            const RS_WIDE_NODE *n = &b->nodes[(ref & ~RS_WIDE_LEAF) >> RS_WIDE_SHIFT];
            uint32_t lane = ref & (RS_WIDE_W - 1u), first = n->child[lane], count = n->count[lane];
            uint32_t i;
#ifdef RS_WIDE_TRI_HIT
            if (count & RS_WIDE_PACKED) {
                RS_WIDE_FN(packed_closest)(b, first, count, &r, &ray, hit);
                count = 0;
            }
#endif
            for (i = 0; i < count; ++i)
                rs_bvh_leaf_closest(g, b->prim_ids[first + i], &ray, hit);
        }
        /* pop the next entry that can still hold a hit no farther than the best so far */
        for (;;) {
            if (sp == 0)
                return hit->prim != RS_NO_HIT;
            --sp;
            if (stack_t[sp] <= ray.tmax * RS_BVH_SLACK)
                break;
        }
        ref = stack[sp];
    }
}

/* Any hit inside (tmin, tmax), as rs_bvh_occluded: every lane hit pushed, none sorted. */
static inline int RS_WIDE_FN(occluded)(const RS_WIDE_TREE *b, const rs_geom *g, rs_ray ray)
{
    uint32_t stack[RS_WIDE_STACK];
    uint32_t sp = 0;
    RS_WIDE_RAY r;
    if (b->n_nodes == 0)
        return 0;
    RS_WIDE_FN(ray_init)(&r, ray.o, ray.d);
    stack[sp++] = 0;
    while (sp > 0) {
        uint32_t ref = stack[--sp];
        if (!(ref & RS_WIDE_LEAF)) {
            const RS_WIDE_NODE *n = &b->nodes[ref];
            RS_WIDE_TN tnv;
            uint32_t mask = RS_WIDE_FN(lanes)(n, &r, ray.tmin, ray.tmax, &tnv);
            while (mask) {
                uint32_t l = (uint32_t)__builtin_ctz(mask);
                mask &= mask - 1;
                RS_ASSERT(sp < RS_WIDE_STACK);
                stack[sp++] = RS_WIDE_REF(n, ref, l);
            }
        } else {
            const RS_WIDE_NODE *n = &b->nodes[(ref & ~RS_WIDE_LEAF) >> RS_WIDE_SHIFT];
            uint32_t lane = ref & (RS_WIDE_W - 1u), first = n->child[lane], count = n->count[lane];
            uint32_t i;
#ifdef RS_WIDE_TRI_HIT
            if (count & RS_WIDE_PACKED) {
                if (RS_WIDE_FN(packed_occluded)(b, first, count, &r, &ray))
                    return 1;
                continue;
            }
#endif
            for (i = 0; i < count; ++i)
                if (rs_bvh_leaf_occluded(g, b->prim_ids[first + i], &ray))
                    return 1;
        }
    }
    return 0;
}

#undef RS_WIDE_REF
#undef RS_WIDE_W
#undef RS_WIDE_SHIFT
#undef RS_WIDE_TREE
#undef RS_WIDE_NODE
#undef RS_WIDE_STACK
#undef RS_WIDE_FN
#undef RS_WIDE_RAY
#undef RS_WIDE_TN
#undef RS_WIDE_TRIS
#undef RS_WIDE_TRI_HIT
#undef RS_WIDE_QUADS_OF
#undef RS_WIDE_QUAD_HIT
#undef RS_WIDE_SPHERES_OF
#undef RS_WIDE_SPHERE_HIT
