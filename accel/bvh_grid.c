/* accel/bvh_grid.c — the thesis's top-down builders (§5.7.2, measured in Table 6.5) and the
 * median builder, which is one of them.
 *
 * Every node's range is cut at its middle, m = count / 2 (the thesis's `m = start + N/2`), after
 * ordering the range on one axis by one key.  The three choices:
 *   axis        random (Shirley, "Ray Tracing in One Weekend" v4), rotational x, y, z, x, ...
 *               by depth (Shirley et al., "The Next Week" 2021), or the largest extent of the
 *               node's centroid bounds (Pharr et al., PBRT 4th ed. §7.3);
 *   partition   full sort (std::sort), partial sort of the lower half (std::partial_sort) or
 *               selection of the m-th element (std::nth_element): the two halves hold the same
 *               primitives up to ties, only the work (and the order inside a half) differs;
 *   comparator  the min corner, the max corner or the centre of the primitives' boxes.
 * Each split halves the range, so depth <= ceil(log2(n)) + 1 whatever the input, and with
 * identical keys a split is still made (by position in the range).  Leaves are made when the
 * range holds at most max_leaf primitives (the thesis stops at 1 or 2).
 *
 * RS_BVH_MEDIAN is largest-nth-centroid, and its quickselect is the one this file always had, so
 * it builds the very tree the original builder built.
 *
 * The random axis is a hash of the node (its range and depth) with a fixed seed instead of a
 * shared generator, so the tree is the same for any thread count and from run to run.
 * Sorting works on (key, id) pairs copied into the scratch array for the node's range, which
 * keeps the comparisons on contiguous memory. */
#include "accel/internal.h"

static float key_of(const rs_bvh_ctx *c, uint32_t id, int axis, uint32_t key)
{
    switch (key) {
    case RS_BVH_KEY_MIN: return rs_v3_get(c->bounds[id].lo, axis);
    case RS_BVH_KEY_MAX: return rs_v3_get(c->bounds[id].hi, axis);
    default: return rs_v3_get(c->centroid[id], axis);
    }
}

/* The finaliser of MurmurHash3 (Appleby): a well-mixed 32-bit hash. */
static uint32_t fmix32(uint32_t h)
{
    h ^= h >> 16;
    h *= 0x85ebca6bu;
    h ^= h >> 13;
    h *= 0xc2b2ae35u;
    h ^= h >> 16;
    return h;
}

static int random_axis(uint32_t first, uint32_t count, uint32_t depth)
{
    uint32_t h = fmix32(0x5eed1234u ^ fmix32(first ^ fmix32(count ^ fmix32(depth))));
    return (int)(h % 3u);
}

/* The axis of largest extent, ties to the lower axis: exactly the original builder's rule. */
static int largest_axis(const rs_bvh_ctx *c, uint32_t first, uint32_t count)
{
    rs_aabb cb = rs_bvh_centroid_bounds(c, first, count);
    rs_vec3 ext = rs_v3_sub(cb.hi, cb.lo);
    return (ext.x >= ext.y && ext.x >= ext.z) ? 0 : (ext.y >= ext.z ? 1 : 2);
}

/* Quickselect with a three-way partition: reorders p[0, n) so that p[k] holds the element of
 * rank k, nothing larger before it and nothing smaller after it.  Elements that compare neither
 * less nor greater than the pivot (equal, or NaN) stay in the middle block, so every round
 * shrinks the range and the loop ends.  (The original builder's select_kth, on pairs.) */
