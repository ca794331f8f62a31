/* streams/batch.h — a batch of rays to trace and where the answers go, and the range copies
 * that devices with buffers of their own (the CUDA device's, the fallback's) stage a chunk with.
 * What traces a batch is accel/trace.h's rs_trace_one. */
#ifndef RS_STREAMS_BATCH_H
#define RS_STREAMS_BATCH_H

#include <string.h>

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
    uint32_t wave;   /* the wave the rays belong to (for the timeline) */
    uint32_t pinned; /* 1: the arrays came from a device's host_alloc (page-locked): a GPU copies
                        ranges of them by DMA without staging */
    rs_ray_soa rays;
    rs_hit_soa hits;
    uint8_t *occluded;
} rs_trace_batch;

/* Staging: rays [begin, begin + n) of the batch into entries [0, n) of `rays`, and the answers
 * back.  Each returns the bytes it moved. */
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
