/* bench/bvh_count.c — the counting pass of bvh_bench: this translation unit alone compiles the
 * traversal with RS_COUNTERS, so the timed traversal in bvh_bench.c carries no counting. */
#define RS_COUNTERS 1
#include "bvh_count.h"

void rs_bench_count_closest(const rs_bvh *bvh, const rs_geom *g, const rs_ray *rays, uint32_t n,
                            double *box_per_ray, double *prim_per_ray)
{
    rs_bvh_view v = rs_bvh_view_of(bvh);
    rs_trace_counters before = rs_counters;
    uint32_t i;
    for (i = 0; i < n; ++i) {
        rs_hit h;
        rs_bvh_closest(&v, g, rays[i], &h);
    }
    *box_per_ray = (double)(rs_counters.box_tests - before.box_tests) / (n ? n : 1);
    *prim_per_ray = (double)(rs_counters.prim_tests - before.prim_tests) / (n ? n : 1);
}
