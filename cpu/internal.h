/* cpu/internal.h — the CPU device's state, shared by its files (cpu/ only). */
#ifndef RS_CPU_INTERNAL_H
#define RS_CPU_INTERNAL_H

#include "accel/bvh4.h"
#include "accel/bvh8.h"
#include "cpu/cpu_device.h"
#include "streams/wave.h"

typedef struct cpu_impl {
    rs_geom geom; /* the caller's arrays, borrowed */
    rs_bvh_view bvh;
    rs_bvh4 *bvh4; /* width 4 */
    rs_bvh8 *bvh8; /* width 8 (AVX2); neither: the binary kernel */
    uint32_t width;
    rs_cores *cores;
    rs_par_strategy strategy;
    int uploaded;
    rs_wave_buffers *wave;        /* render_paths: one wave's buffers per thread (cpu_paths.c) */
    struct cpu_walk_picks *picks; /* render_paths: per thread, its measured walk choices */
    int n_wave;
    rs_cpu_walk walk;
} cpu_impl;

/* Rays [begin, end) of `batch` on the widest tree the device holds (accel/trace.h's answers). */
static inline void rs_cpu_trace_range(const cpu_impl *c, const rs_trace_batch *batch,
                                      uint32_t begin, uint32_t end)
{
    uint32_t i;
    if (c->bvh8) {
        rs_bvh8_trace(c->bvh8, &c->geom, batch, begin, end);
        return;
    }
    for (i = begin; i < end; ++i) {
        if (c->bvh4)
            rs_bvh4_trace_one(c->bvh4, &c->geom, batch, i);
        else
            rs_trace_one(&c->bvh, &c->geom, batch, i);
    }
}

/* The device's render_pass (cpu/cpu_megakernel.c): the thesis's per-pixel loop. */
rs_status rs_cpu_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                             rs_path_counts *counts);

/* The device's render_paths (cpu/cpu_paths.c): each thread runs waves of its own through every
 * stage. */
/* Bytes of one thread's walk choices (cpu_paths.c): upload zeroes them (none made). */
size_t rs_cpu_walk_picks_size(void);

rs_status rs_cpu_render_paths(rs_device *d, const rs_paths_job *job, uint64_t p0, uint64_t p1,
                              uint64_t *done, rs_path_counts *counts);

#endif
