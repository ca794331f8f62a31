/* gpu/cuda_megakernel.cu — the CUDA device's megakernel (its upload_scene and render_pass): the
 * thesis's CUDA integrator, one thread per pixel tracing its path from the camera to the end
 * with rs_gpu_path_radiance (gpu/megakernel_path.h: the binary BVH's traversal around
 * shading/path.h's path steps, the very shading the CPU megakernel and the wavefront's stages
 * run; the host fallback runs the same loop).
 *
 * upload_scene copies the scene into device memory (scheduler/device_copy.h: the scene's arrays
 * once; the tracer's geometry is the mirror's arrays with the uploaded geometry's algorithms, over
 * the uploaded BVH copy) and makes a double buffer.  render_pass runs one kernel per sample on
 * the device's stream and overlaps the host's film add of sample s with the kernel of sample
 * s + 1:
 *
 *   launch s (kernel, copy radiance + counters to slot s&1's pinned buffers, record its event)
 *   wait for s - 1's event, add its image to the film, read its counters, report progress
 *   ... after the last sample (or on cancel, checked between samples): wait for and add it.
 *
 * Each pixel thus gets its samples in sample order, and the film sums as on the CPU.  A slot's
 * buffers are reused only after the host has read them (its film add comes before the next
 * launch into it).  The ray counters are reduced per warp (shuffles over a full warp; threads
 * past the image count 0) and added with one atomic per warp. */
#include "gpu/internal.h"
#include "gpu/megakernel_path.h"

#include <stdlib.h>
#include <string.h>

#include "core/parallel.h"

#define RS_WARP 32

/* Samples [sample, sample + nsamp) of every pixel, one thread each: thread t is pixel t mod npix
 * of sample sample + t div npix, its radiance at radiance[t]. */
__device__ __forceinline__ static void megakernel_body(const rs_render_consts &it,
                                                       const rs_path_tracer &tr, uint32_t sample,
                                                       uint32_t nsamp, rs_vec3 *radiance,
                                                       rs_cuda_mk_counts *counts)
{
    uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    rs_path_counts n;
    unsigned long long closest, shadow;
    unsigned int max_bounce;
    int off;
    n.closest = n.shadow = 0;
    n.max_bounce = 0;
    /* no early return: every lane of the warp takes part in the shuffles below */
    if (t < it.npix * nsamp)
        radiance[t] = rs_gpu_path_radiance(&it, &tr, t % it.npix, sample + t / it.npix, &n);
    closest = n.closest;
    shadow = n.shadow;
    max_bounce = n.max_bounce;
    for (off = RS_WARP / 2; off > 0; off /= 2) {
        closest += __shfl_down_sync(0xffffffffu, closest, off);
        shadow += __shfl_down_sync(0xffffffffu, shadow, off);
        max_bounce = max(max_bounce, __shfl_down_sync(0xffffffffu, max_bounce, off));
    }
    if ((threadIdx.x & (RS_WARP - 1)) == 0) {
        atomicAdd(&counts->closest, closest);
        atomicAdd(&counts->shadow, shadow);
        atomicMax(&counts->max_bounce, max_bounce);
    }
}

__global__ void __launch_bounds__(RS_CUDA_MK_BLOCK_MAX, 1)
    rs_megakernel_kernel(rs_render_consts it, rs_path_tracer tr, uint32_t sample, uint32_t nsamp,
                         rs_vec3 *radiance, rs_cuda_mk_counts *counts)
{
    megakernel_body(it, tr, sample, nsamp, radiance, counts);
}

/* The same with at least two blocks per SM asked of ptxas (at most 128 registers): chosen with
 * RS_MEGAKERNEL_BOUNDS=2 in the environment, so that a GPU run can time both (bench/gpu_bench.py
 * --rows megakernel-b2) before one becomes the default. */
