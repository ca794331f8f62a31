/* gpu/gpu_fallback.c — the stand-in for a CUDA device that is not there.
 *
 * It follows the CUDA device's data flow with host memory and host threads, and runs the same
 * kernel bodies, so that its answers and images are the CUDA device's wherever the CUDA device's
 * own are the CPU's (tests/gpu_trace_test.c says where; render_gpucheck_test checks the fallback
 * against the CPU device bit for bit):
 *   upload       copies the geometry and BVH into memory of its own (scheduler/device_copy.h with
 *                host ops; the GPU: the same call with CUDA ops): nothing of the caller's is
 *                borrowed;
 *   trace        cuts each chunk into the CUDA device's pieces (rs_gpu_piece_size: the same
 *                boundaries, none over the CUDA staging's size) and, piece by piece, copies the
 *                rays into its own staging buffers ("copy in", rs_trace_stage_in), runs the
 *                kernel body — rs_trace_one, the RS_HD binary BVH traversal the CUDA kernel runs —
 *                over them on host threads, and copies the answers back ("copy out",
 *                rs_trace_stage_out); the bytes are counted as the CUDA device counts a chunk's;
 *   upload_scene copies the scene and the render constants (the same rs_device_copy_scene call
 *                as the GPU's; a pass of no pixels is refused, as there);
 *   render_pass  the CUDA render_pass's passes: per sample, rs_gpu_path_radiance (the CUDA
 *                kernel's own loop, gpu/megakernel_path.h) for every pixel into a radiance
 *                buffer (the pixels split among host threads by the job's strategy),
 *                then rs_film_add_image: each pixel's samples added in sample order.  Its image is
 *                the CPU megakernel's, bit for bit.
 * What it does not imitate: the two CUDA streams (its pieces run one after another, so nothing
 * overlaps), the page-locked memory (it has no host_alloc, so a batch is never "pinned" and every
 * piece goes through its staging, where the CUDA device copies a pinned batch by DMA in place),
 * the double-buffered overlap of one sample's film add with the next sample's kernel, and the
 * sizes: it asks the pass loop for 1 sample per render_pass call (the GPU 4) and looks at cancel
 * between pixels as well as between samples, since a host pass is slow; its flags are 0 (no own
 * memory), so the scheduler gives it a CPU's chunk sizes and one wave in flight.  Its stats count
 * chunk traffic only (the GPU also counts the upload, the scene copy and each pass's image).
 * Thread safety: as scheduler/device.h; the ray counters of a pass are atomics. */
#include "gpu/gpu_device.h"

#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include "accel/trace.h"
#include "core/alloc.h"
#include "core/cores.h"
#include "gpu/megakernel_path.h"
#include "gpu/wavefront.h"
#include "scheduler/device_copy.h"
#include "scheduler/sched.h"
#include "shading/path_counts.h"

typedef struct fallback_impl {
    rs_device_geom geom; /* its own copy of what trace reads */
    int uploaded;
    rs_ray_soa rays; /* staging, `cap` entries */
    rs_hit_soa hits;
    uint8_t *occluded;
    uint32_t cap;
    rs_cores *cores;
    /* upload_scene */
    rs_device_scene scene; /* its own copy of the scene */
    rs_render_consts it;   /* the render's constants, it.scene = scene.scene */
    rs_vec3 *radiance;     /* it.npix: one pass */
    rs_path_aux *aux;      /* it.npix: one pass's passes (it.passes), or NULL */
    int pass_ready;
    /* render_paths: the wavefront's buffers (RS_WF_FALLBACK_WAVE paths, made at the first call)
     * and its film (it.npix pixels) */
    rs_paths paths;
    rs_ray_soa queue[2], shadow;
    rs_hit_soa wf_hits;
    uint8_t *occ;
    uint32_t wf_cap;
    rs_wf_film film;
} fallback_impl;

/* The fallback's waves: smaller than the GPU's (host caches), the same stages. */
#define RS_WF_FALLBACK_WAVE (1u << 16)
/* Fewer items than this run on the calling thread: a wave's last segments hold a few paths, and
 * a parallel region for each would cost more than the work (OpenMP's spinning threads). */
#define RS_WF_FALLBACK_PAR_MIN 4096

/* One ray, as the CUDA device traces it: by the flat kernel's body where the geometry has no
 * instances (so the host tests run the code that kernel runs). */
static inline void trace_ray(const rs_bvh_view *b, const rs_geom *g, const rs_trace_batch *tb,
                             uint32_t i)
{
    if (g->n_instances == 0)
        rs_trace_one_flat(b, g, tb, i);
    else
        rs_trace_one(b, g, tb, i);
}

