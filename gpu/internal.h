/* gpu/internal.h — the CUDA device's state, shared by its two files (the .cu files of gpu/ only):
 * gpu/cuda_device.cu (create, upload, trace, host memory, destroy) and gpu/cuda_megakernel.cu
 * (upload_scene, render_pass).
 *
 * Memory the device holds, all made once:
 *   at create        two streams (stage 0's is "the device's stream": the megakernel runs on it);
 *   at upload        the geometry + BVH copy (scheduler/device_copy.h, rs_cuda_mirror_ops) and the
 *                    staging of both stages, sized for the largest piece a chunk is cut into
 *                    (rs_gpu_piece_size(RS_SCHED_MAX_CHUNK)): one pinned and one device block
 *                    per stage, carved into the ray, hit and occlusion arrays;
 *   at upload_scene  the scene copy and the render constants and, per slot of the megakernel's
 *                    double buffer, a device and a pinned radiance image, device and pinned ray
 *                    counters and an event.
 * Every block is released by destroy; a failed upload or upload_scene releases what it made. */
#ifndef RS_GPU_INTERNAL_H
#define RS_GPU_INTERNAL_H

#include <cuda_runtime.h>

#include "gpu/cuda_check.h"
#include "gpu/gpu_device.h"
#include "gpu/wavefront.h"
#include "scheduler/device_copy.h"

#define RS_CUDA_STAGES 2

/* The kernels' __launch_bounds__(MAX, 1): the most threads per block each may be launched with;
 * the occupancy API (cudaOccupancyMaxPotentialBlockSize, which reads the kernel's
 * maxThreadsPerBlock) picks the block size under it.  The second argument, 1 block per SM, is
 * deliberate: with the first alone, ptxas (CUDA 13.0, sm_90) aims at a higher occupancy by itself
 * and cut the megakernel from 160 to 128 registers with 380 bytes of spills per thread; with
 * (256, 1) it allows 255 and keeps what it chose unbounded (-Xptxas -v: the megakernel 162
 * registers, the trace kernel 118, no spills, stack frames of 976 and 736 bytes unchanged). */
#define RS_CUDA_TRACE_BLOCK_MAX 256
#define RS_CUDA_MK_BLOCK_MAX    256
/* The wavefront's kernels (gpu/cuda_wavefront.cu): at most 256 threads a block, registers left
 * to ptxas (no minimum of blocks per SM). */
#define RS_CUDA_WF_BLOCK_MAX 256
/* The wavefront's kernels: 0 raygen, 1 trace, 2 shade, 3 resolve, 4 film, 5 the trace kernel
 * for geometry without instances (accel/trace.h rs_trace_one_flat), 6 the film's passes at the
 * camera rays' hits. */
#define RS_CUDA_WF_ENTRIES 7

/* Cuts `count` elements of `type` for `ptr` at byte `off` of the block at `base` (NULL: only
 * measures), each array 256-byte aligned: the staging sets' and the wavefront slots' layouts. */
#define RS_CUDA_CUT(base, off, ptr, type, count)                                                   \
  do {                                                                                             \
    (ptr) = (base) ? (type *)(void *)((base) + (off)) : NULL;                                      \
    (off) += ((size_t)(count) * sizeof(type) + 255u) & ~(size_t)255u;                              \
  } while (0)
/* Paths per wave of the wavefront (two in flight): enough to fill an H200 (132 SMs x 2048
 * threads) several times over at every segment but the last few. */
#define RS_CUDA_WF_WAVE (1u << 21)

/* One of the two staging sets a chunk's pieces alternate between.  While one piece's rays are
 * copied in, traced and copied out on one stream, the host packs the next piece into the other
 * set's pinned buffers (not needed when the batch itself is pinned: then the copies read and
 * write the batch's arrays directly), and the other stream's copies overlap this one's kernel. */
typedef struct rs_cuda_stage {
    cudaStream_t stream;
    void *h_block, *d_block; /* the pinned and the device block the arrays below are cut from */
    rs_ray_soa h_rays, d_rays;
    rs_hit_soa h_hits, d_hits;
    uint8_t *h_occ, *d_occ;
    uint32_t begin, n; /* the piece in flight: rays [begin, begin + n) of the batch */
    int pending;
    int direct; /* the piece's copies go straight to and from the (pinned) batch */
} rs_cuda_stage;

/* The megakernel's ray counters of one sample, summed on the device (one atomic per warp). */
typedef struct rs_cuda_mk_counts {
    unsigned long long closest, shadow;
    unsigned int max_bounce;
} rs_cuda_mk_counts;

