/* gpu/gpu_fallback.c — the stand-in for a CUDA device that is not there.
 *
 * It does what the CUDA device does, step for step, with host memory and host threads:
 *   upload       copies the geometry and BVH into memory of its own (scheduler/device_copy.h
 *                with host ops), as the GPU copies them into device memory: nothing of the
 *                caller's is borrowed;
 *   trace        copies each chunk's rays into its own staging buffers ("copy in"), runs the
 *                kernel body — rs_trace_one, the RS_HD binary BVH traversal the CUDA kernel
 *                runs — over them on host threads, and copies the answers back ("copy out");
 *                the chunk's transfer bytes are counted as the CUDA device counts them;
 *   pass_begin   copies the scene (the same device_copy call as the GPU's);
 *   render_pass  the CUDA render_pass's passes: per sample, rs_path_radiance for every pixel
 *                into a radiance buffer (the pixels split among host threads by the job's
 *                strategy), then rs_film_add_image.  Its image is the CPU megakernel's, bit for
 *                bit: the same path code, the binary BVH's closest hits (the 4-wide BVH's, by
 *                rs_hit_better), each pixel's samples added in sample order.
 * So a render with --devices cpu,gpu (or the megakernel on gpu) on a machine without a GPU
 * exercises the same data flow, chunk boundaries and answers as one with a GPU.
 *
 * The copies' own upload is not counted in stats.bytes_*: those count chunk traffic only.
 * Thread safety: as scheduler/device.h; the ray counters of a pass are atomics. */
#include "gpu/gpu_device.h"

#include <stdatomic.h>
#include <stdio.h>
#include <string.h>

#include "accel/trace.h"
#include "core/alloc.h"
#include "core/cores.h"
#include "scheduler/device_copy.h"
#include "shading/path_counts.h"

typedef struct fallback_impl {
    rs_device_geom geom; /* its own copy of what trace reads */
    int uploaded;
    rs_ray_soa rays; /* staging, `cap` entries */
    rs_hit_soa hits;
    uint8_t *occluded;
    uint32_t cap;
    rs_cores *cores;
    /* pass_begin */
    rs_device_scene scene; /* its own copy of the scene */
    rs_integrator it;      /* the render's constants, it.scene = scene.scene */
    rs_vec3 *radiance;     /* it.npix: one pass */
    int pass_ready;
} fallback_impl;

static void free_staging(fallback_impl *f)
{
    rs_ray_soa_free(&f->rays);
    rs_hit_soa_free(&f->hits);
    rs_free(f->occluded);
    f->occluded = NULL;
    f->cap = 0;
}

/* Room for n staged rays; grows (at least doubling) only when a chunk is larger than any
 * before, so chunks of a steady size allocate nothing. */
static rs_status ensure_staging(fallback_impl *f, uint32_t n)
{
    rs_status st;
    uint32_t cap;
    if (n <= f->cap)
        return RS_OK;
    cap = f->cap > n / 2 ? (f->cap > UINT32_MAX / 2 ? n : 2 * f->cap) : n;
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

static void release_pass(fallback_impl *f)
{
    rs_device_scene_release(&f->scene, &rs_device_copy_host_ops);
    rs_free(f->radiance);
    f->radiance = NULL;
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

static rs_status fallback_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin,
                                uint32_t end)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    uint32_t n = end - begin;
    rs_trace_batch db;
    rs_status st;
    long i;
    int threads;
    if (!f->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: trace before upload", d->name);
    if (n == 0)
        return RS_OK;
    if ((st = ensure_staging(f, n)) != RS_OK)
        return st;
    d->stats.bytes_to_device += rs_trace_stage_in(&f->rays, batch, begin, n);

    memset(&db, 0, sizeof db);
    db.kind = batch->kind;
    db.count = n;
    db.rays = f->rays;
    db.hits = f->hits;
    db.occluded = f->occluded;
    threads = rs_cores_acquire(f->cores, d->threads);
    (void)threads; /* read only by the OpenMP clause */
#pragma omp parallel for num_threads(threads) schedule(dynamic, 256) if (threads > 1 && n >= 512u)
    for (i = 0; i < (long)n; ++i)
        rs_trace_one(&f->geom.bvh, &f->geom.geom, &db, (uint32_t)i);
    rs_cores_release(f->cores, threads);

    d->stats.bytes_from_device += rs_trace_stage_out(batch, begin, n, &f->hits, f->occluded);
    return RS_OK;
}

static rs_status fallback_pass_begin(rs_device *d, const rs_scene *scene, const rs_integrator *it)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    rs_status st;
    release_pass(f);
    if (!f->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: pass_begin before upload", d->name);
    if ((st = rs_device_copy_scene(scene, &f->geom, &rs_device_copy_host_ops, &f->scene)) != RS_OK)
        return st;
    f->it = *it;
    f->it.scene = f->scene.scene;
    f->radiance = (rs_vec3 *)rs_alloc(it->npix ? it->npix : 1, sizeof *f->radiance);
    if (!f->radiance) {
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
    const rs_integrator *it = &p->f->it;
    const rs_pass_job *job = p->job;
    rs_path_counts n = {0, 0, 0};
    uint64_t base = (uint64_t)p->sample * it->npix;
    uint32_t pixel;
    for (pixel = lo; pixel < hi; ++pixel) {
        /* per pixel: a pass over a large image takes seconds on a few host threads */
        if (atomic_load(&p->stopped) || (job->cancelled && job->cancelled(job->user))) {
            atomic_store(&p->stopped, 1);
            break;
        }
        p->f->radiance[pixel] = rs_path_radiance(it, &p->f->scene.tracer, base + pixel, &n);
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
        return rs_error_set(RS_ERR_ARG, "device %s: render_pass before pass_begin", d->name);
    if (job->film->width * job->film->height != npix)
        return rs_error_set(RS_ERR_ARG, "device %s: the film is not the pass_begin's image size",
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
        if (job->progress)
            job->progress(job->user, npix);
    }
    rs_cores_release(f->cores, threads);
    rs_path_counts_atomic_drain(&p.counts, counts);
    return RS_OK;
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
                                           fallback_pass_begin,
                                           fallback_render_pass};

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
