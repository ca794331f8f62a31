/* accel/bvh4.c — collapsing a binary BVH into the 4-wide one (see accel/bvh4.h). */
#include "accel/bvh4.h"

#include <string.h>

#include "accel/internal.h"
#include "core/alloc.h"

typedef struct collapse {
    const rs_bvh *bin;
    rs_bvh4 *out;
    rs_leaf_packer pk;
    uint32_t cap;
} collapse;

/* Fills 4-wide node `dst` from binary interior node `src` (or, for a tree that is one leaf, from
 * that leaf alone) and recurses into its interior lanes.  Returns the depth below, in nodes. */
static uint32_t collapse_node(collapse *c, uint32_t src, uint32_t dst)
{
    const rs_bvh_node *bn = c->bin->nodes;
    uint32_t lanes[4], n = rs_bvh_wide_lanes(bn, src, 4, lanes), i, depth = 0;
    rs_bvh4_node *d = &c->out->nodes[dst];
    memset(d, 0, sizeof *d);
    d->n_lanes = n;
    for (i = 0; i < n; ++i) {
        const rs_bvh_node *l = &bn[lanes[i]];
        d->lo[0][i] = l->lo.x;
        d->lo[1][i] = l->lo.y;
        d->lo[2][i] = l->lo.z;
        d->hi[0][i] = l->hi.x;
        d->hi[1][i] = l->hi.y;
        d->hi[2][i] = l->hi.z;
        d->count[i] = 0;
        d->child[i] = 0; /* interior lanes: set below */
        if (l->count > 0)
            c->out->n_packed += (uint32_t)rs_leaf_lane(&c->pk, l, &d->child[i], &d->count[i]);
    }
    for (i = 0; i < n; ++i) {
        if (bn[lanes[i]].count == 0) {
            uint32_t child = c->out->n_nodes++, below;
            RS_ASSERT(child < c->cap);
            c->out->nodes[dst].child[i] = child;
            below = collapse_node(c, lanes[i], child);
            if (below > depth)
                depth = below;
        }
    }
    return depth + 1;
}

rs_status rs_bvh4_build(const rs_bvh *b, const rs_geom *g, rs_bvh4 **out)
{
    rs_bvh4 *t;
    collapse c;
    rs_status st;
    *out = NULL;
    memset(&c, 0, sizeof c);
    c.bin = b;
    rs_leaf_packer_init(&c.pk, b, g, 4);
    st = rs_bvh_wide_plan(b, &c.pk, "4-wide BVH", RS_BVH4_MAX_NODES, &c.cap);
    if (st != RS_OK)
        return st;
    t = (rs_bvh4 *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the 4-wide BVH");
    t->prim_ids = b->prim_ids;
    if (c.cap > 0) {
        t->nodes = (rs_bvh4_node *)rs_alloc_aligned(c.cap, sizeof *t->nodes);
        if (c.pk.cap_tri > 0)
            t->tri4 = (rs_bvh4_tri4 *)rs_alloc_aligned(c.pk.cap_tri, sizeof *t->tri4);
        if (c.pk.cap_quad > 0)
            t->quad4 = (rs_bvh4_quad4 *)rs_alloc_aligned(c.pk.cap_quad, sizeof *t->quad4);
        if (!t->nodes || (c.pk.cap_tri > 0 && !t->tri4) || (c.pk.cap_quad > 0 && !t->quad4)) {
            rs_bvh4_destroy(t);
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the 4-wide BVH (%u nodes)", c.cap);
        }
        c.out = t;
        c.pk.tri = t->tri4;
        c.pk.quad = t->quad4;
        t->n_nodes = 1;
        t->depth = collapse_node(&c, 0, 0);
        t->n_tri4 = c.pk.n_tri;
        t->n_quad4 = c.pk.n_quad;
    }
    *out = t;
    return RS_OK;
}

void rs_bvh4_destroy(rs_bvh4 *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->tri4);
    rs_free(b->quad4);
    rs_free(b);
}