static void free_staging(fallback_impl *f)
{
    rs_ray_soa_free(&f->rays);
    rs_hit_soa_free(&f->hits);
    rs_free(f->occluded);
    f->occluded = NULL;
    f->cap = 0;
}

/* Room for n staged rays (a piece: at most the CUDA staging's rs_gpu_piece_size(
 * RS_SCHED_MAX_CHUNK)); grows (at least doubling, up to that size) only when a piece is larger
 * than any before, so pieces of a steady size allocate nothing. */
static rs_status ensure_staging(fallback_impl *f, uint32_t n)
{
    const uint32_t most = rs_gpu_piece_size(RS_SCHED_MAX_CHUNK);
    rs_status st;
    uint32_t cap;
    if (n <= f->cap)
        return RS_OK;
    cap = f->cap > n / 2 ? 2 * f->cap : n; /* f->cap < n <= most: no overflow */
    if (cap > most)
        cap = n > most ? n : most;
    free_staging(f);
    if ((st = rs_ray_soa_init(&f->rays, cap)) != RS_OK ||
        (st = rs_hit_soa_init(&f->hits, cap)) != RS_OK) {
        free_staging(f);
        return st;
    }
    f->occluded = (uint8_t *)rs_alloc_aligned(cap, 1);
    if (!f->occluded) {
        free_staging(f);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for %u staged rays", cap);
    }
    f->cap = cap;
    return RS_OK;
}

static void release_wavefront(fallback_impl *f)
{
    rs_paths_free(&f->paths);
    rs_ray_soa_free(&f->queue[0]);
    rs_ray_soa_free(&f->queue[1]);
    rs_ray_soa_free(&f->shadow);
    rs_hit_soa_free(&f->wf_hits);
    rs_free(f->occ);
    f->occ = NULL;
    f->wf_cap = 0;
    rs_free(f->film.sum);
    rs_free(f->film.count);
    rs_free(f->film.sum_l2);
    rs_free(f->film.nonfinite);
    rs_free(f->film.pass);
    rs_free(f->film.pass_hits);
    memset(&f->film, 0, sizeof f->film);
}

static void release_pass(fallback_impl *f)
{
    release_wavefront(f);
    rs_device_scene_release(&f->scene, &rs_device_copy_host_ops);
    rs_free(f->radiance);
    rs_free(f->aux);
    f->radiance = NULL;
    f->aux = NULL;
    f->pass_ready = 0;
}

static rs_status fallback_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    rs_status st;
    /* a second upload replaces the first (and what the megakernel borrowed of it) */
    release_pass(f);
    rs_device_geom_release(&f->geom, &rs_device_copy_host_ops);
    f->uploaded = 0;
    if ((st = rs_device_copy_geom(g, bvh, &rs_device_copy_host_ops, &f->geom)) != RS_OK)
        return st;
    f->uploaded = 1;
    return RS_OK;
}

/* One piece, rays [begin, begin + n) of the batch: copy in, the kernel body on host threads,
 * copy out. */
static void trace_piece(rs_device *d, fallback_impl *f, const rs_trace_batch *batch, uint32_t begin,
                        uint32_t n)
{
    rs_trace_batch db;
    long i;
    int threads;
    d->stats.bytes_to_device += rs_trace_stage_in(&f->rays, batch, begin, n);
    memset(&db, 0, sizeof db);
    db.kind = batch->kind;
    db.count = n;
    db.wave = batch->wave;
    db.rays = f->rays;
    db.hits = f->hits;
    db.occluded = f->occluded;
    threads = rs_cores_acquire(f->cores, d->threads);
    (void)threads; /* read only by the OpenMP clause */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && n >= 512u)
    for (i = 0; i < (long)n; ++i)
        trace_ray(&f->geom.bvh, &f->geom.geom, &db, (uint32_t)i);
    rs_cores_release(f->cores, threads);
    d->stats.bytes_from_device += rs_trace_stage_out(batch, begin, n, &f->hits, f->occluded);
}

/* The chunk in the CUDA device's pieces (gpu/cuda_device.cu:cuda_trace), one after another. */
static rs_status fallback_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin,
                                uint32_t end)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    uint32_t n = end - begin, piece, off, cap = rs_gpu_piece_size(RS_SCHED_MAX_CHUNK);
    rs_status st;
    if (!f->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: trace before upload", d->name);
    if (n == 0)
        return RS_OK;
    piece = rs_gpu_piece_size(n);
    if (piece > cap)
        piece = cap; /* a fixed chunk size above RS_SCHED_MAX_CHUNK: more pieces */
    if ((st = ensure_staging(f, piece)) != RS_OK)
        return st;
    for (off = begin; off < end; off += piece)
        trace_piece(d, f, batch, off, end - off < piece ? end - off : piece);
    return RS_OK;
}

