/* accel/wide_walk.h — the wide trees' closest-hit and any-hit walks, written once for any width
 * (Embree's BVHN traverser, one source for BVH4 and BVH8).  No include guard: accel/bvh4.h
 * includes it for the 4-wide tree (SSE, or scalar lanes without SSE) and accel/bvh8_avx2.c for
 * the 8-wide one (AVX2), each after defining its width and its per-width primitives:
 *
 *   RS_WIDE_W, RS_WIDE_SHIFT    the width and its log2 (a leaf stack entry holds node << SHIFT)
 *   RS_WIDE_TREE, RS_WIDE_NODE  the tree (nodes, n_nodes, prim_ids, inst_root and the block
 *                               arrays) and its node (child[W], count[W])
 *   RS_WIDE_STACK               stack entries a walk needs (W per level of the binary tree)
 *   RS_WIDE_ENTRY               optional: how FN(closest) and FN(occluded) are declared (static
 *                               inline where not defined; RS_HD_HOT where a thin wrapper calls
 *                               them, so that the walk is compiled into the wrapper)
 *   RS_WIDE_FN(x)               the generated and the per-width functions' names (prefix ## x)
 *   RS_WIDE_RAY, RS_WIDE_TN     the ray broadcast to W lanes; W entry distances in registers
 *   FN(ray_init)(RAY *, o, d)   the broadcast ray
 *   FN(ray_widen)(RAY *, margin)
 *                               for an instance's bottom level: its boxes widened by margin
 *   FN(lanes)(node, RAY *, widen, tmin, tmax, TN *)
 *                               the box test of the node's lanes (widened where `widen`): the
 *                               mask of lanes hit (bit i for lane i, unused lanes never) and
 *                               their entry distances
 *   FN(tn_store)(float[W], const TN *)
 *   RS_WIDE_TRIS(b), RS_WIDE_TRI_HIT(block, RAY *, tmin, tmax, t, u, v) and RS_WIDE_QUADS_OF(b),
 *   RS_WIDE_QUAD_HIT(...)       where the tree packs leaves: the block arrays and the blocks'
 *                               tests (the mask of lanes hit inside (tmin, tmax), t, u, v per
 *                               lane); optionally RS_WIDE_SPHERES_OF(b) and
 *                               RS_WIDE_SPHERE_HIT(block, RAY *, tmin, tmax, t)
 *   RS_WIDE_PREFETCH(b, node, lane)
 *                               optional: ask for the memory lane `lane` of `node` leads to (the
 *                               closest-hit walk calls it for every lane hit)
 *
 * It defines FN(closest) and FN(occluded), the walks they and an instance's bottom level share
 * (FN(walk_closest), FN(walk_occluded), FN(instance_closest), FN(instance_occluded)), the leaf
 * steps and, where the tree packs leaves, FN(packed_closest) and FN(packed_occluded); and
 * undefines every parameter above.
 *
 * Same answers as the binary walk (accel/bvh_traverse.h), bit for bit, at any width: a wide node
 * holds the binary tree's own boxes, its leaves the binary leaves' primitives, and the closest
 * hit follows rs_hit_better whatever order the lanes are visited in (see accel/bvh4.h).  The
 * order is still fixed (lanes by entry distance, ties by lane number), so a walk is
 * deterministic too. */

#include "accel/wide.h"

#if !defined(RS_WIDE_W) || !defined(RS_WIDE_SHIFT) || !defined(RS_WIDE_TREE) ||                    \
    !defined(RS_WIDE_NODE) || !defined(RS_WIDE_STACK) || !defined(RS_WIDE_FN) ||                   \
    !defined(RS_WIDE_RAY) || !defined(RS_WIDE_TN)
#  error "accel/wide_walk.h: define the width's parameters first"
#endif

#ifndef RS_WIDE_ENTRY
#  define RS_WIDE_ENTRY static inline
#endif

/* The stack entry for lane `lane` of node `n`, number `node`. */
#define RS_WIDE_REF(n, node, lane)                                                                 \
  ((n)->count[lane] ? RS_WIDE_LEAF | (node) << RS_WIDE_SHIFT | (lane) : (n)->child[lane])

#ifdef RS_WIDE_TRI_HIT
/* A packed leaf (`count` has RS_WIDE_PACKED) for closest hit: each block's hits taken as
 * rs_bvh_leaf_closest takes them (rs_hit_better; the ray cut just past the best). */
RS_HD_HOT void RS_WIDE_FN(packed_closest)(const RS_WIDE_TREE *b, uint32_t first, uint32_t count,
                                          const RS_WIDE_RAY *r, rs_ray *ray, rs_hit *hit)
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
RS_HD_HOT int RS_WIDE_FN(packed_occluded)(const RS_WIDE_TREE *b, uint32_t first, uint32_t count,
                                          const RS_WIDE_RAY *r, const rs_ray *ray)
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
                                      : RS_WIDE_TRI_HIT(&RS_WIDE_TRIS(b)[first + i], r, ray->tmin,
                                                        ray->tmax, t, u, v);
        if (m)
            return 1;
    }
    return 0;
}
#endif

