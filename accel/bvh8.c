/* accel/bvh8.c — collapsing a binary BVH into the 8-wide one (see accel/bvh8.h), and whether
 * its AVX2 traversal (accel/bvh8_avx2.c) can run here. */
#include "accel/bvh8.h"

#include <math.h>
#include <string.h>

#include "accel/internal.h"
#include "core/alloc.h"

typedef struct collapse {
    const rs_bvh *bin;
    rs_bvh8 *out;
    rs_leaf_packer pk;
    uint32_t cap;
} collapse;

/* Fills 8-wide node `dst` from binary node `src` and recurses into its interior lanes, as
 * accel/bvh4.c does for four.  Unused lanes get an empty box (lo +inf, hi -inf), which no ray
 * enters.  Returns the depth below, in nodes. */
static uint32_t collapse_node(collapse *c, uint32_t src, uint32_t dst)
{
    const rs_bvh_node *bn = c->bin->nodes;
    uint32_t lanes[8], n = rs_bvh_wide_lanes(bn, src, 8, lanes), i, a, depth = 0;
    rs_bvh8_node *d = &c->out->nodes[dst];
    memset(d, 0, sizeof *d);
    d->n_lanes = n;
    for (i = 0; i < 8; ++i)
        for (a = 0; a < 3; ++a) {
            d->b[a][i] = INFINITY;
            d->b[a + 3][i] = -INFINITY;
        }
    for (i = 0; i < n; ++i) {
        const rs_bvh_node *l = &bn[lanes[i]];
        d->b[0][i] = l->lo.x;
        d->b[1][i] = l->lo.y;
        d->b[2][i] = l->lo.z;
        d->b[3][i] = l->hi.x;
        d->b[4][i] = l->hi.y;
        d->b[5][i] = l->hi.z;
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

rs_status rs_bvh8_build(const rs_bvh *b, const rs_geom *g, rs_bvh8 **out)
{
    rs_bvh8 *t;
    collapse c;
    rs_status st;
    *out = NULL;
    memset(&c, 0, sizeof c);
    c.bin = b;
    rs_leaf_packer_init(&c.pk, b, g, 8);
    st = rs_bvh_wide_plan(b, &c.pk, "8-wide BVH", RS_BVH8_MAX_NODES, &c.cap);
    if (st != RS_OK)
        return st;
    t = (rs_bvh8 *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the 8-wide BVH");
    t->prim_ids = b->prim_ids;
    if (c.cap > 0) {
        t->nodes = (rs_bvh8_node *)rs_alloc_aligned(c.cap, sizeof *t->nodes);
        if (c.pk.cap_tri > 0)
            t->tri8 = (rs_bvh8_tri8 *)rs_alloc_aligned(c.pk.cap_tri, sizeof *t->tri8);
        if (c.pk.cap_quad > 0)
            t->quad8 = (rs_bvh8_quad8 *)rs_alloc_aligned(c.pk.cap_quad, sizeof *t->quad8);
        if (c.pk.cap_sphere > 0)
            t->sphere8 = (rs_bvh8_sphere8 *)rs_alloc_aligned(c.pk.cap_sphere, sizeof *t->sphere8);
        if (!t->nodes || (c.pk.cap_tri > 0 && !t->tri8) || (c.pk.cap_quad > 0 && !t->quad8) ||
            (c.pk.cap_sphere > 0 && !t->sphere8)) {
            rs_bvh8_destroy(t);
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the 8-wide BVH (%u nodes)", c.cap);
        }
        c.out = t;
        c.pk.tri = t->tri8;
        c.pk.quad = t->quad8;
        c.pk.sphere = t->sphere8;
        t->n_nodes = 1;
        t->depth = collapse_node(&c, 0, 0);
        t->n_tri8 = c.pk.n_tri;
        t->n_quad8 = c.pk.n_quad;
        t->n_sphere8 = c.pk.n_sphere;
    }
    *out = t;
    return RS_OK;
}

void rs_bvh8_destroy(rs_bvh8 *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->tri8);
    rs_free(b->quad8);
    rs_free(b->sphere8);
    rs_free(b);
}

uint32_t rs_bvh_wide_leaf_size(uint32_t bvh_width, const rs_geom *g)
{
    uint32_t w, n = rs_geom_prim_count(g);
    uint64_t packed = g->n_quads;
    if (bvh_width == 2 || n == 0)
        return 0;
    w = bvh_width == 8 || (bvh_width == 0 && rs_bvh8_supported()) ? 8u : 4u;
    if (g->tri_algo == RS_ISECT_TRI_MOLLER)
        packed += g->n_tris;
    if (w == 8 && !g->sphere_motion && g->sphere_algo == RS_ISECT_SPHERE_ALGEBRAIC)
        packed += g->n_spheres;
    return packed * 10 >= (uint64_t)n * 9 ? w : 0u;
}

int rs_bvh8_supported(void)
{
#if defined(__x86_64__) && defined(__GNUC__) && defined(RS_BVH4_SSE)
    return __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}
