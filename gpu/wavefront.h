/* gpu/wavefront.h — the GPU wavefront's stages, one path or one ray per call: the bodies of the
 * CUDA device's wavefront kernels (gpu/cuda_wavefront.cu) and of its host fallback's loops
 * (gpu/gpu_fallback.c), written once so that the two compute the same bits.  RS_HD: it compiles
 * as C11 and as CUDA C++.
 *
 * A wave is `count` consecutive paths [start, start + count) of the plan (path g: pixel
 * pixel_of[g mod n_active], sample g div n_active; shading/integrator.h), each with its state in
 * the wave's rs_paths slot g - start.  Per segment:
 *
 *   raygen (once)   rs_wf_raygen: the camera ray of slot i into queue[0][i]
 *   trace-closest   rs_trace_one over the current queue (accel/trace.h, the trace kernel's body;
 *                   rs_trace_one_flat where the scene has no instances)
 *   passes          rs_wf_passes, at the camera rays' hits where the render keeps passes
 *   shade           rs_wf_shade: shading/path.h's rs_path_shade_at, the very code the CPU stream
 *                   engine's shade stage and every megakernel run; the caller appends the next
 *                   ray to the other queue and the shadow ray to the shadow queue (an atomic
 *                   counter each: the queues' order varies from run to run, the paths' values
 *                   do not, since a path's radiance depends only on its pixel and sample)
 *   trace-shadow    rs_trace_one over the shadow queue
 *   resolve         rs_wf_resolve: an unoccluded shadow ray's pending light onto its path
 *   (compaction is the appending: the next queue holds only live paths)
 *   film (once)     rs_wf_film_add of each slot's rs_path_result into the device's film (and,
 *                   where the render keeps passes, rs_wf_film_add_pass of what rs_wf_passes
 *                   recorded)
 *
 * The film (rs_wf_film) keeps shading/film.c's exact sums in the same bytes: per channel a
 * 128-bit two's complement integer of film units as two 64-bit words (low first, the layout of
 * rs_film_sum), per pixel a 32-bit count and, when the host film tracks variance, the 192-bit sum
 * of squared luminances (rs_film_sq), when it keeps passes their sums and hit counts, and the
 * non-finite count.  Samples are added with 64-bit
 * atomic adds that carry into the next word: integer addition is associative, so the sums do not
 * depend on the order the threads add in, and the film merges into the host's with
 * rs_film_merge as any film does — the CPU stream engine's image, bit for bit. */
#ifndef RS_GPU_WAVEFRONT_H
#define RS_GPU_WAVEFRONT_H

#include <math.h>

#include "accel/trace.h"
#include "shading/aov.h"
#include "shading/film.h"
#include "shading/path.h"
#include "streams/paths.h"
#include "streams/stream.h"

typedef unsigned long long rs_wf_u64;

/* The device's film (device memory on the GPU, host memory in the fallback). */
typedef struct rs_wf_film {
    rs_wf_u64 *sum;       /* 6 per pixel: channel c's low word at 6 p + 2 c, high at + 1 */
    unsigned int *count;  /* per pixel */
    rs_wf_u64 *sum_l2;    /* 3 per pixel (rs_film_sq's words), or NULL */
    rs_wf_u64 *nonfinite; /* one */
    rs_wf_u64 *pass;      /* 2 RS_FILM_PASSES per pixel (rs_film's passes: channel c's low word at
                             2 (RS_FILM_PASSES p + c)), or NULL */
    unsigned int *pass_hits; /* per pixel, with `pass` */
} rs_wf_film;

/* The plan's map and the wave's place in it. */
typedef struct rs_wf_wave {
    const uint32_t *pixel_of; /* device copy, or NULL */
    uint32_t n_active;
    uint64_t start; /* the wave's first path */
    uint32_t count; /* its paths */
    uint32_t bounce;
} rs_wf_wave;

RS_HD uint32_t rs_wf_pixel(const rs_wf_wave *w, uint64_t g)
{
    uint32_t k = (uint32_t)(g % w->n_active);
    return w->pixel_of ? w->pixel_of[k] : k;
}

/* x (|x| <= RS_FILM_MAX_SAMPLE) in film units as shading/film.c's to_fixed rounds it, as a
 * 128-bit two's complement pair.  Beyond 2^62 units v is a whole number of at most 89 bits:
 * hi = floor(v / 2^64) and lo = v - hi 2^64 in [0, 2^64) are both exact. */
