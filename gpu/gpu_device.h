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
 * and pass_begin + render_pass run the megakernel (one path per pixel per sample,
 * rs_path_radiance of shading/path.h) — there is no second way to reach the GPU. */
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
/* Usable CUDA devices; 0 with a reason in *why (static text) when there are none. */
int rs_gpu_count(const char **why);
/* Creates CUDA device `index` (0-based), named "cuda:INDEX (NAME)": flags RS_DEVICE_OWN_MEMORY,
 * threads 0, pass_samples RS_GPU_PASS_SAMPLES; host_alloc gives page-locked memory that trace
 * copies from and to by DMA.  RS_ERR_DEVICE_LOST when it cannot be used. */
rs_status rs_gpu_device_create(int index, rs_device **out);
/* Samples per render_pass call the CUDA device asks for: few, so that cancel and progress are
 * seen often, enough that the film add of one sample overlaps the kernel of the next. */
#define RS_GPU_PASS_SAMPLES 4u
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
