/* gpu/cuda_device.cu — the CUDA device: the geometry and BVH are copied once at upload
 * (scheduler/device_copy.h through cudaMalloc + cudaMemcpy, no managed memory, ended with a
 * device synchronisation); each chunk is copied in, traced by a kernel that is a thin shell
 * around the shared RS_HD traversal (accel/trace.h, the very code the CPU device runs; closest
 * hit or any hit by the batch's kind), and copied out, in pieces pipelined over two CUDA streams.
 * A chunk of a batch from host_alloc (pinned) is copied by DMA straight from and to the batch's
 * arrays; any other is packed into the stage's pinned buffers first.  The megakernel
 * (upload_scene, render_pass) is gpu/cuda_megakernel.cu; the state both share is
 * gpu/internal.h.
 *
 * Every CUDA call that can fail is checked against its own return value (CUDA_TRY, kernel
 * launches through cudaLaunchKernel) and reported with the call's text, file and line; release
 * paths (cudaFree, cudaFreeHost, cudaStreamDestroy) have nobody to report to and ignore theirs.
 * Launch sizes come from the occupancy API under each kernel's __launch_bounds__ (internal.h), not
 * hand-tuned constants; at create the device's stack limit is raised to what the kernels' own
 * attributes say they need (cudaFuncGetAttributes localSizeBytes), so that no launch has to grow
 * it (a launch that must grow it synchronises the device and can fail mid-render). */
#include "gpu/internal.h"

#include <stdio.h>
#include <string.h>

#include "accel/trace.h"
#include "core/alloc.h"
#include "scheduler/sched.h"

__global__ void __launch_bounds__(RS_CUDA_TRACE_BLOCK_MAX, 1)
    rs_trace_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < batch.count)
        rs_trace_one(&b, &g, &batch, i);
}

/* The same for geometry without instances (g.n_instances == 0): 64 registers, not 118, and no
 * spills (4 blocks of 256 a multiprocessor). */
__global__ void __launch_bounds__(RS_CUDA_TRACE_BLOCK_MAX, 4)
    rs_trace_flat_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < batch.count)
        rs_trace_one_flat(&b, &g, &batch, i);
}

/* ---- the mirror ops: device memory for device_copy ---------------------------------------- */

static rs_status copy_to_device(void *dst, const void *src, size_t bytes)
{
    CUDA_TRY(cudaMemcpy(dst, src, bytes, cudaMemcpyHostToDevice));
    return RS_OK;
}

static rs_status cuda_copy(void *user, void **dst, const void *src, size_t bytes)
{
    rs_status st;
    (void)user;
    *dst = NULL;
    CUDA_TRY(cudaMalloc(dst, bytes));
    if ((st = copy_to_device(*dst, src, bytes)) != RS_OK) {
        (void)cudaFree(*dst);
        *dst = NULL;
    }
    return st;
}

static void cuda_release(void *user, void *p)
{
    (void)user;
    (void)cudaFree(p);
}

const rs_mirror_ops rs_cuda_mirror_ops = {cuda_copy, cuda_release, NULL};

/* ---- staging ------------------------------------------------------------------------------ */

/* Cuts the arrays of one staging set for `cap` rays out of `base` (NULL: only measures) and
 * returns the bytes they take, each array 256-byte aligned. */
static size_t stage_layout(char *base, uint32_t cap, rs_ray_soa *rays, rs_hit_soa *hits,
                           uint8_t **occ)
{
    size_t off = 0;
#define RS_CUT(ptr, type, count) RS_CUDA_CUT(base, off, ptr, type, count);
#define RS_CUT_RAY(type, name) RS_CUT(rays->name, type, cap)
#define RS_CUT_HIT(type, name) RS_CUT(hits->name, type, cap)
    RS_RAY_FIELDS(RS_CUT_RAY)
    RS_HIT_FIELDS(RS_CUT_HIT)
    RS_CUT(*occ, uint8_t, cap)
#undef RS_CUT_HIT
#undef RS_CUT_RAY
#undef RS_CUT
    rays->count = 0;
    rays->capacity = cap;
    hits->capacity = cap;
    return off;
}

