/* accel/bvh.c — the frame every BVH builder runs in: per-primitive boxes, the top-down recursion
 * (with OpenMP tasks for large subtrees), the depth bound, the node boxes, the final node order,
 * and the SAH cost of a finished tree.  The split rules live in bvh_grid.c (median and the thesis
 * grid), bvh_sah.c (binned SAH) and bvh_lbvh.c (Morton codes); names in bvh_builder.c.
 *
 * Invariants of the finished tree, for every builder:
 *   - node 0 is the root; children of an interior node are adjacent (left, left + 1) and come
 *     after their parent; nodes are numbered in the order of a depth-first walk that numbers a
 *     node's two children together when it visits the node (the order the original median
 *     builder produced, so its trees are unchanged bit for bit);
 *   - every primitive appears exactly once in prim_ids, and each leaf's range lies inside it;
 *     leaves hold 1 .. max_leaf primitives;
 *   - each node's bounds are the union of its children's (a leaf's: of its primitives' boxes,
 *     rs_geom_prim_bounds, which cover a moving sphere's whole sweep);
 *   - depth <= RS_BVH_MAX_DEPTH (63 nodes), so traversal's RS_BVH_STACK-entry stacks never
 *     overflow.  The frame keeps the invariant  depth(node) + ceil(log2(count(node))) <= 63:  it
 *     holds at the root for any 32-bit count, a median split (children of at most ceil(count/2)
 *     primitives) preserves it, and a heuristic split that would break it is replaced by a
 *     median split (counted in rs_bvh.n_fallback);
 *   - the tree is a function of the geometry and the options only, never of the thread count.
 *
 * Where nodes go while building.  Subtrees are built concurrently, so a node's index cannot come
 * from a shared counter.  Instead a node with c primitives owns a block of 2c - 2 slots for its
 * descendants (a binary tree over c primitives has at most 2c - 1 nodes): its two children at the
 * block's start, then the left child's block (2 c_left - 2 slots), then the right child's.  Leaves
 * with more than one primitive leave holes; a sequential depth-first pass then copies the reached
 * slots into the final, hole-free array in the order stated above. */
#include "accel/bvh.h"

#include "accel/internal.h"
#include "core/alloc.h"
#include "core/parallel.h"

#include <stdlib.h>
#include <string.h>

/* Subtrees over at least this many primitives are built as OpenMP tasks. */
#define TASK_RANGE 4096u
/* Below this many primitives the whole build runs on the calling thread. */
#define PAR_BUILD 8192u

typedef uint32_t (*split_fn)(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                             int *fallback);

typedef struct frame {
    const rs_bvh_ctx *c;
    rs_bvh_node *slots; /* 2n - 1 build slots */
    split_fn split;
    int keep_order; /* LBVH: the fallback splits the sorted range at its middle, no reordering */
} frame;

/* What a subtree reports back: its depth, leaves and fallback splits. */
typedef struct rec_out {
    uint32_t depth, leaves, fallback;
} rec_out;

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
    if (prim >= g->n_tris)
        return g->instances[prim - g->n_tris].box; /* an instance, as a whole */
    {
        const rs_tri *t = &g->tris[prim];
        b.lo = rs_v3_min(t->v0, rs_v3_min(t->v1, t->v2));
        b.hi = rs_v3_max(t->v0, rs_v3_max(t->v1, t->v2));
    }
    return b;
}

static rs_aabb aabb_empty(void)
{
    rs_aabb b;
    b.lo = rs_v3_splat(INFINITY);
    b.hi = rs_v3_splat(-INFINITY);
    return b;
}

static rs_aabb centroid_bounds_serial(const rs_bvh_ctx *c, uint32_t first, uint32_t count)
{
    rs_aabb b = aabb_empty();
    uint32_t i;
    for (i = first; i < first + count; ++i) {
        rs_vec3 p = c->centroid[c->ids[i]];
        b.lo = rs_v3_min(b.lo, p);
        b.hi = rs_v3_max(b.hi, p);
    }
    return b;
}

