/* gpu/cuda_wavefront.cu — the CUDA device's wavefront (its render_paths, scheduler/device.h): the
 * stream engine's stages as kernels over path state that stays in device memory, the kernels
 * thin shells around gpu/wavefront.h's RS_HD stage bodies (which the host fallback runs as
 * loops), the scene the megakernel's copy (upload_scene).
 *
 * Per wave of consecutive paths, on one of the device's two streams:
 *
 *   raygen -> [trace-closest -> shade (appends the next and the shadow rays; the two counts
 *              copied to pinned memory, an event) ... the host waits for the event ...
 *              -> trace-shadow -> resolve] while rays are alive -> film
 *
 * Only the two counts cross the bus per segment; the camera rays, hits, shadow rays and path
 * state never leave the device.  Two waves are in flight, one per stream, so that while the host
 * waits for one wave's counts the GPU runs the other's kernels.  The kernels' launch sizes come
 * from the occupancy API under their __launch_bounds__; the queues are appended with one atomic
 * per warp (a ballot, a population count and a shuffle).
 *
 * The film: rs_wf_film's exact sums in device memory, cleared once and copied back at the end
 * of each render_paths call, merged into the host film with rs_film_merge (exact: any order), so
 * the image is the CPU stream engine's bit for bit wherever the shading rounds alike on both. */
#include "gpu/internal.h"
#include "gpu/wavefront.h"

#include <string.h>

#include "core/alloc.h"

#define RS_WARP 32

/* ---- kernels ------------------------------------------------------------------------------ */

__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_raygen_kernel(rs_render_consts it, rs_wf_wave w, rs_paths paths, rs_ray_soa queue)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < w.count)
        rs_wf_raygen(&it, &w, i, &paths, &queue);
}

/* Rays [0, *count) of the batch (the count the shade kernel appended, read on the device). */
__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_trace_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch, const unsigned int *count)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < *count)
        rs_trace_one(&b, &g, &batch, i);
}

/* The same for geometry without instances (rs_trace_one_flat: no bottom levels' code). */
__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_trace_flat_kernel(rs_bvh_view b, rs_geom g, rs_trace_batch batch,
                            const unsigned int *count)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < *count)
        rs_trace_one_flat(&b, &g, &batch, i);
}

/* Index in the queue behind *counter for this lane, when `want`: one atomic per warp. */
__device__ static uint32_t rs_wf_append(unsigned int *counter, int want)
{
    unsigned int mask = __ballot_sync(0xffffffffu, want);
    unsigned int lane = threadIdx.x & (RS_WARP - 1), base = 0;
    int leader = __ffs(mask) - 1;
    if (mask == 0)
        return 0;
    if ((int)lane == leader)
        base = atomicAdd(counter, (unsigned int)__popc(mask));
    base = __shfl_sync(0xffffffffu, base, leader);
    return base + (unsigned int)__popc(mask & ((1u << lane) - 1u));
}

/* counts[0]: the next rays appended to `next`, counts[1]: the shadow rays; counts[2] the entries
 * of `queue` (the last segment's counts[0]). */
__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_shade_kernel(rs_render_consts it, rs_wf_wave w, rs_ray_soa queue, rs_hit_soa hits,
                       rs_paths paths, rs_ray_soa next, rs_ray_soa shadow,
                       const unsigned int *alive, unsigned int *counts)
{
    uint32_t j = blockIdx.x * blockDim.x + threadIdx.x, made = 0, p = 0, k;
    rs_ray nr, sr;
    /* no early return: every lane of the warp takes part in the appends' ballots */
    if (j < *alive)
        made = rs_wf_shade(&it, &w, j, &queue, &hits, &paths, &nr, &sr, &p);
    k = rs_wf_append(&counts[1], (made & RS_SHADE_SHADOW) != 0);
    if (made & RS_SHADE_SHADOW)
        rs_ray_soa_set(&shadow, k, &sr, p);
    k = rs_wf_append(&counts[0], (made & RS_SHADE_NEXT) != 0);
    if (made & RS_SHADE_NEXT)
        rs_ray_soa_set(&next, k, &nr, p);
}

