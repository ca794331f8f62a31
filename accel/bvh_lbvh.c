/* accel/bvh_lbvh.c — the linear BVH (Lauterbach, Garland, Sengupta, Luebke, Manocha, "Fast BVH
 * construction on GPUs", Eurographics 2009; Karras, "Maximizing parallelism in the construction
 * of BVHs, octrees, and k-d trees", HPG 2012).
 *
 * 1. Morton codes.  Each centroid is quantised to a 1024^3 grid over the centroid bounds
 *    (10 bits per axis; an axis without extent quantises to 0) and its bits are interleaved
 *    x, y, z from the top into a 30-bit code (Karras's expandBits).
 * 2. Sort.  The (code, id) pairs are sorted by an LSD radix sort, 4 passes of 8 bits, each pass
 *    a histogram per chunk, a prefix sum in (digit, chunk) order and a stable scatter per chunk,
 *    the chunks running in parallel.  A stable sort's output is unique, so equal codes stay in
 *    ascending primitive order and the result does not depend on the thread count.
 * 3. Hierarchy.  The sorted range of a node is split where the highest bit in which its first
 *    and last codes differ turns from 0 to 1 (found by binary search; this is Lauterbach's
 *    bucketing by successive Morton bits, and the same radix tree that Karras builds with one
 *    thread per internal node, here built top-down by OpenMP tasks).  A range whose codes are
 *    all equal is split at its middle (a counted fallback), as is any split that would break the
 *    depth bound (bvh.c); since every bit split consumes a bit, depth <= 31 + ceil(log2(the
 *    longest run of equal codes)) in any case.  Ranges of at most max_leaf primitives are leaves.
 * 4. Bounds are then formed bottom-up by the frame: leaf boxes from their primitives, interior
 *    boxes as the union of the children's. */
#include "accel/internal.h"
#include "accel/morton.h"

#define SORT_CHUNKS 16
#define PAR_SORT    32768u

void rs_bvh_lbvh_frame(const rs_vec3 *centroid, uint32_t n, int threads, float lo[3],
                       float scale[3])
{
    rs_aabb part[SORT_CHUNKS], cb;
    uint32_t chunk = (n + SORT_CHUNKS - 1) / SORT_CHUNKS;
    int par = n >= PAR_SORT && threads > 1, k, a;
    (void)par; /* read only by the OpenMP clauses */

    /* centroid bounds, chunk by chunk (min and max merge exactly) */
#pragma omp parallel for num_threads(threads) if (par) schedule(static)
    for (k = 0; k < SORT_CHUNKS; ++k) {
        uint32_t j, end = (uint32_t)k * chunk + chunk < n ? (uint32_t)k * chunk + chunk : n;
        part[k].lo = rs_v3_splat(INFINITY);
        part[k].hi = rs_v3_splat(-INFINITY);
        for (j = (uint32_t)k * chunk; j < end; ++j) {
            part[k].lo = rs_v3_min(part[k].lo, centroid[j]);
            part[k].hi = rs_v3_max(part[k].hi, centroid[j]);
        }
    }
    cb = part[0];
    for (k = 1; k < SORT_CHUNKS; ++k) {
        cb.lo = rs_v3_min(cb.lo, part[k].lo);
        cb.hi = rs_v3_max(cb.hi, part[k].hi);
    }
    for (a = 0; a < 3; ++a) {
        float ext = rs_v3_get(cb.hi, a) - rs_v3_get(cb.lo, a);
        lo[a] = rs_v3_get(cb.lo, a);
        scale[a] = ext > 0.0f && ext < INFINITY ? 1024.0f / ext : 0.0f;
    }
}

void rs_bvh_lbvh_sort(const rs_vec3 *centroid, uint32_t n, uint32_t *ids, uint32_t *codes,
                      uint32_t *codes_tmp, uint32_t *ids_tmp, int threads)
{
    uint32_t counts[SORT_CHUNKS][256], chunk = (n + SORT_CHUNKS - 1) / SORT_CHUNKS;
    uint32_t *src_c = codes, *src_i = ids, *dst_c = codes_tmp, *dst_i = ids_tmp, *t;
    float lo[3], scale[3];
    int par = n >= PAR_SORT && threads > 1, k, pass;
    (void)par; /* read only by the OpenMP clauses */
    long i;

    rs_bvh_lbvh_frame(centroid, n, threads, lo, scale);
#pragma omp parallel for num_threads(threads) if (par) schedule(static)
    for (i = 0; i < (long)n; ++i) {
        codes[i] = rs_morton3(centroid[ids[i]], lo, scale);
    }

    for (pass = 0; pass < 4; ++pass) {
        int shift = 8 * pass;
        uint32_t run = 0, d;
#pragma omp parallel for num_threads(threads) if (par) schedule(static)
        for (k = 0; k < SORT_CHUNKS; ++k) {
            uint32_t j, end = (uint32_t)k * chunk + chunk < n ? (uint32_t)k * chunk + chunk : n;
            for (j = 0; j < 256; ++j)
                counts[k][j] = 0;
            for (j = (uint32_t)k * chunk; j < end; ++j)
                counts[k][(src_c[j] >> shift) & 255u]++;
        }
        /* exclusive prefix in (digit, chunk) order: chunk k's digit-d items follow those of
         * every smaller digit and of digit d in earlier chunks, which keeps the sort stable */
        for (d = 0; d < 256; ++d)
            for (k = 0; k < SORT_CHUNKS; ++k) {
                uint32_t c = counts[k][d];
                counts[k][d] = run;
                run += c;
            }
#pragma omp parallel for num_threads(threads) if (par) schedule(static)
        for (k = 0; k < SORT_CHUNKS; ++k) {
            uint32_t j, end = (uint32_t)k * chunk + chunk < n ? (uint32_t)k * chunk + chunk : n;
            for (j = (uint32_t)k * chunk; j < end; ++j) {
                uint32_t at = counts[k][(src_c[j] >> shift) & 255u]++;
                dst_c[at] = src_c[j];
                dst_i[at] = src_i[j];
            }
        }
        t = src_c, src_c = dst_c, dst_c = t;
        t = src_i, src_i = dst_i, dst_i = t;
    }
    /* an even number of passes: the result is back in codes and ids */
    RS_ASSERT(src_c == codes && src_i == ids);
}

uint32_t rs_bvh_split_lbvh(const rs_bvh_ctx *c, uint32_t first, uint32_t count, uint32_t depth,
                           int *fallback)
{
    const uint32_t *k = c->codes + first;
    uint32_t x, lo, hi;
    (void)depth;
    if (count <= c->max_leaf)
        return 0;
    if (k[0] == k[count - 1]) {
        *fallback = 1;
        return count / 2;
    }
    /* the highest bit in which the first and last codes differ: the codes are sorted, so every
     * code of the range agrees with both above it, and those with the bit clear come first */
    x = k[0] ^ k[count - 1];
    x |= x >> 1;
    x |= x >> 2;
    x |= x >> 4;
    x |= x >> 8;
    x |= x >> 16;
    x ^= x >> 1;
    lo = 0;
    hi = count - 1; /* k[lo] has the bit clear, k[hi] set */
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (k[mid] & x)
            hi = mid;
        else
            lo = mid;
    }
    return hi;
}