static void free_staging(rs_cuda_impl *c)
{
    int k;
    for (k = 0; k < RS_CUDA_STAGES; ++k) {
        rs_cuda_stage *s = &c->st[k];
        (void)cudaFreeHost(s->h_block);
        (void)cudaFree(s->d_block);
        s->h_block = s->d_block = NULL;
        memset(&s->h_rays, 0, sizeof s->h_rays);
        memset(&s->d_rays, 0, sizeof s->d_rays);
        memset(&s->h_hits, 0, sizeof s->h_hits);
        memset(&s->d_hits, 0, sizeof s->d_hits);
        s->h_occ = s->d_occ = NULL;
        s->pending = 0;
    }
    c->cap = 0;
}

/* Both staging sets for the largest piece of the largest chunk, once per device. */
static rs_status make_staging(rs_cuda_impl *c)
{
    uint32_t cap = rs_gpu_piece_size(RS_SCHED_MAX_CHUNK);
    rs_ray_soa r;
    rs_hit_soa h;
    uint8_t *o;
    size_t bytes = stage_layout(NULL, cap, &r, &h, &o);
    int k;
    if (c->cap == cap)
        return RS_OK;
    for (k = 0; k < RS_CUDA_STAGES; ++k) {
        rs_cuda_stage *s = &c->st[k];
        CUDA_TRY(cudaHostAlloc(&s->h_block, bytes, cudaHostAllocPortable));
        CUDA_TRY(cudaMalloc(&s->d_block, bytes));
        stage_layout((char *)s->h_block, cap, &s->h_rays, &s->h_hits, &s->h_occ);
        stage_layout((char *)s->d_block, cap, &s->d_rays, &s->d_hits, &s->d_occ);
    }
    c->cap = cap;
    return RS_OK;
}

/* ---- upload ------------------------------------------------------------------------------- */

static rs_status sync_device(void)
{
    CUDA_TRY(cudaDeviceSynchronize());
    return RS_OK;
}

static rs_status cuda_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    rs_status st;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    /* a second upload replaces the first (and the megakernel's copy, which borrowed its BVH) */
    rs_cuda_scene_release(c);
    rs_device_geom_release(&c->geom, &rs_cuda_mirror_ops);
    c->uploaded = 0;
    if ((st = rs_device_copy_geom(g, bvh, &rs_cuda_mirror_ops, &c->geom)) != RS_OK)
        return st;
    /* the copies ran on the legacy stream; the kernels run on non-blocking streams */
    if ((st = make_staging(c)) != RS_OK || (st = sync_device()) != RS_OK) {
        free_staging(c);
        rs_device_geom_release(&c->geom, &rs_cuda_mirror_ops);
        return st;
    }
    d->stats.bytes_to_device += c->geom.made.bytes;
    c->uploaded = 1;
    return RS_OK;
}

/* ---- trace -------------------------------------------------------------------------------- */

/* Waits for the stage's piece; copies its answers from the pinned buffers into the batch unless
 * they were copied there directly. */
static rs_status finish_piece(rs_device *d, rs_cuda_stage *s, const rs_trace_batch *batch)
{
    if (!s->pending)
        return RS_OK;
    s->pending = 0;
    CUDA_TRY(cudaStreamSynchronize(s->stream));
    if (!s->direct)
        d->stats.bytes_from_device +=
            rs_trace_stage_out(batch, s->begin, s->n, &s->h_hits, s->h_occ);
    else
        d->stats.bytes_from_device +=
            batch->kind == RS_TRACE_CLOSEST ? (uint64_t)s->n * RS_HIT_BYTES : s->n;
    return RS_OK;
}

/* Queues copy in, kernel and copy out of rays [begin, begin + n) on the stage's stream: from
 * and to the batch's own arrays when it is pinned, else through the stage's pinned buffers
 * (packed here). */
