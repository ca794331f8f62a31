/* accel/bvh_sah.c — the binned SAH builder (Wald, "On fast construction of SAH-based bounding
 * volume hierarchies", IEEE RT 2007).
 *
 * At each node the centroid bounds are cut into K equal bins per axis (K = builder.bins, 2..32,
 * default 16; Wald finds 16-32 enough).  One pass over the range counts the primitives in each
 * bin and grows each bin's box by the primitives' boxes; a sweep from each side then gives, for
 * each of the K - 1 planes between bins, the areas and counts of both sides.  The cost of a split
 * (MacDonald & Booth 1990), and of a leaf, are
 *
 *     C_split = C_trav + C_isect (A_L N_L + A_R N_R) / A,      C_leaf = C_isect N,
 *
 * with C_trav = RS_BVH_COST_TRAV and C_isect = RS_BVH_COST_ISECT, the constants rs_bvh_sah_cost
 * uses (both 1).  With rs_bvh_build_opts.leaf_block = B > 1, every N above counts blocks,
 * ceil(N / B): a leaf test that takes B primitives at once (the wide trees' tri4 blocks) costs
 * the same for 1 and for B of them, so ranges are no longer split down to one or two primitives
 * (Embree's SAH counts its leaves in blocks the same way).  The cheapest plane of the three axes wins (ties: lower axis, lower plane).
 *
 * Leaves.  max_leaf caps the leaf size: a range with more than max_leaf primitives is always
 * split, even where the SAH says a leaf would be cheaper; a range of at most max_leaf becomes a
 * leaf when C_leaf <= C_split, and is split further when splitting is cheaper.
 *
 * Ranges the bins cannot separate (all centroids equal on every axis) are split at their middle
 * without reordering (counted in rs_bvh.n_fallback).  The SAH happily peels a few primitives off
 * a range at each level (large primitives among small ones, exponential spacing), so a tree can
 * get deeper than the traversal stack; the frame in bvh.c replaces such splits by median splits
 * (see its header).
 *
 * Ranges of RS_BVH_PAR_RANGE primitives and more are binned by OpenMP tasks over fixed chunks;
 * bins hold integer counts and min/max boxes, which merge exactly, so the result is the same for
 * any thread count. */
#include "accel/internal.h"

/* n primitives in leaf-test blocks (rs_bvh_build_opts.leaf_block) */
static double blocks(const rs_bvh_ctx *c, uint32_t n)
{
    return (double)((n + c->leaf_block - 1) / c->leaf_block);
}

typedef struct sah_bin {
    rs_aabb box;
    uint32_t n;
} sah_bin;

/* Binning of one range: node box and, per axis, K bins (only axes with extent are filled). */
typedef struct sah_bins {
    rs_aabb node;
    sah_bin bin[3][RS_BVH_SAH_BINS_MAX];
} sah_bins;

typedef struct bin_map {
    float lo[3], k1[3]; /* bin = (c - lo) * k1, clamped to [0, K - 1] */
    int use[3];         /* axes with a positive centroid extent */
    uint32_t bins;
} bin_map;

/* The bin of coordinate x; a NaN lands in bin 0.  Binning and partitioning both use this, so a
 * primitive's side of a plane is the same in both. */
static uint32_t bin_of(const bin_map *m, int axis, float x)
{
    float f = (x - m->lo[axis]) * m->k1[axis];
    return f > 0.0f ? (f < (float)m->bins ? (uint32_t)f : m->bins - 1) : 0;
}

static void bins_clear(sah_bins *s, const bin_map *m)
{
    uint32_t a, i;
    s->node.lo = rs_v3_splat(INFINITY);
    s->node.hi = rs_v3_splat(-INFINITY);
    for (a = 0; a < 3; ++a)
        for (i = 0; m->use[a] && i < m->bins; ++i) {
            s->bin[a][i].box = s->node;
            s->bin[a][i].n = 0;
        }
}

static void bins_serial(const rs_bvh_ctx *c, const bin_map *m, uint32_t first, uint32_t count,
                        sah_bins *s)
{
    uint32_t i;
    int a;
    bins_clear(s, m);
    for (i = first; i < first + count; ++i) {
        uint32_t id = c->ids[i];
        rs_aabb b = c->bounds[id];
        rs_vec3 p = c->centroid[id];
        s->node.lo = rs_v3_min(s->node.lo, b.lo);
        s->node.hi = rs_v3_max(s->node.hi, b.hi);
        for (a = 0; a < 3; ++a) {
            sah_bin *bn;
            if (!m->use[a])
                continue;
            bn = &s->bin[a][bin_of(m, a, rs_v3_get(p, a))];
            bn->box.lo = rs_v3_min(bn->box.lo, b.lo);
            bn->box.hi = rs_v3_max(bn->box.hi, b.hi);
            bn->n++;
        }
    }
}

static void bins_merge(sah_bins *into, const sah_bins *from, const bin_map *m)
{
    uint32_t a, i;
    into->node.lo = rs_v3_min(into->node.lo, from->node.lo);
    into->node.hi = rs_v3_max(into->node.hi, from->node.hi);
    for (a = 0; a < 3; ++a)
        for (i = 0; m->use[a] && i < m->bins; ++i) {
            sah_bin *d = &into->bin[a][i];
            d->box.lo = rs_v3_min(d->box.lo, from->bin[a][i].box.lo);
            d->box.hi = rs_v3_max(d->box.hi, from->bin[a][i].box.hi);
            d->n += from->bin[a][i].n;
        }
}

