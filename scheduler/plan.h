/* scheduler/plan.h — what a render does next: a work plan, in the numbering of its paths.
 *
 * Every path of a render is one sample of one pixel.  A plan covers the image's pixels, or a list
 * of them (adaptive sampling), and numbers its paths sample-major over those pixels:
 *
 *   path i  ->  pixel  pixels ? pixels[i mod n] : i mod n,   sample  i div n
 *
 * with n the plan's pixels (n_pixels, or every pixel).  n consecutive paths from a multiple of n
 * are a *pass*: every pixel of the plan once.  Over the whole image this is the numbering the
 * checkpoints record (app/checkpoint.h).  The plan holds the path ranges still to do, sorted; the
 * engine (scheduler/render.h) runs them in that order, and each pixel gets its samples in sample
 * order, so a render split into any plans is the one plan's bit for bit.
 *
 * Who makes plans: the plain render (one range), a resumed checkpoint (the gaps between what the
 * film holds), adaptive sampling (a pixel list per round), an MPI job (rank 0's plan, which the
 * coordinator cuts into passes of pass_samples; each pass a plan of its own on a rank).  A plan
 * also carries the render's time budget, decided by one rule (rs_work_plan_time_cut) wherever
 * passes are begun. */
#ifndef RS_SCHEDULER_PLAN_H
#define RS_SCHEDULER_PLAN_H

#include <stdint.h>

/* A set of paths: sorted, disjoint, non-touching ranges [lo, hi). */
#define RS_PATH_RANGES_MAX 65536u
typedef struct rs_path_ranges {
    uint64_t (*r)[2];
    uint32_t n, cap;
} rs_path_ranges;

/* Adds [lo, hi) to the set (joined with what it overlaps or touches).  0 when out of memory or
 * past RS_PATH_RANGES_MAX ranges. */
int rs_path_ranges_add(rs_path_ranges *s, uint64_t lo, uint64_t hi);
/* Adds every range of `b` to `a`; 0 as above. */
int rs_path_ranges_union(rs_path_ranges *a, const rs_path_ranges *b);
/* *out (empty) = [0, end) without `s`: what a film holding `s` still lacks.  0 as above. */
int rs_path_ranges_complement(const rs_path_ranges *s, uint64_t end, rs_path_ranges *out);
uint64_t rs_path_ranges_total(const rs_path_ranges *s);
/* Whether the set is one range from 0 (or empty): a prefix [0, total). */
int rs_path_ranges_is_prefix(const rs_path_ranges *s);
void rs_path_ranges_free(rs_path_ranges *s);

typedef struct rs_work_plan {
    rs_path_ranges todo;    /* the paths to render, in the plan's numbering */
    const uint32_t *pixels; /* the plan's pixels (distinct); NULL: every pixel of the image */
    uint32_t n_pixels;      /* with pixels: how many (the pass size) */
    uint32_t pass_samples;  /* samples of every pixel its driver deals out at once (an MPI job's
                               passes, --mpi-pass); 0: the driver's own choice */
    double time_limit_s;    /* > 0: the render's time budget (seconds since it began): past it
                               no new pass is begun (rs_work_plan_time_cut); 0: none */
} rs_work_plan;

/* The time limit's one rule, for every driver of plans (the engine's runs, adaptive sampling's
 * rounds, the MPI coordinator's passes): within p's budget (elapsed_s < p->time_limit_s, or no
 * budget) UINT64_MAX; past it, where the plan ends: the first whole pass (a sample of every pixel
 * of the plan, `npix` of them without a pixel list) at or after `begun` (the paths begun so far
 * end there), and, unless `first_done`, not before the end of the plan's first pass.  So every
 * pixel ends with the same samples, and a render always has one pass. */
uint64_t rs_work_plan_time_cut(const rs_work_plan *p, uint64_t npix, double elapsed_s,
                               uint64_t begun, int first_done);

/* A plan over every pixel: samples [s0, s1) of a render of `npix` pixels (0 when out of
 * memory).  Free with rs_work_plan_free. */
int rs_work_plan_samples(rs_work_plan *p, uint64_t npix, uint32_t s0, uint32_t s1);
void rs_work_plan_free(rs_work_plan *p);

#endif
