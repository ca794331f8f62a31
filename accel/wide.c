/* accel/wide.c — what collapsing a binary BVH into a wide one takes, whatever the width: the
 * choice of each wide node's lanes, the size checks, and packing leaves of triangles into tri4
 * blocks and leaves of parallelograms into quad4 blocks (accel/bvh4.h, accel/bvh8.h; declared in
 * accel/internal.h). */
#include <math.h>
#include <string.h>

#include "accel/bvh8.h"
#include "accel/internal.h"
#include "core/alloc.h"

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

/* Every block type is laid out alike: `fields` vectors of 3 axes of `width` floats each, then
 * `width` primitive numbers (rs_bvh4_tri4: v0, e1, e2; rs_bvh4_quad4: q, u, v, w; the same for the
 * 8-wide rs_bvh8_tri8 / quad8).  The packer writes them through that layout. */
enum { TRI_FIELDS = 3, QUAD_FIELDS = 4 };
typedef char tri4_layout[sizeof(rs_bvh4_tri4) == (TRI_FIELDS * 3 + 1) * 4 * 4 ? 1 : -1];
typedef char quad4_layout[sizeof(rs_bvh4_quad4) == (QUAD_FIELDS * 3 + 1) * 4 * 4 ? 1 : -1];
typedef char tri8_layout[sizeof(rs_bvh8_tri8) == (TRI_FIELDS * 3 + 1) * 8 * 4 ? 1 : -1];
typedef char quad8_layout[sizeof(rs_bvh8_quad8) == (QUAD_FIELDS * 3 + 1) * 8 * 4 ? 1 : -1];

void rs_leaf_packer_init(rs_leaf_packer *p, const rs_bvh *b, const rs_geom *g, uint32_t width)
{
    memset(p, 0, sizeof *p);
    p->g = g;
    p->prim_ids = b->prim_ids;
    p->width = width;
#ifdef RS_BVH4_SSE
    p->pack_tris = g->tri_algo == RS_ISECT_TRI_MOLLER;
    p->pack_quads = 1;
    p->pack_spheres = width == 8 && !g->sphere_motion && g->sphere_algo == RS_ISECT_SPHERE_ALGEBRAIC;
#endif
}

/* How binary leaf `n` is packed: RS_WIDE_PACKED for triangle blocks, RS_WIDE_PACKED |
 * RS_WIDE_QUADS for parallelogram blocks, 0 when it is not (a mix of kinds, spheres, or packing
 * off). */
static uint32_t pack_kind(const rs_leaf_packer *p, const rs_bvh_node *n)
{
    uint32_t i, first_quad = p->g->n_spheres, first_tri = first_quad + p->g->n_quads;
    uint32_t first_inst = first_tri + p->g->n_tris; /* instances are never packed */
    uint32_t tris = 0, quads = 0, spheres = 0;
    if ((n->count + p->width - 1) / p->width > RS_WIDE_BLOCKS)
        return 0;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i];
        /* a cut-out triangle takes the scalar test, which looks up its mask */
        tris += prim >= first_tri && prim < first_inst &&
                !(p->g->tri_mask && p->g->tri_mask[prim - first_tri]);
        quads += prim >= first_quad && prim < first_tri;
        spheres += prim < first_quad;
    }
    if (p->pack_tris && tris == n->count)
        return RS_WIDE_PACKED;
    if (p->pack_quads && quads == n->count)
        return RS_WIDE_PACKED | RS_WIDE_QUADS;
    if (p->pack_spheres && spheres == n->count)
        return RS_WIDE_PACKED | RS_WIDE_SPHERES;
    return 0;
}

/* Packs leaf `n` into the next blocks of `base` (blocks of `fields` vectors); vec(prim, f) gives
 * the f-th vector of primitive `prim`.  Returns the first block's index. */
