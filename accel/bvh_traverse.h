/* accel/bvh_traverse.h — what RS_HD code needs of the binary BVH: the flat node layout shared
 * by host and device, the view traversal reads (plain pointers and counts), the list of the
 * view's arrays that device copies are made from, and the closest-hit / any-hit traversal that
 * the CPU device, the CUDA kernels and the CUDA fallback all call.  Compiles as C11 and as CUDA
 * C++; nothing here allocates or fails.  The host builders and the rs_bvh that owns the arrays
 * are accel/bvh.h's.
 *
 * Node layout (32 bytes, two per 64-byte cache line):
 *   lo, hi       12 B each  bounds
 *   left_first   4 B        interior: index of the left child; the right child is left_first + 1
 *                           leaf:     index of the first entry in prim_ids
 *   count        4 B        0 for an interior node, else the number of primitives in the leaf
 * Node 0 is the root.  An empty scene has no nodes and every ray misses. */
#ifndef RS_ACCEL_BVH_TRAVERSE_H
#define RS_ACCEL_BVH_TRAVERSE_H

#include <stddef.h>

#include "core/geom.h"

/* rs_bvh_node itself is core/geom.h's (the geometry holds instances' bottom levels). */

/* What traversal needs: pointers (host or device) and counts.  Plain data, copied by value. */
typedef struct rs_bvh_view {
    const rs_bvh_node *nodes;
    const uint32_t *prim_ids;
    uint32_t n_nodes;
} rs_bvh_view;

/* Every array of rs_bvh that its view (rs_bvh_view, the same field names) holds, with its
 * element count (`b` a pointer to the rs_bvh, accel/bvh.h).  A device's copy of the BVH
 * (scheduler/device_copy.h) is made from this list: a new array of the view goes here. */
#define RS_BVH_ARRAYS(X, b)                                                                        \
  X(nodes, (size_t)(b)->n_nodes)                                                                   \
  X(prim_ids, (size_t)(b)->n_prims)

/* Deepest stack traversal uses.  Every builder keeps depth <= RS_BVH_MAX_DEPTH = 63 nodes
 * (accel/bvh.h): the closest-hit stack then holds at most depth - 1 entries and the any-hit stack
 * depth + 1. */
#define RS_BVH_STACK 64

/* Traversal counters (the thesis's "ray-object intersection tests" metric): compiled in only in
 * a translation unit that defines RS_COUNTERS before including this header or accel/bvh.h (a
 * benchmark's counting pass), as that unit's thread-local tallies.  Everywhere else RS_COUNT is
 * empty, so the traversal the devices run pays nothing. */
#if defined(RS_COUNTERS) /* host only: never defined in a .cu (_Thread_local is C11) */
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

/* After the box tests of an interior node's children l and r = l + 1 (hl, hr: hit; tl, tr: their
 * entry distances): go on to the nearer child hit (`node`, then `continue`), pushing the other
 * when both are; fall through when neither is.  Spelled with two branches for the one-child
 * cases: a select between l and r there (as an inline helper or a macro) made the binary walk
 * 10-15% slower on triangles (bench/traversal_bench, cornell-teapot, one thread). */
#define RS_BVH_DESCEND(l, r, hl, hr, tl, tr, stack, sp, node)                                   \
  if ((hl) && (hr)) {                                                                            \
    if ((tr) < (tl)) {                                                                           \
      uint32_t tmp_ = (l);                                                                       \
      (l) = (r);                                                                                 \
      (r) = tmp_;                                                                                \
    }                                                                                            \
    RS_ASSERT((sp) < RS_BVH_STACK);                                                              \
    (stack)[(sp)++] = (r);                                                                       \
    (node) = (l);                                                                                \
    continue;                                                                                    \
  }                                                                                              \
  if (hl) {                                                                                      \
    (node) = (l);                                                                                \
    continue;                                                                                    \
  }                                                                                              \
  if (hr) {                                                                                      \
    (node) = (r);                                                                                \
    continue;                                                                                    \
  }

/* Instances (core/geom.h).  A bottom level's box test: node n widened by `margin` on every side
 * (the slab test with the margin above as well). */
RS_HD int rs_blas_node_hit(const rs_bvh_node *n, float margin, rs_vec3 o, rs_vec3 inv_d,
                           float tmin, float tmax, float *t_entry)
{
    rs_aabb b;
    b.lo = rs_v3_sub(n->lo, rs_v3_splat(margin));
    b.hi = rs_v3_add(n->hi, rs_v3_splat(margin));
    return rs_bvh_slab(&b, o, inv_d, tmin, tmax, t_entry);
}