/* At the camera rays' hits, where the render keeps passes: what each showed (rs_wf_passes),
 * before the shade kernel moves its path on. */
__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_passes_kernel(rs_render_consts it, rs_ray_soa queue, rs_hit_soa hits, rs_paths paths,
                        const unsigned int *alive)
{
    uint32_t j = blockIdx.x * blockDim.x + threadIdx.x;
    if (j < *alive)
        rs_wf_passes(&it, j, &queue, &hits, &paths);
}

__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_resolve_kernel(rs_ray_soa shadow, const uint8_t *occluded, rs_paths paths,
                         const unsigned int *count)
{
    uint32_t k = blockIdx.x * blockDim.x + threadIdx.x;
    if (k < *count)
        rs_wf_resolve(k, &shadow, occluded, &paths);
}

__global__ void __launch_bounds__(RS_CUDA_WF_BLOCK_MAX)
    rs_wf_film_kernel(rs_wf_wave w, rs_paths paths, rs_wf_film film)
{
    uint32_t i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < w.count)
        rs_wf_film_path(&w, i, &paths, &film);
}

const void *rs_cuda_wf_entry(int k)
{
    switch (k) {
    case 0: return (const void *)rs_wf_raygen_kernel;
    case 1: return (const void *)rs_wf_trace_kernel;
    case 2: return (const void *)rs_wf_shade_kernel;
    case 3: return (const void *)rs_wf_resolve_kernel;
    case 4: return (const void *)rs_wf_film_kernel;
    case 5: return (const void *)rs_wf_trace_flat_kernel;
    case 6: return (const void *)rs_wf_passes_kernel;
    }
    return NULL;
}

/* ---- memory ------------------------------------------------------------------------------- */

/* The bytes of one slot's arrays for `cap` paths (each array 256-byte aligned), cut from `base`
 * (NULL: only measured). */
static size_t slot_layout(char *base, uint32_t cap, rs_cuda_wf_slot *s)
{
    size_t off = 0;
#define RS_CUT(ptr, type, count) RS_CUDA_CUT(base, off, ptr, type, count);
#define RS_CUT_PATH(type, name) RS_CUT(s->paths.name, type, cap)
#define RS_CUT_Q0(type, name)   RS_CUT(s->queue[0].name, type, cap)
#define RS_CUT_Q1(type, name)   RS_CUT(s->queue[1].name, type, cap)
#define RS_CUT_SH(type, name)   RS_CUT(s->shadow.name, type, cap)
#define RS_CUT_HIT(type, name)  RS_CUT(s->hits.name, type, cap)
    RS_PATH_ALL_FIELDS(RS_CUT_PATH)
    RS_RAY_FIELDS(RS_CUT_Q0)
    RS_RAY_FIELDS(RS_CUT_Q1)
    RS_RAY_FIELDS(RS_CUT_SH)
    RS_HIT_FIELDS(RS_CUT_HIT)
    RS_CUT(s->occ, uint8_t, cap)
    RS_CUT(s->d_counts, unsigned int, 8)
#undef RS_CUT_PATH
#undef RS_CUT_Q0
#undef RS_CUT_Q1
#undef RS_CUT_SH
#undef RS_CUT_HIT
#undef RS_CUT
    s->paths.capacity = cap;
    s->queue[0].capacity = s->queue[1].capacity = s->shadow.capacity = cap;
    s->hits.capacity = cap;
    return off;
}

void rs_cuda_wf_release(rs_cuda_impl *c)
{
    rs_cuda_wf *wf = &c->wf;
    int k;
    for (k = 0; k < 2; ++k) {
        rs_cuda_wf_slot *s = &wf->slot[k];
        if (s->done)
            (void)cudaEventSynchronize(s->done);
        (void)cudaFree(s->block);
        if (s->h_counts)
            (void)cudaFreeHost(s->h_counts);
        if (s->done)
            (void)cudaEventDestroy(s->done);
    }
    (void)cudaFree(wf->film.sum);
    (void)cudaFree(wf->film.count);
    (void)cudaFree(wf->film.sum_l2);
    (void)cudaFree(wf->film.nonfinite);
    (void)cudaFree(wf->film.pass);
    (void)cudaFree(wf->film.pass_hits);
    (void)cudaFree(wf->pixel_of);
    rs_free(wf->h_sum);
    rs_free(wf->h_count);
    rs_free(wf->h_sum_l2);
    rs_free(wf->h_pass);
    rs_free(wf->h_pass_hits);
    memset(wf, 0, sizeof *wf);
}