static rs_status launch_piece(rs_device *d, rs_cuda_impl *c, rs_cuda_stage *s,
                              const rs_trace_batch *batch, uint32_t begin, uint32_t n)
{
    rs_trace_batch db;
    void *args[3];
    int direct = batch->pinned != 0;
    const rs_ray_soa *src = direct ? &batch->rays : &s->h_rays;
    uint32_t off = direct ? begin : 0;
    /* pending from the first queued call on: a later call failing must still be waited for */
    s->begin = begin;
    s->n = n;
    s->direct = direct;
    s->pending = 1;
    if (!direct)
        rs_trace_stage_in(&s->h_rays, batch, begin, n);
#define RS_COPY_IN(type, name)                                                                     \
  CUDA_TRY(cudaMemcpyAsync(s->d_rays.name, src->name + off, n * sizeof(type),                      \
                           cudaMemcpyHostToDevice, s->stream));
    RS_RAY_FIELDS(RS_COPY_IN)
#undef RS_COPY_IN
    d->stats.bytes_to_device += (uint64_t)n * RS_RAY_BYTES;
    memset(&db, 0, sizeof db);
    db.kind = batch->kind;
    db.count = n;
    db.wave = batch->wave;
    db.rays = s->d_rays;
    db.hits = s->d_hits;
    db.occluded = s->d_occ;
    args[0] = &c->geom.bvh;
    args[1] = &c->geom.geom;
    args[2] = &db;
    if (c->geom.geom.n_instances == 0) {
        CUDA_TRY(cudaLaunchKernel((const void *)rs_trace_flat_kernel,
                                  dim3((n + c->block_flat - 1) / c->block_flat),
                                  dim3(c->block_flat), args, 0, s->stream));
    } else {
        CUDA_TRY(cudaLaunchKernel((const void *)rs_trace_kernel,
                                  dim3((n + c->block - 1) / c->block), dim3(c->block), args, 0,
                                  s->stream));
    }
    if (batch->kind == RS_TRACE_CLOSEST) {
        const rs_hit_soa *dst = direct ? &batch->hits : &s->h_hits;
#define RS_COPY_OUT(type, name)                                                                    \
  CUDA_TRY(cudaMemcpyAsync(dst->name + off, s->d_hits.name, n * sizeof(type),                      \
                           cudaMemcpyDeviceToHost, s->stream));
        RS_HIT_FIELDS(RS_COPY_OUT)
#undef RS_COPY_OUT
    } else {
        uint8_t *dst = direct ? batch->occluded + begin : s->h_occ;
        CUDA_TRY(cudaMemcpyAsync(dst, s->d_occ, n, cudaMemcpyDeviceToHost, s->stream));
    }
    return RS_OK;
}

/* A chunk is cut into pieces (up to 4 of a chunk of at most RS_SCHED_MAX_CHUNK rays, none under
 * RS_GPU_MIN_PIECE, none over the staging) that alternate between the two stages: piece k + 1
 * is packed and queued while piece k runs.  Every piece queued is waited for, also on failure. */
static rs_status cuda_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    uint32_t n = end - begin, piece, off, k;
    rs_status st = RS_OK;
    if (!c->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: trace before upload", d->name);
    if (n == 0)
        return RS_OK;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    piece = rs_gpu_piece_size(n);
    if (piece > c->cap)
        piece = c->cap; /* a fixed chunk size above RS_SCHED_MAX_CHUNK: more pieces */
    for (off = begin, k = 0; off < end && st == RS_OK; off += piece, ++k) {
        rs_cuda_stage *s = &c->st[k % RS_CUDA_STAGES];
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

/* ---- host memory, destroy, create --------------------------------------------------------- */

static rs_status host_alloc_on(int ordinal, void **p, size_t bytes)
{
    CUDA_TRY(cudaSetDevice(ordinal));
    CUDA_TRY(cudaHostAlloc(p, bytes, cudaHostAllocPortable));
    return RS_OK;
}

/* Page-locked (portable), page-aligned; NULL with the CUDA error recorded when it fails. */
static void *cuda_host_alloc(rs_device *d, size_t bytes)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    void *p = NULL;
    if (host_alloc_on(c->ordinal, &p, bytes ? bytes : 1) != RS_OK)
        return NULL;
    return p;
}

static void cuda_host_free(rs_device *d, void *p)
{
    (void)d;
    if (p)
        (void)cudaFreeHost(p);
}

static void cuda_destroy(rs_device *d)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    if (c) {
        int k;
        (void)cudaSetDevice(c->ordinal);
        for (k = 0; k < RS_CUDA_STAGES; ++k)
            if (c->st[k].stream)
                (void)cudaStreamSynchronize(c->st[k].stream);
        rs_cuda_scene_release(c);
        free_staging(c);
        rs_device_geom_release(&c->geom, &rs_cuda_mirror_ops);
        for (k = 0; k < RS_CUDA_STAGES; ++k)
            if (c->st[k].stream)
                (void)cudaStreamDestroy(c->st[k].stream);
        rs_free(c);
    }
    rs_free(d);
}