__global__ void __launch_bounds__(RS_CUDA_MK_BLOCK_MAX, 2)
    rs_megakernel_kernel_b2(rs_render_consts it, rs_path_tracer tr, uint32_t sample,
                            uint32_t nsamp, rs_vec3 *radiance, rs_cuda_mk_counts *counts)
{
    megakernel_body(it, tr, sample, nsamp, radiance, counts);
}

/* With it.passes: what the camera ray of each path of the launch (thread t as above) showed,
 * at aux[t] (rs_gpu_path_aux: the megakernel's own camera ray and first hit), a kernel apart so
 * that the megakernel does not carry the passes' code. */
#define RS_MK_AUX_BLOCK 256
__global__ void __launch_bounds__(RS_MK_AUX_BLOCK)
    rs_megakernel_aux_kernel(rs_render_consts it, rs_path_tracer tr, uint32_t sample,
                             uint32_t nsamp, rs_path_aux *aux)
{
    uint32_t t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t < it.npix * nsamp)
        aux[t] = rs_gpu_path_aux(&it, &tr, t % it.npix, sample + t / it.npix);
}

const void *rs_cuda_megakernel_entry(void) { return (const void *)rs_megakernel_kernel; }
const void *rs_cuda_megakernel_b2_entry(void) { return (const void *)rs_megakernel_kernel_b2; }
const void *rs_cuda_megakernel_aux_entry(void) { return (const void *)rs_megakernel_aux_kernel; }

/* The kernel this process runs: RS_MEGAKERNEL_BOUNDS=2 picks the two-blocks-per-SM build. */
static const void *megakernel_fn(void)
{
    const char *v = getenv("RS_MEGAKERNEL_BOUNDS");
    return v && strcmp(v, "2") == 0 ? rs_cuda_megakernel_b2_entry() : rs_cuda_megakernel_entry();
}

void rs_cuda_scene_release(rs_cuda_impl *c)
{
    rs_cuda_mk *mk = &c->mk;
    int k;
    rs_cuda_wf_release(c); /* the wavefront reads the scene copy */
    for (k = 0; k < 2; ++k) {
        rs_cuda_mk_slot *sl = &mk->slot[k];
        if (sl->done)
            (void)cudaEventSynchronize(sl->done);
        (void)cudaFree(sl->d_rad);
        (void)cudaFree(sl->d_aux);
        (void)cudaFree(sl->d_cnt);
        if (sl->h_rad)
            (void)cudaFreeHost(sl->h_rad);
        if (sl->h_aux)
            (void)cudaFreeHost(sl->h_aux);
        if (sl->h_cnt)
            (void)cudaFreeHost(sl->h_cnt);
        if (sl->done)
            (void)cudaEventDestroy(sl->done);
    }
    rs_device_scene_release(&mk->copy, &rs_cuda_mirror_ops);
    memset(mk, 0, sizeof *mk);
}

