/* cpu/megakernel.h — the classic integrator, as the thesis wrote it: one loop over the pixels,
 * each pixel's samples traced to the end one after the other (the recursive radiance() of Ray
 * Tracing in One Weekend, unrolled), the pixel loop split among OpenMP threads by one of the
 * thesis's strategies (core/parallel.h):
 *   for-dynamic  rows handed out dynamically (`parallel for schedule(dynamic)`);
 *   columns      each thread one contiguous block of image columns (the thesis's Fig. 5.1);
 *   tasks        a task per row, made by one thread, run by any (the thesis's Listing 5.8).
 * It is the baseline the wavefront engine must beat or explain (bench/ablation_bench).  It calls
 * the wavefront's own stages on streams of one path, with the same random numbers, and adds each
 * pixel's samples in sample order: its image is the wavefront's, bit for bit. */
#ifndef RS_CPU_MEGAKERNEL_H
#define RS_CPU_MEGAKERNEL_H

#include "scheduler/render.h"

typedef struct rs_megakernel_opts {
    rs_par_strategy strategy;
    uint32_t bvh_width; /* 4 (also 0): the 4-wide BVH where it applies; 2: the binary kernel */
} rs_megakernel_opts;

/* Renders like rs_render (settings->threads threads; waves, chunks and cores are ignored); the
 * scene's geometry `g` with the BVH `bvh` built over it.  Progress is reported per row; on
 * cancel the rows not started are left empty. */
rs_status rs_render_megakernel(const rs_scene *scene, const rs_geom *g, const rs_bvh *bvh,
                               const rs_render_settings *settings, const rs_megakernel_opts *opts,
                               const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

#endif