static const rs_device_ops cuda_ops = {cuda_upload,        cuda_trace,     cuda_destroy,
                                       cuda_host_alloc,    cuda_host_free, rs_cuda_upload_scene,
                                       rs_cuda_render_pass, rs_cuda_render_paths};

extern "C" int rs_gpu_compiled(void) { return 1; }

/* "12.4" from CUDA's version number 12040 (1000 major + 10 minor). */
static void cuda_version_text(int v, char *buf, size_t n)
{
    snprintf(buf, n, "%d.%d", v / 1000, v % 1000 / 10);
}

/* What cudaGetDeviceCount said, once per process (the runtime reads the devices once). */
typedef struct gpu_probe {
    int n;
    char why[320];
} gpu_probe;

static gpu_probe probe_devices(void)
{
    gpu_probe p;
    int n = 0, drv = 0, rt = 0;
    char dv[16], rv[16];
    cudaError_t e = cudaGetDeviceCount(&n);
    memset(&p, 0, sizeof p);
    if (e == cudaSuccess && n > 0) {
        p.n = n;
        return p;
    }
    /* the driver's and the runtime's CUDA versions: the driver's is 0 where none is installed */
    if (cudaDriverGetVersion(&drv) != cudaSuccess)
        drv = 0;
    if (cudaRuntimeGetVersion(&rt) != cudaSuccess)
        rt = CUDART_VERSION;
    cuda_version_text(drv, dv, sizeof dv);
    cuda_version_text(rt, rv, sizeof rv);
    if (e == cudaErrorInsufficientDriver && drv == 0)
        snprintf(p.why, sizeof p.why,
                 "no NVIDIA driver is loaded (cudaDriverGetVersion reports none; this build's CUDA "
                 "runtime is %s)",
                 rv);
    else if (e == cudaErrorInsufficientDriver && drv < rt)
        snprintf(p.why, sizeof p.why,
                 "the NVIDIA driver is older than this build's CUDA runtime: the driver supports "
                 "CUDA %s, the runtime is CUDA %s (cudaErrorInsufficientDriver; CUDA 13.x needs "
                 "driver 580 or newer, 12.x 525 or newer): update the driver or build with an "
                 "older toolkit",
                 dv, rv);
    else if (e == cudaSuccess || e == cudaErrorNoDevice)
        snprintf(p.why, sizeof p.why,
                 "no CUDA device is present (driver for CUDA %s, runtime CUDA %s; "
                 "CUDA_VISIBLE_DEVICES may hide them)",
                 dv, rv);
    else
        snprintf(p.why, sizeof p.why,
                 "the CUDA runtime could not start: %s, %s (driver for CUDA %s, runtime CUDA %s)",
                 cudaGetErrorName(e), cudaGetErrorString(e), dv, rv);
    return p;
}

extern "C" int rs_gpu_count(const char **why)
{
    static const gpu_probe p = probe_devices(); /* C++ static: made once, thread-safely */
    if (p.n == 0 && why)
        *why = p.why;
    return p.n;
}