static uint32_t pack(rs_leaf_packer *p, const rs_bvh_node *n, void *base, uint32_t *n_blocks,
                     uint32_t cap, uint32_t fields, int quads)
{
    const uint32_t w = p->width, floats = fields * 3 * w;
    const size_t block_bytes = (size_t)(floats + w) * 4;
    uint32_t first = *n_blocks, i, f, a;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i], l = i % w;
        unsigned char *blk = (unsigned char *)base + (size_t)(first + i / w) * block_bytes;
        float *x = (float *)(void *)blk;
        uint32_t *ids = (uint32_t *)(void *)(blk + (size_t)floats * 4);
        rs_vec3 v[4];
        if (quads) {
            const rs_quad *q = &p->g->quads[prim - p->g->n_spheres];
            v[0] = q->q;
            v[1] = q->u;
            v[2] = q->v;
            v[3] = q->w;
        } else {
            const rs_tri *t = &p->g->tris[prim - p->g->n_spheres - p->g->n_quads];
            v[0] = t->v0;
            v[1] = rs_v3_sub(t->v1, t->v0);
            v[2] = rs_v3_sub(t->v2, t->v0);
        }
        if (l == 0) {
            /* unused lanes: all zero (det or denominator 0: never a hit), no primitive */
            memset(blk, 0, block_bytes);
            for (a = 0; a < w; ++a)
                ids[a] = RS_NO_HIT;
        }
        for (f = 0; f < fields; ++f)
            for (a = 0; a < 3; ++a)
                x[(f * 3 + a) * w + l] = rs_v3_get(v[f], (int)a);
        ids[l] = prim;
    }
    *n_blocks += (n->count + w - 1) / w;
    RS_ASSERT(*n_blocks <= cap);
    (void)cap;
    return first;
}

/* Packs leaf `n` of spheres into the next sphere8 blocks; returns the first block's index. */
static uint32_t pack_spheres(rs_leaf_packer *p, const rs_bvh_node *n)
{
    uint32_t first = p->n_sphere, i, a, l;
    for (i = 0; i < n->count; ++i) {
        uint32_t prim = p->prim_ids[n->left_first + i];
        const rs_sphere *sp = &p->g->spheres[prim];
        rs_bvh8_sphere8 *blk = &p->sphere[first + i / 8];
        if (i % 8 == 0) {
            memset(blk, 0, sizeof *blk);
            for (l = 0; l < 8; ++l) {
                blk->r[l] = NAN; /* an unused lane: disc is NaN, never a hit */
                blk->prim[l] = RS_NO_HIT;
            }
        }
        for (a = 0; a < 3; ++a)
            blk->c[a][i % 8] = rs_v3_get(sp->center, (int)a);
        blk->r[i % 8] = sp->radius;
        blk->prim[i % 8] = prim;
    }
    p->n_sphere += (n->count + 7) / 8;
    RS_ASSERT(p->n_sphere <= p->cap_sphere);
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
    *child = kind & RS_WIDE_SPHERES ? pack_spheres(p, l)
             : kind & RS_WIDE_QUADS
                 ? pack(p, l, p->quad, &p->n_quad, p->cap_quad, QUAD_FIELDS, 1)
                 : pack(p, l, p->tri, &p->n_tri, p->cap_tri, TRI_FIELDS, 0);
    *count = (uint16_t)(kind | (l->count + p->width - 1) / p->width);
    return 1;
}

rs_status rs_bvh_wide_plan(const rs_bvh *b, rs_leaf_packer *p, const char *what,
                           uint32_t max_nodes, uint32_t *cap_nodes)
{
    uint32_t i, interior = 0;
    p->cap_tri = p->cap_quad = p->cap_sphere = 0;
    for (i = 0; i < b->n_nodes; ++i) {
        if (b->nodes[i].count > 0x7fffu)
            return rs_error_set(RS_ERR_ARG, "%s: a leaf of %u primitives (at most 32767 fit a lane)",
                                what, b->nodes[i].count);
        interior += b->nodes[i].count == 0;
        if (b->nodes[i].count > 0) {
            uint32_t kind = pack_kind(p, &b->nodes[i]);
            uint32_t blocks = (b->nodes[i].count + p->width - 1) / p->width;
            if (kind & RS_WIDE_SPHERES)
                p->cap_sphere += blocks;
            else if (kind & RS_WIDE_QUADS)
                p->cap_quad += blocks;
            else if (kind)
                p->cap_tri += blocks;
        }
    }
    if (interior + 1 > max_nodes)
        return rs_error_set(RS_ERR_ARG, "%s: %u nodes are more than the %u it can index", what,
                            interior + 1, max_nodes);
    /* at most one wide node per binary interior node (one for a single-leaf tree) */
    *cap_nodes = b->n_nodes == 0 ? 0 : interior > 0 ? interior : 1;
    return RS_OK;
}

