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
    double time_limit_s; /* > 0: the render's time budget, every round's plan's (scheduler/
                            plan.h rs_work_plan.time_limit_s); 0: none */
} rs_adaptive;

typedef struct rs_adaptive_stats {
    uint32_t rounds;  /* plans run, the first (every pixel) included */
    uint64_t samples; /* samples taken, all pixels together */
    uint32_t stopped; /* pixels that stopped before spp */
} rs_adaptive_stats;

/* Where an adaptive render stands whenever the film holds whole waves: with the film (and its
 * squared-luminance sums) this is all a checkpoint needs to continue it bit for bit. */
typedef struct rs_adaptive_state {
    uint8_t *running;    /* per pixel: still sampled (in the round under way); NULL: not begun */
    uint32_t n;          /* samples every running pixel had when the round under way began */
    uint32_t step;       /* that round's samples per pixel; 0: no round under way, the next one
                            is decided from the film */
    uint64_t round_done; /* that round's paths on the film: the first round_done of its plan */
    rs_adaptive_stats stats;
} rs_adaptive_state;

/* A state for a film of `npix` pixels before any sample: every pixel running.  RS_ERR_NOMEM. */
rs_status rs_adaptive_state_init(rs_adaptive_state *s, uint32_t npix);
void rs_adaptive_state_free(rs_adaptive_state *s);
/* Whether `s` can be the state of a film with these counts (a checkpoint's): running pixels
 * have between n and n + step samples and the round's done paths, the others at most n. */
int rs_adaptive_state_fits(const rs_adaptive_state *s, const uint32_t *count, uint32_t npix,
                           uint32_t spp);

/* Adaptive sampling up to the engine's spp samples a pixel (a stream engine), as plans on
 * engine `e`, from *state: a fresh one (running NULL: the film must be empty, and then tracks
 * its variance) or one saved with the film (a checkpoint: the film holds its squared-luminance
 * sums).  *state follows the render: whenever hooks->film_ready is called it describes the
 * film, so a checkpoint written there continues to the same image.  The time limit (a's,
 * on every round's plan) ends the rounds (the last one on a whole pass of its pixels); progress counts a stopped
 * pixel's remaining samples as done.  *stats sums the rounds' (seconds: the whole). */
rs_status rs_adaptive_run(rs_engine *e, const rs_adaptive *a, rs_adaptive_state *state,
                          const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);
/* Runs one plan onto `film` with `hooks`, its statistics into *stats (paths_done, and
 * time_limited when the time limit cut it short: then the plan's first paths_done paths are on
 * the film): the engine's rs_engine_run, or an MPI job over the ranks (app/dist_glue.c). */
typedef rs_status (*rs_plan_runner)(void *user, const rs_work_plan *plan,
                                    const rs_render_hooks *hooks, rs_film *film,
                                    rs_render_stats *stats);
/* rs_adaptive_run with the plans run by `run` (up to `spp` samples a pixel): the rounds are
 * decided here, from `film`, whoever renders them. */
rs_status rs_adaptive_run_plans(rs_plan_runner run, void *user, uint32_t spp,
                                const rs_adaptive *a, rs_adaptive_state *state,
                                const rs_render_hooks *hooks, rs_film *film,
                                rs_render_stats *stats);
/* rs_adaptive_run from a fresh state, its statistics in *astats. */
rs_status rs_render_adaptive(rs_engine *e, const rs_adaptive *a, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats, rs_adaptive_stats *astats);

#endif
