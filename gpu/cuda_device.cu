/* gpu/cuda_device.cu — the CUDA device: the scene and BVH are uploaded once; each chunk is
 * copied in, traced by a kernel that is a thin shell around the shared RS_HD traversal
 * (accel/trace.h, the very code the CPU device runs), and copied out.
 *
 * Every CUDA call is checked against its own return value and reported with the call's text,
 * file and line.  Launch sizes come from the occupancy API, not hand-tuned constants. */
#include "gpu/gpu_device.h"

#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"

#define CUDA_TRY(call)                                                                             \
  do {                                                                                             \
    cudaError_t e_ = (call);                                                                       \
    if (e_ != cudaSuccess)                                                                         \
      return rs_error_set(RS_ERR_CUDA, "%s failed (%s:%d): %s", #call, __FILE__, __LINE__,         \
                          cudaGetErrorString(e_));                                                 \
  } while (0)

__global__ void rs_trace_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < batch.count)
        rs_trace_one(&b, &g, &batch, i);
}

typedef struct cuda_impl {
    int ordinal;
    rs_geom geom;    /* device pointers */
    rs_bvh_view bvh; /* device pointers */
    rs_ray_soa rays; /* device staging, `cap` entries */
    rs_hit_soa hits;
    uint8_t *occluded;
    uint32_t cap;
    int block; /* threads per block from the occupancy API */
} cuda_impl;

static void free_staging(cuda_impl *c)
{
#define FREE_FIELD(type, name) cudaFree(c->rays.name);
    RS_RAY_FIELDS(FREE_FIELD)
#undef FREE_FIELD
#define FREE_FIELD(type, name) cudaFree(c->hits.name);
    RS_HIT_FIELDS(FREE_FIELD)
#undef FREE_FIELD
    cudaFree(c->occluded);
    memset(&c->rays, 0, sizeof c->rays);
    memset(&c->hits, 0, sizeof c->hits);
    c->occluded = NULL;
    c->cap = 0;
}

static rs_status ensure_staging(cuda_impl *c, uint32_t n)
{
    if (n <= c->cap)
        return RS_OK;
    free_staging(c);
#define ALLOC_FIELD(type, name) CUDA_TRY(cudaMalloc((void **)&c->rays.name, n * sizeof(type)));
    RS_RAY_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
#define ALLOC_FIELD(type, name) CUDA_TRY(cudaMalloc((void **)&c->hits.name, n * sizeof(type)));
    RS_HIT_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
    CUDA_TRY(cudaMalloc((void **)&c->occluded, n));
    c->cap = n;
    return RS_OK;
}

static rs_status upload_array(void **dst, const void *src, size_t bytes, rs_device *d)
{
    *dst = NULL;
    if (bytes == 0)
        return RS_OK;
    CUDA_TRY(cudaMalloc(dst, bytes));
    CUDA_TRY(cudaMemcpy(*dst, src, bytes, cudaMemcpyHostToDevice));
    d->stats.bytes_to_device += bytes;
    return RS_OK;
}

static rs_status cuda_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    cuda_impl *c = (cuda_impl *)d->impl;
    rs_status st;
    void *p;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    c->geom = *g;
    if ((st = upload_array(&p, g->spheres, g->n_spheres * sizeof(rs_sphere), d)) != RS_OK)
        return st;
    c->geom.spheres = (const rs_sphere *)p;
    if ((st = upload_array(&p, g->quads, g->n_quads * sizeof(rs_quad), d)) != RS_OK)
        return st;
    c->geom.quads = (const rs_quad *)p;
    if ((st = upload_array(&p, g->tris, g->n_tris * sizeof(rs_tri), d)) != RS_OK)
        return st;
    c->geom.tris = (const rs_tri *)p;
    c->bvh.n_nodes = bvh->n_nodes;
    if ((st = upload_array(&p, bvh->nodes, bvh->n_nodes * sizeof(rs_bvh_node), d)) != RS_OK)
        return st;
    c->bvh.nodes = (const rs_bvh_node *)p;
    if ((st = upload_array(&p, bvh->prim_ids, bvh->n_prims * sizeof(uint32_t), d)) != RS_OK)
        return st;
    c->bvh.prim_ids = (const uint32_t *)p;
    return RS_OK;
}

