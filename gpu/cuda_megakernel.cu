/* gpu/cuda_megakernel.cu — the thesis's CUDA megakernel: one thread per pixel traces its path
 * from the camera to the end with rs_path_radiance (shading/path.h), the very function the CPU
 * megakernel and the wavefront's stages run.  The scene is mirrored into device memory once
 * (rs_scene_mirror_create with cudaMalloc + cudaMemcpy); each pass is one sample of every pixel,
 * copied back for the host to add to the film in sample order, so progress and Ctrl-C work
 * between passes and the film sums as on the CPU.
 *
 * Every CUDA call is checked; the block size comes from the occupancy API. */
#include "gpu/gpu_device.h"

#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "gpu/cuda_check.h"

/* Per pass: rays traced and the deepest segment, summed over the threads. */
typedef struct mk_counts {
    unsigned long long closest, shadow;
    unsigned int max_bounce;
} mk_counts;

__global__ void rs_megakernel_pass_kernel(rs_integrator it, rs_path_tracer tr, uint32_t sample,
                                          rs_vec3 *radiance, mk_counts *counts)
{
    uint32_t pixel = blockIdx.x * blockDim.x + threadIdx.x;
    rs_path_counts n;
    if (pixel >= it.npix)
        return;
    n.closest = n.shadow = 0;
    n.max_bounce = 0;
    radiance[pixel] = rs_path_radiance(&it, &tr, (uint64_t)sample * it.npix + pixel, &n);
    atomicAdd(&counts->closest, (unsigned long long)n.closest);
    atomicAdd(&counts->shadow, (unsigned long long)n.shadow);
    atomicMax(&counts->max_bounce, n.max_bounce);
}

struct rs_gpu_megakernel {
    int ordinal;
    char name[96];
    rs_scene_mirror mirror; /* device copies of the scene's arrays */
    rs_scene *d_scene;      /* the mirror's struct on the device */
    rs_integrator it;       /* it.scene = d_scene */
    rs_path_tracer tracer;  /* device pointers: the mirror's geometry, the BVH below */
    void *d_nodes, *d_prim_ids;
    rs_vec3 *d_radiance;
    mk_counts *d_counts;
    int block;
    uint64_t bytes;
};

static rs_status cuda_copy(void *user, void **dst, const void *src, size_t bytes)
{
    (void)user;
    *dst = NULL;
    CUDA_TRY(cudaMalloc(dst, bytes));
    if (cudaMemcpy(*dst, src, bytes, cudaMemcpyHostToDevice) != cudaSuccess) {
        cudaFree(*dst);
        *dst = NULL;
        return rs_error_set(RS_ERR_CUDA, "copying %zu bytes of the scene to the GPU failed", bytes);
    }
    return RS_OK;
}

static void cuda_release(void *user, void *p)
{
    (void)user;
    cudaFree(p);
}

static const rs_mirror_ops cuda_mirror_ops = {cuda_copy, cuda_release, NULL};

extern "C" void rs_gpu_megakernel_destroy(rs_gpu_megakernel *m)
{
    if (!m)
        return;
    cudaSetDevice(m->ordinal);
    rs_scene_mirror_release(&m->mirror, &cuda_mirror_ops);
    cudaFree(m->d_scene);
    cudaFree(m->d_nodes);
    cudaFree(m->d_prim_ids);
    cudaFree(m->d_radiance);
    cudaFree(m->d_counts);
    rs_free(m);
}