RS_HD void rs_wf_fixed(double x, rs_wf_u64 *lo, rs_wf_u64 *hi)
{
    double v = x * RS_FILM_SCALE;
    if (fabs(v) < 0x1p62) {
        long long i = (long long)(v + (v >= 0 ? 0.5 : -0.5));
        *lo = (rs_wf_u64)i;
        *hi = i < 0 ? ~0ull : 0ull;
    } else {
        double h = floor(v * 0x1p-64);
        *hi = (rs_wf_u64)(long long)h;
        *lo = (rs_wf_u64)(v - h * 0x1p64);
    }
}

/* s[0..1] += (lo, hi) as 128-bit integers: the low word's wrap (seen from the value the atomic
 * found) carries into the high word, so every order of adds ends at the same sum. */
RS_HD void rs_wf_add128(rs_wf_u64 *s, rs_wf_u64 lo, rs_wf_u64 hi)
{
    rs_wf_u64 old = RS_ATOMIC_ADD_U64(&s[0], lo);
    hi += (rs_wf_u64)(old + lo < old);
    if (hi)
        (void)RS_ATOMIC_ADD_U64(&s[1], hi);
}

/* shading/film.c's sq_of: d (0 <= d < 2^96) in units of 2^-64, three words. */
RS_HD void rs_wf_sq(double d, rs_wf_u64 w[3])
{
    double v = d * 0x1p64, hi = floor(v * 0x1p-128), mid, lo;
    v -= hi * 0x1p128;
    mid = floor(v * 0x1p-64);
    lo = v - mid * 0x1p64;
    w[2] = (rs_wf_u64)hi;
    w[1] = (rs_wf_u64)mid;
    w[0] = lo < 0x1p52 ? (rs_wf_u64)(lo + 0.5) : (rs_wf_u64)lo;
}

/* s[0..2] += w as 192-bit integers, each word's wrap carried into the next. */
RS_HD void rs_wf_add192(rs_wf_u64 *s, const rs_wf_u64 w[3])
{
    rs_wf_u64 old = RS_ATOMIC_ADD_U64(&s[0], w[0]);
    rs_wf_u64 mid = w[1] + (rs_wf_u64)(old + w[0] < old), top = w[2];
    top += (rs_wf_u64)(mid < w[1]); /* w[1] + carry wrapped */
    if (mid) {
        old = RS_ATOMIC_ADD_U64(&s[1], mid);
        top += (rs_wf_u64)(old + mid < old);
    }
    if (top)
        (void)RS_ATOMIC_ADD_U64(&s[2], top);
}

/* shading/film.c's rs_film_add onto the device's film. */
RS_HD void rs_wf_film_add(const rs_wf_film *f, uint32_t pixel, rs_vec3 c)
{
    rs_wf_u64 lo, hi;
    (void)RS_ATOMIC_ADD_U32(&f->count[pixel], 1u);
    if (!(fabs(c.x) <= RS_FILM_MAX_SAMPLE && fabs(c.y) <= RS_FILM_MAX_SAMPLE &&
          fabs(c.z) <= RS_FILM_MAX_SAMPLE)) {
        (void)RS_ATOMIC_ADD_U64(f->nonfinite, 1ull);
        return;
    }
    rs_wf_fixed(c.x, &lo, &hi);
    rs_wf_add128(&f->sum[6 * (size_t)pixel], lo, hi);
    rs_wf_fixed(c.y, &lo, &hi);
    rs_wf_add128(&f->sum[6 * (size_t)pixel + 2], lo, hi);
    rs_wf_fixed(c.z, &lo, &hi);
    rs_wf_add128(&f->sum[6 * (size_t)pixel + 4], lo, hi);
    if (f->sum_l2) {
        double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        rs_wf_u64 w[3];
        rs_wf_sq(l * l, w);
        rs_wf_add192(&f->sum_l2[3 * (size_t)pixel], w);
    }
}

/* One component of a pass onto its sum: shading/film.c's pass_fixed (zero where not finite or
 * beyond RS_FILM_MAX_SAMPLE). */
RS_HD void rs_wf_pass_add(rs_wf_u64 *s, float x)
{
    rs_wf_u64 lo, hi;
    if (!(fabsf(x) <= (float)RS_FILM_MAX_SAMPLE))
        return;
    rs_wf_fixed(x, &lo, &hi);
    rs_wf_add128(s, lo, hi);
}

