/* shading/film.c — see film.h. */
#include "shading/film.h"

#include <math.h>
#include <string.h>

#include "core/alloc.h"
#include "core/parallel.h"

rs_status rs_film_create(uint32_t width, uint32_t height, rs_film **out)
{
    size_t npix;
    rs_film *f;
    *out = NULL;
    if (!rs_mul_size(width, height, &npix) || npix == 0)
        return rs_error_set(RS_ERR_ARG, "bad image size %ux%u", width, height);
    f = (rs_film *)rs_calloc(1, sizeof *f);
    if (!f)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the film");
    f->width = width;
    f->height = height;
    f->sum = (rs_film_sum *)rs_calloc(npix * 3, sizeof *f->sum);
    f->count = (uint32_t *)rs_calloc(npix, sizeof *f->count);
    if (!f->sum || !f->count) {
        rs_film_destroy(f);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for a %ux%u film", width, height);
    }
    *out = f;
    return RS_OK;
}

void rs_film_destroy(rs_film *f)
{
    if (!f)
        return;
    rs_free(f->sum);
    rs_free(f->count);
    rs_free(f->sum_l2);
    rs_free(f->pass);
    rs_free(f->pass_hits);
    rs_free(f);
}

/* x (|x| <= RS_FILM_MAX_SAMPLE) in film units, rounded to the nearest (ties away from zero):
 * the scaling by a power of two is exact, and below 2^62 units (4.2e6 radiance) the rounding is
 * one add and one truncating conversion, inline (rint is a libm call without SSE4.1) */
static inline rs_film_sum to_fixed(double x)
{
    double v = x * RS_FILM_SCALE;
    if (fabs(v) < 0x1p62)
        return (rs_film_sum)(int64_t)(v + (v >= 0 ? 0.5 : -0.5));
    return (rs_film_sum)v; /* an integer already: 2^62 is past a double's fraction bits */
}

static inline double from_fixed(rs_film_sum s) { return (double)s * (1.0 / RS_FILM_SCALE); }

/* d (0 <= d < 2^96) in units of 2^-64, the last one rounded to the nearest: each step takes
 * the whole part of a power-of-two scaling, so every subtraction is exact. */
static inline rs_film_sq sq_of(double d)
{
    rs_film_sq q;
    double v = d * 0x1p64, hi = floor(v * 0x1p-128), mid, lo;
    v -= hi * 0x1p128;
    mid = floor(v * 0x1p-64);
    lo = v - mid * 0x1p64;
    q.w[2] = (uint64_t)hi;
    q.w[1] = (uint64_t)mid;
    q.w[0] = lo < 0x1p52 ? (uint64_t)(lo + 0.5) : (uint64_t)lo; /* >= 2^52: a whole number */
    return q;
}

static inline void sq_add(rs_film_sq *a, const rs_film_sq *b)
{
    unsigned __int128 t = (unsigned __int128)a->w[0] + b->w[0];
    a->w[0] = (uint64_t)t;
    t = (t >> 64) + a->w[1] + b->w[1];
    a->w[1] = (uint64_t)t;
    a->w[2] += b->w[2] + (uint64_t)(t >> 64);
}

static inline double sq_value(const rs_film_sq *q)
{
    return ((double)q->w[2] * 0x1p64 + (double)q->w[1]) + (double)q->w[0] * 0x1p-64;
}

void rs_film_add(rs_film *f, uint32_t pixel, rs_vec3 c)
{
    rs_film_sum *s = &f->sum[3 * (size_t)pixel];
    f->count[pixel]++;
    if (!(fabs(c.x) <= RS_FILM_MAX_SAMPLE && fabs(c.y) <= RS_FILM_MAX_SAMPLE &&
          fabs(c.z) <= RS_FILM_MAX_SAMPLE)) { /* NaN fails every comparison */
        /* the one counter shared by every pixel: the megakernel adds pixels from many threads */
#pragma omp atomic
        f->nonfinite++;
        return;
    }
    s[0] += to_fixed(c.x);
    s[1] += to_fixed(c.y);
    s[2] += to_fixed(c.z);
    if (f->sum_l2) {
        double l = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        rs_film_sq q = sq_of(l * l);
        sq_add(&f->sum_l2[pixel], &q);
    }
}

rs_status rs_film_track_variance(rs_film *f)
{
    if (f->sum_l2)
        return RS_OK;
    f->sum_l2 = (rs_film_sq *)rs_calloc((size_t)f->width * f->height, sizeof *f->sum_l2);
    if (!f->sum_l2)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the film's variance");
    return RS_OK;
}