/* One slot of the megakernel's double buffer: sample `sample` is traced into d_rad (and d_aux),
 * copied to h_rad (h_aux) with its counters, and `done` is recorded after the copies. */
typedef struct rs_cuda_mk_slot {
    rs_vec3 *d_rad, *h_rad;
    rs_path_aux *d_aux, *h_aux; /* with it.passes: what each path's camera ray showed */
    rs_cuda_mk_counts *d_cnt, *h_cnt;
    cudaEvent_t done;
    uint32_t sample, nsamp; /* samples [sample, sample + nsamp) */
    int pending;
} rs_cuda_mk_slot;

typedef struct rs_cuda_mk {
    rs_device_scene copy; /* the scene on the device; borrows the upload's BVH copy */
    rs_render_consts it;  /* the render's constants, it.scene = copy.scene (a device pointer) */
    rs_cuda_mk_slot slot[2];
    int block; /* threads per block: the occupancy API's, a multiple of the warp size */
    int ready;
} rs_cuda_mk;

/* One wave of the wavefront in flight, on one stream: its path state, its two queues (current
 * and next), the shadow queue, hits and occlusion, all cut from one device block; d_counts[0]
 * the next rays appended, [1] the shadow rays, [2] the current queue's entries; h_counts pinned
 * (the first two copied back per segment, [4] the wave's size copied in). */
typedef struct rs_cuda_wf_slot {
    void *block;
    rs_paths paths;
    rs_ray_soa queue[2], shadow;
    rs_hit_soa hits;
    uint8_t *occ;
    unsigned int *d_counts, *h_counts;
    cudaEvent_t done;
    cudaStream_t stream; /* the device's stage k stream */
    rs_wf_wave w;
    uint32_t cur, upper;
    int active, pending;
} rs_cuda_wf_slot;

typedef struct rs_cuda_wf {
    rs_cuda_wf_slot slot[2];
    uint32_t cap;  /* paths per wave */
    int block[RS_CUDA_WF_ENTRIES]; /* threads per block of each kernel (rs_cuda_wf_entry order) */
    rs_wf_film film;
    rs_wf_u64 *h_sum, *h_sum_l2; /* the film copied back */
    rs_wf_u64 *h_pass;           /* its passes copied back (with film.pass) */
    unsigned int *h_pass_hits;
    unsigned int *h_count;
    uint32_t *pixel_of, pixel_cap; /* the plan's pixels on the device */
    uint64_t plan_id;
} rs_cuda_wf;

typedef struct rs_cuda_impl {
    int ordinal;
    int block;      /* the trace kernel's threads per block, from the occupancy API */
    int block_flat; /* the same for its instance-free twin (rs_trace_flat_kernel) */
    rs_device_geom geom;
    int uploaded;
    rs_cuda_stage st[RS_CUDA_STAGES];
    uint32_t cap; /* entries per staging set */
    rs_cuda_mk mk;
    rs_cuda_wf wf; /* render_paths: over mk's scene copy */
} rs_cuda_impl;

/* cudaMalloc + cudaMemcpy (pageable, on the legacy stream: whoever copies through these ends
 * with cudaDeviceSynchronize before a kernel on the device's own streams reads the copy) and
 * cudaFree.  Call with the device current. */
extern const rs_mirror_ops rs_cuda_mirror_ops;

/* gpu/cuda_megakernel.cu: the device's upload_scene and render_pass (scheduler/device.h), and the
 * release of what upload_scene made (a no-op when it made nothing; the device must be current). */
rs_status rs_cuda_upload_scene(rs_device *d, const rs_scene *scene, const rs_render_consts *it);
rs_status rs_cuda_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                              rs_path_counts *counts);
void rs_cuda_scene_release(rs_cuda_impl *c);
/* gpu/cuda_wavefront.cu: render_paths (scheduler/device.h), the release of what it made, and its
 * kernels' entry points (RS_CUDA_WF_ENTRIES' order; NULL past them). */
rs_status rs_cuda_render_paths(rs_device *d, const rs_paths_job *job, uint64_t p0, uint64_t p1,
                               uint64_t *done, rs_path_counts *counts);
void rs_cuda_wf_release(rs_cuda_impl *c);
const void *rs_cuda_wf_entry(int k);
/* The megakernel's entry point, for cudaFuncGetAttributes (gpu/cuda_device.cu sizes the stack
 * from it and the trace kernel). */
const void *rs_cuda_megakernel_entry(void);
const void *rs_cuda_megakernel_b2_entry(void); /* the two-blocks-per-SM build of it */
const void *rs_cuda_megakernel_aux_entry(void); /* its passes' kernel */

#endif