/* Everything upload_scene makes; on failure the caller releases what was made. */
static rs_status pass_make(rs_cuda_impl *c, const rs_scene *scene, const rs_render_consts *it)
{
    rs_cuda_mk *mk = &c->mk;
    /* RS_GPU_LAUNCH_SAMPLES samples of every pixel per launch */
    size_t image = (size_t)it->npix * RS_GPU_LAUNCH_SAMPLES * sizeof(rs_vec3);
    int min_grid = 0, block = 0, k;
    rs_status st;
    /* at most RS_CUDA_MK_BLOCK_MAX (the kernel's __launch_bounds__, which the API reads) */
    CUDA_TRY(cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, megakernel_fn(), 0, 0));
    /* whole warps only: the counters' shuffles need every lane */
    block -= block % RS_WARP;
    mk->block = block >= RS_WARP ? block : RS_WARP;
    if ((st = rs_device_copy_scene(scene, &c->geom, &rs_cuda_mirror_ops, &mk->copy)) != RS_OK)
        return st;
    mk->it = *it;
    mk->it.scene = mk->copy.scene;
    for (k = 0; k < 2; ++k) {
        rs_cuda_mk_slot *sl = &mk->slot[k];
        CUDA_TRY(cudaMalloc((void **)&sl->d_rad, image));
        CUDA_TRY(cudaMalloc((void **)&sl->d_cnt, sizeof *sl->d_cnt));
        CUDA_TRY(cudaHostAlloc((void **)&sl->h_rad, image, cudaHostAllocPortable));
        if (it->passes) {
            size_t aux = (size_t)it->npix * RS_GPU_LAUNCH_SAMPLES * sizeof(rs_path_aux);
            CUDA_TRY(cudaMalloc((void **)&sl->d_aux, aux));
            CUDA_TRY(cudaHostAlloc((void **)&sl->h_aux, aux, cudaHostAllocPortable));
        }
        CUDA_TRY(cudaHostAlloc((void **)&sl->h_cnt, sizeof *sl->h_cnt, cudaHostAllocPortable));
        CUDA_TRY(cudaEventCreateWithFlags(&sl->done, cudaEventDisableTiming));
    }
    /* the scene was copied on the legacy stream; the kernels run on the device's own */
    CUDA_TRY(cudaDeviceSynchronize());
    return RS_OK;
}

rs_status rs_cuda_upload_scene(rs_device *d, const rs_scene *scene, const rs_render_consts *it)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    rs_status st;
    CUDA_TRY(cudaSetDevice(c->ordinal));
    rs_cuda_scene_release(c);
    if (!c->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: upload_scene before upload", d->name);
    if (it->npix == 0)
        return rs_error_set(RS_ERR_ARG, "device %s: a pass of no pixels", d->name);
    if ((st = pass_make(c, scene, it)) != RS_OK) {
        rs_cuda_scene_release(c);
        return st;
    }
    d->stats.bytes_to_device += c->mk.copy.mirror.made.bytes;
    c->mk.ready = 1;
    return RS_OK;
}

/* Queues samples [s, s + ns) into slot sl on `stream`: counters zeroed, one kernel over
 * ns x npix threads, both copies, event. */
static rs_status launch_sample(rs_cuda_mk *mk, rs_cuda_mk_slot *sl, uint32_t s, uint32_t ns,
                               cudaStream_t stream)
{
    uint32_t npix = mk->it.npix;
    uint64_t threads = (uint64_t)npix * ns, grid = (threads + mk->block - 1) / mk->block;
    void *args[6];
    if (threads > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "%u samples of %u pixels in one launch", ns, npix);
    args[0] = &mk->it;
    args[1] = &mk->copy.tracer;
    args[2] = &s;
    args[3] = &ns;
    args[4] = &sl->d_rad;
    args[5] = &sl->d_cnt;
    CUDA_TRY(cudaMemsetAsync(sl->d_cnt, 0, sizeof *sl->d_cnt, stream));
    CUDA_TRY(cudaLaunchKernel(megakernel_fn(), dim3((unsigned)grid), dim3(mk->block), args, 0,
                              stream));
    if (sl->d_aux) {
        args[4] = &sl->d_aux;
        CUDA_TRY(cudaLaunchKernel(rs_cuda_megakernel_aux_entry(),
                                  dim3((unsigned)((threads + RS_MK_AUX_BLOCK - 1) / RS_MK_AUX_BLOCK)),
                                  dim3(RS_MK_AUX_BLOCK), args, 0, stream));
    }
    CUDA_TRY(cudaMemcpyAsync(sl->h_rad, sl->d_rad, (size_t)threads * sizeof(rs_vec3),
                             cudaMemcpyDeviceToHost, stream));
    if (sl->d_aux)
        CUDA_TRY(cudaMemcpyAsync(sl->h_aux, sl->d_aux, (size_t)threads * sizeof(rs_path_aux),
                                 cudaMemcpyDeviceToHost, stream));
    CUDA_TRY(
        cudaMemcpyAsync(sl->h_cnt, sl->d_cnt, sizeof *sl->h_cnt, cudaMemcpyDeviceToHost, stream));
    CUDA_TRY(cudaEventRecord(sl->done, stream));
    sl->sample = s;
    sl->nsamp = ns;
    sl->pending = 1;
    return RS_OK;
}