/* The walks below serve both levels of an instanced scene: the top tree from its root (node 0,
 * `in` NULL), and an instance's bottom level from its wide root (b->inst_root, `in` the instance)
 * with the ray in the instance's object space for the box tests (rs_instance_ray), each box
 * widened by the instance's margin, and the leaves' triangles as the instance places them, tested
 * in world space: the binary bottom walk's tests (rs_blas_node_hit, rs_instance_tri_hit in
 * accel/bvh_traverse.h), so the hits are its own.  Forced inline into their callers, where `in`
 * is a constant, so the top walk pays nothing for the bottom's case. */

/* Instance i's bottom level, out of line (as the binary walk keeps rs_instance_closest): below. */
RS_HD_COLD void RS_WIDE_FN(instance_closest)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t i,
                                             rs_ray *ray, rs_hit *hit);
RS_HD_COLD int RS_WIDE_FN(instance_occluded)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t i,
                                             const rs_ray *ray);

/* One primitive of a leaf for closest hit: the top tree's through rs_bvh_leaf_closest, or for an
 * instance its bottom level; a bottom level's triangle as `in` places it. */
RS_HD_HOT void RS_WIDE_FN(leaf_closest)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t id,
                                        rs_ray *ray, rs_hit *hit, const rs_instance *in)
{
    if (in) {
        float t, u, v;
        uint32_t prim;
        if (rs_instance_tri_hit(g, in, g->blas_prim_ids[id], ray, &t, &u, &v, &prim) &&
            rs_hit_better(t, prim, hit)) {
            ray->tmax = rs_float_next_up(t);
            hit->t = t;
            hit->u = u;
            hit->v = v;
            hit->prim = prim;
        }
        return;
    }
    id = b->prim_ids[id];
    if (g->n_instances && id >= rs_geom_own_count(g) && b->inst_root)
        RS_WIDE_FN(instance_closest)(b, g, id - rs_geom_own_count(g), ray, hit);
    else
        rs_bvh_leaf_closest(g, id, ray, hit);
}

RS_HD_HOT int RS_WIDE_FN(leaf_occluded)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t id,
                                        const rs_ray *ray, const rs_instance *in)
{
    if (in) {
        float t, u, v;
        uint32_t prim;
        return rs_instance_tri_hit(g, in, g->blas_prim_ids[id], ray, &t, &u, &v, &prim);
    }
    id = b->prim_ids[id];
    if (g->n_instances && id >= rs_geom_own_count(g) && b->inst_root)
        return RS_WIDE_FN(instance_occluded)(b, g, id - rs_geom_own_count(g), ray);
    return rs_bvh_leaf_occluded(g, id, ray);
}

/* The closest hit under root `root`, if closer than *hit (rs_hit_better); the ray cut just past
 * each hit.  Ordered: the nearest lane hit is visited next and the others pushed far to near with
 * their entry distances (one lane: no sort; two: one compare; more: insertion sort); a popped entry
 * that starts beyond the closest hit so far is dropped without touching its node. */
RS_HD_HOT void RS_WIDE_FN(walk_closest)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t root,
                                        const RS_WIDE_RAY *r, rs_ray *ray, rs_hit *hit,
                                        const rs_instance *in)
{
    uint32_t stack[RS_WIDE_STACK];
    float stack_t[RS_WIDE_STACK];
    uint32_t sp = 0, ref = root;
    for (;;) {
        if (!(ref & RS_WIDE_LEAF)) {
            const RS_WIDE_NODE *n = &b->nodes[ref];
            RS_WIDE_TN tnv;
            uint32_t mask = RS_WIDE_FN(lanes)(n, r, in != NULL, ray->tmin, ray->tmax, &tnv);
#ifdef RS_WIDE_PREFETCH
            {
                /* every lane hit asked for now, while the lanes are ordered and pushed */
                uint32_t m = mask;
                while (m) {
                    RS_WIDE_PREFETCH(b, n, (uint32_t)__builtin_ctz(m));
                    m &= m - 1;
                }
            }
#endif
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
            if (count & RS_WIDE_PACKED) { /* never in a bottom level */
                RS_WIDE_FN(packed_closest)(b, first, count, r, ray, hit);
                count = 0;
            }
#endif
            for (i = 0; i < count; ++i)
                RS_WIDE_FN(leaf_closest)(b, g, first + i, ray, hit, in);
        }
        /* pop the next entry that can still hold a hit no farther than the best so far */
        for (;;) {
            if (sp == 0)
                return;
            --sp;
            if (stack_t[sp] <= ray->tmax * RS_BVH_SLACK)
                break;
        }
        ref = stack[sp];
    }
}

/* Whether a leaf (its first entry and count as a node lane holds them) blocks the ray. */
RS_HD_HOT int RS_WIDE_FN(leaf_run_occluded)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t first,
                                            uint32_t count, const RS_WIDE_RAY *r,
                                            const rs_ray *ray, const rs_instance *in)
{
    uint32_t i;
#ifdef RS_WIDE_TRI_HIT
    if (count & RS_WIDE_PACKED)
        return RS_WIDE_FN(packed_occluded)(b, first, count, r, ray);
#else
    (void)r;
#endif
    for (i = 0; i < count; ++i)
        if (RS_WIDE_FN(leaf_occluded)(b, g, first + i, ray, in))
            return 1;
    return 0;
}

