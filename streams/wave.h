/* streams/wave.h — every buffer one wave of paths needs, allocated once per render (nothing per
 * chunk or per bounce).  Per path slot: two extension-ray streams (current and next, ping-pong),
 * the shadow rays, the hits, the occlusion byte, the shade stage's run records (three words,
 * streams/stream.h), the path state and the passes' record (streams/paths.h rs_path_aux):
 * 40 + 40 + 40 + 16 + 1 + 12 + 45 + 40 = 234 B.  The streams a device reads and writes (the
 * extension rays, the shadow rays, the hits and the occlusion bytes) come from the allocator
 * given (a GPU's page-locked host memory); the rest from rs_alloc. */
#ifndef RS_STREAMS_WAVE_H
#define RS_STREAMS_WAVE_H

#include "streams/paths.h"
#include "streams/stream.h"

typedef struct rs_wave_buffers {
    rs_ray_soa ext[2]; /* extension rays: current and next (ping-pong) */
    rs_ray_soa shadow; /* shadow rays */
    rs_hit_soa hits;
    uint8_t *occluded;
    rs_stream_runs runs; /* where the shade stage left the next and the shadow rays */
    rs_paths paths;
    rs_host_allocator alloc; /* where ext, shadow, hits and occluded came from */
    int pinned;              /* 1: `alloc` is a device's host_alloc */
} rs_wave_buffers;

#ifdef __cplusplus
extern "C" {
#endif
/* Buffers for `paths` path slots; `a` (NULL: rs_alloc) for the device-facing streams.  On
 * RS_ERR_NOMEM nothing stays allocated. */
rs_status rs_wave_buffers_create(uint32_t paths, const rs_host_allocator *a, rs_wave_buffers *b);
/* Frees everything; a zeroed struct is a no-op. */
void rs_wave_buffers_destroy(rs_wave_buffers *b);
#ifdef __cplusplus
}
#endif

#endif