rs_status rs_film_keep_passes(rs_film *f)
{
    size_t n = (size_t)f->width * f->height;
    if (f->pass)
        return RS_OK;
    f->pass = (rs_film_sum *)rs_calloc(n * RS_FILM_PASSES, sizeof *f->pass);
    f->pass_hits = (uint32_t *)rs_calloc(n, sizeof *f->pass_hits);
    if (!f->pass || !f->pass_hits) {
        rs_free(f->pass);
        rs_free(f->pass_hits);
        f->pass = NULL;
        f->pass_hits = NULL;
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the film's passes (%ux%u)", f->width,
                            f->height);
    }
    return RS_OK;
}

/* x in film units, or zero where it is not finite or beyond RS_FILM_MAX_SAMPLE. */
static inline rs_film_sum pass_fixed(float x)
{
    return fabsf(x) <= (float)RS_FILM_MAX_SAMPLE ? to_fixed(x) : 0;
}

void rs_film_add_pass(rs_film *f, uint32_t pixel, const rs_path_aux *a)
{
    rs_film_sum *s = &f->pass[RS_FILM_PASSES * (size_t)pixel];
    s[RS_FILM_PASS_ALBEDO] += pass_fixed(a->albedo.x);
    s[RS_FILM_PASS_ALBEDO + 1] += pass_fixed(a->albedo.y);
    s[RS_FILM_PASS_ALBEDO + 2] += pass_fixed(a->albedo.z);
    s[RS_FILM_PASS_NORMAL] += pass_fixed(a->normal.x);
    s[RS_FILM_PASS_NORMAL + 1] += pass_fixed(a->normal.y);
    s[RS_FILM_PASS_NORMAL + 2] += pass_fixed(a->normal.z);
    s[RS_FILM_PASS_EMISSION] += pass_fixed(a->emission.x);
    s[RS_FILM_PASS_EMISSION + 1] += pass_fixed(a->emission.y);
    s[RS_FILM_PASS_EMISSION + 2] += pass_fixed(a->emission.z);
    if (fabsf(a->depth) <= (float)RS_FILM_MAX_SAMPLE) {
        s[RS_FILM_PASS_DEPTH] += to_fixed(a->depth);
        f->pass_hits[pixel]++;
    }
}

void rs_film_resolve_passes(const rs_film *f, float *albedo, float *normal, float *emission,
                            float *depth)
{
    size_t i, c, n = (size_t)f->width * f->height;
    for (i = 0; i < n; ++i) {
        const rs_film_sum *s = f->pass ? &f->pass[RS_FILM_PASSES * i] : NULL;
        double inv = f->count[i] ? 1.0 / f->count[i] : 0.0, v[3], l;
        for (c = 0; c < 3; ++c) {
            if (albedo)
                albedo[3 * i + c] = s ? (float)(from_fixed(s[RS_FILM_PASS_ALBEDO + c]) * inv) : 0.0f;
            if (emission)
                emission[3 * i + c] =
                    s ? (float)(from_fixed(s[RS_FILM_PASS_EMISSION + c]) * inv) : 0.0f;
            v[c] = s ? from_fixed(s[RS_FILM_PASS_NORMAL + c]) : 0.0;
        }
        if (normal) { /* the mean's direction: the sum's */
            l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            for (c = 0; c < 3; ++c)
                normal[3 * i + c] = l > 0.0 ? (float)(v[c] / l) : 0.0f;
        }
        if (depth)
            depth[i] = s && f->pass_hits[i]
                           ? (float)(from_fixed(s[RS_FILM_PASS_DEPTH]) / f->pass_hits[i])
                           : INFINITY;
    }
}

rs_status rs_film_merge(rs_film *dst, const rs_film *src)
{
    size_t i, n = (size_t)dst->width * dst->height;
    if (src->width != dst->width || src->height != dst->height)
        return rs_error_set(RS_ERR_ARG, "merging a %ux%u film into a %ux%u one", src->width,
                            src->height, dst->width, dst->height);
    if (dst->pass && !src->pass) /* its samples would lack their passes */
        return rs_error_set(RS_ERR_ARG, "merging a film without passes into one that keeps them");
    for (i = 0; i < 3 * n; ++i)
        dst->sum[i] += src->sum[i];
    for (i = 0; i < n; ++i)
        dst->count[i] += src->count[i];
    if (dst->sum_l2 && src->sum_l2)
        for (i = 0; i < n; ++i)
            sq_add(&dst->sum_l2[i], &src->sum_l2[i]);
    if (dst->pass && src->pass) {
        for (i = 0; i < RS_FILM_PASSES * n; ++i)
            dst->pass[i] += src->pass[i];
        for (i = 0; i < n; ++i)
            dst->pass_hits[i] += src->pass_hits[i];
    }
    dst->nonfinite += src->nonfinite;
    return RS_OK;
}

