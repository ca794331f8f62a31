/* gpu/cuda_device.cu — the CUDA device: the scene and BVH are uploaded once (cudaMalloc, no
 * managed memory); each chunk is copied in, traced by a kernel that is a thin shell around the
 * shared RS_HD traversal (accel/trace.h, the very code the CPU device runs; closest hit or any
 * hit by the batch's kind), and copied out, in pieces pipelined over two CUDA streams with pinned
 * double buffers.
 *
 * Every CUDA call is checked against its own return value and reported with the call's text,
 * file and line.  Launch sizes come from the occupancy API, not hand-tuned constants. */
#include "gpu/gpu_device.h"

#include <cuda_runtime.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "gpu/cuda_check.h"

__global__ void rs_trace_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < batch.count)
        rs_trace_one(&b, &g, &batch, i);
}

/* One of the two staging sets a chunk's pieces alternate between: pinned host buffers (so the
 * copies are asynchronous DMA), device buffers, and a stream.  While one piece's rays are copied
 * in, traced and copied out on one stream, the host packs the next piece into the other set's
 * pinned buffers, and the other stream's copies overlap this one's kernel. */
typedef struct stage {
    cudaStream_t stream;
    rs_ray_soa h_rays, d_rays;
    rs_hit_soa h_hits, d_hits;
    uint8_t *h_occ, *d_occ;
    uint32_t begin, n; /* the piece in flight: rays [begin, begin + n) of the batch */
    int pending;
} stage;

#define RS_CUDA_STAGES    2
#define RS_CUDA_MIN_PIECE 32768u /* pieces smaller than this are not worth a stream switch */

typedef struct cuda_impl {
    int ordinal;
    rs_geom geom;    /* device pointers */
    rs_bvh_view bvh; /* device pointers */
    stage st[RS_CUDA_STAGES];
    uint32_t cap; /* entries per staging set */
    int block;    /* threads per block from the occupancy API */
} cuda_impl;

static void free_staging(cuda_impl *c)
{
    int k;
    for (k = 0; k < RS_CUDA_STAGES; ++k) {
        stage *s = &c->st[k];
        if (s->stream)
            cudaStreamSynchronize(s->stream);
#define FREE_FIELD(type, name) cudaFreeHost(s->h_rays.name), cudaFree(s->d_rays.name);
        RS_RAY_FIELDS(FREE_FIELD)
#undef FREE_FIELD
#define FREE_FIELD(type, name) cudaFreeHost(s->h_hits.name), cudaFree(s->d_hits.name);
        RS_HIT_FIELDS(FREE_FIELD)
#undef FREE_FIELD
        cudaFreeHost(s->h_occ);
        cudaFree(s->d_occ);
        memset(&s->h_rays, 0, sizeof s->h_rays);
        memset(&s->d_rays, 0, sizeof s->d_rays);
        memset(&s->h_hits, 0, sizeof s->h_hits);
        memset(&s->d_hits, 0, sizeof s->d_hits);
        s->h_occ = s->d_occ = NULL;
        s->pending = 0;
    }
    c->cap = 0;
}

static rs_status ensure_staging(cuda_impl *c, uint32_t n)
{
    int k;
    if (n <= c->cap)
        return RS_OK;
    free_staging(c);
    for (k = 0; k < RS_CUDA_STAGES; ++k) {
        stage *s = &c->st[k];
        if (!s->stream)
            CUDA_TRY(cudaStreamCreateWithFlags(&s->stream, cudaStreamNonBlocking));
#define ALLOC_FIELD(type, name)                                                                    \
  CUDA_TRY(cudaMallocHost((void **)&s->h_rays.name, n * sizeof(type)));                            \
  CUDA_TRY(cudaMalloc((void **)&s->d_rays.name, n * sizeof(type)));
        RS_RAY_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
#define ALLOC_FIELD(type, name)                                                                    \
  CUDA_TRY(cudaMallocHost((void **)&s->h_hits.name, n * sizeof(type)));                            \
  CUDA_TRY(cudaMalloc((void **)&s->d_hits.name, n * sizeof(type)));
        RS_HIT_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
        CUDA_TRY(cudaMallocHost((void **)&s->h_occ, n));
        CUDA_TRY(cudaMalloc((void **)&s->d_occ, n));
    }
    c->cap = n;
    return RS_OK;
}