rs_aabb rs_bvh_centroid_bounds(const rs_bvh_ctx *c, uint32_t first, uint32_t count)
{
    rs_aabb part[RS_BVH_PAR_CHUNKS], b;
    uint32_t chunk = (count + RS_BVH_PAR_CHUNKS - 1) / RS_BVH_PAR_CHUNKS;
    int k;
    if (count < RS_BVH_PAR_RANGE)
        return centroid_bounds_serial(c, first, count);
        /* fixed chunks merged in order; min and max are exact, so this equals the serial pass */
#pragma omp taskloop grainsize(1) shared(part)
    for (k = 0; k < (int)RS_BVH_PAR_CHUNKS; ++k) {
        uint32_t lo = (uint32_t)k * chunk, hi = lo + chunk < count ? lo + chunk : count;
        part[k] = centroid_bounds_serial(c, first + lo, hi - lo);
    }
    b = part[0];
    for (k = 1; k < (int)RS_BVH_PAR_CHUNKS; ++k) {
        b.lo = rs_v3_min(b.lo, part[k].lo);
        b.hi = rs_v3_max(b.hi, part[k].hi);
    }
    return b;
}

/* Smallest k with 2^k >= n. */
static uint32_t ceil_log2(uint32_t n)
{
    uint32_t k = 0;
    while (k < 32 && (1ull << k) < n)
        ++k;
    return k;
}

static rec_out build_rec(const frame *f, uint32_t slot, uint32_t block, uint32_t first,
                         uint32_t count, uint32_t depth)
{
    const rs_bvh_ctx *c = f->c;
    rs_bvh_node *n = &f->slots[slot];
    rec_out o, ol, orr;
    int fallback = 0;
    uint32_t mid = count > 1 ? f->split(c, first, count, depth, &fallback) : 0, big;
    if (mid >= count || (mid == 0 && count > c->max_leaf)) {
        RS_ASSERT(0); /* a split function broke its contract: split at the middle instead */
        mid = count / 2;
        fallback = 1;
    }
    big = mid > count - mid ? mid : count - mid;
    if (mid > 0 && depth + 1 + ceil_log2(big) > RS_BVH_MAX_DEPTH) {
        /* the heuristic's split could push a leaf past the traversal stack: halve instead */
        mid = f->keep_order ? count / 2 : rs_bvh_split_median(c, first, count);
        fallback = 1;
    }
    if (mid == 0) {
        rs_aabb b = c->bounds[c->ids[first]];
        uint32_t i;
        for (i = first + 1; i < first + count; ++i) {
            b.lo = rs_v3_min(b.lo, c->bounds[c->ids[i]].lo);
            b.hi = rs_v3_max(b.hi, c->bounds[c->ids[i]].hi);
        }
        n->lo = b.lo;
        n->hi = b.hi;
        n->left_first = first;
        n->count = count;
        o.depth = depth;
        o.leaves = 1;
        o.fallback = 0;
        return o;
    }
    /* children at block, block + 1; the left child's block of 2 mid - 2 slots follows them, then
     * the right child's 2 (count - mid) - 2: together exactly this node's 2 count - 2 */
#pragma omp task shared(ol) if (count >= TASK_RANGE)
    ol = build_rec(f, block, block + 2, first, mid, depth + 1);
    orr = build_rec(f, block + 1, block + 2 * mid, first + mid, count - mid, depth + 1);
#pragma omp taskwait
    n->lo = rs_v3_min(f->slots[block].lo, f->slots[block + 1].lo);
    n->hi = rs_v3_max(f->slots[block].hi, f->slots[block + 1].hi);
    n->left_first = block;
    n->count = 0;
    o.depth = ol.depth > orr.depth ? ol.depth : orr.depth;
    o.leaves = ol.leaves + orr.leaves;
    o.fallback = ol.fallback + orr.fallback + (uint32_t)fallback;
    return o;
}

