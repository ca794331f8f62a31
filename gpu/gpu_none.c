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

rs_status rs_gpu_lbvh_sort(void *user, const rs_vec3 *centroid, uint32_t n, const float lo[3],
                           const float scale[3], uint32_t *ids, uint32_t *codes)
{
    (void)user, (void)centroid, (void)n, (void)lo, (void)scale, (void)ids, (void)codes;
    return rs_error_set(RS_ERR_DEVICE_LOST, "the GPU LBVH build needs CUDA: this build has none");
}

rs_status rs_gpu_megakernel_create(int index, const rs_scene *scene, const rs_geom *g,
                                   const rs_bvh *bvh, const rs_integrator *it,
                                   rs_gpu_megakernel **out)
{
    (void)scene, (void)g, (void)bvh, (void)it;
    *out = NULL;
    return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: this build has no CUDA support", index);
}

rs_status rs_gpu_megakernel_pass(rs_gpu_megakernel *m, uint32_t sample, rs_vec3 *radiance,
                                 rs_path_counts *n)
{
    (void)m, (void)sample, (void)radiance, (void)n;
    return rs_error_set(RS_ERR_DEVICE_LOST, "the CUDA megakernel needs CUDA: this build has none");
}

const char *rs_gpu_megakernel_name(const rs_gpu_megakernel *m)
{
    (void)m;
    return "cuda (none)";
}

uint64_t rs_gpu_megakernel_bytes(const rs_gpu_megakernel *m)
{
    (void)m;
    return 0;
}

void rs_gpu_megakernel_destroy(rs_gpu_megakernel *m) { (void)m; }
