/* gpu/gpu_fallback.c — the stand-in for a CUDA device that is not there.
 *
 * It does what the CUDA device does, step for step, with host memory and host threads: each
 * chunk's rays are copied into the device's own staging buffers ("copy in"), the kernel body —
 * rs_trace_one, the RS_HD binary BVH traversal the CUDA kernel runs — runs over the staged rays
 * on OpenMP threads, and the answers are copied back into the caller's batch ("copy out").  The
 * transfer bytes are counted as the CUDA device counts them.  So a render with --devices
 * cpu,gpu on a machine without a GPU exercises the same data flow, chunk boundaries and
 * answers as one with a GPU. */
#include "gpu/gpu_device.h"

#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/cores.h"

typedef struct fallback_impl {
    rs_geom geom;
    rs_bvh_view bvh;
    rs_ray_soa rays; /* staging, `cap` entries */
    rs_hit_soa hits;
    uint8_t *occluded;
    uint32_t cap;
    rs_cores *cores;
    int uploaded;
} fallback_impl;

static void free_staging(fallback_impl *f)
{
    rs_ray_soa_free(&f->rays);
    rs_hit_soa_free(&f->hits);
    rs_free(f->occluded);
    f->occluded = NULL;
    f->cap = 0;
}

static rs_status ensure_staging(fallback_impl *f, uint32_t n)
{
    rs_status st;
    if (n <= f->cap)
        return RS_OK;
    free_staging(f);
    if ((st = rs_ray_soa_init(&f->rays, n)) != RS_OK ||
        (st = rs_hit_soa_init(&f->hits, n)) != RS_OK)
        return st;
    f->occluded = (uint8_t *)rs_alloc_aligned(n, 1);
    if (!f->occluded)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for %u staged rays", n);
    f->cap = n;
    return RS_OK;
}

static rs_status fallback_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    f->geom = *g;
    f->bvh = rs_bvh_view_of(bvh);
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
        rs_trace_one(&f->bvh, &f->geom, &db, (uint32_t)i);
    rs_cores_release(f->cores, threads);

    d->stats.bytes_from_device += rs_trace_stage_out(batch, begin, n, &f->hits, f->occluded);
    return RS_OK;
}

static void fallback_destroy(rs_device *d)
{
    fallback_impl *f = (fallback_impl *)d->impl;
    if (f)
        free_staging(f);
    rs_free(f);
    rs_free(d);
}

static const rs_device_ops fallback_ops = {fallback_upload, fallback_trace, fallback_destroy};

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
    d->threads = threads < 1 ? 1 : threads;
    snprintf(d->name, sizeof d->name, "gpu-fallback:%d", gpu_index);
    *out = d;
    return RS_OK;
}