/* Copies the subtree at build slot `from` to out[to], numbering children in depth-first order. */
static void compact(const rs_bvh_node *slots, uint32_t from, rs_bvh_node *out, uint32_t to,
                    uint32_t *next, uint32_t *max_count)
{
    rs_bvh_node n = slots[from];
    if (n.count > 0) {
        out[to] = n;
        if (n.count > *max_count)
            *max_count = n.count;
        return;
    }
    out[to] = n;
    out[to].left_first = *next;
    *next += 2;
    compact(slots, n.left_first, out, out[to].left_first, next, max_count);
    compact(slots, n.left_first + 1, out, out[to].left_first + 1, next, max_count);
}

/* The builder as rs_bvh.builder records it: the fields of opts->builder that its method reads
 * (bins filled in), the others zero; the median builder when opts is NULL.  RS_ERR_ARG (with
 * rs_bvh_builder_check's message) for an invalid builder. */
static rs_status resolve_builder(const rs_bvh_build_opts *opts, rs_bvh_builder *out)
{
    memset(out, 0, sizeof *out);
    if (!opts)
        return RS_OK;
    if (rs_bvh_builder_check(&opts->builder) != RS_OK)
        return RS_ERR_ARG;
    out->method = opts->builder.method;
    if (out->method == RS_BVH_GRID) {
        out->axis = opts->builder.axis;
        out->partition = opts->builder.partition;
        out->key = opts->builder.key;
    } else if (out->method == RS_BVH_SAH) {
        out->bins = opts->builder.bins ? opts->builder.bins : RS_BVH_SAH_BINS_DEFAULT;
    }
    return RS_OK;
}

/* What a build allocates up front besides the tree's own arrays, and frees when it ends. */
typedef struct scratch {
    rs_aabb *bounds;       /* per primitive */
    rs_vec3 *centroid;     /* per primitive */
    rs_bvh_node *slots;    /* 2n - 1 build slots */
    rs_bvh_key_id *pairs;  /* all but LBVH */
    rs_bvh_key_id *pairs2; /* RS_BVH_GRID with RS_BVH_PART_SORT */
    uint32_t *codes;       /* LBVH */
    uint32_t *codes_tmp;   /* LBVH */
    uint32_t *ids_tmp;     /* LBVH */
} scratch;

/* Allocates the scratch `builder` needs for b->n_prims >= 1 primitives, and b->prim_ids (in that
 * order among them, every allocation tried even after one fails).  1 if all succeeded; on 0 what
 * was allocated is freed by free_scratch and rs_bvh_destroy. */
static int alloc_scratch(scratch *s, rs_bvh *b, const rs_bvh_builder *builder)
{
    uint32_t n = b->n_prims;
    int lbvh = builder->method == RS_BVH_LBVH, need_pairs = !lbvh;
    int need_pairs2 = builder->method == RS_BVH_GRID && builder->partition == RS_BVH_PART_SORT;
    memset(s, 0, sizeof *s);
    s->bounds = (rs_aabb *)rs_alloc(n, sizeof *s->bounds);
    s->centroid = (rs_vec3 *)rs_alloc(n, sizeof *s->centroid);
    b->prim_ids = (uint32_t *)rs_alloc(n, sizeof *b->prim_ids);
    s->slots = (rs_bvh_node *)rs_alloc(2 * (size_t)n - 1, sizeof *s->slots);
    if (need_pairs)
        s->pairs = (rs_bvh_key_id *)rs_alloc(n, sizeof *s->pairs);
    if (need_pairs2)
        s->pairs2 = (rs_bvh_key_id *)rs_alloc(n, sizeof *s->pairs2);
    if (lbvh) {
        s->codes = (uint32_t *)rs_alloc(n, sizeof *s->codes);
        s->codes_tmp = (uint32_t *)rs_alloc(n, sizeof *s->codes_tmp);
        s->ids_tmp = (uint32_t *)rs_alloc(n, sizeof *s->ids_tmp);
    }
    return s->bounds && s->centroid && b->prim_ids && s->slots && (!need_pairs || s->pairs) &&
           (!need_pairs2 || s->pairs2) && (!lbvh || (s->codes && s->codes_tmp && s->ids_tmp));
}