/* Paths per wave: RS_CUDA_WF_WAVE, or what a quarter of the free memory holds for both slots. */
static uint32_t wave_capacity(void)
{
    size_t free_b = 0, total = 0, per;
    rs_cuda_wf_slot probe;
    uint32_t cap = RS_CUDA_WF_WAVE;
    memset(&probe, 0, sizeof probe);
    per = slot_layout(NULL, 1024, &probe) / 1024 + 1;
    if (cudaMemGetInfo(&free_b, &total) == cudaSuccess && free_b / 4 / (2 * per) < cap)
        cap = (uint32_t)(free_b / 4 / (2 * per));
    return cap < 65536u ? 65536u : cap;
}

static int block_of(const void *fn)
{
    int min_grid = 0, block = 0;
    if (cudaOccupancyMaxPotentialBlockSize(&min_grid, &block, fn, 0, 0) != cudaSuccess || block <= 0)
        return 128;
    block -= block % RS_WARP; /* whole warps: the appends' ballots need every lane */
    return block >= RS_WARP ? block : RS_WARP;
}

/* Threads of `fn` resident on the whole device at once, in blocks of `block` (0 if unknown). */
static uint32_t resident_of(int ordinal, const void *fn, int block)
{
    int per_sm = 0, sms = 0;
    if (cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, fn, block, 0) != cudaSuccess ||
        cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, ordinal) != cudaSuccess)
        return 0;
    return (uint32_t)per_sm * (uint32_t)sms * (uint32_t)block;
}

/* Everything render_paths needs, made at its first call (the film's variance words when the
 * host film first keeps them); on failure the caller releases what was made. */