static void select_kth(rs_bvh_key_id *p, uint32_t n, uint32_t k)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        float pivot = p[lo + (hi - lo) / 2].key;
        uint32_t lt = lo, i = lo, gt = hi;
        rs_bvh_key_id t;
        while (i < gt) {
            float x = p[i].key;
            if (x < pivot) {
                t = p[lt];
                p[lt++] = p[i];
                p[i++] = t;
            } else if (x > pivot) {
                t = p[--gt];
                p[gt] = p[i];
                p[i] = t;
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

/* Stable bottom-up merge sort of p[0, n) by key, using tmp[0, n): insertion sort of runs of 16,
 * then rounds of merges that alternate between the two arrays.  O(n log n) comparisons; with NaN
 * keys the order is unspecified but the result is still a permutation. */
static void merge_sort(rs_bvh_key_id *p, rs_bvh_key_id *tmp, uint32_t n)
{
    enum { RUN = 16 };
    rs_bvh_key_id *src = p, *dst = tmp, *sw;
    uint32_t i, j, w;
    for (i = 0; i < n; i += RUN) {
        uint32_t end = i + RUN < n ? i + RUN : n;
        for (j = i + 1; j < end; ++j) {
            rs_bvh_key_id x = p[j];
            uint32_t k = j;
            while (k > i && x.key < p[k - 1].key) {
                p[k] = p[k - 1];
                --k;
            }
            p[k] = x;
        }
    }
    for (w = RUN; w < n; w *= 2) { /* w < n < 2^31: no overflow */
        for (i = 0; i < n; i += 2 * w) {
            uint32_t mid = i + w < n ? i + w : n, end = i + 2 * w < n ? i + 2 * w : n;
            uint32_t a = i, b = mid, o = i;
            while (a < mid && b < end)
                dst[o++] = (src[b].key < src[a].key) ? src[b++] : src[a++];
            while (a < mid)
                dst[o++] = src[a++];
            while (b < end)
                dst[o++] = src[b++];
        }
        sw = src;
        src = dst;
        dst = sw;
    }
    if (src != p)
        for (i = 0; i < n; ++i)
            p[i] = src[i];
}

/* Restores the max-heap property of h[0, n) below position i. */
static void sift_down(rs_bvh_key_id *h, uint32_t n, uint32_t i)
{
    for (;;) {
        uint32_t l = 2 * i + 1, r = l + 1, top = i;
        rs_bvh_key_id t;
        if (l < n && h[top].key < h[l].key)
            top = l;
        if (r < n && h[top].key < h[r].key)
            top = r;
        if (top == i)
            return;
        t = h[i];
        h[i] = h[top];
        h[top] = t;
        i = top;
    }
}

/* std::partial_sort(p, p + m, p + n) as libstdc++ does it: a max-heap of the first m elements,
 * each later element smaller than the heap's top replaces it, then the heap is sorted.  After
 * it p[0, m) holds the m smallest keys in order; p[m, n) the rest, unordered.  O(n log m). */
static void partial_sort(rs_bvh_key_id *p, uint32_t m, uint32_t n)
{
    uint32_t i;
    rs_bvh_key_id t;
    if (m == 0)
        return;
    for (i = m / 2; i-- > 0;)
        sift_down(p, m, i);
    for (i = m; i < n; ++i) {
        if (p[i].key < p[0].key) {
            t = p[0];
            p[0] = p[i];
            p[i] = t;
            sift_down(p, m, 0);
        }
    }
    for (i = m; i-- > 1;) {
        t = p[0];
        p[0] = p[i];
        p[i] = t;
        sift_down(p, i, 0);
    }
}

/* Orders ids[first, first + count) by `key` on `axis` with `partition` and returns count / 2. */
static uint32_t split_middle(const rs_bvh_ctx *c, uint32_t first, uint32_t count, int axis,
                             uint32_t partition, uint32_t key)
{
    rs_bvh_key_id *p = c->pairs + first;
    uint32_t *ids = c->ids + first, i, mid = count / 2;
    for (i = 0; i < count; ++i) {
        p[i].key = key_of(c, ids[i], axis, key);
        p[i].id = ids[i];
    }
    switch (partition) {
    case RS_BVH_PART_SORT: merge_sort(p, c->pairs2 + first, count); break;
    case RS_BVH_PART_PARTIAL: partial_sort(p, mid, count); break;
    default: select_kth(p, count, mid); break;
    }
    for (i = 0; i < count; ++i)
        ids[i] = p[i].id;
    return mid;
}

uint32_t rs_bvh_split_median(const rs_bvh_ctx *c, uint32_t first, uint32_t count)
{
    return split_middle(c, first, count, largest_axis(c, first, count), RS_BVH_PART_NTH,
                        RS_BVH_KEY_CENTROID);
}

uint32_t rs_bvh_split_grid(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                           int *fallback)
{
    const rs_bvh_builder *b = &c->builder;
    int axis;
    (void)fallback; /* halving always splits */
    if (count <= c->max_leaf)
        return 0;
    if (b->method == RS_BVH_MEDIAN)
        return rs_bvh_split_median(c, first, count);
    switch (b->axis) {
    case RS_BVH_AXIS_RANDOM: axis = random_axis(first, count, depth); break;
    case RS_BVH_AXIS_ROTATIONAL: axis = (int)((depth - 1) % 3); break;
    default: axis = largest_axis(c, first, count); break;
    }
    return split_middle(c, first, count, axis, b->partition, b->key);
}