/* Every kernel of the device, for their attributes: the trace kernel, the megakernel, the
 * wavefront's, the megakernel's bounds variant, the flat trace kernel, the megakernel's
 * passes. */
#define RS_CUDA_KERNELS (5 + RS_CUDA_WF_ENTRIES)
static void kernel_entries(const void **fn)
{
    int k;
    fn[0] = (const void *)rs_trace_kernel;
    fn[1] = rs_cuda_megakernel_entry();
    for (k = 0; k < RS_CUDA_WF_ENTRIES; ++k)
        fn[2 + k] = rs_cuda_wf_entry(k);
    fn[2 + RS_CUDA_WF_ENTRIES] = rs_cuda_megakernel_b2_entry();
    fn[3 + RS_CUDA_WF_ENTRIES] = (const void *)rs_trace_flat_kernel;
    fn[4 + RS_CUDA_WF_ENTRIES] = rs_cuda_megakernel_aux_entry();
}

/* Raises device `index`'s stack limit (per thread; the device current) to the most local memory
 * a kernel of ours uses, as cudaFuncGetAttributes reports it (also what fails first when the
 * build has no code for this GPU's architecture).  The limit is never lowered. */
static rs_status size_stack(int index)
{
    static const char *const names[RS_CUDA_KERNELS] = {
        "rs_trace_kernel",    "rs_megakernel_kernel", "rs_wf_raygen_kernel", "rs_wf_trace_kernel",
        "rs_wf_shade_kernel", "rs_wf_resolve_kernel", "rs_wf_film_kernel",
        "rs_wf_trace_flat_kernel", "rs_wf_passes_kernel", "rs_megakernel_kernel_b2",
        "rs_trace_flat_kernel", "rs_megakernel_aux_kernel"};
    const void *fn[RS_CUDA_KERNELS];
    cudaFuncAttributes a;
    size_t need = 0, have = 0, local[RS_CUDA_KERNELS];
    cudaError_t e;
    int k, most = 0;
    kernel_entries(fn);
    for (k = 0; k < RS_CUDA_KERNELS; ++k) {
        if ((e = cudaFuncGetAttributes(&a, fn[k])) != cudaSuccess) {
            cudaDeviceProp prop;
            int major = 0, minor = 0;
            if (cudaGetDeviceProperties(&prop, index) == cudaSuccess)
                major = prop.major, minor = prop.minor;
            return rs_error_set(RS_ERR_CUDA,
                                "gpu:%d: cudaFuncGetAttributes(%s) failed: %s (the build's "
                                "CMAKE_CUDA_ARCHITECTURES must include this GPU's sm_%d%d)",
                                index, names[k], cudaGetErrorString(e), major, minor);
        }
        local[k] = a.localSizeBytes;
        if (local[k] > need) {
            need = local[k];
            most = k;
        }
    }
    CUDA_TRY(cudaDeviceGetLimit(&have, cudaLimitStackSize));
    if (have >= need)
        return RS_OK;
    if ((e = cudaDeviceSetLimit(cudaLimitStackSize, need)) != cudaSuccess)
        return rs_error_set(RS_ERR_CUDA,
                            "gpu:%d: cannot raise the CUDA stack from %zu to %zu bytes per thread, "
                            "the kernels' local memory (cudaFuncGetAttributes localSizeBytes: "
                            "%s %zu): cudaDeviceSetLimit(cudaLimitStackSize) failed: %s",
                            index, have, need, names[most], local[most], cudaGetErrorString(e));
    CUDA_TRY(cudaDeviceGetLimit(&have, cudaLimitStackSize));
    if (have < need)
        return rs_error_set(RS_ERR_CUDA,
                            "gpu:%d: the CUDA stack limit reads %zu bytes per thread after "
                            "cudaDeviceSetLimit(cudaLimitStackSize, %zu), under the kernels' %zu",
                            index, have, need, need);
    return RS_OK;
}

