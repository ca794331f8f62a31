/* gpu/gpu_none.c — the CUDA device in a build without the CUDA toolkit: never available. */
#include "gpu/gpu_device.h"

#include <stddef.h>

int rs_gpu_compiled(void) { return 0; }

int rs_gpu_count(const char **why)
{
    if (why)
        *why = "this build has no CUDA support (configured with RS_CUDA=OFF or without nvcc)";
    return 0;
}

rs_status rs_gpu_device_create(int index, rs_device **out)
{
    *out = NULL;
    return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: this build has no CUDA support", index);
}