static rs_status cuda_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end)
{
    cuda_impl *c = (cuda_impl *)d->impl;
    uint32_t n = end - begin;
    rs_trace_batch db;
    rs_status st;
    if (n == 0)
        return RS_OK;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    if ((st = ensure_staging(c, n)) != RS_OK)
        return st;
#define COPY_IN(type, name)                                                                        \
  CUDA_TRY(cudaMemcpy(c->rays.name, batch->rays.name + begin, n * sizeof(type),                    \
                      cudaMemcpyHostToDevice));
    RS_RAY_FIELDS(COPY_IN)
#undef COPY_IN
    d->stats.bytes_to_device += (uint64_t)n * RS_RAY_BYTES;
    memset(&db, 0, sizeof db);
    db.kind = batch->kind;
    db.count = n;
    db.rays = c->rays;
    db.hits = c->hits;
    db.occluded = c->occluded;
    rs_trace_kernel<<<(n + c->block - 1) / c->block, c->block>>>(c->bvh, c->geom, db);
    CUDA_TRY(cudaGetLastError());
    CUDA_TRY(cudaDeviceSynchronize());
    if (batch->kind == RS_TRACE_CLOSEST) {
#define COPY_OUT(type, name)                                                                       \
  CUDA_TRY(cudaMemcpy(batch->hits.name + begin, c->hits.name, n * sizeof(type),                    \
                      cudaMemcpyDeviceToHost));
        RS_HIT_FIELDS(COPY_OUT)
#undef COPY_OUT
        d->stats.bytes_from_device += (uint64_t)n * RS_HIT_BYTES;
    } else {
        CUDA_TRY(cudaMemcpy(batch->occluded + begin, c->occluded, n, cudaMemcpyDeviceToHost));
        d->stats.bytes_from_device += n;
    }
    return RS_OK;
}

static void cuda_destroy(rs_device *d)
{
    cuda_impl *c = (cuda_impl *)d->impl;
    if (c) {
        cudaSetDevice(c->ordinal);
        free_staging(c);
        cudaFree((void *)c->geom.spheres);
        cudaFree((void *)c->geom.quads);
        cudaFree((void *)c->geom.tris);
        cudaFree((void *)c->bvh.nodes);
        cudaFree((void *)c->bvh.prim_ids);
        rs_free(c);
    }
    rs_free(d);
}

static const rs_device_ops cuda_ops = {cuda_upload, cuda_trace, cuda_destroy};

extern "C" int rs_gpu_compiled(void) { return 1; }

extern "C" int rs_gpu_count(const char **why)
{
    int n = 0;
    cudaError_t e = cudaGetDeviceCount(&n);
    if (e != cudaSuccess) {
        if (why)
            *why = e == cudaErrorInsufficientDriver ? "no NVIDIA driver is loaded"
                   : e == cudaErrorNoDevice         ? "no CUDA device is present"
                                                    : "the CUDA runtime could not start";
        return 0;
    }
    if (n == 0 && why)
        *why = "no CUDA device is present";
    return n;
}

extern "C" rs_status rs_gpu_device_create(int index, rs_device **out)
{
    const char *why = "";
    int n = rs_gpu_count(&why);
    cudaDeviceProp prop;
    rs_device *d;
    cuda_impl *c;
    int min_grid = 0, block = 0;
    *out = NULL;
    if (index < 0 || index >= n)
        return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: not available (%s)", index,
                            n == 0 ? why : "index out of range");
    CUDA_TRY(cudaGetDeviceProperties(&prop, index));
    CUDA_TRY(cudaSetDevice(index));
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_trace_kernel, 0, 0));
    d = (rs_device *)rs_calloc(1, sizeof *d);
    c = (cuda_impl *)rs_calloc(1, sizeof *c);
    if (!d || !c) {
        rs_free(d);
        rs_free(c);
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the CUDA device");
    }
    c->ordinal = index;
    c->block = block > 0 ? block : 128;
    d->ops = &cuda_ops;
    d->impl = c;
    d->threads = 0;
    snprintf(d->name, sizeof d->name, "cuda:%d (%s)", index, prop.name);
    *out = d;
    return RS_OK;
}
