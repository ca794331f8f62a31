/* bench/bvh_count.h — ray/box and ray/primitive tests per ray (the thesis's "total number of
 * ray-object intersection tests"), counted on one thread in a separate translation unit. */
#ifndef RS_BENCH_BVH_COUNT_H
#define RS_BENCH_BVH_COUNT_H

#include "accel/bvh.h"

void rs_bench_count_closest(const rs_bvh *bvh, const rs_geom *g, const rs_ray *rays, uint32_t n,
                            double *box_per_ray, double *prim_per_ray);

#endif
