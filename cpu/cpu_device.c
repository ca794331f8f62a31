/* cpu/cpu_device.c — see cpu_device.h.  Borrows the host scene and BVH arrays (no copy); owns
 * only the wide tree it collapses from the BVH.  Its megakernel is cpu/cpu_megakernel.c. */
#include "cpu/cpu_device.h"

#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/parallel.h"
#include "cpu/internal.h"

static rs_status cpu_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    cpu_impl *c = (cpu_impl *)d->impl;
    c->geom = *g;
    c->bvh = rs_bvh_view_of(bvh);
    rs_bvh4_destroy(c->bvh4);
    rs_bvh8_destroy(c->bvh8);
    c->bvh4 = NULL;
    c->bvh8 = NULL;
    if (c->width == 8 && g->aabb_algo == RS_ISECT_AABB_SLAB) {
        rs_status st = rs_bvh8_build(bvh, g, &c->bvh8);
        if (st != RS_OK)
            return st;
    } else if (c->width == 4 && g->aabb_algo == RS_ISECT_AABB_SLAB) {
        rs_status st = rs_bvh4_build(bvh, g, &c->bvh4);
        if (st != RS_OK)
            return st;
    }
    if (c->picks) /* what the threads measured was for the old scene */
        memset(c->picks, 0, (size_t)d->threads * rs_cpu_walk_picks_size());
    c->uploaded = 1;
    return RS_OK;
}

static rs_status cpu_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end)
{
    const cpu_impl *c = (const cpu_impl *)d->impl;
    long i;
    int threads;
    if (!c->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: trace before upload", d->name);
    threads = rs_cores_acquire(c->cores, d->threads);
    (void)threads; /* read only by the OpenMP clauses */
    if (c->bvh8) {
        /* the 8-wide kernel is a function of its own (compiled for AVX2): called on runs of
         * 64 rays, 4 runs to a dynamic chunk as below */
        long runs = ((long)(end - begin) + 63) / 64;
#pragma omp parallel for num_threads(threads)                                                      \
    schedule(dynamic, 4) if (threads > 1 && end - begin >= 512u)
        for (i = 0; i < runs; ++i) {
            uint32_t b0 = begin + (uint32_t)i * 64u;
            rs_cpu_trace_range(c, batch, b0, end - b0 < 64u ? end : b0 + 64u);
        }
        rs_cores_release(c->cores, threads);
        return RS_OK;
    }
    /* dynamic schedule: ray costs vary a lot (a miss of the root box vs a deep traversal).
     * A chunk too small to feed every thread runs on the dispatch thread alone: waking a team
     * costs more than it saves. */
#pragma omp parallel for num_threads(threads)                                                      \
    schedule(dynamic, 256) if (threads > 1 && end - begin >= 512u)
    for (i = (long)begin; i < (long)end; ++i)
        rs_cpu_trace_range(c, batch, (uint32_t)i, (uint32_t)i + 1u);
    rs_cores_release(c->cores, threads);
    return RS_OK;
}

static void cpu_destroy(rs_device *d)
{
    cpu_impl *c = (cpu_impl *)d->impl;
    if (c) {
        int k;
        for (k = 0; k < c->n_wave; ++k)
            rs_wave_buffers_destroy(&c->wave[k]);
        rs_free(c->wave);
        rs_free(c->picks);
        rs_bvh4_destroy(c->bvh4);
        rs_bvh8_destroy(c->bvh8);
    }
    rs_free(c);
    rs_free(d);
}

const char *rs_cpu_walk_name(rs_cpu_walk w)
{
    switch (w) {
    case RS_CPU_WALK_AUTO: return "auto";
    case RS_CPU_WALK_SINGLE: return "single";
    case RS_CPU_WALK_PACKETS: return "packets";
    }
    return "?";
}

int rs_cpu_walk_parse(const char *text, rs_cpu_walk *out)
{
    int i;
    for (i = RS_CPU_WALK_AUTO; i <= RS_CPU_WALK_PACKETS; ++i)
        if (strcmp(text, rs_cpu_walk_name((rs_cpu_walk)i)) == 0) {
            *out = (rs_cpu_walk)i;
            return 1;
        }
    return 0;
}

static const rs_device_ops cpu_ops = {
    .upload = cpu_upload,
    .trace = cpu_trace,
    .destroy = cpu_destroy,
    .render_pass = rs_cpu_render_pass, /* host memory, no scene copy: no upload_scene */
    .render_paths = rs_cpu_render_paths,
};

rs_status rs_cpu_device_create(int threads, const char *name, rs_device **out)
{
    rs_cpu_device_opts o;
    memset(&o, 0, sizeof o);
    o.threads = threads;
    o.name = name;
    return rs_cpu_device_create_opts(&o, out);
}

rs_status rs_cpu_device_create_opts(const rs_cpu_device_opts *o, rs_device **out)
{
    rs_device *d = (rs_device *)rs_calloc(1, sizeof *d);
    cpu_impl *c = (cpu_impl *)rs_calloc(1, sizeof *c);
    *out = NULL;
    if (!d || !c) {
        rs_free(d);
        rs_free(c);
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating the CPU device");
    }
    if (o->bvh_width != 0 && o->bvh_width != 2 && o->bvh_width != 4 && o->bvh_width != 8) {
        rs_free(d);
        rs_free(c);
        return rs_error_set(RS_ERR_ARG, "BVH width %u: 2, 4 or 8", o->bvh_width);
    }
    if (o->bvh_width == 8 && !rs_bvh8_supported()) {
        rs_free(d);
        rs_free(c);
        return rs_error_set(RS_ERR_ARG, "BVH width 8 needs a CPU with AVX2 (this one has none; "
                                        "use 4)");
    }
    c->width = o->bvh_width ? o->bvh_width : rs_bvh8_supported() ? 8 : 4;
    c->cores = o->cores;
    c->strategy = o->strategy;
    c->walk = o->walk;
    d->ops = &cpu_ops;
    d->impl = c;
    d->flags = RS_DEVICE_HOST_PATHS;
    d->threads = o->threads < 1 ? 1 : o->threads;
    snprintf(d->name, sizeof d->name, "%s", o->name ? o->name : "cpu");
    *out = d;
    return RS_OK;
}