/* ---- the collapse itself, for any width ---------------------------------------------------- */

typedef struct collapse {
    const rs_bvh *bin;
    const rs_bvh_node *bn; /* the binary nodes being collapsed: b->nodes, or b->blas_nodes */
    int bottom;            /* collapsing a bottom level: leaves never packed */
    const rs_wide_layout *L;
    rs_wide_tree *out;
    rs_leaf_packer pk;
    uint32_t cap;
} collapse;

static unsigned char *node_at(const collapse *c, uint32_t i)
{
    return (unsigned char *)c->out->nodes + (size_t)i * c->L->node_size;
}

/* Fills wide node `dst` from binary node `src` (or, for a tree that is one leaf, from that leaf
 * alone) and recurses into its interior lanes.  Returns the depth below, in nodes. */
static uint32_t collapse_node(collapse *c, uint32_t src, uint32_t dst)
{
    const rs_bvh_node *bn = c->bn;
    uint32_t lanes[RS_WIDE_MAX], n = rs_bvh_wide_lanes(bn, src, c->L->width, lanes), i,
                                 depth = 0;
    unsigned char *d = node_at(c, dst);
    uint32_t *child = (uint32_t *)(void *)(d + c->L->child_offset);
    uint16_t *count = (uint16_t *)(void *)(d + c->L->count_offset);
    memset(d, 0, c->L->node_size);
    *(uint32_t *)(void *)(d + c->L->n_lanes_offset) = n;
    for (i = 0; i < c->L->width; ++i)
        c->L->set_box(d, i, i < n ? &bn[lanes[i]] : NULL);
    for (i = 0; i < n; ++i) {
        if (bn[lanes[i]].count == 0) /* interior lanes below */
            continue;
        if (c->bottom) {
            child[i] = bn[lanes[i]].left_first;
            count[i] = (uint16_t)bn[lanes[i]].count;
        } else {
            c->out->n_packed +=
                (uint32_t)rs_leaf_lane(&c->pk, &bn[lanes[i]], &child[i], &count[i]);
        }
    }
    {
        uint32_t leaves = 0;
        for (i = 0; i < n; ++i)
            leaves |= (uint32_t)(count[i] != 0) << i;
        *(uint32_t *)(void *)(d + c->L->leaf_mask_offset) = leaves;
    }
    for (i = 0; i < n; ++i) {
        if (bn[lanes[i]].count == 0) {
            uint32_t next = c->out->n_nodes++, below;
            RS_ASSERT(next < c->cap);
            /* the recursion writes other nodes only: d stays valid */
            child[i] = next;
            below = collapse_node(c, lanes[i], next);
            if (below > depth)
                depth = below;
        }
    }
    return depth + 1;
}

/* The bottom levels' checks and node count: every leaf fits a lane, and at most one wide node
 * per binary node of the pool (a bottom level collapses to at most its interior nodes, or one). */
static rs_status plan_bottoms(const rs_bvh *b, const rs_geom *g, const rs_wide_layout *L,
                              uint32_t *cap_nodes)
{
    uint32_t i;
    *cap_nodes = 0;
    if (!b->instances || g->n_instances == 0)
        return RS_OK;
    for (i = 0; i < b->n_blas_nodes; ++i)
        if (b->blas_nodes[i].count > 0x7fffu)
            return rs_error_set(RS_ERR_ARG,
                                "%s: an instance's leaf of %u primitives (at most 32767 fit a lane)",
                                L->what, b->blas_nodes[i].count);
    *cap_nodes = b->n_blas_nodes;
    return RS_OK;
}

/* Each prototype's bottom level into the nodes after the top tree's, once per prototype (its
 * instances share the root); out->inst_root[i] for every instance.  `wide_of` has a slot per
 * node of the pool. */
