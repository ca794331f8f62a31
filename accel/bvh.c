/* accel/bvh.c — the host BVH builder: median split on the axis of largest centroid extent.
 *
 * Invariants of the finished tree:
 *   - node 0 is the root; children of an interior node are adjacent (left, left + 1);
 *   - every primitive appears exactly once in prim_ids, and each leaf's range lies inside it;
 *   - each node's bounds contain the bounds of everything below it.
 * The split halves the primitive range with a quickselect on centroids (an nth_element), so the
 * depth is at most ceil(log2(n)) + 1 and the build is O(n log n). */
#include "accel/bvh.h"

#include "core/alloc.h"

typedef struct build_ctx {
    const rs_aabb *bounds;   /* per primitive */
    const rs_vec3 *centroid; /* per primitive */
    uint32_t *ids;
    rs_bvh_node *nodes;
    uint32_t n_nodes;
    uint32_t max_leaf;
    uint32_t depth;
} build_ctx;

rs_aabb rs_geom_prim_bounds(const rs_geom *g, uint32_t prim)
{
    rs_aabb b;
    if (prim < g->n_spheres) {
        const rs_sphere *s = &g->spheres[prim];
        rs_vec3 r = rs_v3_splat(fabsf(s->radius));
        rs_vec3 c0 = rs_geom_sphere_center(g, prim, g->time0);
        rs_vec3 c1 = rs_geom_sphere_center(g, prim, g->time1);
        /* a moving sphere's centre runs along a segment: bound both ends */
        b.lo = rs_v3_sub(rs_v3_min(c0, c1), r);
        b.hi = rs_v3_add(rs_v3_max(c0, c1), r);
        (void)s;
        return b;
    }
    prim -= g->n_spheres;
    if (prim < g->n_quads) {
        const rs_quad *q = &g->quads[prim];
        rs_vec3 p1 = rs_v3_add(q->q, q->u), p2 = rs_v3_add(q->q, q->v);
        rs_vec3 p3 = rs_v3_add(p1, q->v);
        b.lo = rs_v3_min(rs_v3_min(q->q, p1), rs_v3_min(p2, p3));
        b.hi = rs_v3_max(rs_v3_max(q->q, p1), rs_v3_max(p2, p3));
        return b;
    }
    prim -= g->n_quads;
    {
        const rs_tri *t = &g->tris[prim];
        b.lo = rs_v3_min(t->v0, rs_v3_min(t->v1, t->v2));
        b.hi = rs_v3_max(t->v0, rs_v3_max(t->v1, t->v2));
    }
    return b;
}

static float centroid_on(const build_ctx *c, uint32_t id, int axis)
{
    return rs_v3_get(c->centroid[id], axis);
}

/* Quickselect with a three-way partition: reorders ids[lo, hi) so that ids[k] holds the element
 * of rank k by centroid on `axis`, nothing larger before it and nothing smaller after it.
 * Elements that compare neither less nor greater (equal, or NaN) stay in the middle block, so
 * every round shrinks the range and the loop ends. */
static void select_kth(const build_ctx *c, uint32_t *ids, uint32_t lo, uint32_t hi, uint32_t k,
                       int axis)
{
    while (hi - lo > 1) {
        float pivot = centroid_on(c, ids[lo + (hi - lo) / 2], axis);
        uint32_t lt = lo, i = lo, gt = hi, t;
        while (i < gt) {
            float x = centroid_on(c, ids[i], axis);
            if (x < pivot) {
                t = ids[lt];
                ids[lt++] = ids[i];
                ids[i++] = t;
            } else if (x > pivot) {
                t = ids[--gt];
                ids[gt] = ids[i];
                ids[i] = t;
            } else {
                ++i;
            }
        }
        if (k < lt)
            hi = lt;
        else if (k >= gt)
            lo = gt;
        else
            return;
    }
}