/* The world ray r in instance in's object space, for the box tests: the direction is not
 * normalised, so t means the same distance along both. */
RS_HD void rs_instance_ray(const rs_instance *in, const rs_ray *r, rs_vec3 *o, rs_vec3 *d)
{
    const double *m = in->inv;
    double x = r->o.x, y = r->o.y, z = r->o.z, a = r->d.x, b = r->d.y, c = r->d.z;
    *o = rs_v3((float)(m[0] * x + m[1] * y + m[2] * z + m[3]),
               (float)(m[4] * x + m[5] * y + m[6] * z + m[7]),
               (float)(m[8] * x + m[9] * y + m[10] * z + m[11]));
    *d = rs_v3((float)(m[0] * a + m[1] * b + m[2] * c), (float)(m[4] * a + m[5] * b + m[6] * c),
               (float)(m[8] * a + m[9] * b + m[10] * c));
}

/* Triangle t of the prototype (an index into inst_tris) as instance `in` places it, tested in
 * world space against `ray`; *prim is its global number. */
RS_HD int rs_instance_tri_hit(const rs_geom *g, const rs_instance *in, uint32_t t,
                              const rs_ray *ray, float *th, float *u, float *v, uint32_t *prim)
{
    rs_tri w = rs_instance_tri(in, &g->inst_tris[t]);
    *prim = in->prim_base + (t - in->first_tri);
    return rs_isect_tri_by(g->tri_algo, &w, ray, th, u, v);
}

/* The closest hit of `ray` among instance i's triangles, if closer than *hit (rs_hit_better):
 * the bottom level's walk, nearer child first, the ray cut just past each hit. */
RS_HD_COLD void rs_instance_closest(const rs_geom *g, uint32_t i, rs_ray *ray, rs_hit *hit)
{
    const rs_instance *in = &g->instances[i];
    uint32_t stack[RS_BVH_STACK];
    uint32_t sp = 0, node = in->root;
    rs_vec3 o, d, inv_d;
    float te, margin = in->margin;
    RS_ASSERT(g->blas_nodes); /* rs_bvh_attach */
    rs_instance_ray(in, ray, &o, &d);
    inv_d = rs_bvh_inv_dir(d);
    if (!rs_blas_node_hit(&g->blas_nodes[node], margin, o, inv_d, ray->tmin, ray->tmax, &te))
        return;
    for (;;) {
        const rs_bvh_node *n = &g->blas_nodes[node];
        if (n->count > 0) {
            uint32_t k;
            RS_COUNT(prim_tests, n->count);
            for (k = 0; k < n->count; ++k) {
                float t, u, v;
                uint32_t prim;
                if (rs_instance_tri_hit(g, in, g->blas_prim_ids[n->left_first + k], ray, &t, &u,
                                        &v, &prim) &&
                    rs_hit_better(t, prim, hit)) {
                    ray->tmax = rs_float_next_up(t);
                    hit->t = t;
                    hit->u = u;
                    hit->v = v;
                    hit->prim = prim;
                }
            }
        } else {
            uint32_t l = n->left_first, r = l + 1;
            float tl = 0.0f, tr = 0.0f;
            int hl = rs_blas_node_hit(&g->blas_nodes[l], margin, o, inv_d, ray->tmin, ray->tmax, &tl);
            int hr = rs_blas_node_hit(&g->blas_nodes[r], margin, o, inv_d, ray->tmin, ray->tmax, &tr);
            RS_COUNT(box_tests, 2);
            RS_BVH_DESCEND(l, r, hl, hr, tl, tr, stack, sp, node)
        }
        for (;;) {
            if (sp == 0)
                return;
            node = stack[--sp];
            if (rs_blas_node_hit(&g->blas_nodes[node], margin, o, inv_d, ray->tmin, ray->tmax, &te))
                break;
        }
    }
}