static uint32_t collapse_bottoms(collapse *c, const rs_geom *g, uint32_t *wide_of)
{
    const rs_bvh *b = c->bin;
    uint32_t i, depth = 0;
    c->bn = b->blas_nodes;
    c->bottom = 1;
    for (i = 0; i < b->n_blas_nodes; ++i)
        wide_of[i] = RS_NO_HIT;
    for (i = 0; i < g->n_instances; ++i) {
        uint32_t root = b->instances[i].root;
        RS_ASSERT(root < b->n_blas_nodes);
        if (wide_of[root] == RS_NO_HIT) {
            uint32_t dst = c->out->n_nodes++, below;
            RS_ASSERT(dst < c->cap);
            wide_of[root] = dst;
            below = collapse_node(c, root, dst);
            if (below > depth)
                depth = below;
        }
        c->out->inst_root[i] = wide_of[root];
    }
    return depth;
}

rs_status rs_wide_build(const rs_bvh *b, const rs_geom *g, const rs_wide_layout *L,
                        rs_wide_tree *out)
{
    collapse c;
    rs_status st;
    uint32_t cap_bottom = 0, *wide_of = NULL;
    memset(out, 0, sizeof *out);
    memset(&c, 0, sizeof c);
    c.bin = b;
    c.L = L;
    c.out = out;
    rs_leaf_packer_init(&c.pk, b, g, L->width);
    st = rs_bvh_wide_plan(b, &c.pk, L->what, L->max_nodes, &c.cap);
    if (st == RS_OK && c.cap > 0)
        st = plan_bottoms(b, g, L, &cap_bottom);
    if (st != RS_OK || c.cap == 0)
        return st;
    if (cap_bottom > L->max_nodes - c.cap)
        return rs_error_set(RS_ERR_ARG, "%s: %u nodes and the instances' %u are more than the %u it "
                            "can index", L->what, c.cap, cap_bottom, L->max_nodes);
    c.cap += cap_bottom;
    if (cap_bottom > 0) {
        out->inst_root = (uint32_t *)rs_alloc(g->n_instances, sizeof *out->inst_root);
        wide_of = (uint32_t *)rs_alloc(b->n_blas_nodes, sizeof *wide_of);
    }
    out->nodes = rs_alloc_aligned(c.cap, L->node_size);
    if (c.pk.cap_tri > 0)
        out->tri = rs_alloc_aligned(c.pk.cap_tri, L->tri_size);
    if (c.pk.cap_quad > 0)
        out->quad = rs_alloc_aligned(c.pk.cap_quad, L->quad_size);
    if (c.pk.cap_sphere > 0)
        out->sphere = (rs_bvh8_sphere8 *)rs_alloc_aligned(c.pk.cap_sphere, sizeof *out->sphere);
    if (!out->nodes || (c.pk.cap_tri > 0 && !out->tri) || (c.pk.cap_quad > 0 && !out->quad) ||
        (c.pk.cap_sphere > 0 && !out->sphere) || (cap_bottom > 0 && (!out->inst_root || !wide_of))) {
        rs_free(wide_of);
        rs_wide_free(out);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the %s (%u nodes)", L->what, c.cap);
    }
    c.pk.tri = out->tri;
    c.pk.quad = out->quad;
    c.pk.sphere = out->sphere;
    out->n_nodes = 1;
    c.bn = b->nodes;
    out->depth = collapse_node(&c, 0, 0);
    if (cap_bottom > 0) {
        /* a bottom level's depth is its own walk's: out->depth stays the top tree's */
        (void)collapse_bottoms(&c, g, wide_of);
        rs_free(wide_of);
    }
    out->n_tri = c.pk.n_tri;
    out->n_quad = c.pk.n_quad;
    out->n_sphere = c.pk.n_sphere;
    return RS_OK;
}

void rs_wide_free(rs_wide_tree *t)
{
    rs_free(t->nodes);
    rs_free(t->tri);
    rs_free(t->quad);
    rs_free(t->sphere);
    rs_free(t->inst_root);
    memset(t, 0, sizeof *t);
}
