/* gpu/gpu_device.h — the CUDA device and its host stand-in.
 *
 * Built from gpu/cuda_device.cu and gpu/cuda_megakernel.cu (one device, two files behind
 * gpu/internal.h) when the CUDA toolkit is found at configure time, else from gpu/gpu_none.c,
 * which reports that the build has no CUDA.  The binary links only the static CUDA runtime,
 * never the driver library: on a machine without an NVIDIA driver the runtime reports no device
 * and the caller falls back to the CPU.
 *
 * Both devices fill every entry of rs_device_ops (scheduler/device.h): upload copies the
 * geometry and BVH into the device's own memory (scheduler/device_copy.h), trace answers chunks,
 * and upload_scene + render_pass run the megakernel (one path per pixel per sample,
 * rs_gpu_path_radiance of gpu/megakernel_path.h) — there is no second way to reach the GPU. */
#ifndef RS_GPU_GPU_DEVICE_H
#define RS_GPU_GPU_DEVICE_H

#include "scheduler/device.h"
#include "shading/path.h"

typedef struct rs_cores rs_cores; /* core/cores.h (C11 atomics: not included from CUDA C++) */

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if this build contains the CUDA device. */
int rs_gpu_compiled(void);
/* Usable CUDA devices; 0 with a reason in *why (text that lives as long as the process) when
 * there are none: no driver, a driver older than this build's CUDA runtime (with both versions,
 * cudaDriverGetVersion / cudaRuntimeGetVersion), no device, or the runtime's own error. */
int rs_gpu_count(const char **why);
/* One line about CUDA device `index` into buf (n bytes): its name and compute capability, the
 * driver's and the runtime's CUDA versions, each kernel's registers, local memory per thread and
 * largest block (cudaFuncGetAttributes) and the device's stack limit.  0, or -1 with the reason
 * in buf (no such device, a build without CUDA). */
int rs_gpu_describe(int index, char *buf, size_t n);
/* Creates CUDA device `index` (0-based), named "cuda:INDEX (NAME)": flags RS_DEVICE_OWN_MEMORY,
 * threads 0, pass_samples RS_GPU_PASS_SAMPLES; host_alloc gives page-locked memory that trace
 * copies from and to by DMA.  RS_ERR_DEVICE_LOST when it cannot be used. */
rs_status rs_gpu_device_create(int index, rs_device **out);
/* Samples per render_pass call the CUDA device asks for: few, so that cancel and progress are
 * seen often, enough that the film add of one sample overlaps the kernel of the next. */
#define RS_GPU_PASS_SAMPLES 16u
/* Samples of every pixel one launch of the CUDA megakernel runs (one thread each): a million
 * paths and more in flight at 512x512, the film add of one launch overlapping the next. */
#define RS_GPU_LAUNCH_SAMPLES 4u
/* Pieces smaller than this are not worth a CUDA stream switch. */
#define RS_GPU_MIN_PIECE 32768u
/* The piece size the CUDA device (and its fallback) cut a trace chunk of n rays into: a quarter
 * of it (up to four pieces, over the CUDA device's two streams), but at least RS_GPU_MIN_PIECE
 * rays (all of a smaller chunk).  Both stage at most rs_gpu_piece_size(RS_SCHED_MAX_CHUNK) rays
 * at a time; a larger chunk (a fixed --chunk-size) is cut into more pieces of that size. */
static inline uint32_t rs_gpu_piece_size(uint32_t n)
{
    uint32_t piece = n / 4 + (n % 4 != 0);
    if (piece < RS_GPU_MIN_PIECE)
        piece = n < RS_GPU_MIN_PIECE ? n : RS_GPU_MIN_PIECE;
    return piece;
}
/* The stand-in for CUDA device `gpu_index` where it cannot be used (gpu/gpu_fallback.c, in every
 * build): named "gpu-fallback:INDEX", flags 0 (it runs on host threads), pass_samples 1.  It
 * keeps its own copy of the geometry and BVH (made at upload as the GPU makes its own), stages
 * each chunk in its own buffers and runs the CUDA kernel's body (the binary BVH traversal) on
 * `threads` host threads taken from `cores` (NULL: no budget); its render_pass runs the CUDA
 * render_pass's passes on those threads, over its copy of the scene. */
rs_status rs_gpu_fallback_create(int threads, int gpu_index, rs_cores *cores, rs_device **out);
/* The LBVH's Morton codes and radix sort on CUDA device *(int *)user (NULL: device 0), as an
 * rs_bvh_build_opts.lbvh_sort (accel/bvh.h): the tree is the host LBVH's, bit for bit.
 * RS_ERR_DEVICE_LOST in a build without CUDA, RS_ERR_CUDA when a CUDA call fails. */
rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                           const float scale[3], uint32_t *ids, uint32_t *codes);

#ifdef __cplusplus
}
#endif
#endif
