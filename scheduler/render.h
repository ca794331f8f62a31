/* scheduler/render.h — the render engine: set up once per render, then runs work plans.
 *
 * An engine (Cycles' Session is the model) is made once per render with the scene, the settings
 * and the way it traces: the stream engine through a scheduler's devices, or the megakernel on
 * one device.  It owns what costs to set up: the render's constants, the stream engine's wave
 * buffers (with a GPU, page-locked memory) or the megakernel's scene copy on its device.  Then
 * rs_engine_run runs any number of work plans (scheduler/plan.h) onto a film, and every driver
 * is a producer of plans: the plain render (one plan), a resumed checkpoint (its gaps), adaptive
 * sampling (a plan per round, scheduler/adaptive.h), an MPI rank (a plan per pass).  The time
 * limit is the engine's, checked in one place for every driver.
 *
 * The stream engine (stream_engine.c).  Paths are processed in waves of at most `wave_paths`
 * consecutive paths of the plan, so memory is bounded whatever the image size and spp.  Each
 * wave runs the named stages of rs_stage (scheduler/timeline.h) from the stage table in
 * stream_engine.c:
 *
 *   raygen -> trace-closest -> shade -> [trace-shadow -> resolve-shadows] -> compact
 *               ^  (devices, through the scheduler)                            |
 *               +------------------ while paths are alive ---------------------+
 *   -> film: the wave's radiances added in path order (bit-reproducible), waves in wave order.
 *
 * Pipelining.  `waves_in_flight` waves (each of wave_paths / waves_in_flight paths) are worked
 * on at once, each in a slot that holds the index of its next stage.  The loop visits the slots
 * round robin and runs a slot's stages up to its next wait for the devices or its end, so the
 * CPU shades one wave while the devices trace another.  The shading stages and the CPU devices
 * take their OpenMP teams from one core budget (`cores`), so the overlap does not oversubscribe
 * the machine.  Auto (0) means 2 waves when a device traces off the host (a GPU: the shading
 * then runs while the GPU traces) and 1 when every device runs on the host's cores, where
 * overlap only makes the devices and the shading take turns on the same cores
 * (docs/scheduler.md).
 *
 * The megakernel (passes.c): the thesis's classic integrator, each sample's path traced from
 * the camera to its end (shading/path.h's rs_path_step: the same per-path code and random
 * numbers) on one device through its render_pass entry (scheduler/device.h), in calls of
 * d->pass_samples samples, whole images only.
 *
 * Every stage is timed under its name (rs_render_stats.stage_s, --stats) and, with a timeline,
 * logged as a span on the render thread's lane.
 *
 * The image depends only on the seed and the settings below, not on devices, chunk sizes,
 * thread counts, the wave size, the integrator or how the paths are split into plans. */
#ifndef RS_SCHEDULER_RENDER_H
#define RS_SCHEDULER_RENDER_H

#include <stdatomic.h>

#include "core/cores.h"
#include "scheduler/plan.h"
#include "scheduler/sched.h"
#include "scheduler/timeline.h"
#include "shading/film.h"
#include "shading/integrator.h"

typedef struct rs_render_settings {
    uint32_t width, height;
    uint32_t spp;       /* samples per pixel of the whole render, all plans together */
    uint32_t max_depth; /* most ray segments per path, camera ray included */
    uint32_t rr_depth;  /* Russian roulette from this segment on; 0 means 3 */
    uint64_t seed;
    rs_sampling sampling;
    rs_sampler sampler;       /* independent (zeroed), sobol or zsobol */
    rs_filter filter;         /* the pixel filter (shading/filter.h); zeroed: a box of one
                                 pixel */
    uint32_t texture_filter;  /* rs_texture_filter (shading/texture.h); zeroed: trilinear */
    uint32_t light_sampler;   /* rs_light_sampler (shading/light_sampler.h); zeroed: by power */
    uint32_t passes;          /* 1: the devices write the film's passes (shading/film.h; the
                                 film must keep them: rs_film_keep_passes) */
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
    /* rs_render and rs_render_passes only: their plan's time budget (scheduler/plan.h
     * rs_work_plan.time_limit_s; the engine reads a plan's, counted from rs_engine_create:
     * past it no new pass is begun (a pass: every pixel of the plan once), the paths up to the
     * end of the pass under way are finished, so every pixel has the same number of samples,
     * the rest of the plan is dropped and the run returns RS_OK with stats->time_limited set.
     * At least one pass of the render is always finished). */
    double time_limit_s;
    uint64_t path_begin; /* rs_render and rs_render_passes only: the film already holds paths
                            [0, path_begin) of this render (a resumed checkpoint) */
} rs_render_settings;

#define RS_RENDER_DEFAULT_WAVE (1u << 20)
/* Paths in flight per shading thread when every device runs on the host: a wave's buffers
 * (streams/wave.h) then stay in the caches from one stage to the next, where a wave of 2^20
 * paths streams through memory at every stage (measured: docs/performance.md). */
#define RS_RENDER_HOST_WAVE 16384u
/* The same when the process may use more than one core, so that the CPU device's dispatch thread
 * traces beside the stages: larger waves keep it busy (docs/performance.md). */
