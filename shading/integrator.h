/* shading/integrator.h — the path tracer as wavefront stages: raygen, shade, resolve shadows.
 *
 * The render loop (scheduler/render.c) owns the buffers and calls the stages in order; devices
 * trace between them.  Each stage is a parallel loop over one stream and writes each path's
 * state only from that path's own slot, so results do not depend on thread count or order.
 *
 * A path is named by its index in the wave; its global index g = wave_start + path gives the
 * pixel (g mod npix) and the sample (g div npix), and with the bounce, the random numbers.
 * Each stage is a loop around the RS_HD per-path code of shading/path.h. */
#ifndef RS_SHADING_INTEGRATOR_H
#define RS_SHADING_INTEGRATOR_H

#include "shading/path.h"
#include "streams/stream.h"

#ifdef __cplusplus
extern "C" {
#  ifdef __cplusplus
}
#  endif

#endif

const char *rs_sampling_name(rs_sampling s);
/* Parses "mis", "mixture", "bsdf" or "uniform"; returns 0 if unknown. */
int rs_sampling_parse(const char *text, rs_sampling *out);

/* Per-path state of one wave (SoA, indexed by path). */
typedef struct rs_paths {
    rs_vec3 *throughput; /* product of f cos / pdf so far */
    rs_vec3 *radiance;   /* light gathered so far */
    rs_vec3 *pending;    /* next-event contribution waiting for its shadow ray */
    float *bsdf_pdf;     /* solid-angle pdf of the BSDF sample that made the current ray */
    float *time;         /* the path's time in the shutter interval (its rays share it) */
    uint8_t *flags;      /* RS_PATH_* */
    uint32_t capacity;
} rs_paths;

rs_status rs_paths_init(rs_paths *p, uint32_t capacity);
void rs_paths_free(rs_paths *p);

/* Fills `out` with the camera rays of paths [0, count) and resets their state. */
void rs_integrator_raygen(const rs_integrator *it, uint64_t wave_start, uint32_t count,
                          rs_paths *paths, rs_ray_soa *out);

/* Shades the hits of `rays` (segment number `bounce`).  For each input slot j it may write the
 * path's next ray to slot j of `next` (next_valid[j] = 1) and a shadow ray to slot j of
 * `shadow` (shadow_valid[j] = 1, contribution in paths->pending). */
void rs_integrator_shade(const rs_integrator *it, uint64_t wave_start, uint32_t bounce,
                         const rs_ray_soa *rays, const rs_hit_soa *hits, uint32_t count,
                         rs_paths *paths, rs_ray_soa *next, uint8_t *next_valid, rs_ray_soa *shadow,
                         uint8_t *shadow_valid);

/* Adds each unoccluded shadow ray's pending contribution to its path. */
void rs_integrator_resolve_shadows(const rs_integrator *it, const rs_ray_soa *shadow,
                                   const uint8_t *occluded, uint32_t count, rs_paths *paths);

/* Compacts the valid entries of src[0, count) into dst, keeping their order; returns how many.
 * Deterministic for any thread count (a blocked two-pass scan). */
uint32_t rs_stream_compact(const rs_ray_soa *src, const uint8_t *valid, uint32_t count,
                           rs_ray_soa *dst, int threads);

#ifdef __cplusplus
}
#endif

#endif
