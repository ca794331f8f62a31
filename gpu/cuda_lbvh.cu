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
#include <string.h>

#include "accel/morton.h"
#include "gpu/cuda_check.h"

typedef struct morton_frame {
    float lo[3], scale[3];
} morton_frame;

#define RS_MORTON_BLOCK_MAX 256 /* its __launch_bounds__; the occupancy API chooses under it */

__global__ void __launch_bounds__(RS_MORTON_BLOCK_MAX, 1)
    rs_morton_kernel(const rs_vec3 *centroid, uint32_t n, morton_frame f, uint32_t *codes,
                     uint32_t *ids)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < n) {
        codes[i] = rs_morton3(centroid[i], f.lo, f.scale);
        ids[i] = i;
    }
}

/* The device buffers of one sort; freed by the caller whatever happened. */
typedef struct lbvh_bufs {
    rs_vec3 *centroid;
    uint32_t *codes[2], *ids[2];
    void *temp;
} lbvh_bufs;

static rs_status lbvh_run(lbvh_bufs *b, int ordinal, const rs_vec3 *centroid, uint32_t n,
                          morton_frame f, uint32_t *ids, uint32_t *codes)
{
    int min_grid = 0, block = 0, a;
    size_t temp_bytes = 0;
    void *args[5];
    CUDA_TRY(cudaSetDevice(ordinal));
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_morton_kernel, 0, 0));
    CUDA_TRY(cudaMalloc((void **)&b->centroid, n * sizeof(rs_vec3)));
    for (a = 0; a < 2; ++a) {
        CUDA_TRY(cudaMalloc((void **)&b->codes[a], n * sizeof(uint32_t)));
        CUDA_TRY(cudaMalloc((void **)&b->ids[a], n * sizeof(uint32_t)));
    }
    CUDA_TRY(cudaMemcpy(b->centroid, centroid, n * sizeof(rs_vec3), cudaMemcpyHostToDevice));
    args[0] = &b->centroid;
    args[1] = &n;
    args[2] = &f;
    args[3] = &b->codes[0];
    args[4] = &b->ids[0];
    CUDA_TRY(cudaLaunchKernel((const void *)rs_morton_kernel, dim3((n + block - 1) / block),
                              dim3(block), args, 0, 0));
    /* 30-bit keys: sort bits [0, 30) only */
    CUDA_TRY(cub::DeviceRadixSort::SortPairs(NULL, temp_bytes, b->codes[0], b->codes[1], b->ids[0],
                                             b->ids[1], (int)n, 0, 30));
    CUDA_TRY(cudaMalloc(&b->temp, temp_bytes));
    CUDA_TRY(cub::DeviceRadixSort::SortPairs(b->temp, temp_bytes, b->codes[0], b->codes[1],
                                             b->ids[0], b->ids[1], (int)n, 0, 30));
    CUDA_TRY(cudaMemcpy(codes, b->codes[1], n * sizeof(uint32_t), cudaMemcpyDeviceToHost));
    CUDA_TRY(cudaMemcpy(ids, b->ids[1], n * sizeof(uint32_t), cudaMemcpyDeviceToHost));
    return RS_OK;
}

extern "C" rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n,
                                      const float lo[3], const float scale[3], uint32_t *ids,
                                      uint32_t *codes)
{
    int ordinal = user ? *(const int *)user : 0, a;
    morton_frame f;
    lbvh_bufs b;
    rs_status st;
    if (n == 0)
        return RS_OK;
    for (a = 0; a < 3; ++a) {
        f.lo[a] = lo[a];
        f.scale[a] = scale[a];
    }
    memset(&b, 0, sizeof b);
    st = lbvh_run(&b, ordinal, centroid, n, f, ids, codes);
    /* release: nobody to report a failed free to */
    (void)cudaFree(b.temp);
    (void)cudaFree(b.centroid);
    for (a = 0; a < 2; ++a) {
        (void)cudaFree(b.codes[a]);
        (void)cudaFree(b.ids[a]);
    }
    return st;
}