static void bins_fill(const rs_bvh_ctx *c, const bin_map *m, uint32_t first, uint32_t count,
                      sah_bins *s)
{
    sah_bins part[RS_BVH_PAR_CHUNKS];
    uint32_t chunk = (count + RS_BVH_PAR_CHUNKS - 1) / RS_BVH_PAR_CHUNKS;
    int k;
    if (count < RS_BVH_PAR_RANGE) {
        bins_serial(c, m, first, count, s);
        return;
    }
#pragma omp taskloop grainsize(1) shared(part)
    for (k = 0; k < (int)RS_BVH_PAR_CHUNKS; ++k) {
        uint32_t lo = (uint32_t)k * chunk, hi = lo + chunk < count ? lo + chunk : count;
        bins_serial(c, m, first + lo, hi - lo, &part[k]);
    }
    *s = part[0];
    for (k = 1; k < (int)RS_BVH_PAR_CHUNKS; ++k)
        bins_merge(s, &part[k], m);
}

static double area_of(const rs_aabb *b)
{
    double x = (double)b->hi.x - b->lo.x, y = (double)b->hi.y - b->lo.y;
    double z = (double)b->hi.z - b->lo.z;
    return 2.0 * (x * y + y * z + z * x);
}

uint32_t rs_bvh_split_sah(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                          int *fallback)
{
    sah_bins s;
    bin_map m;
    rs_aabb cb = rs_bvh_centroid_bounds(c, first, count);
    double area, best = INFINITY, right_area[RS_BVH_SAH_BINS_MAX];
    uint32_t right_n[RS_BVH_SAH_BINS_MAX], k = c->builder.bins, i, j, best_plane = 0;
    int a, best_axis = -1;
    (void)depth;
    m.bins = k;
    for (a = 0; a < 3; ++a) {
        float lo = rs_v3_get(cb.lo, a), ext = rs_v3_get(cb.hi, a) - lo;
        m.lo[a] = lo;
        m.use[a] = ext > 0.0f && ext < INFINITY;
        m.k1[a] = m.use[a] ? (float)k / ext : 0.0f;
    }
    if (!m.use[0] && !m.use[1] && !m.use[2]) {
        /* every centroid the same: no plane separates them */
        if (count <= c->max_leaf)
            return 0;
        *fallback = 1;
        return count / 2;
    }
    bins_fill(c, &m, first, count, &s);
    area = area_of(&s.node);
    /* unnormalised costs: multiply both sides of the comparison by A */
    for (a = 0; a < 3; ++a) {
        rs_aabb acc;
        uint32_t n_acc = 0;
        if (!m.use[a])
            continue;
        /* right side of plane i (between bins i and i + 1): bins i + 1 .. k - 1.  An empty bin
         * adds nothing, so its plane repeats the next one's numbers (most bins of a small range
         * are empty: skipping them keeps the per-node cost low without changing the result) */
        acc = s.bin[a][k - 1].box;
        n_acc = s.bin[a][k - 1].n;
        right_area[k - 2] = n_acc ? area_of(&acc) : 0.0;
        right_n[k - 2] = n_acc;
        for (i = k - 2; i-- > 0;) {
            const sah_bin *bn = &s.bin[a][i + 1];
            if (bn->n == 0) {
                right_area[i] = right_area[i + 1];
                right_n[i] = n_acc;
                continue;
            }
            acc.lo = rs_v3_min(acc.lo, bn->box.lo);
            acc.hi = rs_v3_max(acc.hi, bn->box.hi);
            n_acc += bn->n;
            right_area[i] = area_of(&acc);
            right_n[i] = n_acc;
        }
        acc = s.bin[a][0].box;
        n_acc = 0;
        for (i = 0; i + 1 < k; ++i) {
            const sah_bin *bn = &s.bin[a][i];
            double cost;
            /* an empty bin i gives plane i the partition of plane i - 1: same cost, and the
             * strict comparison below keeps the lower plane anyway */
            if (bn->n == 0)
                continue;
            acc.lo = rs_v3_min(acc.lo, bn->box.lo);
            acc.hi = rs_v3_max(acc.hi, bn->box.hi);
            n_acc += bn->n;
            if (right_n[i] == 0)
                continue;
            cost = RS_BVH_COST_TRAV * area +
                   RS_BVH_COST_ISECT * (area_of(&acc) * blocks(c, n_acc) +
                                        right_area[i] * blocks(c, right_n[i]));
            if (cost < best) {
                best = cost;
                best_axis = a;
                best_plane = i;
            }
        }
    }
    if (best_axis < 0) {
        /* cannot happen with a positive extent (the extreme centroids fall in the first and the
         * last bin), but NaN coordinates are not worth trusting */
        if (count <= c->max_leaf)
            return 0;
        *fallback = 1;
        return count / 2;
    }
    if (count <= c->max_leaf && RS_BVH_COST_ISECT * blocks(c, count) * area <= best)
        return 0;
    /* partition: bins 0 .. best_plane to the left */
    i = first;
    j = first + count;
    while (i < j) {
        uint32_t id = c->ids[i];
        if (bin_of(&m, best_axis, rs_v3_get(c->centroid[id], best_axis)) <= best_plane) {
            ++i;
        } else {
            c->ids[i] = c->ids[--j];
            c->ids[j] = id;
        }
    }
    return i - first;
}
