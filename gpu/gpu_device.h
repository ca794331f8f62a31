/* gpu/gpu_device.h — the CUDA device.
 *
 * Built from gpu/cuda_device.cu when the CUDA toolkit is found at configure time, else from
 * gpu/gpu_none.c, which reports that the build has no CUDA.  The binary links only the static
 * CUDA runtime, never the driver library: on a machine without an NVIDIA driver the runtime
 * reports no device and the caller falls back to the CPU. */
#ifndef RS_GPU_GPU_DEVICE_H
#define RS_GPU_GPU_DEVICE_H

#include "scheduler/device.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if this build contains the CUDA device. */
int rs_gpu_compiled(void);
/* Usable CUDA devices; 0 with a reason in *why (static text) when there are none. */
int rs_gpu_count(const char **why);
/* Creates CUDA device `index` (0-based).  RS_ERR_DEVICE_LOST when it cannot be used. */
rs_status rs_gpu_device_create(int index, rs_device **out);

#ifdef __cplusplus
}
#endif
#endif
