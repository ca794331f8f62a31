/* accel/wide.c — what collapsing a binary BVH into a wide one takes, whatever the width: the
 * choice of each wide node's lanes, the size checks, and packing leaves of triangles into tri4
 * blocks and leaves of parallelograms into quad4 blocks (accel/bvh4.h, accel/bvh8.h; declared in
 * accel/internal.h). */
#include <string.h>

#include "accel/internal.h"

static float half_area(const rs_bvh_node *n)
{
    rs_vec3 e = rs_v3_sub(n->hi, n->lo);
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

uint32_t rs_bvh_wide_lanes(const rs_bvh_node *bn, uint32_t src, uint32_t width, uint32_t *lanes)
{
    uint32_t n = 0, i;
    if (bn[src].count > 0) {
        lanes[n++] = src;
        return n;
    }
    lanes[n++] = bn[src].left_first;
    lanes[n++] = bn[src].left_first + 1;
    /* open the interior lane of largest surface area until there are `width` (the first on ties) */
    while (n < width) {
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
    return n;
}

void rs_leaf_packer_init(rs_leaf_packer *p, const rs_bvh *b, const rs_geom *g)
{
    memset(p, 0, sizeof *p);
    p->g = g;
    p->prim_ids = b->prim_ids;
#ifdef RS_BVH4_SSE
    p->pack_tris = g->tri_algo == RS_ISECT_TRI_MOLLER;
    p->pack_quads = 1;
#endif
}

/* How binary leaf `n` is packed: RS_BVH4_PACKED for tri4 blocks, RS_BVH4_PACKED | RS_BVH4_QUADS
 * for quad4 blocks, 0 when it is not (a mix of kinds, spheres, or packing off). */
static uint32_t pack_kind(const rs_leaf_packer *p, const rs_bvh_node *n)
{
    uint32_t i, first_quad = p->g->n_spheres, first_tri = first_quad + p->g->n_quads;
    uint32_t tris = 0, quads = 0;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i];
        tris += prim >= first_tri;
        quads += prim >= first_quad && prim < first_tri;
    }
    if (p->pack_tris && tris == n->count)
        return RS_BVH4_PACKED;
    if (p->pack_quads && quads == n->count)
        return RS_BVH4_PACKED | RS_BVH4_QUADS;
    return 0;
}

static uint32_t pack_tris(rs_leaf_packer *p, const rs_bvh_node *n)
{
    uint32_t first = p->n_tri4, i, a;
    uint32_t first_tri = p->g->n_spheres + p->g->n_quads;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i];
        const rs_tri *t = &p->g->tris[prim - first_tri];
        rs_bvh4_tri4 *blk = &p->tri4[first + i / 4];
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
    p->n_tri4 += (n->count + 3) / 4;
    RS_ASSERT(p->n_tri4 <= p->cap_tri4);
    return first;
}

static uint32_t pack_quads(rs_leaf_packer *p, const rs_bvh_node *n)
{
    uint32_t first = p->n_quad4, i, a;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i];
        const rs_quad *q = &p->g->quads[prim - p->g->n_spheres];
        rs_bvh4_quad4 *blk = &p->quad4[first + i / 4];
        uint32_t l = i % 4;
        if (l == 0) {
            memset(blk, 0, sizeof *blk);
            blk->prim[0] = blk->prim[1] = blk->prim[2] = blk->prim[3] = RS_NO_HIT;
        }
        for (a = 0; a < 3; ++a) {
            blk->q[a][l] = rs_v3_get(q->q, (int)a);
            blk->u[a][l] = rs_v3_get(q->u, (int)a);
            blk->v[a][l] = rs_v3_get(q->v, (int)a);
            blk->w[a][l] = rs_v3_get(q->w, (int)a);
        }
        blk->prim[l] = prim;
    }
    p->n_quad4 += (n->count + 3) / 4;
    RS_ASSERT(p->n_quad4 <= p->cap_quad4);
    return first;
}

int rs_leaf_lane(rs_leaf_packer *p, const rs_bvh_node *l, uint32_t *child, uint16_t *count)
{
    uint32_t kind = pack_kind(p, l);
    if (kind == 0) {
        *child = l->left_first;
        *count = (uint16_t)l->count;
        return 0;
    }
    *child = kind & RS_BVH4_QUADS ? pack_quads(p, l) : pack_tris(p, l);
    *count = (uint16_t)(kind | (l->count + 3) / 4);
    return 1;
}

rs_status rs_bvh_wide_plan(const rs_bvh *b, rs_leaf_packer *p, const char *what,
                           uint32_t max_nodes, uint32_t *cap_nodes)
{
    uint32_t i, interior = 0;
    p->cap_tri4 = p->cap_quad4 = 0;
    for (i = 0; i < b->n_nodes; ++i) {
        if (b->nodes[i].count > 0x7fffu)
            return rs_error_set(RS_ERR_ARG, "%s: a leaf of %u primitives (at most 32767 fit a lane)",
                                what, b->nodes[i].count);
        interior += b->nodes[i].count == 0;
        if (b->nodes[i].count > 0) {
            uint32_t kind = pack_kind(p, &b->nodes[i]), blocks = (b->nodes[i].count + 3) / 4;
            if (kind & RS_BVH4_QUADS)
                p->cap_quad4 += blocks;
            else if (kind)
                p->cap_tri4 += blocks;
        }
    }
    if (interior + 1 > max_nodes)
        return rs_error_set(RS_ERR_ARG, "%s: %u nodes are more than the %u it can index", what,
                            interior + 1, max_nodes);
    /* at most one wide node per binary interior node (one for a single-leaf tree) */
    *cap_nodes = b->n_nodes == 0 ? 0 : interior > 0 ? interior : 1;
    return RS_OK;
}