static rs_status wf_make(rs_cuda_impl *c, int l2, int passes)
{
    rs_cuda_wf *wf = &c->wf;
    size_t npix = c->mk.it.npix;
    int k;
    if (!wf->cap) {
        uint32_t cap, most = 0;
        for (k = 0; k < RS_CUDA_WF_ENTRIES; ++k)
            wf->block[k] = block_of(rs_cuda_wf_entry(k));
        /* a whole number of the busiest kernels' resident threads: no partial last wave of
         * threads at a wave's first bounce (the trace kernels' count is twice the shade
         * kernel's on an H200: 135,168 and 67,584) */
        for (k = 0; k < 3; ++k) {
            static const int busy[3] = {1, 2, 5}; /* trace, shade, flat trace */
            uint32_t r = resident_of(c->ordinal, rs_cuda_wf_entry(busy[k]), wf->block[busy[k]]);
            most = r > most ? r : most;
        }
        cap = wave_capacity();
        if (most > 0 && cap >= most)
            cap -= cap % most;
        for (k = 0; k < 2; ++k) {
            rs_cuda_wf_slot *s = &wf->slot[k];
            size_t bytes = slot_layout(NULL, cap, s);
            CUDA_TRY(cudaMalloc(&s->block, bytes));
            slot_layout((char *)s->block, cap, s);
            CUDA_TRY(cudaHostAlloc((void **)&s->h_counts, 8 * sizeof(unsigned int),
                                   cudaHostAllocPortable));
            CUDA_TRY(cudaEventCreateWithFlags(&s->done, cudaEventDisableTiming));
        }
        CUDA_TRY(cudaMalloc((void **)&wf->film.sum, 6 * npix * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMalloc((void **)&wf->film.count, npix * sizeof(unsigned int)));
        CUDA_TRY(cudaMalloc((void **)&wf->film.nonfinite, sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMemset(wf->film.sum, 0, 6 * npix * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMemset(wf->film.count, 0, npix * sizeof(unsigned int)));
        CUDA_TRY(cudaMemset(wf->film.nonfinite, 0, sizeof(rs_wf_u64)));
        wf->h_sum = (rs_wf_u64 *)rs_alloc(6 * npix, sizeof(rs_wf_u64));
        wf->h_count = (unsigned int *)rs_alloc(npix, sizeof(unsigned int));
        if (!wf->h_sum || !wf->h_count)
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the wavefront's film");
        wf->cap = cap;
    }
    if (l2 && !wf->film.sum_l2) {
        CUDA_TRY(cudaMalloc((void **)&wf->film.sum_l2, 3 * npix * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMemset(wf->film.sum_l2, 0, 3 * npix * sizeof(rs_wf_u64)));
        if (!(wf->h_sum_l2 = (rs_wf_u64 *)rs_alloc(3 * npix, sizeof(rs_wf_u64))))
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the wavefront's film");
    }
    if (passes && !wf->film.pass) {
        size_t words = 2 * RS_FILM_PASSES * npix;
        CUDA_TRY(cudaMalloc((void **)&wf->film.pass, words * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMalloc((void **)&wf->film.pass_hits, npix * sizeof(unsigned int)));
        CUDA_TRY(cudaMemset(wf->film.pass, 0, words * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMemset(wf->film.pass_hits, 0, npix * sizeof(unsigned int)));
        wf->h_pass = (rs_wf_u64 *)rs_alloc(words, sizeof(rs_wf_u64));
        wf->h_pass_hits = (unsigned int *)rs_alloc(npix, sizeof(unsigned int));
        if (!wf->h_pass || !wf->h_pass_hits)
            return rs_error_set(RS_ERR_NOMEM, "out of memory for the wavefront's passes");
    }
    CUDA_TRY(cudaDeviceSynchronize()); /* the memsets ran on the legacy stream */
    return RS_OK;
}

/* The plan's pixels on the device, copied again whenever the plan changes. */
static rs_status wf_pixels(rs_cuda_impl *c, const rs_paths_job *job)
{
    rs_cuda_wf *wf = &c->wf;
    if (!job->pixel_of || (wf->pixel_of && wf->plan_id == job->plan_id))
        return RS_OK;
    if (wf->pixel_cap < job->n_active) {
        (void)cudaFree(wf->pixel_of);
        wf->pixel_of = NULL;
        wf->pixel_cap = 0;
        CUDA_TRY(cudaMalloc((void **)&wf->pixel_of, (size_t)job->n_active * sizeof(uint32_t)));
        wf->pixel_cap = job->n_active;
    }
    CUDA_TRY(cudaMemcpy(wf->pixel_of, job->pixel_of, (size_t)job->n_active * sizeof(uint32_t),
                        cudaMemcpyHostToDevice));
    wf->plan_id = job->plan_id;
    return RS_OK;
}

/* ---- the waves ---------------------------------------------------------------------------- */

/* The trace kernel for the scene: the flat one where it has no instances. */
static int trace_kernel(const rs_path_tracer *tr) { return tr->geom.n_instances == 0 ? 5 : 1; }

static rs_status launch(const void *fn, uint32_t n, int block, void **args, cudaStream_t stream)
{
    if (n == 0)
        return RS_OK;
    CUDA_TRY(cudaLaunchKernel(fn, dim3((n + (uint32_t)block - 1) / (uint32_t)block), dim3(block),
                              args, 0, stream));
    return RS_OK;
}

/* Slot s's segment: closest hits of the current queue (its count on the device: d_counts[2]),
 * shading, the counts copied out, the event.  `upper` bounds the queue's entries (the grid). */
static rs_status wf_segment(rs_cuda_impl *c, rs_cuda_wf_slot *s, uint32_t upper)
{
    rs_cuda_wf *wf = &c->wf;
    rs_trace_batch tb;
    const rs_path_tracer *tr = &c->mk.copy.tracer;
    unsigned int *alive = &s->d_counts[2];
    unsigned int *counts = s->d_counts;
    rs_ray_soa *next = &s->queue[s->cur ^ 1];
    void *targs[4], *sargs[9];
    rs_status st;
    memset(&tb, 0, sizeof tb);
    tb.kind = RS_TRACE_CLOSEST;
    tb.rays = s->queue[s->cur];
    tb.hits = s->hits;
    targs[0] = (void *)&tr->bvh;
    targs[1] = (void *)&tr->geom;
    targs[2] = &tb;
    targs[3] = &alive;
    if ((st = launch(rs_cuda_wf_entry(trace_kernel(tr)), upper, wf->block[trace_kernel(tr)], targs,
                     s->stream)) != RS_OK)
        return st;
    CUDA_TRY(cudaMemsetAsync(counts, 0, 2 * sizeof(unsigned int), s->stream));
    if (s->w.bounce == 0 && c->mk.it.passes) {
        void *pargs[5];
        pargs[0] = &c->mk.it;
        pargs[1] = &s->queue[s->cur];
        pargs[2] = &s->hits;
        pargs[3] = &s->paths;
        pargs[4] = &alive;
        if ((st = launch(rs_cuda_wf_entry(6), upper, wf->block[6], pargs, s->stream)) != RS_OK)
            return st;
    }
    sargs[0] = &c->mk.it;
    sargs[1] = &s->w;
    sargs[2] = &s->queue[s->cur];
    sargs[3] = &s->hits;
    sargs[4] = &s->paths;
    sargs[5] = next;
    sargs[6] = &s->shadow;
    sargs[7] = &alive;
    sargs[8] = &counts;
    if ((st = launch(rs_cuda_wf_entry(2), upper, wf->block[2], sargs, s->stream)) != RS_OK)
        return st;
    CUDA_TRY(cudaMemcpyAsync(s->h_counts, counts, 2 * sizeof(unsigned int), cudaMemcpyDeviceToHost,
                             s->stream));
    CUDA_TRY(cudaEventRecord(s->done, s->stream));
    s->upper = upper;
    s->pending = 1;
    return RS_OK;
}

/* Starts a wave of paths [g, g + n) in slot s: raygen, the first segment. */
static rs_status wf_start(rs_cuda_impl *c, rs_cuda_wf_slot *s, const rs_paths_job *job, uint64_t g,
                          uint32_t n)
{
    rs_cuda_wf *wf = &c->wf;
    void *args[4];
    rs_status st;
    memset(&s->w, 0, sizeof s->w);
    s->w.pixel_of = job->pixel_of ? wf->pixel_of : NULL;
    s->w.n_active = job->n_active;
    s->w.start = g;
    s->w.count = n;
    s->w.bounce = 0;
    s->cur = 0;
    args[0] = &c->mk.it;
    args[1] = &s->w;
    args[2] = &s->paths;
    args[3] = &s->queue[0];
    if ((st = launch(rs_cuda_wf_entry(0), n, wf->block[0], args, s->stream)) != RS_OK)
        return st;
    /* the first queue's count, the wave's paths, from pinned memory that stays as it is until
     * the wave has ended */
    s->h_counts[4] = n;
    CUDA_TRY(cudaMemcpyAsync(&s->d_counts[2], &s->h_counts[4], sizeof(unsigned int),
                             cudaMemcpyHostToDevice, s->stream));
    s->active = 1;
    return wf_segment(c, s, n);
}

/* Slot s's segment has ended (its event): the shadow rays traced and resolved, then the next
 * segment, or the film when no path is alive.  *finished: the wave is on the film (queued). */
static rs_status wf_advance(rs_cuda_impl *c, rs_cuda_wf_slot *s, rs_path_counts *counts,
                            int *finished)
{
    rs_cuda_wf *wf = &c->wf;
    const rs_path_tracer *tr = &c->mk.copy.tracer;
    uint32_t n_next = s->h_counts[0], n_shadow = s->h_counts[1];
    rs_status st;
    *finished = 0;
    s->pending = 0;
    counts->closest += s->upper;
    if (s->w.bounce > counts->max_bounce)
        counts->max_bounce = s->w.bounce;
    if (n_shadow) {
        rs_trace_batch tb;
        unsigned int *cnt = &s->d_counts[1];
        void *targs[4], *rargs[4];
        memset(&tb, 0, sizeof tb);
        tb.kind = RS_TRACE_OCCLUDED;
        tb.rays = s->shadow;
        tb.occluded = s->occ;
        targs[0] = (void *)&tr->bvh;
        targs[1] = (void *)&tr->geom;
        targs[2] = &tb;
        targs[3] = &cnt;
        if ((st = launch(rs_cuda_wf_entry(trace_kernel(tr)), n_shadow,
                         wf->block[trace_kernel(tr)], targs, s->stream)) != RS_OK)
            return st;
        rargs[0] = &s->shadow;
        rargs[1] = &s->occ;
        rargs[2] = &s->paths;
        rargs[3] = &cnt;
        if ((st = launch(rs_cuda_wf_entry(3), n_shadow, wf->block[3], rargs, s->stream)) != RS_OK)
            return st;
        counts->shadow += n_shadow;
    }
    if (n_next) {
        s->cur ^= 1;
        s->w.bounce++;
        /* the next queue's count becomes the current one's on the device */
        CUDA_TRY(cudaMemcpyAsync(&s->d_counts[2], &s->d_counts[0], sizeof(unsigned int),
                                 cudaMemcpyDeviceToDevice, s->stream));
        return wf_segment(c, s, n_next);
    }
    {
        void *args[3];
        args[0] = &s->w;
        args[1] = &s->paths;
        args[2] = &wf->film;
        if ((st = launch(rs_cuda_wf_entry(4), s->w.count, wf->block[4], args, s->stream)) != RS_OK)
            return st;
    }
    s->active = 0;
    *finished = 1;
    return RS_OK;
}

/* The device film onto the host's (exact), then cleared on the device. */
static rs_status wf_film_out(rs_device *d, rs_cuda_impl *c, rs_film *film)
{
    rs_cuda_wf *wf = &c->wf;
    size_t npix = c->mk.it.npix;
    rs_wf_u64 nonfinite = 0;
    rs_wf_film host;
    rs_film view;
    int l2 = film->sum_l2 != NULL && wf->film.sum_l2 != NULL;
    int passes = film->pass != NULL && wf->film.pass != NULL;
    size_t pass_words = 2 * RS_FILM_PASSES * npix;
    CUDA_TRY(cudaDeviceSynchronize());
    CUDA_TRY(cudaMemcpy(wf->h_sum, wf->film.sum, 6 * npix * sizeof(rs_wf_u64),
                        cudaMemcpyDeviceToHost));
    CUDA_TRY(cudaMemcpy(wf->h_count, wf->film.count, npix * sizeof(unsigned int),
                        cudaMemcpyDeviceToHost));
    CUDA_TRY(cudaMemcpy(&nonfinite, wf->film.nonfinite, sizeof nonfinite, cudaMemcpyDeviceToHost));
    if (l2)
        CUDA_TRY(cudaMemcpy(wf->h_sum_l2, wf->film.sum_l2, 3 * npix * sizeof(rs_wf_u64),
                            cudaMemcpyDeviceToHost));
    if (passes) {
        CUDA_TRY(cudaMemcpy(wf->h_pass, wf->film.pass, pass_words * sizeof(rs_wf_u64),
                            cudaMemcpyDeviceToHost));
        CUDA_TRY(cudaMemcpy(wf->h_pass_hits, wf->film.pass_hits, npix * sizeof(unsigned int),
                            cudaMemcpyDeviceToHost));
        d->stats.bytes_from_device += pass_words * sizeof(rs_wf_u64) + npix * sizeof(unsigned int);
    }
    d->stats.bytes_from_device += npix * (6 * sizeof(rs_wf_u64) + sizeof(unsigned int)) +
                                  (l2 ? 3 * npix * sizeof(rs_wf_u64) : 0);
    CUDA_TRY(cudaMemset(wf->film.sum, 0, 6 * npix * sizeof(rs_wf_u64)));
    CUDA_TRY(cudaMemset(wf->film.count, 0, npix * sizeof(unsigned int)));
    CUDA_TRY(cudaMemset(wf->film.nonfinite, 0, sizeof(rs_wf_u64)));
    if (wf->film.sum_l2)
        CUDA_TRY(cudaMemset(wf->film.sum_l2, 0, 3 * npix * sizeof(rs_wf_u64)));
    if (wf->film.pass) {
        CUDA_TRY(cudaMemset(wf->film.pass, 0, pass_words * sizeof(rs_wf_u64)));
        CUDA_TRY(cudaMemset(wf->film.pass_hits, 0, npix * sizeof(unsigned int)));
    }
    CUDA_TRY(cudaDeviceSynchronize());
    memset(&host, 0, sizeof host);
    host.sum = wf->h_sum;
    host.count = wf->h_count;
    host.sum_l2 = l2 ? wf->h_sum_l2 : NULL;
    host.nonfinite = &nonfinite;
    host.pass = passes ? wf->h_pass : NULL;
    host.pass_hits = passes ? wf->h_pass_hits : NULL;
    view = rs_wf_film_view(&host, film->width, film->height);
    return rs_film_merge(film, &view);
}

rs_status rs_cuda_render_paths(rs_device *d, const rs_paths_job *job, uint64_t p0, uint64_t p1,
                               uint64_t *done, rs_path_counts *counts)
{
    rs_cuda_impl *c = (rs_cuda_impl *)d->impl;
    rs_cuda_wf *wf = &c->wf;
    uint64_t next = p0;
    rs_status st = RS_OK;
    int k, stop = 0;
    *done = 0;
    if (!c->mk.ready)
        return rs_error_set(RS_ERR_ARG, "device %s: render_paths before upload_scene", d->name);
    if (job->film->width * job->film->height != c->mk.it.npix)
        return rs_error_set(RS_ERR_ARG, "device %s: the film is not the upload_scene's image size",
                            d->name);
    CUDA_TRY(cudaSetDevice(c->ordinal));
    if ((st = wf_make(c, job->film->sum_l2 != NULL, job->film->pass != NULL && c->mk.it.passes)) !=
            RS_OK ||
        (st = wf_pixels(c, job)) != RS_OK) {
        rs_cuda_wf_release(c);
        return st;
    }
    for (k = 0; k < 2; ++k)
        wf->slot[k].stream = c->st[k].stream;
    /* two waves in flight; the host waits for whichever segment it queued first */
    for (;;) {
        int any = 0;
        for (k = 0; k < 2 && st == RS_OK; ++k) {
            rs_cuda_wf_slot *s = &wf->slot[k];
            if (!s->active && !stop && next < p1) {
                uint32_t n = p1 - next < wf->cap ? (uint32_t)(p1 - next) : wf->cap;
                st = wf_start(c, s, job, next, n);
                next += n;
            }
            any |= s->active;
        }
        if (st != RS_OK || !any)
            break;
        for (k = 0; k < 2 && st == RS_OK; ++k) {
            rs_cuda_wf_slot *s = &wf->slot[k];
            int finished = 0;
            if (!s->pending)
                continue;
            if (cudaEventSynchronize(s->done) != cudaSuccess) {
                st = rs_error_set(RS_ERR_CUDA, "device %s: a wavefront kernel failed: %s",
                                  d->name, cudaGetErrorString(cudaGetLastError()));
                break;
            }
            st = wf_advance(c, s, counts, &finished);
        }
        if (!stop && job->cancelled && job->cancelled(job->user))
            stop = 1; /* no new wave; the waves under way end on the film */
    }
    if (st != RS_OK) {
        for (k = 0; k < 2; ++k)
            wf->slot[k].active = wf->slot[k].pending = 0;
        (void)cudaDeviceSynchronize();
        *done = 0;
        return st;
    }
    *done = next - p0; /* every wave started has ended on the film: a prefix */
    return wf_film_out(d, c, job->film);
}