void rs_film_clear(rs_film *f)
{
    size_t n = (size_t)f->width * f->height;
    memset(f->sum, 0, 3 * n * sizeof *f->sum);
    memset(f->count, 0, n * sizeof *f->count);
    if (f->sum_l2)
        memset(f->sum_l2, 0, n * sizeof *f->sum_l2);
    if (f->pass) {
        memset(f->pass, 0, RS_FILM_PASSES * n * sizeof *f->pass);
        memset(f->pass_hits, 0, n * sizeof *f->pass_hits);
    }
    f->nonfinite = 0;
}

void rs_film_pixel_sum(const rs_film *f, uint32_t pixel, double out[3])
{
    const rs_film_sum *s = &f->sum[3 * (size_t)pixel];
    out[0] = from_fixed(s[0]);
    out[1] = from_fixed(s[1]);
    out[2] = from_fixed(s[2]);
}

double rs_film_pixel_sq(const rs_film *f, uint32_t pixel)
{
    return f->sum_l2 ? sq_value(&f->sum_l2[pixel]) : 0.0;
}

double rs_film_rel_error(const rs_film *f, uint32_t pixel)
{
    double s[3];
    uint32_t n = f->count[pixel];
    double mean, var;
    if (n < 2 || !f->sum_l2)
        return INFINITY;
    rs_film_pixel_sum(f, pixel, s);
    mean = (0.2126 * s[0] + 0.7152 * s[1] + 0.0722 * s[2]) / n;
    var = (sq_value(&f->sum_l2[pixel]) / n - mean * mean) * n / (n - 1);
    if (!(var > 0))
        return 0.0;
    return sqrt(var / n) / (mean > 1e-3 ? mean : 1e-3);
}

/* One image of samples (radiance, or aux: the passes) onto the film, a pixel each, the pixels
 * split among `threads` host threads. */
typedef struct add_image_ctx {
    rs_film *film;
    const rs_vec3 *radiance;
    const rs_path_aux *aux;
} add_image_ctx;

static void add_image_range(void *ctx, uint32_t lo, uint32_t hi)
{
    const add_image_ctx *a = (const add_image_ctx *)ctx;
    uint32_t i;
    for (i = lo; i < hi; ++i) {
        if (a->radiance)
            rs_film_add(a->film, i, a->radiance[i]);
        if (a->aux)
            rs_film_add_pass(a->film, i, &a->aux[i]);
    }
}

static void add_image(rs_film *f, const rs_vec3 *radiance, const rs_path_aux *aux, int threads)
{
    add_image_ctx a;
    a.film = f;
    a.radiance = radiance;
    a.aux = aux;
    rs_parallel_range(RS_PAR_FOR_DYNAMIC, threads, 0, f->width * f->height, 16384, add_image_range,
                      &a);
}

void rs_film_add_image(rs_film *f, const rs_vec3 *radiance, int threads)
{
    add_image(f, radiance, NULL, threads);
}

void rs_film_add_pass_image(rs_film *f, const rs_path_aux *aux, int threads)
{
    add_image(f, NULL, aux, threads);
}

void rs_film_resolve(const rs_film *f, float *rgb)
{
    size_t i, n = (size_t)f->width * f->height;
    for (i = 0; i < n; ++i) {
        double inv = f->count[i] ? 1.0 / f->count[i] : 0.0;
        rgb[3 * i + 0] = (float)(from_fixed(f->sum[3 * i + 0]) * inv);
        rgb[3 * i + 1] = (float)(from_fixed(f->sum[3 * i + 1]) * inv);
        rgb[3 * i + 2] = (float)(from_fixed(f->sum[3 * i + 2]) * inv);
    }
}

uint64_t rs_film_samples(const rs_film *f)
{
    size_t i, n = (size_t)f->width * f->height;
    uint64_t t = 0;
    for (i = 0; i < n; ++i)
        t += f->count[i];
    return t;
}

uint32_t rs_film_min_count(const rs_film *f)
{
    size_t i, n = (size_t)f->width * f->height;
    uint32_t m = UINT32_MAX;
    for (i = 0; i < n; ++i)
        if (f->count[i] < m)
            m = f->count[i];
    return n ? m : 0;
}
