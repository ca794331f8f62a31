/* scheduler/adaptive.h — adaptive sampling (`--adaptive THRESHOLD`): pixels stop once their
 * error estimate is below the threshold, as Cycles' do, so that the samples go where the noise
 * is.
 *
 * Every pixel first gets min_spp samples.  Then, in rounds, the pixels still running whose
 * relative error (rs_film_rel_error: the standard error of the mean luminance over the mean)
 * is above the threshold, and their eight neighbours (so that a converged patch's edge keeps up
 * with the noise beside it), get a quarter more samples each (at least 4, up to spp), by a
 * plan over just those pixels (scheduler/plan.h), run by the render's one engine; the others
 * stop for good.  Which pixels go on is decided from the film alone,
 * between rounds, and each path keeps its (pixel, sample) and with them its random numbers: so
 * the image does not depend on the devices, threads, chunks or waves (the stream engine's rule),
 * a pixel that stops after n samples is exactly that pixel of an n-sample render, and one that
 * never stops is the full render's. */
#ifndef RS_SCHEDULER_ADAPTIVE_H
#define RS_SCHEDULER_ADAPTIVE_H

#include "scheduler/render.h"

typedef struct rs_adaptive {
    double threshold; /* > 0: a pixel stops once its relative error is at most this */
    uint32_t min_spp; /* every pixel's first samples, before any stops (at most spp; >= 2) */
} rs_adaptive;

typedef struct rs_adaptive_stats {
    uint32_t rounds;  /* renders, the first (every pixel) included */
    uint64_t samples; /* samples taken, all pixels together */
    uint32_t stopped; /* pixels that stopped before spp */
} rs_adaptive_stats;

/* Adaptive sampling up to the engine's spp samples a pixel (a stream engine, a fresh film), as
 * plans on engine `e`.  hooks as rs_engine_run's but film_ready, which must be NULL; the
 * engine's time limit ends the rounds (the last one on a whole pass of its pixels); progress
 * counts a stopped pixel's remaining samples as done.  *stats sums the rounds' (seconds: the
 * whole). */
rs_status rs_render_adaptive(rs_engine *e, const rs_adaptive *a, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats, rs_adaptive_stats *astats);

#endif
