/* accel/trace.h — the trace kernel body: one ray of a batch, closest hit or occlusion.
 * The CPU device runs it in an OpenMP loop, the CUDA kernels one ray per thread, the fallback on
 * host threads: the very same function everywhere. */
#ifndef RS_ACCEL_TRACE_H
#define RS_ACCEL_TRACE_H

#include <string.h>

#include "accel/bvh.h"
#include "streams/stream.h"

typedef enum rs_trace_kind {
    RS_TRACE_CLOSEST = 0, /* fill hits[i] */
    RS_TRACE_OCCLUDED = 1 /* fill occluded[i] */
} rs_trace_kind;

/* A batch of rays to trace and where the answers go.  `kind` is stored as uint32_t (fixed width
 * on host and device).  Exactly one of hits / occluded is used, according to kind. */
typedef struct rs_trace_batch {
    uint32_t kind;
    uint32_t count;
    rs_ray_soa rays;
    rs_hit_soa hits;
    uint8_t *occluded;
} rs_trace_batch;

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

/* Staging, for devices that trace a chunk in buffers of their own (the CUDA device's pinned
 * buffers, the fallback's): rays [begin, begin + n) of the batch into entries [0, n) of `rays`,
 * and the answers back.  Each returns the bytes it moved. */
static inline uint64_t rs_trace_stage_in(rs_ray_soa *rays, const rs_trace_batch *batch,
                                         uint32_t begin, uint32_t n)
{
#define RS_STAGE_IN(type, name) memcpy(rays->name, batch->rays.name + begin, n * sizeof(type));
    RS_RAY_FIELDS(RS_STAGE_IN)
#undef RS_STAGE_IN
    return (uint64_t)n * RS_RAY_BYTES;
}

static inline uint64_t rs_trace_stage_out(const rs_trace_batch *batch, uint32_t begin, uint32_t n,
                                          const rs_hit_soa *hits, const uint8_t *occluded)
{
    if (batch->kind == RS_TRACE_CLOSEST) {
#define RS_STAGE_OUT(type, name) memcpy(batch->hits.name + begin, hits->name, n * sizeof(type));
        RS_HIT_FIELDS(RS_STAGE_OUT)
#undef RS_STAGE_OUT
        return (uint64_t)n * RS_HIT_BYTES;
    }
    memcpy(batch->occluded + begin, occluded, n);
    return n;
}

#endif
