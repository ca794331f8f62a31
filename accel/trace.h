/* accel/trace.h — the trace kernel body: one ray of a batch, closest hit or occlusion.
 * The CPU device runs it in an OpenMP loop, the CUDA kernels one ray per thread, the fallback on
 * host threads: the very same function everywhere.  The batch itself is streams/batch.h's. */
#ifndef RS_ACCEL_TRACE_H
#define RS_ACCEL_TRACE_H

#include "accel/bvh_traverse.h"
#include "streams/batch.h"

RS_HD void rs_trace_one(const rs_bvh_view *b, const rs_geom *g, const rs_trace_batch *batch,
                        uint32_t i)
{
    rs_ray r = rs_ray_soa_get(&batch->rays, i);
    if (batch->kind == RS_TRACE_CLOSEST) {
        rs_hit h;
        rs_bvh_closest(b, g, r, &h);
        rs_hit_soa_set(&batch->hits, i, &h);
    } else {
        batch->occluded[i] = (uint8_t)rs_bvh_occluded(b, g, r);
    }
}

#endif
