/* shading/integrator.h — the stream engine's host stages of the path tracer: raygen, shade,
 * resolve shadows (rs_stage_*), with the host-only constants they read besides the render's.
 *
 * The render loop (scheduler/stream_engine.c) owns the buffers and calls the stages in order;
 * devices trace between them.  Each stage is a parallel loop over one stream and writes each path's
 * state only from that path's own slot, so results do not depend on thread count or order.
 *
 * A path is named by its index in the wave; its global index g = wave_start + path gives, through
 * the plan's rs_path_map, the pixel and the sample, and with the bounce, the random numbers.
 * Each stage is a loop around the RS_HD per-path code of shading/path.h. */
#ifndef RS_SHADING_INTEGRATOR_H
#define RS_SHADING_INTEGRATOR_H

#include "shading/path.h"
#include "streams/paths.h"
#include "streams/stream.h"

#include "core/parallel.h"

#ifdef __cplusplus
extern "C" {
#endif

const char *rs_sampling_name(rs_sampling s);
/* Parses "mis", "mixture", "bsdf" or "uniform"; returns 0 if unknown. */
int rs_sampling_parse(const char *text, rs_sampling *out);

const char *rs_sampler_name(rs_sampler s);
/* Parses "independent", "sobol" or "zsobol"; returns 0 if unknown. */
int rs_sampler_parse(const char *text, rs_sampler *out);

/* How a stage runs on the host: up to `threads` OpenMP threads, split as `strategy` says (the
 * render loop takes the threads from its core budget for each stage). */
typedef struct rs_stage_exec {
    int threads;
    rs_par_strategy strategy;
} rs_stage_exec;

/* Which pixel and sample each path of the plan being run is (scheduler/plan.h): host memory,
 * read only by the stream engine's host stages and its film stage, never by a device (the
 * megakernel runs only plans over every pixel, scheduler/engine.c).  Path g is pixel
 * pixel_of[g mod n_active] (NULL: g mod n_active itself, n_active = npix), sample g div
 * n_active. */
typedef struct rs_path_map {
    const uint32_t *pixel_of;
    uint32_t n_active;
} rs_path_map;

/* Pixel and sample of path g. */
static inline uint32_t rs_path_map_pixel(const rs_path_map *m, uint64_t g)
{
    uint32_t k = (uint32_t)(g % m->n_active);
    return m->pixel_of ? m->pixel_of[k] : k;
}
static inline uint32_t rs_path_map_sample(const rs_path_map *m, uint64_t g)
{
    return (uint32_t)(g / m->n_active);
}

/* Fills `out` with the camera rays of paths [0, count) and resets their state. */
void rs_stage_raygen(const rs_render_consts *it, const rs_path_map *map, const rs_stage_exec *ex,
                     uint64_t wave_start, uint32_t count, rs_paths *paths, rs_ray_soa *out);

/* Shades the hits of `rays` (segment number `bounce`): each path may make its next ray and a
 * shadow ray (its contribution in paths->pending).  The stream is split into ranges (by the
 * strategy); each range writes its next rays packed from its first slot in `next` and its
 * shadow rays likewise in `shadow` (within each batch of 64 entries those the eight-lane code
 * shades first, then the others in slot order: the order of a stream's rays changes no answer,
 * only which rays walk the tree together), and records the counts in `runs` (first: next rays,
 * second: shadow rays); rs_stream_pack_runs then packs each stream (the ranges' rays in range
 * order, whatever the split). */
void rs_stage_shade(const rs_render_consts *it, const rs_path_map *map, const rs_stage_exec *ex,
                    uint64_t wave_start, uint32_t bounce, const rs_ray_soa *rays,
                    const rs_hit_soa *hits, uint32_t count, rs_paths *paths, rs_ray_soa *next,
                    rs_ray_soa *shadow, const rs_stream_runs *runs);

/* Adds each unoccluded shadow ray's pending contribution to its path. */
void rs_stage_resolve_shadows(const rs_stage_exec *ex, const rs_ray_soa *shadow,
                              const uint8_t *occluded, uint32_t count, rs_paths *paths);

#ifdef __cplusplus
}
#endif

#endif
