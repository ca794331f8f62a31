/* cpu/cpu_megakernel.c — the CPU device's render_pass: the classic integrator as the thesis
 * wrote it, one loop over the pixels with each pixel's samples traced to the end one after the
 * other (the recursive radiance() of Ray Tracing in One Weekend, unrolled: path_radiance below,
 * over shading/path.h's rs_path_start / rs_path_step), the pixel loop split among the device's
 * threads by one of the thesis's strategies (core/parallel.h):
 *   for-dynamic  rows handed out dynamically (`parallel for schedule(dynamic)`);
 *   columns      each thread one contiguous block of image columns (the thesis's Fig. 5.1);
 *   tasks        a task per row, made by one thread, run by any (the thesis's Listing 5.8).
 * It traces with the device's own trees (the 8-wide BVH where the device built one, else the
 * 4-wide, else the binary one: cpu/internal.h), which answer as the binary traversal does, and
 * adds each pixel's samples in sample order: its image is the wavefront's, bit for bit.  Ctrl-C
 * is checked per pixel (at high spp a row can take seconds), progress reported per line. */
#include <string.h>

#include "cpu/internal.h"
#include "shading/aov.h"
#include "shading/path_counts.h"

typedef struct line_ctx {
    const rs_pass_job *job;
    const cpu_impl *impl; /* the trees traced: borrowed geometry and BVH, the device's wide one */
    uint32_t s0, n, width, height;
    int by_columns;
    rs_path_counts_atomic counts; /* every thread's rays */
} line_ctx;

/* The closest hit of r, on the widest tree the device holds. */
static inline void closest(const cpu_impl *c, rs_ray r, rs_hit *h)
{
    if (c->bvh8)
        rs_bvh8_closest(c->bvh8, &c->geom, r, h);
    else if (c->bvh4)
        rs_bvh4_closest(c->bvh4, &c->geom, r, h);
    else
        rs_bvh_closest(&c->bvh, &c->geom, r, h);
}

static inline int occluded(const cpu_impl *c, rs_ray r)
{
    if (c->bvh8)
        return rs_bvh8_occluded(c->bvh8, &c->geom, r);
    if (c->bvh4)
        return rs_bvh4_occluded(c->bvh4, &c->geom, r);
    return rs_bvh_occluded(&c->bvh, &c->geom, r);
}

/* Path (pixel, sample) from the camera to its end; its rays counted in *n; where the render
 * keeps passes, what its camera ray showed into *aux. */
static inline rs_vec3 path_radiance(const rs_render_consts *it, const cpu_impl *c, uint32_t pixel,
                                    uint32_t sample, rs_path_counts *n, rs_path_aux *aux)
{
    rs_path p;
    rs_path_start(it, pixel, sample, &p);
    for (;;) {
        rs_hit h;
        uint32_t made;
        closest(c, p.ray, &h);
        ++n->closest;
        if (p.bounce > n->max_bounce)
            n->max_bounce = p.bounce;
        if (p.bounce == 0 && it->passes)
            *aux = rs_path_aux_at(it, &p.ray, &h, &p.ps);
        made = rs_path_step(it, &p, &h);
        if (made & RS_SHADE_SHADOW) {
            ++n->shadow;
            if (!occluded(c, p.shadow))
                rs_path_unoccluded(&p);
        }
        if (!(made & RS_SHADE_NEXT))
            return rs_path_result(p.ps.radiance, p.ps.flags);
    }
}

static void report(const rs_pass_job *job, uint64_t paths)
{
    if (!job->progress || paths == 0)
        return;
#pragma omp critical(rs_cpu_megakernel_progress)
    job->progress(job->user, paths);
}

/* Rows (or columns) [lo, hi) of the image. */
static void render_lines(void *ctx, uint32_t lo, uint32_t hi)
{
    line_ctx *c = (line_ctx *)ctx;
    const rs_pass_job *job = c->job;
    uint32_t line, k, s;
    rs_path_counts n = {0, 0, 0};
    for (line = lo; line < hi; ++line) {
        uint32_t len = c->by_columns ? c->height : c->width;
        for (k = 0; k < len; ++k) {
            uint32_t x = c->by_columns ? line : k, y = c->by_columns ? k : line;
            uint32_t pixel = y * c->width + x;
            if (job->cancelled && job->cancelled(job->user)) {
                report(job, (uint64_t)k * c->n);
                goto out;
            }
            for (s = c->s0; s < c->s0 + c->n; ++s) {
                rs_path_aux aux;
                rs_vec3 L = path_radiance(job->it, c->impl, pixel, s, &n, &aux);
                rs_film_add(job->film, pixel, L);
                if (job->film->pass && job->it->passes)
                    rs_film_add_pass(job->film, pixel, &aux);
            }
        }
        report(job, (uint64_t)len * c->n);
    }
out:
    rs_path_counts_atomic_add(&c->counts, &n);
}

rs_status rs_cpu_render_pass(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                             rs_path_counts *counts)
{
    const cpu_impl *impl = (const cpu_impl *)d->impl;
    line_ctx c;
    if (!impl->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: render before upload", d->name);
    memset(&c, 0, sizeof c);
    c.job = job;
    c.impl = impl;
    c.s0 = s0;
    c.n = n;
    c.width = job->it->width;
    c.height = job->it->height;
    c.by_columns = job->strategy == RS_PAR_COLUMNS;
    rs_path_counts_atomic_init(&c.counts);
    rs_parallel_range(job->strategy, d->threads, 0, c.by_columns ? c.width : c.height, 1,
                      render_lines, &c);
    rs_path_counts_atomic_drain(&c.counts, counts);
    return RS_OK;
}
