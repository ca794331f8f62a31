/* gpu/gpu_none.c — the CUDA device in a build without the CUDA toolkit: never available. */
#include "gpu/gpu_device.h"

#include <stddef.h>
#include <stdio.h>

int rs_gpu_compiled(void) { return 0; }

int rs_gpu_count(const char **why)
{
    if (why)
        *why = "this build has no CUDA support (configured with RS_CUDA=OFF or without nvcc)";
    return 0;
}

int rs_gpu_describe(int index, char *buf, size_t n)
{
    snprintf(buf, n, "gpu:%d: this build has no CUDA support", index);
    return -1;
}

rs_status rs_gpu_device_create(int index, rs_device **out)
{
    *out = NULL;
    return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: this build has no CUDA support", index);
}

rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                           const float scale[3], uint32_t *ids, uint32_t *codes)
{
    (void)user, (void)centroid, (void)n, (void)lo, (void)scale, (void)ids, (void)codes;
    return rs_error_set(RS_ERR_DEVICE_LOST, "the GPU LBVH build needs CUDA: this build has none");
}