static rs_status fallback_upload_scene(rs_device *d, const rs_scene *scene,
                                       const rs_render_consts *it)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    rs_status st;
    release_pass(f);
    if (!f->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: upload_scene before upload", d->name);
    if (it->npix == 0)
        return rs_error_set(RS_ERR_ARG, "device %s: a pass of no pixels", d->name);
    if ((st = rs_device_copy_scene(scene, &f->geom, &rs_device_copy_host_ops, &f->scene)) != RS_OK)
        return st;
    f->it = *it;
    f->it.scene = f->scene.scene;
    f->radiance = (rs_vec3 *)rs_alloc(it->npix, sizeof *f->radiance);
    if (it->passes)
        f->aux = (rs_path_aux *)rs_alloc(it->npix, sizeof *f->aux);
    if (!f->radiance || (it->passes && !f->aux)) {
        release_pass(f);
        return rs_error_set(RS_ERR_NOMEM, "device %s: out of memory for a %u-pixel pass", d->name,
                            it->npix);
    }
    f->pass_ready = 1;
    return RS_OK;
}

/* One pass on host threads: pixels of sample `sample`, the rays counted per range and summed
 * with atomics (the ranges run on any threads at once). */
typedef struct pass_ctx {
    const fallback_impl *f;
    const rs_pass_job *job;
    uint32_t sample;
    atomic_int stopped; /* job->cancelled said so: the pass is dropped */
    rs_path_counts_atomic counts;
} pass_ctx;

static void pass_pixels(void *ctx, uint32_t lo, uint32_t hi)
{
    pass_ctx *p = (pass_ctx *)ctx;
    const rs_render_consts *it = &p->f->it;
    const rs_pass_job *job = p->job;
    rs_path_counts n = {0, 0, 0};
    uint32_t pixel;
    for (pixel = lo; pixel < hi; ++pixel) {
        /* per pixel: a pass over a large image takes seconds on a few host threads */
        if (atomic_load(&p->stopped) || (job->cancelled && job->cancelled(job->user))) {
            atomic_store(&p->stopped, 1);
            break;
        }
        p->f->radiance[pixel] = rs_gpu_path_radiance(it, &p->f->scene.tracer, pixel, p->sample, &n);
        if (p->f->aux)
            p->f->aux[pixel] = rs_gpu_path_aux(it, &p->f->scene.tracer, pixel, p->sample);
    }
    rs_path_counts_atomic_add(&p->counts, &n);
}

static rs_status fallback_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                                      rs_path_counts *counts)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    uint32_t npix = f->it.npix, s;
    pass_ctx p;
    int threads;
    if (!f->pass_ready)
        return rs_error_set(RS_ERR_ARG, "device %s: render_pass before upload_scene", d->name);
    if (job->film->width * job->film->height != npix)
        return rs_error_set(RS_ERR_ARG, "device %s: the film is not the upload_scene's image size",
                            d->name);
    memset(&p, 0, sizeof p);
    p.f = f;
    p.job = job;
    atomic_init(&p.stopped, 0);
    rs_path_counts_atomic_init(&p.counts);
    threads = rs_cores_acquire(f->cores, d->threads);
    for (s = s0; s - s0 < n; ++s) {
        if (job->cancelled && job->cancelled(job->user))
            break;
        p.sample = s;
        rs_parallel_range(job->strategy, threads, 0, npix, 1024, pass_pixels, &p);
        if (atomic_load(&p.stopped))
            break; /* a partial pass is left out: the film holds whole samples */
        rs_film_add_image(job->film, f->radiance, threads);
        if (job->film->pass && f->aux)
            rs_film_add_pass_image(job->film, f->aux, threads);
        if (job->progress)
            job->progress(job->user, npix);
    }
    rs_cores_release(f->cores, threads);
    rs_path_counts_atomic_drain(&p.counts, counts);
    return RS_OK;
}

/* The wavefront's buffers and film, made at the first render_paths (the film's variance words
 * and passes when the host film first keeps them). */