static void free_scratch(scratch *s)
{
    rs_free(s->bounds);
    rs_free(s->centroid);
    rs_free(s->slots);
    rs_free(s->pairs);
    rs_free(s->pairs2);
    rs_free(s->codes);
    rs_free(s->codes_tmp);
    rs_free(s->ids_tmp);
}

/* Each primitive's box and the box's centre, and the identity permutation in ids. */
static void prim_bounds(const rs_geom *g, uint32_t n, int threads, scratch *s, uint32_t *ids)
{
    long i;
#pragma omp parallel for schedule(static) num_threads(threads) if (n >= PAR_BUILD)
    for (i = 0; i < (long)n; ++i) {
        s->bounds[i] = rs_geom_prim_bounds(g, (uint32_t)i);
        s->centroid[i] = rs_v3_scale(rs_v3_add(s->bounds[i].lo, s->bounds[i].hi), 0.5f);
        ids[i] = (uint32_t)i;
    }
}

/* LBVH: ids sorted by the centroids' Morton codes, s->codes[i] the code of ids[i]; through
 * opts->lbvh_sort where it is set (RS_OK or the hook's error), else on the host. */
static rs_status lbvh_order(const rs_bvh_build_opts *opts, uint32_t n, int threads, scratch *s,
                            uint32_t *ids)
{
    if (opts->lbvh_sort) {
        float lo[3], scale[3];
        rs_bvh_lbvh_frame(s->centroid, n, threads, lo, scale);
        return opts->lbvh_sort(opts->lbvh_sort_user, s->centroid, n, lo, scale, ids, s->codes);
    }
    rs_bvh_lbvh_sort(s->centroid, n, ids, s->codes, s->codes_tmp, s->ids_tmp, threads);
    return RS_OK;
}

/* The top-down recursion over all n >= 1 primitives with `builder`'s split rule: the nodes go to
 * s->slots (the root at slot 0), ids is reordered into the leaves' ranges.  Returns the root's
 * report. */
static rec_out build_tree(const scratch *s, uint32_t *ids, uint32_t n, uint32_t max_leaf,
                          uint32_t leaf_block, const rs_bvh_builder *builder, int threads)
{
    rs_bvh_ctx c;
    frame f;
    rec_out res;
    memset(&c, 0, sizeof c);
    c.bounds = s->bounds;
    c.centroid = s->centroid;
    c.ids = ids;
    c.max_leaf = max_leaf;
    c.leaf_block = leaf_block ? leaf_block : 1;
    c.builder = *builder;
    c.pairs = s->pairs;
    c.pairs2 = s->pairs2;
    c.codes = s->codes;
    f.c = &c;
    f.slots = s->slots;
    f.keep_order = builder->method == RS_BVH_LBVH;
    switch (builder->method) {
    case RS_BVH_SAH: f.split = rs_bvh_split_sah; break;
    case RS_BVH_LBVH: f.split = rs_bvh_split_lbvh; break;
    default: f.split = rs_bvh_split_grid; break;
    }
#pragma omp parallel num_threads(threads) if (n >= PAR_BUILD && threads > 1)
#pragma omp single
    res = build_rec(&f, 0, 1, 0, n, 1);
    return res;
}

/* The finished tree in b: the statistics from the root's report `res` and the hole-free node
 * array copied out of the build slots.  RS_ERR_NOMEM (no message yet) if that array cannot be
 * allocated. */
static rs_status finish_tree(rs_bvh *b, const rs_bvh_node *slots, rec_out res)
{
    uint32_t next = 1, max_count = 0;
    b->n_nodes = 2 * res.leaves - 1;
    b->n_leaves = res.leaves;
    b->depth = res.depth;
    b->n_fallback = res.fallback;
    b->nodes = (rs_bvh_node *)rs_alloc(b->n_nodes, sizeof *b->nodes);
    if (!b->nodes)
        return RS_ERR_NOMEM;
    compact(slots, 0, b->nodes, 0, &next, &max_count);
    RS_ASSERT(next == b->n_nodes);
    b->max_leaf_count = max_count;
    return RS_OK;
}