/* shading/film.c's rs_film_add_pass onto the device's film. */
RS_HD void rs_wf_film_add_pass(const rs_wf_film *f, uint32_t pixel, const rs_path_aux *a)
{
    rs_wf_u64 *s = &f->pass[2 * RS_FILM_PASSES * (size_t)pixel];
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_ALBEDO], a->albedo.x);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_ALBEDO + 2], a->albedo.y);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_ALBEDO + 4], a->albedo.z);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_NORMAL], a->normal.x);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_NORMAL + 2], a->normal.y);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_NORMAL + 4], a->normal.z);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_EMISSION], a->emission.x);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_EMISSION + 2], a->emission.y);
    rs_wf_pass_add(&s[2 * RS_FILM_PASS_EMISSION + 4], a->emission.z);
    if (fabsf(a->depth) <= (float)RS_FILM_MAX_SAMPLE) {
        rs_wf_pass_add(&s[2 * RS_FILM_PASS_DEPTH], a->depth);
        (void)RS_ATOMIC_ADD_U32(&f->pass_hits[pixel], 1u);
    }
}

/* Slot i of the wave: its camera ray into queue[i] (path i), its state reset. */
RS_HD void rs_wf_raygen(const rs_render_consts *it, const rs_wf_wave *w, uint32_t i,
                        const rs_paths *paths, const rs_ray_soa *queue)
{
    uint64_t g = w->start + i;
    rs_path_state ps;
    rs_ray ray = rs_path_begin_at(it, rs_wf_pixel(w, g), (uint32_t)(g / w->n_active), NULL, &ps);
    rs_ray_soa_set(queue, i, &ray, i);
    rs_paths_store(paths, i, &ps);
}

/* Entry j of the first queue at its camera ray's hit (before rs_wf_shade moves it on): what the
 * ray showed, for the film's passes (it->passes), into its path's aux record.  A stage of its own
 * (a kernel on the GPU), so that the shade kernel does not carry the passes' code. */
RS_HD void rs_wf_passes(const rs_render_consts *it, uint32_t j, const rs_ray_soa *queue,
                        const rs_hit_soa *hits, const rs_paths *paths)
{
    uint32_t p = queue->path[j];
    rs_ray r = rs_ray_soa_get(queue, j);
    rs_hit h = rs_hit_soa_get(hits, j);
    rs_path_state ps = rs_paths_load(paths, p);
    paths->aux[p] = rs_path_aux_at(it, &r, &h, &ps);
}

/* Entry j of the current queue shaded at its hit (segment w->bounce): the path's state stored
 * back; returns rs_path_shade_at's RS_SHADE_* flags with the next ray in *next and the shadow
 * ray in *shadow, and the path's slot in *path, for the caller to append. */
RS_HD uint32_t rs_wf_shade(const rs_render_consts *it, const rs_wf_wave *w, uint32_t j,
                           const rs_ray_soa *queue, const rs_hit_soa *hits, const rs_paths *paths,
                           rs_ray *next, rs_ray *shadow, uint32_t *path)
{
    uint32_t p = queue->path[j], made;
    uint64_t g = w->start + p;
    rs_ray r = rs_ray_soa_get(queue, j);
    rs_hit h = rs_hit_soa_get(hits, j);
    rs_path_state ps = rs_paths_load(paths, p);
    made = rs_path_shade_at(it, rs_wf_pixel(w, g), (uint32_t)(g / w->n_active), w->bounce, NULL,
                            &r, &h, &ps, next, shadow);
    rs_paths_store(paths, p, &ps);
    *path = p;
    return made;
}

/* Shadow ray k: unoccluded, its path gains the pending light (integrator.c's resolve). */
RS_HD void rs_wf_resolve(uint32_t k, const rs_ray_soa *shadow, const uint8_t *occluded,
                         const rs_paths *paths)
{
    if (!occluded[k]) {
        uint32_t p = shadow->path[k];
        paths->radiance[p] = rs_v3_add(paths->radiance[p], paths->pending[p]);
    }
}

/* Slot i's finished path onto the film. */
RS_HD void rs_wf_film_path(const rs_wf_wave *w, uint32_t i, const rs_paths *paths, const rs_wf_film *f)
{
    uint32_t pixel = rs_wf_pixel(w, w->start + i);
    rs_wf_film_add(f, pixel, rs_path_result(paths->radiance[i], paths->flags[i]));
    if (f->pass)
        rs_wf_film_add_pass(f, pixel, &paths->aux[i]);
}

/* The device film as an rs_film over the same bytes (host memory), for rs_film_merge. */
static inline rs_film rs_wf_film_view(const rs_wf_film *f, uint32_t width, uint32_t height)
{
    rs_film v;
    v.width = width;
    v.height = height;
    v.sum = (rs_film_sum *)(void *)f->sum;
    v.count = (uint32_t *)f->count;
    v.sum_l2 = (rs_film_sq *)(void *)f->sum_l2;
    v.nonfinite = *f->nonfinite;
    v.pass = (rs_film_sum *)(void *)f->pass;
    v.pass_hits = (uint32_t *)f->pass_hits;
    return v;
}

#endif