static rs_status wavefront_ready(rs_device *d, fallback_impl *f, int l2, int passes)
{
    size_t npix = f->it.npix;
    rs_status st;
    if (!f->wf_cap) {
        uint32_t cap = RS_WF_FALLBACK_WAVE;
        if ((st = rs_paths_init(&f->paths, cap)) != RS_OK ||
            (st = rs_ray_soa_init(&f->queue[0], cap)) != RS_OK ||
            (st = rs_ray_soa_init(&f->queue[1], cap)) != RS_OK ||
            (st = rs_ray_soa_init(&f->shadow, cap)) != RS_OK ||
            (st = rs_hit_soa_init(&f->wf_hits, cap)) != RS_OK)
            goto fail;
        f->occ = (uint8_t *)rs_alloc_aligned(cap, 1);
        f->film.sum = (rs_wf_u64 *)rs_calloc(6 * npix, sizeof *f->film.sum);
        f->film.count = (unsigned int *)rs_calloc(npix, sizeof *f->film.count);
        f->film.nonfinite = (rs_wf_u64 *)rs_calloc(1, sizeof *f->film.nonfinite);
        if (!f->occ || !f->film.sum || !f->film.count || !f->film.nonfinite)
            goto nomem;
        f->wf_cap = cap;
    }
    if (l2 && !f->film.sum_l2 &&
        !(f->film.sum_l2 = (rs_wf_u64 *)rs_calloc(3 * npix, sizeof *f->film.sum_l2)))
        goto nomem;
    if (passes && !f->film.pass) {
        f->film.pass = (rs_wf_u64 *)rs_calloc(2 * RS_FILM_PASSES * npix, sizeof *f->film.pass);
        f->film.pass_hits = (unsigned int *)rs_calloc(npix, sizeof *f->film.pass_hits);
        if (!f->film.pass || !f->film.pass_hits)
            goto nomem;
    }
    return RS_OK;
nomem:
    st = rs_error_set(RS_ERR_NOMEM, "device %s: out of memory for the wavefront", d->name);
fail:
    release_wavefront(f);
    return st;
}

/* One wave of the wavefront on host threads: the CUDA kernels' bodies (gpu/wavefront.h) as
 * loops, the queues appended with atomics as there. */
static void run_wave(fallback_impl *f, int threads, rs_wf_wave *w, rs_path_counts *counts)
{
    const rs_render_consts *it = &f->it;
    const rs_path_tracer *tr = &f->scene.tracer;
    uint32_t alive = w->count, cur = 0;
    long i;
    (void)threads; /* read only by the OpenMP clauses */
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && w->count >= RS_WF_FALLBACK_PAR_MIN)
    for (i = 0; i < (long)w->count; ++i)
        rs_wf_raygen(it, w, (uint32_t)i, &f->paths, &f->queue[0]);
    for (w->bounce = 0; alive > 0; w->bounce++) {
        rs_trace_batch tb;
        uint32_t n_next = 0, n_shadow = 0;
        memset(&tb, 0, sizeof tb);
        tb.kind = RS_TRACE_CLOSEST;
        tb.count = alive;
        tb.rays = f->queue[cur];
        tb.hits = f->wf_hits;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && alive >= RS_WF_FALLBACK_PAR_MIN)
        for (i = 0; i < (long)alive; ++i)
            trace_ray(&tr->bvh, &tr->geom, &tb, (uint32_t)i);
        counts->closest += alive;
        if (w->bounce > counts->max_bounce)
            counts->max_bounce = w->bounce;
        if (w->bounce == 0 && it->passes) {
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && alive >= RS_WF_FALLBACK_PAR_MIN)
            for (i = 0; i < (long)alive; ++i)
                rs_wf_passes(it, (uint32_t)i, &f->queue[cur], &f->wf_hits, &f->paths);
        }
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && alive >= RS_WF_FALLBACK_PAR_MIN)
        for (i = 0; i < (long)alive; ++i) {
            rs_ray nr, sr;
            uint32_t p, made = rs_wf_shade(it, w, (uint32_t)i, &f->queue[cur], &f->wf_hits, &f->paths,
                                           &nr, &sr, &p);
            if (made & RS_SHADE_SHADOW)
                rs_ray_soa_set(&f->shadow, RS_ATOMIC_ADD_U32(&n_shadow, 1u), &sr, p);
            if (made & RS_SHADE_NEXT)
                rs_ray_soa_set(&f->queue[cur ^ 1], RS_ATOMIC_ADD_U32(&n_next, 1u), &nr, p);
        }
        if (n_shadow) {
            tb.kind = RS_TRACE_OCCLUDED;
            tb.count = n_shadow;
            tb.rays = f->shadow;
            tb.occluded = f->occ;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && n_shadow >= RS_WF_FALLBACK_PAR_MIN)
            for (i = 0; i < (long)n_shadow; ++i)
                trace_ray(&tr->bvh, &tr->geom, &tb, (uint32_t)i);
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && n_shadow >= RS_WF_FALLBACK_PAR_MIN)
            for (i = 0; i < (long)n_shadow; ++i)
                rs_wf_resolve((uint32_t)i, &f->shadow, f->occ, &f->paths);
            counts->shadow += n_shadow;
        }
        cur ^= 1;
        alive = n_next;
    }
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1 && w->count >= RS_WF_FALLBACK_PAR_MIN)
    for (i = 0; i < (long)w->count; ++i)
        rs_wf_film_path(w, (uint32_t)i, &f->paths, &f->film);
}