/* Whether anything under root `root` blocks the ray inside (tmin, tmax): the leaves among a
 * node's lanes hit tested at once, the other lanes pushed, none sorted. */
RS_HD_HOT int RS_WIDE_FN(walk_occluded)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t root,
                                        const RS_WIDE_RAY *r, const rs_ray *ray,
                                        const rs_instance *in)
{
    uint32_t stack[RS_WIDE_STACK];
    uint32_t sp = 0;
    stack[sp++] = root;
    while (sp > 0) {
        uint32_t ref = stack[--sp];
        if (!(ref & RS_WIDE_LEAF)) {
            const RS_WIDE_NODE *n = &b->nodes[ref];
            RS_WIDE_TN tnv;
            uint32_t mask = RS_WIDE_FN(lanes)(n, r, in != NULL, ray->tmin, ray->tmax, &tnv);
            /* the leaves hit first, now: a shadow ray is blocked in a leaf, and a node pushed
             * may never need its visit (docs/traversal.md, "Leaves first for any hit") */
            uint32_t leaves = n->leaf_mask & mask, l;
            mask &= ~leaves;
            while (leaves) {
                l = (uint32_t)__builtin_ctz(leaves);
                leaves &= leaves - 1;
                if (RS_WIDE_FN(leaf_run_occluded)(b, g, n->child[l], n->count[l], r, ray, in))
                    return 1;
            }
            while (mask) {
                l = (uint32_t)__builtin_ctz(mask);
                mask &= mask - 1;
                RS_ASSERT(sp < RS_WIDE_STACK);
                stack[sp++] = RS_WIDE_REF(n, ref, l);
            }
        } else {
            /* a leaf entry as the root */
            const RS_WIDE_NODE *n = &b->nodes[(ref & ~RS_WIDE_LEAF) >> RS_WIDE_SHIFT];
            uint32_t lane = ref & (RS_WIDE_W - 1u);
            if (RS_WIDE_FN(leaf_run_occluded)(b, g, n->child[lane], n->count[lane], r, ray, in))
                return 1;
        }
    }
    return 0;
}

/* Instance i's bottom level: the walks above from b->inst_root[i], the ray in its object space. */
RS_HD_COLD void RS_WIDE_FN(instance_closest)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t i,
                                             rs_ray *ray, rs_hit *hit)
{
    const rs_instance *in = &g->instances[i];
    RS_WIDE_RAY r;
    rs_vec3 o, d;
    rs_instance_ray(in, ray, &o, &d);
    RS_WIDE_FN(ray_init)(&r, o, d);
    RS_WIDE_FN(ray_widen)(&r, in->margin);
    RS_WIDE_FN(walk_closest)(b, g, b->inst_root[i], &r, ray, hit, in);
}

RS_HD_COLD int RS_WIDE_FN(instance_occluded)(const RS_WIDE_TREE *b, const rs_geom *g, uint32_t i,
                                             const rs_ray *ray)
{
    const rs_instance *in = &g->instances[i];
    RS_WIDE_RAY r;
    rs_vec3 o, d;
    rs_instance_ray(in, ray, &o, &d);
    RS_WIDE_FN(ray_init)(&r, o, d);
    RS_WIDE_FN(ray_widen)(&r, in->margin);
    return RS_WIDE_FN(walk_occluded)(b, g, b->inst_root[i], &r, ray, in);
}

/* Closest hit, as rs_bvh_closest: 1 and *hit on a hit, else hit->prim = RS_NO_HIT and 0. */
RS_WIDE_ENTRY int RS_WIDE_FN(closest)(const RS_WIDE_TREE *b, const rs_geom *g, rs_ray ray,
                                      rs_hit *hit)
{
    RS_WIDE_RAY r;
    hit->prim = RS_NO_HIT;
    hit->t = ray.tmax;
    hit->u = hit->v = 0.0f;
    if (b->n_nodes == 0)
        return 0;
    RS_WIDE_FN(ray_init)(&r, ray.o, ray.d);
    RS_WIDE_FN(walk_closest)(b, g, 0, &r, &ray, hit, NULL);
    return hit->prim != RS_NO_HIT;
}

/* Any hit inside (tmin, tmax), as rs_bvh_occluded. */
RS_WIDE_ENTRY int RS_WIDE_FN(occluded)(const RS_WIDE_TREE *b, const rs_geom *g, rs_ray ray)
{
    RS_WIDE_RAY r;
    if (b->n_nodes == 0)
        return 0;
    RS_WIDE_FN(ray_init)(&r, ray.o, ray.d);
    return RS_WIDE_FN(walk_occluded)(b, g, 0, &r, &ray, NULL);
}

#undef RS_WIDE_REF
#undef RS_WIDE_PREFETCH
#undef RS_WIDE_ENTRY
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