#define RS_RENDER_HOST_WAVE_FREE 131072u
#define RS_RENDER_MAX_WAVES      4u
/* Devices of an engine that run paths whole (rs_engine_create_paths). */
#define RS_ENGINE_MAX_PATH_DEVICES 8

typedef struct rs_render_stats {
    double seconds;                 /* wall time of the run */
    double stage_s[RS_STAGE_COUNT]; /* seconds the render thread spent in each stage (in the
                                       trace stages: waiting for the devices) */
    double host_s; /* the render thread's own stages (raygen, shade, resolve, compact, film) */
    double wait_s; /* the render thread waiting for the devices (the trace stages) */
    uint64_t paths_total, paths_done;
    uint64_t rays_closest, rays_shadow;
    uint32_t waves;
    uint32_t max_bounce; /* deepest segment reached */
    int time_limited;    /* the time limit stopped it before paths_total (at a whole pass) */
    uint32_t wave_paths; /* paths per wave (the stream engine, as chosen) */
} rs_render_stats;

typedef struct rs_render_hooks {
    /* Called from the render thread after every stage that ends paths; may be NULL.  Counts
     * are the run's. */
    void (*progress)(void *user, uint64_t paths_done, uint64_t paths_total);
    void *user;
    /* When non-NULL and set, the run stops at the next stage boundary: the current wave is
     * dropped, the film keeps every finished wave, and RS_ERR_CANCELLED is returned. */
    const atomic_int *cancel;
    /* May be NULL.  Called from the render thread whenever the film holds exactly what it held
     * before the run plus the paths `done` of the plan (a prefix of the plan's ranges, in its
     * numbering; after each wave, for the megakernel after each call of render_pass); the film
     * may be read, not written, during the call. */
    void (*film_ready)(void *user, const rs_film *film, const rs_path_ranges *done);
} rs_render_hooks;

/* Adds the counts and stage times of `r` to `sum` (a render made of several runs); `seconds`
 * is left to the caller, who knows the wall time of them all. */
void rs_render_stats_add(rs_render_stats *sum, const rs_render_stats *r);

typedef struct rs_engine rs_engine;

/* An engine for rendering `scene` with `settings`: the stream engine through `sched`'s devices
 * (mk NULL), or the megakernel on device `mk` (sched NULL; already uploaded, with render_pass).
 * Checks the settings (RS_ERR_ARG with a message), allocates the wave buffers or runs the
 * device's upload_scene, and starts the time limit's clock.  Used from one thread. */
rs_status rs_engine_create(const rs_scene *scene, const rs_render_settings *settings,
                           rs_sched *sched, rs_device *mk, rs_engine **out);
/* An engine whose devices devs[0..n) (already uploaded, each with render_paths: a GPU) run
 * their paths whole: the stream engine's stages as each device's own wavefront
 * (gpu/wavefront.h), no ray crossing to the host.  With `sched` (NULL: none) the stream engine
 * runs beside them on the render thread, over the scheduler's devices (the CPU), shading on the
 * host as ever.  The plan's paths are dealt in ranges to whoever is free, sized by each one's
 * measured rate, and every device's samples go onto the one film with exact sums: any plan, any
 * split, the CPU stream engine's image bit for bit.  Each device gets upload_scene here. */
rs_status rs_engine_create_paths(const rs_scene *scene, const rs_render_settings *settings,
                                 rs_sched *sched, rs_device *const *devs, int n, rs_engine **out);
/* Renders the plan's paths onto `film` (the render's size): each pixel's samples are added in
 * sample order after what the film holds.  `hooks` may be NULL; *stats is this run's.  The
 * megakernel takes plans over every pixel, in whole samples (RS_ERR_ARG otherwise). */
rs_status rs_engine_run(rs_engine *e, const rs_work_plan *plan, const rs_render_hooks *hooks,
                        rs_film *film, rs_render_stats *stats);
/* The runs so far, summed (seconds: since rs_engine_create). */
void rs_engine_totals(const rs_engine *e, rs_render_stats *out);
/* The paths the last run put on its film (in its plan's numbering), kept until the next run. */
const rs_path_ranges *rs_engine_done(const rs_engine *e);
/* The settings with the automatic choices made (wave size, waves in flight). */
const rs_render_settings *rs_engine_settings(const rs_engine *e);
void rs_engine_destroy(rs_engine *e);

/* One plan, the whole render from settings->path_begin on, on an engine made for it: the
 * stream engine through `sched`, or (rs_render_passes) the megakernel on device `d`.  With
 * path_begin > 0 the film must hold exactly paths [0, path_begin) of a render with the same
 * settings; the result is then the uninterrupted render's bit for bit. */
rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *settings,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);
rs_status rs_render_passes(const rs_scene *scene, rs_device *d, const rs_render_settings *settings,
                           const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

/* The settings checked (RS_ERR_ARG with a message when a size is 0, the image has 2^32 pixels
 * or more, or path_begin lies past the render's paths) and the render's device-safe constants
 * *it over every pixel (camera, seed, sizes, depths, sampling). */
rs_status rs_render_constants(const rs_scene *scene, const rs_render_settings *settings,
                              rs_render_consts *it);

#endif