static rs_status fallback_render_paths(rs_device *d, const rs_paths_job *job, uint64_t p0,
                                       uint64_t p1, uint64_t *done, rs_path_counts *counts)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    rs_wf_wave w;
    rs_film view;
    rs_status st;
    uint64_t g;
    int threads;
    *done = 0;
    if (!f->pass_ready)
        return rs_error_set(RS_ERR_ARG, "device %s: render_paths before upload_scene", d->name);
    if (job->film->width * job->film->height != f->it.npix)
        return rs_error_set(RS_ERR_ARG, "device %s: the film is not the upload_scene's image size",
                            d->name);
    if ((st = wavefront_ready(d, f, job->film->sum_l2 != NULL,
                              job->film->pass != NULL && f->it.passes)) != RS_OK)
        return st;
    memset(&w, 0, sizeof w);
    w.pixel_of = job->pixel_of; /* host memory is the fallback's own */
    w.n_active = job->n_active;
    threads = rs_cores_acquire(f->cores, d->threads);
    for (g = p0; g < p1; g += w.count) {
        if (job->cancelled && job->cancelled(job->user))
            break;
        w.start = g;
        w.count = p1 - g < f->wf_cap ? (uint32_t)(p1 - g) : f->wf_cap;
        run_wave(f, threads, &w, counts);
        *done += w.count;
    }
    rs_cores_release(f->cores, threads);
    /* the finished waves onto the host's film, the device's cleared for the next call */
    view = rs_wf_film_view(&f->film, job->film->width, job->film->height);
    if (!job->film->sum_l2)
        view.sum_l2 = NULL;
    if (!job->film->pass)
        view.pass = NULL;
    st = rs_film_merge(job->film, &view);
    memset(f->film.sum, 0, 6 * (size_t)f->it.npix * sizeof *f->film.sum);
    memset(f->film.count, 0, (size_t)f->it.npix * sizeof *f->film.count);
    if (f->film.sum_l2)
        memset(f->film.sum_l2, 0, 3 * (size_t)f->it.npix * sizeof *f->film.sum_l2);
    if (f->film.pass) {
        memset(f->film.pass, 0, 2 * RS_FILM_PASSES * (size_t)f->it.npix * sizeof *f->film.pass);
        memset(f->film.pass_hits, 0, (size_t)f->it.npix * sizeof *f->film.pass_hits);
    }
    *f->film.nonfinite = 0;
    return st;
}

static void fallback_destroy(rs_device *d)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    if (f) {
        free_staging(f);
        release_pass(f);
        rs_device_geom_release(&f->geom, &rs_device_copy_host_ops);
    }
    rs_free(f);
    rs_free(d);
}

static const rs_device_ops fallback_ops = {fallback_upload,
                                           fallback_trace,
                                           fallback_destroy,
                                           NULL, /* host_alloc: malloc */
                                           NULL,
                                           fallback_upload_scene,
                                           fallback_render_pass,
                                           fallback_render_paths};

rs_status rs_gpu_fallback_create(int threads, int gpu_index, rs_cores *cores, rs_device **out)
{
    rs_device *d = (rs_device *)rs_calloc(1, sizeof *d);
    fallback_impl *f = (fallback_impl *)rs_calloc(1, sizeof *f);
    *out = NULL;
    if (!d || !f) {
        rs_free(d);
        rs_free(f);
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the GPU fallback device");
    }
    f->cores = cores;
    d->ops = &fallback_ops;
    d->impl = f;
    d->flags = 0; /* it runs on host threads */
    d->threads = threads < 1 ? 1 : threads;
    d->pass_samples = 1;
    snprintf(d->name, sizeof d->name, "gpu-fallback:%d", gpu_index);
    *out = d;
    return RS_OK;
}