extern "C" int rs_gpu_describe(int index, char *buf, size_t n)
{
    static const char *const names[RS_CUDA_KERNELS] = {
        "trace", "megakernel", "wf-raygen", "wf-trace", "wf-shade", "wf-resolve", "wf-film",
        "megakernel-b2"};
    const void *fn[RS_CUDA_KERNELS];
    const char *why = "";
    int count = rs_gpu_count(&why), drv = 0, rt = 0, k;
    char dv[16], rv[16];
    cudaDeviceProp prop;
    size_t used, stack = 0;
    if (index < 0 || index >= count) {
        snprintf(buf, n, "gpu:%d: not available (%s)", index, count ? "index out of range" : why);
        return -1;
    }
    if (cudaGetDeviceProperties(&prop, index) != cudaSuccess ||
        cudaSetDevice(index) != cudaSuccess) {
        snprintf(buf, n, "gpu:%d: its properties cannot be read", index);
        return -1;
    }
    (void)cudaDriverGetVersion(&drv);
    (void)cudaRuntimeGetVersion(&rt);
    cuda_version_text(drv, dv, sizeof dv);
    cuda_version_text(rt, rv, sizeof rv);
    (void)cudaDeviceGetLimit(&stack, cudaLimitStackSize);
    used = (size_t)snprintf(buf, n, "gpu:%d %s (sm_%d%d, %d SMs), driver for CUDA %s, runtime %s;",
                            index, prop.name, prop.major, prop.minor, prop.multiProcessorCount, dv,
                            rv);
    kernel_entries(fn);
    for (k = 0; k < RS_CUDA_KERNELS && used < n; ++k) {
        cudaFuncAttributes a;
        if (cudaFuncGetAttributes(&a, fn[k]) != cudaSuccess)
            used += (size_t)snprintf(buf + used, n - used, " %s: no attributes;", names[k]);
        else
            used += (size_t)snprintf(buf + used, n - used,
                                     " %s: %d registers, %zu B local, blocks <= %d;", names[k],
                                     a.numRegs, a.localSizeBytes, a.maxThreadsPerBlock);
    }
    if (used < n)
        snprintf(buf + used, n - used, " stack limit %zu B per thread", stack);
    return 0;
}

static rs_status make_streams(rs_cuda_impl *c)
{
    int k;
    for (k = 0; k < RS_CUDA_STAGES; ++k)
        CUDA_TRY(cudaStreamCreateWithFlags(&c->st[k].stream, cudaStreamNonBlocking));
    return RS_OK;
}

extern "C" rs_status rs_gpu_device_create(int index, rs_device **out)
{
    const char *why = "";
    int n = rs_gpu_count(&why);
    cudaDeviceProp prop;
    rs_device *d;
    rs_cuda_impl *c;
    rs_status st;
    int min_grid = 0, block = 0;
    *out = NULL;
    if (index < 0 || index >= n)
        return rs_error_set(RS_ERR_DEVICE_LOST, "gpu:%d: not available (%s)", index,
                            n == 0 ? why : "index out of range");
    CUDA_TRY(cudaGetDeviceProperties(&prop, index));
    CUDA_TRY(cudaSetDevice(index));
    if ((st = size_stack(index)) != RS_OK)
        return st;
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_trace_kernel, 0, 0));
    d = (rs_device *)rs_calloc(1, sizeof *d);
    c = (rs_cuda_impl *)rs_calloc(1, sizeof *c);
    if (!d || !c) {
        rs_free(d);
        rs_free(c);
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the CUDA device");
    }
    c->ordinal = index;
    c->block = block > 0 ? block : 128;
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, rs_trace_flat_kernel, 0, 0));
    c->block_flat = block > 0 ? block : 128;
    d->ops = &cuda_ops;
    d->impl = c;
    d->flags = RS_DEVICE_OWN_MEMORY;
    d->threads = 0;
    d->pass_samples = RS_GPU_PASS_SAMPLES;
    snprintf(d->name, sizeof d->name, "cuda:%d (%.36s)", index, prop.name);
    if ((st = make_streams(c)) != RS_OK) {
        cuda_destroy(d);
        return st;
    }
    *out = d;
    return RS_OK;
}
