/* scheduler/render.h — the wavefront render loop, and what both integrators share.
 *
 * Paths are numbered globally sample-major (g = sample * npix + pixel) and processed in waves of
 * at most `wave_paths` consecutive paths, so memory is bounded whatever the image size and spp,
 * and an interrupted render holds whole early passes.  Each wave runs the named stages of
 * rs_stage (scheduler/timeline.h) from a table in render.c:
 *
 *   raygen -> trace-closest -> shade -> [trace-shadow -> resolve-shadows] -> compact
 *               ^  (devices, through the scheduler)                            |
 *               +------------------ while paths are alive ---------------------+
 *   -> film: the wave's radiances added in path order (bit-reproducible), waves in wave order.
 *
 * Pipelining.  `waves_in_flight` waves (each of wave_paths / waves_in_flight paths) are worked
 * on at once, each in a slot that holds the index of its next stage.  The loop visits the slots
 * round robin and runs a slot's stages up to its next trace (a submission to the scheduler) or
 * its end, so the CPU shades one wave while the devices trace another.  The shading stages and
 * the CPU devices take their OpenMP teams from one core budget (`cores`), so the overlap does not
 * oversubscribe the machine.  Auto (0) means 2 waves when a device traces off the host (a GPU:
 * the shading then runs while the GPU traces) and 1 when every device runs on the host's cores,
 * where overlap only makes the devices and the shading take turns on the same cores (measured in
 * bench/scheduler_bench: docs/scheduler.md).
 *
 * Every stage is timed under its name (rs_render_stats.stage_s, --stats) and, with a timeline,
 * logged as a span on the render thread's lane.
 *
 * The image depends only on the seed and the settings below, not on devices, chunk sizes,
 * thread counts or the wave size. */
#ifndef RS_SCHEDULER_RENDER_H
#define RS_SCHEDULER_RENDER_H

#include <stdatomic.h>

#include "core/cores.h"
#include "scheduler/sched.h"
#include "scheduler/timeline.h"
#include "shading/film.h"
#include "shading/integrator.h"

typedef struct rs_render_settings {
    uint32_t width, height, spp;
    uint32_t max_depth; /* most ray segments per path, camera ray included */
    uint32_t rr_depth;  /* Russian roulette from this segment on; 0 means 3 */
    uint64_t seed;
    rs_sampling sampling;
    rs_sampler sampler;       /* independent (zeroed), sobol or zsobol */
    uint32_t wave_paths;      /* paths in flight; 0: auto (one CPU device: RS_RENDER_HOST_WAVE
                                 per thread on one core, RS_RENDER_HOST_WAVE_FREE per thread
                                 on more; RS_RENDER_DEFAULT_WAVE with a GPU or several
                                 devices) */
    uint32_t waves_in_flight; /* 1..RS_RENDER_MAX_WAVES; 0: auto (below) */
    int threads;              /* OpenMP threads for the shading stages (at most) */
    rs_cores *cores;          /* the budget shared with the CPU devices; NULL: none */
    rs_par_strategy strategy; /* how the shade stage splits a wave among threads */
    rs_timeline *timeline;    /* stage spans on lane `timeline_lane`; NULL: none */
    uint16_t timeline_lane;   /* the render thread's lane: the number of devices */
    uint64_t path_begin;      /* the film already holds paths [0, path_begin) of this render
                                 (a resumed checkpoint, app/checkpoint.h); the render adds the
                                 rest, [path_begin, width * height * spp).  0: a fresh film */
    /* A render of some pixels only, from a later sample on (adaptive sampling,
     * scheduler/adaptive.h; the stream integrator only): samples [sample_base, sample_base +
     * spp) of pixels[0, n_pixels) (distinct), of a render of spp_total samples per pixel (the
     * zsobol sampler's block; 0: spp).  NULL pixels: every pixel, samples from sample_base. */
    const uint32_t *pixels;
    uint32_t n_pixels, sample_base, spp_total;
} rs_render_settings;

#define RS_RENDER_DEFAULT_WAVE (1u << 20)
/* Paths in flight per shading thread when every device runs on the host: 16384 paths' buffers
 * (224 B each, streams/wave.h: 3.6 MB) stay in the caches from one stage to the next, where a
 * wave of 2^20 paths (235 MB) streams through memory at every stage and pays a page fault for
 * every 4 KB of its buffers once.  Cornell 256x256 16 spp on one thread: 0.76 s of stages
 * against 0.96 s (docs/performance.md). */
#define RS_RENDER_HOST_WAVE    16384u
/* The same when the process may use more than one core, so that the CPU device's dispatch thread
 * traces beside the stages: larger waves keep it busy (Cornell 300x300 16 spp, unpinned: 1.13 s
 * against 1.31 s at one thread, 0.68 s against 0.85 s at two). */
#define RS_RENDER_HOST_WAVE_FREE 131072u
#define RS_RENDER_MAX_WAVES    4u

typedef struct rs_render_stats {
    double seconds;                 /* wall time of rs_render */
    double stage_s[RS_STAGE_COUNT]; /* seconds the render thread spent in each stage (in the
                                       trace stages: waiting for the devices) */
    double trace_s, shade_s; /* the trace stages' sum / every other stage's (raygen to film) */
    uint64_t paths_total, paths_done;
    uint64_t rays_closest, rays_shadow;
    uint32_t waves;
    uint32_t max_bounce; /* deepest segment reached */
    int time_limited;    /* the time limit stopped it before paths_total (at a whole pass) */
} rs_render_stats;

typedef struct rs_render_hooks {
    /* Called from the render thread after every stage that ends paths; may be NULL. */
    void (*progress)(void *user, uint64_t paths_done, uint64_t paths_total);
    void *user;
    /* When non-NULL and set, the render stops at the next stage boundary: the current wave is
     * dropped, the film keeps every finished wave, and RS_ERR_CANCELLED is returned. */
    const atomic_int *cancel;
    /* > 0: once this many seconds of the render have passed, no new pass is begun: the paths up
     * to the end of the pass under way (sample-major numbering: a pass is npix paths) are
     * finished, so every pixel has the same number of samples, and RS_OK is returned with
     * stats->time_limited set.  At least one pass is always finished. */
    double time_limit_s;
    /* May be NULL.  Called from the render thread whenever the film holds exactly the paths
     * [0, paths_on_film) (after each wave is added; for the megakernel after each call of
     * render_pass); the film may be read, not written, during the call. */
    void (*film_ready)(void *user, const rs_film *film, uint64_t paths_on_film);
} rs_render_hooks;

/* Adds the counts and stage times of `r` to `sum` (a render made of several calls: adaptive
 * rounds, the gaps of a resumed checkpoint, an MPI rank's passes); `seconds` is left to the
 * caller, who knows the wall time of them all. */
void rs_render_stats_add(rs_render_stats *sum, const rs_render_stats *r);

/* Renders `scene` into `film` (whose size must match settings).  `hooks` may be NULL.  With
 * settings->path_begin > 0 the film must hold exactly paths [0, path_begin) of a render with
 * the same settings; the result is then the uninterrupted render's bit for bit, since each
 * pixel sums its samples in path order whatever the waves (stats count this call's paths). */
rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *settings,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

/* What both integrators check and share: the settings against the film (RS_ERR_ARG with a
 * message when a size is 0, the film does not match, the image has 2^32 pixels or more, or
 * path_begin lies past the render's paths), and
 * the render's device-safe constants *it (camera, seed, sizes, depths, sampling). */
rs_status rs_render_constants(const rs_scene *scene, const rs_render_settings *settings,
                              const rs_film *film, rs_integrator *it);

#endif