/* Whether any of instance i's triangles blocks `ray` inside (tmin, tmax). */
RS_HD_COLD int rs_instance_occluded(const rs_geom *g, uint32_t i, const rs_ray *ray)
{
    const rs_instance *in = &g->instances[i];
    uint32_t stack[RS_BVH_STACK];
    uint32_t sp = 0;
    rs_vec3 o, d, inv_d;
    float te;
    RS_ASSERT(g->blas_nodes);
    rs_instance_ray(in, ray, &o, &d);
    inv_d = rs_bvh_inv_dir(d);
    stack[sp++] = in->root;
    while (sp > 0) {
        const rs_bvh_node *n = &g->blas_nodes[stack[--sp]];
        if (!rs_blas_node_hit(n, in->margin, o, inv_d, ray->tmin, ray->tmax, &te))
            continue;
        if (n->count > 0) {
            uint32_t k;
            for (k = 0; k < n->count; ++k) {
                float t, u, v;
                uint32_t prim;
                if (rs_instance_tri_hit(g, in, g->blas_prim_ids[n->left_first + k], ray, &t, &u,
                                        &v, &prim))
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

/* One primitive of a leaf for closest hit: where it is hit no farther than the best so far (ties
 * to the lower primitive, rs_hit_better), it becomes the best and the ray is cut just past it.
 * An instance's triangles go through its bottom level.  The binary and the wide traversals
 * (accel/bvh4.h, accel/bvh8.h) all take their leaves' unpacked primitives here. */
RS_HD_HOT void rs_bvh_leaf_closest_k(const rs_geom *g, uint32_t prim, rs_ray *ray, rs_hit *hit,
                                     int inst)
{
    float t, u, v;
    if (inst && g->n_instances && prim >= rs_geom_own_count(g)) {
        rs_instance_closest(g, prim - rs_geom_own_count(g), ray, hit);
        return;
    }
    if (rs_geom_intersect(g, prim, ray, &t, &u, &v) && rs_hit_better(t, prim, hit)) {
        ray->tmax = rs_float_next_up(t);
        hit->t = t;
        hit->u = u;
        hit->v = v;
        hit->prim = prim;
    }
}

RS_HD void rs_bvh_leaf_closest(const rs_geom *g, uint32_t prim, rs_ray *ray, rs_hit *hit)
{
    rs_bvh_leaf_closest_k(g, prim, ray, hit, 1);
}

/* One primitive of a leaf for the any-hit query (instances through their bottom levels). */
RS_HD_HOT int rs_bvh_leaf_occluded_k(const rs_geom *g, uint32_t prim, const rs_ray *ray, int inst)
{
    float t, u, v;
    if (inst && g->n_instances && prim >= rs_geom_own_count(g))
        return rs_instance_occluded(g, prim - rs_geom_own_count(g), ray);
    return rs_geom_intersect(g, prim, ray, &t, &u, &v);
}

RS_HD int rs_bvh_leaf_occluded(const rs_geom *g, uint32_t prim, const rs_ray *ray)
{
    return rs_bvh_leaf_occluded_k(g, prim, ray, 1);
}

/* The traversals below take `inst`, a constant where they are inlined: 0 leaves the instances'
 * bottom levels out of the code (for geometry without instances, g->n_instances == 0, and only
 * there).  On a GPU their call (a frame, and the outer walk's state kept across it) more than
 * doubles the registers the trace kernels take: 113 and 80 against 59 and 62 on sm_90. */

/* Closest hit along `ray` (ordered, stack-based traversal: the nearer child first, the other
 * pushed).  Returns 1 and fills *hit on a hit; on a miss sets hit->prim = RS_NO_HIT, returns 0.
 * Ties go to the lowest primitive number (rs_hit_better). */
RS_HD_HOT int rs_bvh_closest_k(const rs_bvh_view *b, const rs_geom *g, rs_ray ray, rs_hit *hit,
                               int inst)
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
            for (i = 0; i < n->count; ++i)
                rs_bvh_leaf_closest_k(g, b->prim_ids[n->left_first + i], &ray, hit, inst);
        } else {
            uint32_t l = n->left_first, r = l + 1;
            float tl = 0.0f, tr = 0.0f;
            int hl;
            RS_COUNT(box_tests, 2);
            hl = rs_bvh_node_hit(&b->nodes[l], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &tl);
            int hr =
                rs_bvh_node_hit(&b->nodes[r], g->aabb_algo, ray.o, inv_d, ray.tmin, ray.tmax, &tr);
            RS_BVH_DESCEND(l, r, hl, hr, tl, tr, stack, sp, node)
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

RS_HD int rs_bvh_closest(const rs_bvh_view *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    return rs_bvh_closest_k(b, g, ray, hit, 1);
}

/* Any hit inside (tmin, tmax): the shadow-ray query.  Returns 1 if something blocks the ray. */
RS_HD_HOT int rs_bvh_occluded_k(const rs_bvh_view *b, const rs_geom *g, rs_ray ray, int inst)
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
                RS_COUNT(prim_tests, 1);
                if (rs_bvh_leaf_occluded_k(g, b->prim_ids[n->left_first + i], &ray, inst))
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

RS_HD int rs_bvh_occluded(const rs_bvh_view *b, const rs_geom *g, rs_ray ray)
{
    return rs_bvh_occluded_k(b, g, ray, 1);
}

#endif
