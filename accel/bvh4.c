/* accel/bvh4.c — collapsing a binary BVH into the 4-wide one (see accel/bvh4.h). */
#include "accel/bvh4.h"

#include <string.h>

#include "core/alloc.h"

static float half_area(const rs_bvh_node *n)
{
    rs_vec3 e = rs_v3_sub(n->hi, n->lo);
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

typedef struct collapse {
    const rs_bvh *bin;
    const rs_geom *g;
    rs_bvh4 *out;
    uint32_t cap, cap_tri4;
    int pack; /* pack leaves of triangles (SSE build, Möller-Trumbore) */
} collapse;

/* Whether binary leaf `n` is packed: every primitive a triangle. */
static int packable(const collapse *c, const rs_bvh_node *n)
{
    uint32_t i, first_tri = c->g->n_spheres + c->g->n_quads;
    if (!c->pack)
        return 0;
    for (i = 0; i < n->count; ++i)
        if (c->bin->prim_ids[n->left_first + i] < first_tri)
            return 0;
    return 1;
}

/* Copies binary leaf `n`'s triangles into tri4 blocks; returns the first block's index. */
static uint32_t pack_leaf(collapse *c, const rs_bvh_node *n)
{
    uint32_t first = c->out->n_tri4, i, a;
    uint32_t first_tri = c->g->n_spheres + c->g->n_quads;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = c->bin->prim_ids[n->left_first + i];
        const rs_tri *t = &c->g->tris[prim - first_tri];
        rs_bvh4_tri4 *blk = &c->out->tri4[first + i / 4];
        uint32_t l = i % 4;
        rs_vec3 e1 = rs_v3_sub(t->v1, t->v0), e2 = rs_v3_sub(t->v2, t->v0);
        float v0v[3] = {t->v0.x, t->v0.y, t->v0.z}, e1v[3] = {e1.x, e1.y, e1.z};
        float e2v[3] = {e2.x, e2.y, e2.z};
        if (l == 0) {
            memset(blk, 0, sizeof *blk);
            blk->prim[0] = blk->prim[1] = blk->prim[2] = blk->prim[3] = RS_NO_HIT;
        }
        for (a = 0; a < 3; ++a) {
            blk->v0[a][l] = v0v[a];
            blk->e1[a][l] = e1v[a];
            blk->e2[a][l] = e2v[a];
        }
        blk->prim[l] = prim;
    }
    c->out->n_tri4 += (n->count + 3) / 4;
    RS_ASSERT(c->out->n_tri4 <= c->cap_tri4);
    return first;
}

/* Fills 4-wide node `dst` from binary interior node `src` (or, for a tree that is one leaf, from
 * that leaf alone) and recurses into its interior lanes.  Returns the depth below, in nodes. */
static uint32_t collapse_node(collapse *c, uint32_t src, uint32_t dst)
{
    const rs_bvh_node *bn = c->bin->nodes;
    uint32_t lanes[4], n = 0, i, depth = 0;
    if (bn[src].count > 0) {
        lanes[n++] = src;
    } else {
        lanes[n++] = bn[src].left_first;
        lanes[n++] = bn[src].left_first + 1;
    }
    /* open the interior lane of largest surface area until there are four (the first on ties) */
    while (n < 4) {
        int best = -1;
        float best_area = -1.0f;
        for (i = 0; i < n; ++i)
            if (bn[lanes[i]].count == 0 && half_area(&bn[lanes[i]]) > best_area) {
                best = (int)i;
                best_area = half_area(&bn[lanes[i]]);
            }
        if (best < 0)
            break;
        lanes[n++] = bn[lanes[best]].left_first + 1;
        lanes[best] = bn[lanes[best]].left_first;
    }
    {
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
            d->count[i] = (uint16_t)l->count;
            d->child[i] = l->left_first; /* a leaf's first entry; interior lanes below */
            if (l->count > 0 && packable(c, l)) {
                d->child[i] = pack_leaf(c, l);
                d->count[i] = (uint16_t)(RS_BVH4_PACKED | (l->count + 3) / 4);
                c->out->n_packed++;
            }
        }
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
    uint32_t i, interior = 0;
    *out = NULL;
    memset(&c, 0, sizeof c);
    c.bin = b;
    c.g = g;
#ifdef RS_BVH4_SSE
    c.pack = g->tri_algo == RS_ISECT_TRI_MOLLER;
#endif
    for (i = 0; i < b->n_nodes; ++i) {
        if (b->nodes[i].count > 0x7fffu)
            return rs_error_set(RS_ERR_ARG,
                                "4-wide BVH: a leaf of %u primitives (at most 32767 fit a lane)",
                                b->nodes[i].count);
        interior += b->nodes[i].count == 0;
        if (b->nodes[i].count > 0 && packable(&c, &b->nodes[i]))
            c.cap_tri4 += (b->nodes[i].count + 3) / 4;
    }
    if (interior + 1 > RS_BVH4_MAX_NODES)
        return rs_error_set(RS_ERR_ARG, "4-wide BVH: %u nodes are more than the 2^29 it can index",
                            interior + 1);
    t = (rs_bvh4 *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the 4-wide BVH");
    t->prim_ids = b->prim_ids;
    if (b->n_nodes > 0) {
        /* at most one 4-wide node per binary interior node (one for a single-leaf tree) */
        c.cap = interior > 0 ? interior : 1;
        t->nodes = (rs_bvh4_node *)rs_alloc_aligned(c.cap, sizeof *t->nodes);
        if (c.cap_tri4 > 0)
            t->tri4 = (rs_bvh4_tri4 *)rs_alloc_aligned(c.cap_tri4, sizeof *t->tri4);
        if (!t->nodes || (c.cap_tri4 > 0 && !t->tri4)) {
            rs_bvh4_destroy(t);
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the 4-wide BVH (%u nodes)", c.cap);
        }
        c.out = t;
        t->n_nodes = 1;
        t->depth = collapse_node(&c, 0, 0);
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
    rs_free(b);
}