static void free_scene(cuda_impl *c)
{
    cudaFree((void *)c->geom.spheres);
    cudaFree((void *)c->geom.quads);
    cudaFree((void *)c->geom.tris);
    cudaFree((void *)c->bvh.nodes);
    cudaFree((void *)c->bvh.prim_ids);
    memset(&c->geom, 0, sizeof c->geom);
    memset(&c->bvh, 0, sizeof c->bvh);
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
    free_scene(c); /* a second upload replaces the first */
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

/* Waits for the stage's piece and copies its answers from the pinned buffers into the batch. */
static rs_status finish_piece(rs_device *d, stage *s, const rs_trace_batch *batch)
{
    if (!s->pending)
        return RS_OK;
    s->pending = 0;
    CUDA_TRY(cudaStreamSynchronize(s->stream));
    d->stats.bytes_from_device += rs_trace_stage_out(batch, s->begin, s->n, &s->h_hits, s->h_occ);
    return RS_OK;
}

/* Packs rays [begin, begin + n) into the stage's pinned buffers and queues copy in, kernel and
 * copy out on its stream. */
static rs_status launch_piece(rs_device *d, cuda_impl *c, stage *s, const rs_trace_batch *batch,
                              uint32_t begin, uint32_t n)
{
    rs_trace_batch db;
    uint64_t bytes = rs_trace_stage_in(&s->h_rays, batch, begin, n);
#define COPY_IN(type, name)                                                                        \
  CUDA_TRY(cudaMemcpyAsync(s->d_rays.name, s->h_rays.name, n * sizeof(type),                       \
                           cudaMemcpyHostToDevice, s->stream));
    RS_RAY_FIELDS(COPY_IN)
#undef COPY_IN
    d->stats.bytes_to_device += bytes;
    memset(&db, 0, sizeof db);
    db.kind = batch->kind;
    db.count = n;
    db.rays = s->d_rays;
    db.hits = s->d_hits;
    db.occluded = s->d_occ;
    rs_trace_kernel<<<(n + c->block - 1) / c->block, c->block, 0, s->stream>>>(c->bvh, c->geom, db);
    CUDA_TRY(cudaGetLastError());
    if (batch->kind == RS_TRACE_CLOSEST) {
#define COPY_OUT(type, name)                                                                       \
  CUDA_TRY(cudaMemcpyAsync(s->h_hits.name, s->d_hits.name, n * sizeof(type),                       \
                           cudaMemcpyDeviceToHost, s->stream));
        RS_HIT_FIELDS(COPY_OUT)
#undef COPY_OUT
    } else {
        CUDA_TRY(cudaMemcpyAsync(s->h_occ, s->d_occ, n, cudaMemcpyDeviceToHost, s->stream));
    }
    s->begin = begin;
    s->n = n;
    s->pending = 1;
    return RS_OK;
}

/* A chunk is cut into pieces (up to 4, none under RS_CUDA_MIN_PIECE rays) that alternate between
 * the two stages: piece k + 1 is packed and queued while piece k runs. */
static rs_status cuda_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end)
{
    cuda_impl *c = (cuda_impl *)d->impl;
    uint32_t n = end - begin, piece, off, k;
    rs_status st = RS_OK;
    if (n == 0)
        return RS_OK;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    piece = (n + 3) / 4;
    if (piece < RS_CUDA_MIN_PIECE)
        piece = n < RS_CUDA_MIN_PIECE ? n : RS_CUDA_MIN_PIECE;
    if ((st = ensure_staging(c, piece)) != RS_OK)
        return st;
    for (off = begin, k = 0; off < end && st == RS_OK; off += piece, ++k) {
        stage *s = &c->st[k % RS_CUDA_STAGES];
        uint32_t m = end - off < piece ? end - off : piece;
        if ((st = finish_piece(d, s, batch)) == RS_OK)
            st = launch_piece(d, c, s, batch, off, m);
    }
    for (k = 0; k < RS_CUDA_STAGES; ++k) {
        rs_status fs = finish_piece(d, &c->st[k], batch);
        if (st == RS_OK)
            st = fs;
    }
    return st;
}

static void cuda_destroy(rs_device *d)
{
    cuda_impl *c = (cuda_impl *)d->impl;
    if (c) {
        int k;
        cudaSetDevice(c->ordinal);
        free_staging(c);
        for (k = 0; k < RS_CUDA_STAGES; ++k)
            if (c->st[k].stream)
                cudaStreamDestroy(c->st[k].stream);
        free_scene(c);
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
