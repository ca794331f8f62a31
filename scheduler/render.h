/* scheduler/render.h — the wavefront render loop.
 *
 * Paths are numbered globally sample-major (g = sample * npix + pixel) and processed in waves of
 * at most `wave_paths` consecutive paths, so memory is bounded whatever the image size and spp,
 * and an interrupted render holds whole early passes.  For each wave:
 *
 *   raygen ─► trace closest (scheduler ─► devices) ─► shade ─► trace shadows ─► resolve shadows
 *            ▲                                          │
 *            └──────────── compact next rays ◄─────────┘   ... until no path is alive
 *   then the wave's radiances are added to the film in path order (bit-reproducible).
 *
 * Pipelining.  `waves_in_flight` waves (each of wave_paths / waves_in_flight paths) are worked
 * on at once: the loop submits a wave's rays to the scheduler and, instead of waiting, shades the
 * wave whose rays were submitted before, so the CPU shades one wave while the devices trace the
 * other.  Waves are added to the film in wave order, whatever order they end in.  The shading
 * stages and the CPU devices take their OpenMP teams from one core budget (`cores`), so the
 * overlap does not oversubscribe the machine.  Auto (0) means 2 waves when a device traces off
 * the host (a GPU: the shading then runs while the GPU traces) and 1 when every device runs on
 * the host's cores, where overlap only makes the devices and the shading take turns on the same
 * cores (measured in bench/scheduler: docs/scheduler.md).
 *
 * The image depends only on the seed and the settings below, not on devices, chunk sizes,
 * thread counts or the wave size. */
#ifndef RS_SCHEDULER_RENDER_H
#define RS_SCHEDULER_RENDER_H

#include <stdatomic.h>

#include "core/cores.h"
#include "scheduler/sched.h"
#include "shading/film.h"
#include "shading/integrator.h"

typedef struct rs_render_settings {
    uint32_t width, height, spp;
    uint32_t max_depth; /* most ray segments per path, camera ray included */
    uint32_t rr_depth;  /* Russian roulette from this segment on; 0 means 3 */
    uint64_t seed;
    rs_sampling sampling;
    uint32_t wave_paths;      /* paths in flight; 0 means RS_RENDER_DEFAULT_WAVE */
    uint32_t waves_in_flight; /* 1..RS_RENDER_MAX_WAVES; 0: auto (below) */
    int threads;              /* OpenMP threads for the shading stages (at most) */
    rs_cores *cores;          /* the budget shared with the CPU devices; NULL: none */
    rs_par_strategy strategy; /* how the shade stage splits a wave among threads */
} rs_render_settings;

#define RS_RENDER_DEFAULT_WAVE (1u << 20)
#define RS_RENDER_MAX_WAVES    4u

typedef struct rs_render_stats {
    double seconds;          /* wall time of rs_render */
    double trace_s, shade_s; /* time waiting for traces / in the shading stages (incl. raygen) */
    uint64_t paths_total, paths_done;
    uint64_t rays_closest, rays_shadow;
    uint32_t waves;
    uint32_t max_bounce; /* deepest segment reached */
} rs_render_stats;

typedef struct rs_render_hooks {
    /* Called from the render thread after every stage that ends paths; may be NULL. */
    void (*progress)(void *user, uint64_t paths_done, uint64_t paths_total);
    void *user;
    /* When non-NULL and set, the render stops at the next stage boundary: the current wave is
     * dropped, the film keeps every finished wave, and RS_ERR_CANCELLED is returned. */
    const atomic_int *cancel;
} rs_render_hooks;

/* Renders `scene` into `film` (whose size must match settings).  `hooks` may be NULL. */
rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *settings,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

#endif