static rs_status build_one(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out)
{
    uint32_t n = rs_geom_prim_count(g), max_leaf = (opts && opts->max_leaf) ? opts->max_leaf : 4;
    int threads = (opts && opts->threads) ? (int)opts->threads : rs_default_threads();
    rs_bvh_builder builder;
    scratch s;
    rs_bvh *b;
    rs_status st;
    *out = NULL;
    if ((st = resolve_builder(opts, &builder)) != RS_OK)
        return st;
    if (n > 0x7fffffffu)
        return rs_error_set(RS_ERR_ARG, "BVH: %u primitives, at most 2^31 - 1 supported", n);

    b = (rs_bvh *)rs_calloc(1, sizeof *b);
    if (!b)
        return rs_error_set(RS_ERR_NOMEM, "out of memory building the BVH");
    b->n_prims = n;
    b->builder = builder;
    if (n == 0) {
        *out = b;
        return RS_OK;
    }
    st = RS_ERR_NOMEM; /* until the tree is complete */
    if (alloc_scratch(&s, b, &builder)) {
        prim_bounds(g, n, threads, &s, b->prim_ids);
        st = builder.method == RS_BVH_LBVH ? lbvh_order(opts, n, threads, &s, b->prim_ids) : RS_OK;
        if (st == RS_OK)
            st = finish_tree(b, s.slots,
                             build_tree(&s, b->prim_ids, n, max_leaf,
                                        opts ? opts->leaf_block : 0, &builder, threads));
    }
    free_scratch(&s); /* success and a failed lbvh_sort too: the scratch goes either way */
    if (st != RS_OK) {
        rs_bvh_destroy(b);
        return st != RS_ERR_NOMEM
                   ? st
                   : rs_error_set(RS_ERR_NOMEM, "out of memory building the BVH over %u primitives",
                                  n);
    }
    *out = b;
    return RS_OK;
}

/* Instances of the same prototype together: by first triangle, count, then instance. */
typedef struct proto_key {
    uint32_t first, n, inst;
} proto_key;

static int by_prototype(const void *a, const void *b)
{
    const proto_key *x = (const proto_key *)a, *y = (const proto_key *)b;
    if (x->first != y->first)
        return x->first < y->first ? -1 : 1;
    if (x->n != y->n)
        return x->n < y->n ? -1 : 1;
    return x->inst < y->inst ? -1 : x->inst > y->inst;
}

/* The bottom levels: one binary BVH per prototype, over its triangles in object space, by the
 * same builder as the top level, appended to b's pools (node and prim-id indices rebased), and
 * b's copy of the instance table with each instance's root. */