static rs_status upload(rs_gpu_megakernel *m, const rs_scene *scene, const rs_geom *g,
                        const rs_bvh *bvh, const rs_integrator *it)
{
    rs_status st;
    const rs_scene *d;
    size_t nodes = (size_t)bvh->n_nodes * sizeof(rs_bvh_node),
           ids = (size_t)bvh->n_prims * sizeof(uint32_t);
    if ((st = rs_scene_mirror_create(scene, &cuda_mirror_ops, &m->mirror)) != RS_OK)
        return st;
    d = &m->mirror.scene;
    CUDA_TRY(cudaMalloc((void **)&m->d_scene, sizeof(rs_scene)));
    CUDA_TRY(cudaMemcpy(m->d_scene, d, sizeof(rs_scene), cudaMemcpyHostToDevice));
    if (nodes) {
        CUDA_TRY(cudaMalloc(&m->d_nodes, nodes));
        CUDA_TRY(cudaMemcpy(m->d_nodes, bvh->nodes, nodes, cudaMemcpyHostToDevice));
    }
    if (ids) {
        CUDA_TRY(cudaMalloc(&m->d_prim_ids, ids));
        CUDA_TRY(cudaMemcpy(m->d_prim_ids, bvh->prim_ids, ids, cudaMemcpyHostToDevice));
    }
    CUDA_TRY(cudaMalloc((void **)&m->d_radiance, (size_t)it->npix * sizeof(rs_vec3)));
    CUDA_TRY(cudaMalloc((void **)&m->d_counts, sizeof(mk_counts)));
    m->bytes = m->mirror.bytes + sizeof(rs_scene) + nodes + ids;
    m->it = *it;
    m->it.scene = m->d_scene;
    /* the render's geometry (its intersection algorithms, its shutter) over the mirror's arrays */
    m->tracer.geom = *g;
    m->tracer.geom.spheres = d->spheres;
    m->tracer.geom.sphere_motion = d->sphere_motion;
    m->tracer.geom.quads = d->quads;
    m->tracer.geom.tris = d->tris;
    m->tracer.bvh.nodes = (const rs_bvh_node *)m->d_nodes;
    m->tracer.bvh.prim_ids = (const uint32_t *)m->d_prim_ids;
    m->tracer.bvh.n_nodes = bvh->n_nodes;
    m->tracer.bvh4 = NULL;
    return RS_OK;
}

extern "C" rs_status rs_gpu_megakernel_create(int index, const rs_scene *scene, const rs_geom *g,
                                              const rs_bvh *bvh, const rs_integrator *it,
                                              rs_gpu_megakernel **out)
{
    const char *why = "";
    int n = rs_gpu_count(&why), min_grid = 0, block = 0;
    cudaDeviceProp prop;
    rs_gpu_megakernel *m;
    rs_status st;
    *out = NULL;
    if (index < 0 || index >= n)
        return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: not available (%s)", index,
                            n == 0 ? why : "index out of range");
    CUDA_TRY(cudaGetDeviceProperties(&prop, index));
    CUDA_TRY(cudaSetDevice(index));
    CUDA_TRY(
        cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_megakernel_pass_kernel, 0, 0));
    m = (rs_gpu_megakernel *)rs_calloc(1, sizeof *m);
    if (!m)
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the CUDA megakernel");
    m->ordinal = index;
    m->block = block > 0 ? block : 128;
    snprintf(m->name, sizeof m->name, "cuda:%d (%s)", index, prop.name);
    if ((st = upload(m, scene, g, bvh, it)) != RS_OK) {
        rs_gpu_megakernel_destroy(m);
        return st;
    }
    *out = m;
    return RS_OK;
}

extern "C" rs_status rs_gpu_megakernel_pass(rs_gpu_megakernel *m, uint32_t sample,
                                            rs_vec3 *radiance, rs_path_counts *n)
{
    mk_counts c;
    uint32_t npix = m->it.npix;
    CUDA_TRY(cudaSetDevice(m->ordinal));
    CUDA_TRY(cudaMemset(m->d_counts, 0, sizeof(mk_counts)));
    rs_megakernel_pass_kernel<<<(npix + m->block - 1) / m->block, m->block>>>(
        m->it, m->tracer, sample, m->d_radiance, m->d_counts);
    CUDA_TRY(cudaGetLastError());
    CUDA_TRY(cudaMemcpy(radiance, m->d_radiance, (size_t)npix * sizeof(rs_vec3),
                        cudaMemcpyDeviceToHost));
    CUDA_TRY(cudaMemcpy(&c, m->d_counts, sizeof c, cudaMemcpyDeviceToHost));
    n->closest += c.closest;
    n->shadow += c.shadow;
    if (c.max_bounce > n->max_bounce)
        n->max_bounce = c.max_bounce;
    return RS_OK;
}

extern "C" const char *rs_gpu_megakernel_name(const rs_gpu_megakernel *m) { return m->name; }

extern "C" uint64_t rs_gpu_megakernel_bytes(const rs_gpu_megakernel *m) { return m->bytes; }
