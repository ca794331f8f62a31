/* gpu/gpu_device.h — the CUDA device.
 *
 * Built from gpu/cuda_device.cu when the CUDA toolkit is found at configure time, else from
 * gpu/gpu_none.c, which reports that the build has no CUDA.  The binary links only the static
 * CUDA runtime, never the driver library: on a machine without an NVIDIA driver the runtime
 * reports no device and the caller falls back to the CPU. */
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
/* Creates CUDA device `index` (0-based).  RS_ERR_DEVICE_LOST when it cannot be used. */
rs_status rs_gpu_device_create(int index, rs_device **out);
/* The stand-in for CUDA device `gpu_index` where it cannot be used (gpu/gpu_fallback.c, in every
 * build): named "gpu-fallback:INDEX", it stages each chunk in its own buffers and runs the CUDA
 * kernel's body (the binary BVH traversal) on `threads` host threads taken from `cores` (NULL:
 * no budget). */
/* The LBVH's Morton codes and radix sort on CUDA device *(int *)user (NULL: device 0), as an
 * rs_bvh_build_opts.lbvh_sort (accel/bvh.h): the tree is the host LBVH's, bit for bit.
 * RS_ERR_DEVICE_LOST in a build without CUDA, RS_ERR_CUDA when a CUDA call fails. */
rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                           const float scale[3], uint32_t *ids, uint32_t *codes);
rs_status rs_gpu_fallback_create(int threads, int gpu_index, rs_cores *cores, rs_device **out);

/* The megakernel on CUDA device `index` (gpu/cuda_megakernel.cu): the scene is mirrored into
 * device memory (rs_scene_mirror_create), the geometry `g` and its binary BVH uploaded, and each
 * pass runs rs_path_radiance (shading/path.h) once per pixel, one thread each.  `it` gives the
 * render's constants (its scene pointer is replaced by the device's mirror). */
typedef struct rs_gpu_megakernel rs_gpu_megakernel;
rs_status rs_gpu_megakernel_create(int index, const rs_scene *scene, const rs_geom *g,
                                   const rs_bvh *bvh, const rs_integrator *it,
                                   rs_gpu_megakernel **out);
/* Sample `sample` of every pixel: radiance[pixel] for pixel in [0, it->npix) (host memory), and
 * the rays traced added to *n. */
rs_status rs_gpu_megakernel_pass(rs_gpu_megakernel *m, uint32_t sample, rs_vec3 *radiance,
                                 rs_path_counts *n);
/* "cuda:INDEX (NAME)"; bytes copied to the device (scene, geometry, BVH). */
const char *rs_gpu_megakernel_name(const rs_gpu_megakernel *m);
uint64_t rs_gpu_megakernel_bytes(const rs_gpu_megakernel *m);
void rs_gpu_megakernel_destroy(rs_gpu_megakernel *m);

#ifdef __cplusplus
}
#endif
#endif