static rs_status build_instances(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh *b)
{
    rs_bvh_build_opts o;
    proto_key *order;
    uint32_t i, n = g->n_instances, cap_nodes = 0;
    rs_status st = RS_OK;
    if (opts)
        o = *opts;
    else
        memset(&o, 0, sizeof o);
    o.lbvh_sort = NULL; /* the host's LBVH gives the same tree */
    /* disjoint prototypes over n_inst_tris triangles have at most 2 n_inst_tris nodes */
    cap_nodes = 2 * g->n_inst_tris;
    b->instances = (rs_instance *)rs_alloc(n, sizeof *b->instances);
    b->blas_nodes = (rs_bvh_node *)rs_alloc(cap_nodes ? cap_nodes : 1, sizeof *b->blas_nodes);
    b->blas_prim_ids = (uint32_t *)rs_alloc(g->n_inst_tris ? g->n_inst_tris : 1, sizeof(uint32_t));
    order = (proto_key *)rs_alloc(n, sizeof *order);
    if (!b->instances || !b->blas_nodes || !b->blas_prim_ids || !order) {
        rs_free(order);
        return RS_ERR_NOMEM;
    }
    memcpy(b->instances, g->instances, (size_t)n * sizeof *b->instances);
    for (i = 0; i < n; ++i) {
        order[i].first = g->instances[i].first_tri;
        order[i].n = g->instances[i].n_tris;
        order[i].inst = i;
    }
    qsort(order, n, sizeof *order, by_prototype);
    for (i = 0; i < n && st == RS_OK; ++i) {
        const rs_instance *in = &g->instances[order[i].inst];
        const rs_instance *prev = i ? &g->instances[order[i - 1].inst] : NULL;
        rs_geom pg;
        rs_bvh *blas = NULL;
        uint32_t k, base;
        if (prev && prev->first_tri == in->first_tri && prev->n_tris == in->n_tris) {
            b->instances[order[i].inst].root = b->instances[order[i - 1].inst].root;
            continue;
        }
        if (in->n_tris == 0 || (uint64_t)in->first_tri + in->n_tris > g->n_inst_tris) {
            st = rs_error_set(RS_ERR_ARG, "BVH: instance %u's triangles out of range", order[i].inst);
            break;
        }
        memset(&pg, 0, sizeof pg);
        pg.tris = g->inst_tris + in->first_tri;
        pg.n_tris = in->n_tris;
        pg.tri_algo = g->tri_algo;
        pg.time0 = g->time0;
        pg.time1 = g->time1;
        if ((st = build_one(&pg, &o, &blas)) != RS_OK)
            break;
        base = b->n_blas_nodes;
        if ((uint64_t)base + blas->n_nodes > cap_nodes) { /* prototypes that overlap */
            rs_bvh_destroy(blas);
            st = rs_error_set(RS_ERR_ARG, "BVH: instance prototypes overlap");
            break;
        }
        for (k = 0; k < blas->n_nodes; ++k) {
            rs_bvh_node nd = blas->nodes[k];
            /* interior: the child's index; leaf: its first prim id, both rebased */
            nd.left_first += nd.count > 0 ? in->first_tri : base;
            b->blas_nodes[base + k] = nd;
        }
        for (k = 0; k < in->n_tris; ++k)
            b->blas_prim_ids[in->first_tri + k] = in->first_tri + blas->prim_ids[k];
        b->n_blas_nodes += blas->n_nodes;
        b->instances[order[i].inst].root = base;
        rs_bvh_destroy(blas);
    }
    rs_free(order);
    return st;
}

rs_status rs_bvh_build(const rs_geom *g, const rs_bvh_build_opts *opts, rs_bvh **out)
{
    rs_status st = build_one(g, opts, out);
    if (st != RS_OK || g->n_instances == 0)
        return st;
    st = build_instances(g, opts, *out);
    if (st != RS_OK) {
        rs_bvh_destroy(*out);
        *out = NULL;
        return st != RS_ERR_NOMEM ? st
                                  : rs_error_set(RS_ERR_NOMEM,
                                                 "out of memory building %u instances' BVHs",
                                                 g->n_instances);
    }
    return RS_OK;
}

void rs_bvh_attach(const rs_bvh *b, rs_geom *g)
{
    if (!b || !b->instances)
        return;
    g->instances = b->instances;
    g->blas_nodes = b->blas_nodes;
    g->blas_prim_ids = b->blas_prim_ids;
    g->n_blas_nodes = b->n_blas_nodes;
}

static double box_area(rs_vec3 lo, rs_vec3 hi)
{
    double x = (double)hi.x - lo.x, y = (double)hi.y - lo.y, z = (double)hi.z - lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

double rs_bvh_sah_cost(const rs_bvh *b)
{
    double root, sum = 0.0;
    uint32_t i;
    if (!b || b->n_nodes == 0)
        return 0.0;
    root = box_area(b->nodes[0].lo, b->nodes[0].hi);
    for (i = 0; i < b->n_nodes; ++i) {
        const rs_bvh_node *nd = &b->nodes[i];
        double w = root > 0.0 ? box_area(nd->lo, nd->hi) / root : 1.0;
        sum += w * (nd->count > 0 ? RS_BVH_COST_ISECT * nd->count : RS_BVH_COST_TRAV);
    }
    return sum;
}

void rs_bvh_destroy(rs_bvh *b)
{
    if (!b)
        return;
    rs_free(b->nodes);
    rs_free(b->prim_ids);
    rs_free(b->instances);
    rs_free(b->blas_nodes);
    rs_free(b->blas_prim_ids);
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
