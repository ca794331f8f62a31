/* cpu/cpu_device.h — the CPU device: OpenMP workers tracing chunks.  By default it traverses the
 * 8-wide AVX2 BVH (accel/bvh8.h) where the CPU has AVX2, else the 4-wide SSE one (accel/bvh4.h),
 * collapsed from the scene's binary BVH at upload; with bvh_width 2 it runs the binary RS_HD
 * traversal the CUDA kernels run.  All give the same hits.
 * Each chunk's team is taken from the core budget (core/cores.h), when one is given, so that the
 * device and the shading of a pipelined wave share the cores. */
#ifndef RS_CPU_CPU_DEVICE_H
#define RS_CPU_CPU_DEVICE_H

#include "core/cores.h"
#include "core/parallel.h"
#include "scheduler/device.h"

/* How the CPU device's own waves (render_paths) walk the 8-wide tree: each ray alone, eight
 * neighbouring rays as a packet (accel/bvh8.h's rs_bvh8_trace_packets), or, by default, whichever
 * a thread measured faster on its first waves, for camera rays, the first bounce and the later
 * ones, closest and any hit apart.  The answers are the same bit for bit, so the choice only
 * changes the speed. */
typedef enum rs_cpu_walk {
    RS_CPU_WALK_AUTO = 0,
    RS_CPU_WALK_SINGLE,
    RS_CPU_WALK_PACKETS
} rs_cpu_walk;

/* "auto", "single", "packets"; the parse returns 0 for another name. */
const char *rs_cpu_walk_name(rs_cpu_walk w);
int rs_cpu_walk_parse(const char *text, rs_cpu_walk *out);

typedef struct rs_cpu_device_opts {
    int threads;              /* OpenMP threads per chunk (>= 1) */
    const char *name;         /* copied; NULL: "cpu" */
    uint32_t bvh_width;       /* 8: the 8-wide AVX2 BVH (RS_ERR_ARG without AVX2); 4: the 4-wide
                                 SSE BVH; 0: the widest this CPU runs; 2: the binary BVH kernel.
                                 The binary kernel is used anyway when the geometry selects a box
                                 test other than the slab test (--isect-aabb). */
    rs_cores *cores;          /* the budget each chunk's team is taken from; NULL: none */
    rs_par_strategy strategy; /* how a chunk is split among the team (zeroed: for-dynamic) */
    rs_cpu_walk walk;         /* render_paths' traversal (zeroed: auto); the 8-wide tree only */
} rs_cpu_device_opts;

rs_status rs_cpu_device_create_opts(const rs_cpu_device_opts *o, rs_device **out);
/* The default device: `threads` threads, `name` (e.g. "cpu"), the widest BVH this CPU runs. */
rs_status rs_cpu_device_create(int threads, const char *name, rs_device **out);

#endif
