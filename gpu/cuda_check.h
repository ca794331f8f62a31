/* gpu/cuda_check.h — CUDA_TRY(call), the one CUDA error macro of the build: runs a CUDA runtime
 * call and, if it fails, returns RS_ERR_CUDA from the enclosing function (which returns
 * rs_status) with the call's text, file, line and CUDA's message for that call's own result
 * (never cudaGetLastError's: kernels are launched through cudaLaunchKernel, so a launch is
 * checked by its own result too).  Where a failure must release what was made, the calls go
 * into a small function that the caller cleans up after.  For the .cu files only. */
#ifndef RS_GPU_CUDA_CHECK_H
#define RS_GPU_CUDA_CHECK_H

#include <cuda_runtime.h>

#include "core/status.h"

#define CUDA_TRY(call)                                                                             \
  do {                                                                                             \
    cudaError_t e_ = (call);                                                                       \
    if (e_ != cudaSuccess)                                                                         \
      return rs_error_set(RS_ERR_CUDA, "%s failed (%s:%d): %s", #call, __FILE__, __LINE__,         \
                          cudaGetErrorString(e_));                                                 \
  } while (0)

#endif