static void build_node(build_ctx *c, uint32_t node, uint32_t first, uint32_t count, uint32_t depth)
{
    rs_bvh_node *n = &c->nodes[node];
    rs_aabb b = c->bounds[c->ids[first]];
    rs_vec3 clo = c->centroid[c->ids[first]], chi = clo, ext;
    uint32_t i;
    int axis;
    if (depth > c->depth)
        c->depth = depth;
    for (i = first + 1; i < first + count; ++i) {
        uint32_t id = c->ids[i];
        b.lo = rs_v3_min(b.lo, c->bounds[id].lo);
        b.hi = rs_v3_max(b.hi, c->bounds[id].hi);
        clo = rs_v3_min(clo, c->centroid[id]);
        chi = rs_v3_max(chi, c->centroid[id]);
    }
    n->lo = b.lo;
    n->hi = b.hi;
    if (count <= c->max_leaf) {
        n->left_first = first;
        n->count = count;
        return;
    }
    ext = rs_v3_sub(chi, clo);
    axis = (ext.x >= ext.y && ext.x >= ext.z) ? 0 : (ext.y >= ext.z ? 1 : 2);
    {
        uint32_t half = count / 2, left = c->n_nodes;
        select_kth(c, c->ids, first, first + count, first + half, axis);
        c->n_nodes += 2;
        n->left_first = left;
        n->count = 0;
        build_node(c, left, first, half, depth + 1);
        build_node(c, left + 1, first + half, count - half, depth + 1);
    }
}

rs_status rs_bvh_build(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out)
{
    uint32_t n = rs_geom_prim_count(g), i;
    build_ctx c = {0};
    rs_bvh *b = (rs_bvh *)rs_calloc(1, sizeof *b);
    rs_aabb *bounds = NULL;
    rs_vec3 *centroid = NULL;
    *out = NULL;
    if (!b)
        return rs_error_set(RS_ERR_NOMEM, "out of memory building the BVH");
    b->n_prims = n;
    if (n == 0) {
        *out = b;
        return RS_OK;
    }
    bounds = (rs_aabb *)rs_alloc(n, sizeof *bounds);
    centroid = (rs_vec3 *)rs_alloc(n, sizeof *centroid);
    b->prim_ids = (uint32_t *)rs_alloc(n, sizeof *b->prim_ids);
    /* a binary tree with n leaves of >= 1 primitive has at most 2n - 1 nodes */
    b->nodes = (rs_bvh_node *)rs_alloc(2 * (size_t)n, sizeof *b->nodes);
    if (!bounds || !centroid || !b->prim_ids || !b->nodes) {
        rs_free(bounds);
        rs_free(centroid);
        rs_bvh_destroy(b);
        return rs_error_set(RS_ERR_NOMEM, "out of memory building the BVH over %u primitives", n);
    }
    for (i = 0; i < n; ++i) {
        bounds[i] = rs_geom_prim_bounds(g, i);
        centroid[i] = rs_v3_scale(rs_v3_add(bounds[i].lo, bounds[i].hi), 0.5f);
        b->prim_ids[i] = i;
    }
    c.bounds = bounds;
    c.centroid = centroid;
    c.ids = b->prim_ids;
    c.nodes = b->nodes;
    c.n_nodes = 1;
    c.max_leaf = (opts && opts->max_leaf > 0) ? opts->max_leaf : 4;
    build_node(&c, 0, 0, n, 1);
    b->n_nodes = c.n_nodes;
    b->depth = c.depth;
    rs_free(bounds);
    rs_free(centroid);
    *out = b;
    return RS_OK;
}

void rs_bvh_destroy(rs_bvh *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->prim_ids);
    rs_free(b);
}

rs_bvh_view rs_bvh_view_of(const rs_bvh *b)
{
    rs_bvh_view v;
    v.nodes = b->nodes;
    v.prim_ids = b->prim_ids;
    v.n_nodes = b->n_nodes;
    return v;
}
