/* scheduler/fault.c — see fault.h. */
#include "scheduler/fault.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

typedef struct fault_impl {
    rs_device *inner;
    long after, done;
    rs_device_ops ops; /* the inner device's optional entries, where it has them */
} fault_impl;

static rs_status fault_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    fault_impl *f = (fault_impl *)d->impl;
    return rs_device_upload(f->inner, g, bvh);
}

static rs_status fault_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin,
                             uint32_t end)
{
    fault_impl *f = (fault_impl *)d->impl;
    rs_status st;
    if (f->done >= f->after)
        return rs_error_set(RS_ERR_DEVICE_LOST, "%s: injected fault after %ld chunks (RS_FAULT)",
                            d->name, f->after);
    st = f->inner->ops->trace(f->inner, batch, begin, end);
    if (st == RS_OK)
        f->done++;
    return st;
}

static void fault_destroy(rs_device *d)
{
    fault_impl *f = (fault_impl *)d->impl;
    if (f)
        rs_device_destroy(f->inner);
    rs_free(f);
    rs_free(d);
}

/* The rest goes straight to the wrapped device: only chunks fail. */
static void *fault_host_alloc(rs_device *d, size_t bytes)
{
    fault_impl *f = (fault_impl *)d->impl;
    return f->inner->ops->host_alloc(f->inner, bytes);
}

static void fault_host_free(rs_device *d, void *p)
{
    fault_impl *f = (fault_impl *)d->impl;
    f->inner->ops->host_free(f->inner, p);
}

static rs_status fault_upload_scene(rs_device *d, const rs_scene *scene, const rs_render_consts *it)
{
    fault_impl *f = (fault_impl *)d->impl;
    return f->inner->ops->upload_scene(f->inner, scene, it);
}

static rs_status fault_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                                   rs_path_counts *counts)
{
    fault_impl *f = (fault_impl *)d->impl;
    return f->inner->ops->render_pass(f->inner, job, s0, n, counts);
}

rs_status rs_fault_wrap(rs_device **d, int after)
{
    rs_device *w = (rs_device *)rs_calloc(1, sizeof *w);
    fault_impl *f = (fault_impl *)rs_calloc(1, sizeof *f);
    if (!w || !f) {
        rs_free(w);
        rs_free(f);
        return rs_error_set(RS_ERR_NOMEM, "out of memory wrapping a device for RS_FAULT");
    }
    f->inner = *d;
    f->after = after < 0 ? 0 : after;
    /* the wrapper offers what the inner device offers */
    f->ops.upload = fault_upload;
    f->ops.trace = fault_trace;
    f->ops.destroy = fault_destroy;
    if ((*d)->ops->host_alloc && (*d)->ops->host_free) {
        f->ops.host_alloc = fault_host_alloc;
        f->ops.host_free = fault_host_free;
    }
    if ((*d)->ops->upload_scene)
        f->ops.upload_scene = fault_upload_scene;
    if ((*d)->ops->render_pass)
        f->ops.render_pass = fault_render_pass;
    w->ops = &f->ops;
    w->impl = f;
    w->flags = (*d)->flags;
    w->threads = (*d)->threads;
    w->pass_samples = (*d)->pass_samples;
    memcpy(w->name, (*d)->name, sizeof w->name);
    *d = w;
    return RS_OK;
}

rs_status rs_fault_parse(const char *text, rs_fault_spec *out)
{
    char buf[256], *tok, *save = NULL;
    out->cpu_after = out->gpu_after = -1;
    if (!text || !*text)
        return RS_OK;
    if (strlen(text) >= sizeof buf)
        return rs_error_set(RS_ERR_ARG, "RS_FAULT is too long");
    strcpy(buf, text);
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        int *slot = NULL;
        char *end = NULL;
        long n;
        if (strncmp(tok, "cpu:after=", 10) == 0)
            slot = &out->cpu_after;
        else if (strncmp(tok, "gpu:after=", 10) == 0)
            slot = &out->gpu_after;
        if (!slot)
            return rs_error_set(RS_ERR_ARG, "RS_FAULT: '%s' is not cpu:after=N or gpu:after=N",
                                tok);
        n = strtol(tok + 10, &end, 10);
        if (end == tok + 10 || *end || n < 0 || n > 1000000000L)
            return rs_error_set(RS_ERR_ARG, "RS_FAULT: '%s': N must be a whole number >= 0", tok);
        *slot = (int)n;
    }
    return RS_OK;
}
