/* tests/gpu_hdmath_eval.cu — hdm_eval (tests/hdmath_eval.h) over arrays on CUDA device 0, for
 * gpu_trace_test's test_hdmath_device_bits.  Compiled with the project's --fmad=false. */
#include <stdio.h>

#include <cuda_runtime.h>

#include "hdmath_eval.h"

__global__ void hdm_eval_kernel(int f, const float *x, const float *y, float *out, size_t n)
{
    size_t i = blockIdx.x * (size_t)blockDim.x + threadIdx.x;
    if (i < n)
        out[i] = hdm_eval(f, x[i], y[i]);
}

#define HDM_CHECK(call)                                                                            \
  do {                                                                                             \
    cudaError_t e_ = (call);                                                                       \
    if (e_ != cudaSuccess) {                                                                       \
      snprintf(msg, msg_size, "%s: %s (%s:%d)", #call, cudaGetErrorString(e_), __FILE__,           \
               __LINE__);                                                                          \
      goto done;                                                                                   \
    }                                                                                              \
  } while (0)

extern "C" int hdm_eval_on_gpu(int f, const float *x, const float *y, float *out, size_t n,
                               char *msg, size_t msg_size)
{
    float *dx = NULL, *dy = NULL, *dout = NULL;
    int rc = -1;
    HDM_CHECK(cudaMalloc((void **)&dx, n * sizeof(float)));
    HDM_CHECK(cudaMalloc((void **)&dy, n * sizeof(float)));
    HDM_CHECK(cudaMalloc((void **)&dout, n * sizeof(float)));
    HDM_CHECK(cudaMemcpy(dx, x, n * sizeof(float), cudaMemcpyHostToDevice));
    HDM_CHECK(cudaMemcpy(dy, y, n * sizeof(float), cudaMemcpyHostToDevice));
    hdm_eval_kernel<<<(unsigned)((n + 255) / 256), 256>>>(f, dx, dy, dout, n);
    HDM_CHECK(cudaGetLastError());
    HDM_CHECK(cudaMemcpy(out, dout, n * sizeof(float), cudaMemcpyDeviceToHost));
    rc = 0;
done:
    cudaFree(dx);
    cudaFree(dy);
    cudaFree(dout);
    return rc;
}
