/* accel/trace.h — the trace kernel body: one ray of a batch, closest hit or occlusion.
 * The CPU device runs it in an OpenMP loop, the CUDA kernels one ray per thread, the fallback on
 * host threads: the very same function everywhere (rs_trace_one_flat where the geometry has no
 * instances).  The batch itself is streams/batch.h's. */
#ifndef RS_ACCEL_TRACE_H
#define RS_ACCEL_TRACE_H

#include "accel/bvh_traverse.h"
#include "streams/batch.h"

RS_HD_HOT void rs_trace_one_k(const rs_bvh_view *b, const rs_geom *g,
                              const rs_trace_batch *batch, uint32_t i, int inst)
{
    rs_ray r = rs_ray_soa_get(&batch->rays, i);
    if (batch->kind == RS_TRACE_CLOSEST) {
        rs_hit h;
        rs_bvh_closest_k(b, g, r, &h, inst);
        rs_hit_soa_set(&batch->hits, i, &h);
    } else {
        batch->occluded[i] = (uint8_t)rs_bvh_occluded_k(b, g, r, inst);
    }
}

RS_HD void rs_trace_one(const rs_bvh_view *b, const rs_geom *g, const rs_trace_batch *batch,
                        uint32_t i)
{
    rs_trace_one_k(b, g, batch, i, 1);
}

/* rs_trace_one for geometry without instances (g->n_instances == 0): the same answers, without
 * the bottom levels' code (accel/bvh_traverse.h): the GPU's flat trace kernels. */
RS_HD void rs_trace_one_flat(const rs_bvh_view *b, const rs_geom *g, const rs_trace_batch *batch,
                             uint32_t i)
{
    RS_ASSERT(g->n_instances == 0);
    rs_trace_one_k(b, g, batch, i, 0);
}

#endif
