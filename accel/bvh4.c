/* accel/bvh4.c — the 4-wide tree's node layout for the collapse in accel/wide.c (see
 * accel/bvh4.h). */
#include "accel/bvh4.h"

#include <stddef.h>

#include "accel/internal.h"
#include "core/alloc.h"

/* An unused lane keeps the zero box: lanes from n_lanes on are masked off by the traversal. */
static void set_box(void *node, uint32_t i, const rs_bvh_node *l)
{
    rs_bvh4_node *d = (rs_bvh4_node *)node;
    if (!l)
        return;
    d->lo[0][i] = l->lo.x;
    d->lo[1][i] = l->lo.y;
    d->lo[2][i] = l->lo.z;
    d->hi[0][i] = l->hi.x;
    d->hi[1][i] = l->hi.y;
    d->hi[2][i] = l->hi.z;
}

static const rs_wide_layout layout = {
    "4-wide BVH", 4, RS_BVH4_MAX_NODES, sizeof(rs_bvh4_node), offsetof(rs_bvh4_node, child),
    offsetof(rs_bvh4_node, count), offsetof(rs_bvh4_node, n_lanes),
    offsetof(rs_bvh4_node, leaf_mask), sizeof(rs_bvh4_tri4),
    sizeof(rs_bvh4_quad4), set_box};

rs_status rs_bvh4_build(const rs_bvh *b, const rs_geom *g, rs_bvh4 **out)
{
    rs_wide_tree w;
    rs_bvh4 *t;
    rs_status st;
    *out = NULL;
    t = (rs_bvh4 *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the 4-wide BVH");
    st = rs_wide_build(b, g, &layout, &w);
    if (st != RS_OK) {
        rs_free(t);
        return st;
    }
    RS_ASSERT(w.sphere == NULL); /* spheres pack in the 8-wide tree only */
    t->nodes = (rs_bvh4_node *)w.nodes;
    t->tri4 = (rs_bvh4_tri4 *)w.tri;
    t->quad4 = (rs_bvh4_quad4 *)w.quad;
    t->prim_ids = b->prim_ids;
    t->inst_root = w.inst_root;
    t->n_nodes = w.n_nodes;
    t->n_tri4 = w.n_tri;
    t->n_quad4 = w.n_quad;
    t->depth = w.depth;
    t->n_packed = w.n_packed;
    *out = t;
    return RS_OK;
}

void rs_bvh4_destroy(rs_bvh4 *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->inst_root);
    rs_free(b->tri4);
    rs_free(b->quad4);
    rs_free(b);
}
