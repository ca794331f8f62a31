/* cpu/megakernel.h — the classic integrator, as the thesis wrote it: one loop over the pixels,
 * each pixel's samples traced to the end one after the other (the recursive radiance() of Ray
 * Tracing in One Weekend, unrolled), the pixel loop split among OpenMP threads by one of the
 * thesis's strategies (core/parallel.h):
 *   for-dynamic  rows handed out dynamically (`parallel for schedule(dynamic)`);
 *   columns      each thread one contiguous block of image columns (the thesis's Fig. 5.1);
 *   tasks        a task per row, made by one thread, run by any (the thesis's Listing 5.8).
 * It is the baseline the wavefront engine must beat or explain (bench/ablation_bench).  Each path
 * is rs_path_radiance (shading/path.h): the wavefront's own per-path code with the same random
 * numbers, and each pixel's samples are added in sample order: its image is the wavefront's, bit
 * for bit.  The CUDA megakernel (gpu/cuda_megakernel.cu) runs the same function per pixel. */
#ifndef RS_CPU_MEGAKERNEL_H
#define RS_CPU_MEGAKERNEL_H

#include "scheduler/render.h"

/* Where the megakernel runs. */
typedef enum rs_megakernel_device {
    RS_MK_CPU = 0,         /* the pixel loop above on the CPU's threads */
    RS_MK_CUDA = 1,        /* CUDA device gpu_index: one thread per pixel, one pass per sample */
    RS_MK_GPU_FALLBACK = 2 /* the CUDA megakernel's passes on host threads, the binary BVH (where
                              the GPU cannot be used) */
} rs_megakernel_device;

typedef struct rs_megakernel_opts {
    rs_par_strategy strategy; /* how threads split the pixels (CPU and fallback) */
    uint32_t bvh_width; /* CPU: 4 (also 0): the 4-wide BVH where it applies; 2: the binary kernel */
    rs_megakernel_device device;
    int gpu_index;
    /* out: what ran it ("cpu", "cuda:0 (NAME)", "gpu-fallback:0") and the bytes it uploaded */
    char device_name[96];
    uint64_t bytes_to_device;
} rs_megakernel_opts;

/* "cpu", "cuda", "gpu-fallback". */
const char *rs_megakernel_device_name(rs_megakernel_device d);

/* Renders like rs_render (settings->threads threads; waves, chunks and cores are ignored); the
 * scene's geometry `g` with the BVH `bvh` built over it, on opts->device (NULL opts: the CPU).
 * Progress is reported per row (CPU) or per pass (GPU, fallback); on cancel the rows or passes
 * not started are left out.  Every device gives the same image up to the GPU's arithmetic; the
 * CPU and the fallback give the wavefront's bit for bit. */
rs_status rs_render_megakernel(const rs_scene *scene, const rs_geom *g, const rs_bvh *bvh,
                               const rs_render_settings *settings, rs_megakernel_opts *opts,
                               const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

#endif
