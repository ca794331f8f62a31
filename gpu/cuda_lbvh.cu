/* gpu/cuda_lbvh.cu — the LBVH builder's Morton codes and sort on the GPU.
 *
 * One thread per primitive computes its 30-bit code with accel/morton.h (the host builder's very
 * function, in the host builder's frame), and CUB's device radix sort orders the (code, id)
 * pairs.  That sort is a stable LSD radix sort, as the host's is, and the ids start in ascending
 * order, so equal codes keep ascending ids and the result — hence the tree the host then links
 * from it (accel/bvh.c) — is the host builder's, bit for bit. */
#include "gpu/gpu_device.h"

#include <cub/device/device_radix_sort.cuh>
#include <cuda_runtime.h>

#include "accel/morton.h"

#define CUDA_TRY(call)                                                                             \
  do {                                                                                             \
    cudaError_t e_ = (call);                                                                       \
    if (e_ != cudaSuccess) {                                                                       \
      st = rs_error_set(RS_ERR_CUDA, "%s failed (%s:%d): %s", #call, __FILE__, __LINE__,           \
                        cudaGetErrorString(e_));                                                   \
      goto out;                                                                                    \
    }                                                                                              \
  } while (0)

typedef struct morton_frame {
    float lo[3], scale[3];
} morton_frame;

__global__ void rs_morton_kernel(const rs_vec3 *centroid, uint32_t n, morton_frame f,
                                 uint32_t *codes, uint32_t *ids)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) {
        codes[i] = rs_morton3(centroid[i], f.lo, f.scale);
        ids[i] = i;
    }
}

extern "C" rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n,
                                      const float lo[3], const float scale[3], uint32_t *ids,
                                      uint32_t *codes)
{
    int ordinal = user ? *(const int *)user : 0, min_grid = 0, block = 0, a;
    rs_vec3 *d_centroid = NULL;
    uint32_t *d_codes[2] = {NULL, NULL}, *d_ids[2] = {NULL, NULL};
    void *d_temp = NULL;
    size_t temp_bytes = 0;
    morton_frame f;
    rs_status st = RS_OK;
    if (n == 0)
        return RS_OK;
    for (a = 0; a < 3; ++a) {
        f.lo[a] = lo[a];
        f.scale[a] = scale[a];
    }
    CUDA_TRY(cudaSetDevice(ordinal));
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_morton_kernel, 0, 0));
    CUDA_TRY(cudaMalloc((void **)&d_centroid, n * sizeof(rs_vec3)));
    for (a = 0; a < 2; ++a) {
        CUDA_TRY(cudaMalloc((void **)&d_codes[a], n * sizeof(uint32_t)));
        CUDA_TRY(cudaMalloc((void **)&d_ids[a], n * sizeof(uint32_t)));
    }
    CUDA_TRY(cudaMemcpy(d_centroid, centroid, n * sizeof(rs_vec3), cudaMemcpyHostToDevice));
    rs_morton_kernel<<<(n + block - 1) / block, block>>>(d_centroid, n, f, d_codes[0], d_ids[0]);
    CUDA_TRY(cudaGetLastError());
    /* 30-bit keys: sort bits [0, 30) only */
    CUDA_TRY(cub::DeviceRadixSort::SortPairs(NULL, temp_bytes, d_codes[0], d_codes[1], d_ids[0],
                                             d_ids[1], (int)n, 0, 30));
    CUDA_TRY(cudaMalloc(&d_temp, temp_bytes));
    CUDA_TRY(cub::DeviceRadixSort::SortPairs(d_temp, temp_bytes, d_codes[0], d_codes[1], d_ids[0],
                                             d_ids[1], (int)n, 0, 30));
    CUDA_TRY(cudaMemcpy(codes, d_codes[1], n * sizeof(uint32_t), cudaMemcpyDeviceToHost));
    CUDA_TRY(cudaMemcpy(ids, d_ids[1], n * sizeof(uint32_t), cudaMemcpyDeviceToHost));
out:
    cudaFree(d_temp);
    cudaFree(d_centroid);
    for (a = 0; a < 2; ++a) {
        cudaFree(d_codes[a]);
        cudaFree(d_ids[a]);
    }
    return st;
}