/* Waits for slot sl's sample; with `add`, puts it on the film, its counters into *counts and
 * reports its paths.  Without (after a failure), only waits, so the buffers are free. */
static rs_status finish_sample(rs_device *d, rs_cuda_mk_slot *sl, const rs_pass_job *job,
                               rs_path_counts *counts, int add)
{
    uint32_t npix = ((rs_cuda_impl *)d->impl)->mk.it.npix;
    if (!sl->pending)
        return RS_OK;
    sl->pending = 0;
    uint32_t j;
    CUDA_TRY(cudaEventSynchronize(sl->done));
    if (!add)
        return RS_OK;
    /* the host is otherwise idle while the GPU runs the next samples: every core adds, each
     * pixel's samples in sample order */
    for (j = 0; j < sl->nsamp; ++j) {
        rs_film_add_image(job->film, sl->h_rad + (size_t)j * npix, rs_cpu_count());
        if (job->film->pass && sl->h_aux)
            rs_film_add_pass_image(job->film, sl->h_aux + (size_t)j * npix, rs_cpu_count());
    }
    counts->closest += sl->h_cnt->closest;
    counts->shadow += sl->h_cnt->shadow;
    if (sl->h_cnt->max_bounce > counts->max_bounce)
        counts->max_bounce = sl->h_cnt->max_bounce;
    d->stats.bytes_from_device += (uint64_t)npix * sl->nsamp * sizeof(rs_vec3) + sizeof *sl->h_cnt;
    if (sl->h_aux)
        d->stats.bytes_from_device += (uint64_t)npix * sl->nsamp * sizeof(rs_path_aux);
    if (job->progress)
        job->progress(job->user, (uint64_t)npix * sl->nsamp);
    return RS_OK;
}

rs_status rs_cuda_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                              rs_path_counts *counts)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    rs_cuda_mk *mk = &c->mk;
    cudaStream_t stream = c->st[0].stream;
    rs_status st = RS_OK;
    uint32_t s, ns, i;
    int k;
    if (!mk->ready)
        return rs_error_set(RS_ERR_ARG, "device %s: render_pass before upload_scene", d->name);
    if (job->film->width * job->film->height != mk->it.npix)
        return rs_error_set(RS_ERR_ARG, "device %s: the film is not the upload_scene's image size",
                            d->name);
    CUDA_TRY(cudaSetDevice(c->ordinal));
    for (s = s0, i = 0; s - s0 < n && st == RS_OK; s += ns, ++i) {
        rs_cuda_mk_slot *cur = &mk->slot[i & 1], *prev = &mk->slot[(i & 1) ^ 1];
        ns = n - (s - s0) < RS_GPU_LAUNCH_SAMPLES ? n - (s - s0) : RS_GPU_LAUNCH_SAMPLES;
        if (job->cancelled && job->cancelled(job->user))
            break;
        /* cur was finished (or never used) before: its film add is done */
        if ((st = launch_sample(mk, cur, s, ns, stream)) == RS_OK)
            st = finish_sample(d, prev, job, counts, 1);
    }
    /* the last sample launched (both slots, oldest first, after a failure) */
    for (k = 0; k < 2; ++k) {
        rs_cuda_mk_slot *a = &mk->slot[0], *b = &mk->slot[1];
        rs_cuda_mk_slot *first = a->pending && (!b->pending || a->sample < b->sample) ? a : b;
        rs_status fs = finish_sample(d, first, job, counts, st == RS_OK);
        if (st == RS_OK)
            st = fs;
    }
    return st;
}
