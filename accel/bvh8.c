/* accel/bvh8.c — collapsing a binary BVH into the 8-wide one (see accel/bvh8.h), and whether
 * its AVX2 traversal (accel/bvh8_avx2.c) can run here. */
#include "accel/bvh8.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "accel/internal.h"
#include "core/alloc.h"

/* Lanes hold the binary boxes by plane; an unused lane the empty box (lo +inf, hi -inf), which
 * no ray enters whatever its direction. */
static void set_box(void *node, uint32_t i, const rs_bvh_node *l)
{
    rs_bvh8_node *d = (rs_bvh8_node *)node;
    d->b[0][i] = l ? l->lo.x : INFINITY;
    d->b[1][i] = l ? l->lo.y : INFINITY;
    d->b[2][i] = l ? l->lo.z : INFINITY;
    d->b[3][i] = l ? l->hi.x : -INFINITY;
    d->b[4][i] = l ? l->hi.y : -INFINITY;
    d->b[5][i] = l ? l->hi.z : -INFINITY;
}

static const rs_wide_layout layout = {
    "8-wide BVH", 8, RS_BVH8_MAX_NODES, sizeof(rs_bvh8_node), offsetof(rs_bvh8_node, child),
    offsetof(rs_bvh8_node, count), offsetof(rs_bvh8_node, n_lanes),
    offsetof(rs_bvh8_node, leaf_mask), sizeof(rs_bvh8_tri8),
    sizeof(rs_bvh8_quad8), set_box};

rs_status rs_bvh8_build(const rs_bvh *b, const rs_geom *g, rs_bvh8 **out)
{
    rs_wide_tree w;
    rs_bvh8 *t;
    rs_status st;
    *out = NULL;
    t = (rs_bvh8 *)rs_calloc(1, sizeof *t);
    if (!t)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the 8-wide BVH");
    st = rs_wide_build(b, g, &layout, &w);
    if (st != RS_OK) {
        rs_free(t);
        return st;
    }
    t->nodes = (rs_bvh8_node *)w.nodes;
    t->tri8 = (rs_bvh8_tri8 *)w.tri;
    t->quad8 = (rs_bvh8_quad8 *)w.quad;
    t->sphere8 = w.sphere;
    t->prim_ids = b->prim_ids;
    t->inst_root = w.inst_root;
    t->n_nodes = w.n_nodes;
    t->n_tri8 = w.n_tri;
    t->n_quad8 = w.n_quad;
    t->n_sphere8 = w.n_sphere;
    t->depth = w.depth;
    t->n_packed = w.n_packed;
    *out = t;
    return RS_OK;
}

void rs_bvh8_destroy(rs_bvh8 *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->inst_root);
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
