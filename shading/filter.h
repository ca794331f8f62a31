/* shading/filter.h — pixel reconstruction filters drawn by filter importance sampling.
 *
 * Each camera sample's offset from its pixel's centre is drawn from the filter itself, and the
 * sample is added to its own pixel with weight 1 (Ernst et al. 2006, "Filter importance
 * sampling"; pbrt-v4's FilterSampler, Cycles' filter table).  A pixel's value is still the plain
 * mean of its samples, so the exact film, the bit-identical images on any devices and splits,
 * adaptive sampling and checkpoints are untouched by the choice of filter.
 *
 * Every filter here is separable, f(x, y) = f(x) f(y), and drawn one axis at a time from a table
 * of RS_FILTER_BINS bins over [-radius, radius] (equal, but that Mitchell's zero crossings are
 * edges too), over which |f| is taken as linear between its values at the edges (host,
 * rs_filter_make): a bin is picked by its area, the offset inside it by inverting the linear
 * density.  The filter a render applies is therefore f interpolated linearly at about 1/64 of
 * its width, within 0.2% of f (its chi-square test, tests/shading_filter_test.c, draws against
 * the exact integrals).  A filter with negative lobes (Mitchell) is drawn from |f|; a
 * sample counts with weight f(x) f(y) / (p(x, y) (int f)^2) (rs_filter_weight: about
 * +-1.07, negative under one negative lobe), so the estimate of int f L / int f is unbiased for
 * f itself.
 *
 *   box:W              f = 1 on [-W/2, W/2]                              (default W 1: the old
 *                      images, bit for bit: the offset is the uniform number itself)
 *   gaussian:W         f = exp(-x^2 / 2 s^2) - exp(-r^2 / 2 s^2), s = W / 6, r = W / 2
 *                      (pbrt-v4's Gaussian, default W 3: sigma 0.5, radius 1.5)
 *   blackman-harris:W  f = 0.35875 - 0.48829 cos(2 pi t) + 0.14128 cos(4 pi t)
 *                          - 0.01168 cos(6 pi t), t = x / W + 1/2 (Cycles' filter, default
 *                      W 1.5; separable here, radial in Cycles)
 *   mitchell:W         Mitchell-Netravali 1988, B = C = 1/3, on t = 4 x / W in [-2, 2]
 *                      (pbrt-v4's MitchellFilter, default W 4: radius 2) */
#ifndef RS_SHADING_FILTER_H
#define RS_SHADING_FILTER_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "core/hd.h"

#define RS_FILTER_BINS 64

typedef enum rs_filter_kind {
    RS_FILTER_BOX = 0,
    RS_FILTER_GAUSSIAN = 1,
    RS_FILTER_BLACKMAN_HARRIS = 2,
    RS_FILTER_MITCHELL = 3
} rs_filter_kind;

/* A filter as a render uses it: plain data, part of the render's constants (shading/path.h). */
typedef struct rs_filter {
    uint32_t kind;                 /* rs_filter_kind */
    float width;                   /* full width in pixels: the support is [-width/2, width/2] */
    float cdf[RS_FILTER_BINS + 1]; /* cdf[k]: the probability of bins [0, k) of |f|; cdf[0] = 0,
                                      cdf[RS_FILTER_BINS] = 1 (unused by box) */
    float edge[RS_FILTER_BINS + 1]; /* the bins' edges in pixels, edge[0] = -width/2: equal
                                       bins, but for Mitchell, whose zero crossings are edges
                                       (so each bin lies under one sign of f) */
    /* per bin k, the density over s in [0, 1] across it (|f| linear between its edges' values
     * a and b, normalised): g(s) = alpha + beta s, alpha = 2a / (a + b), beta = 2(b - a) /
     * (a + b); inv_beta = 1 / beta, 0 for a bin flat to 1e-3 (drawn uniformly); inv_p = 1 / the
     * bin's probability (0 for none); pdf = the probability over the bin's width */
    float alpha[RS_FILTER_BINS], beta[RS_FILTER_BINS], inv_beta[RS_FILTER_BINS];
    float inv_p[RS_FILTER_BINS], pdf[RS_FILTER_BINS];
    float weight;                  /* Mitchell: 1 / int f (its weights); else 1 */
} rs_filter;

/* Whether the filter leaves the uniform numbers as they are: box of width 1. */
RS_HD int rs_filter_is_identity(const rs_filter *f)
{
    return f->kind == RS_FILTER_BOX && f->width == 1.0f;
}

/* The bin of cdf that u in [0, 1) falls in: the largest k with cdf[k] <= u (a bin of zero
 * probability is never returned). */
RS_HD uint32_t rs_filter_bin(const rs_filter *f, float u)
{
    /* a fixed number of halvings with no branch on the data: a camera sample's u is random, and
     * a branchy search mispredicted half its steps (4% of a Cornell box render's time) */
    uint32_t k = 0, step;
    for (step = RS_FILTER_BINS / 2; step > 0; step >>= 1)
        k += f->cdf[k + step] <= u ? step : 0u;
    return k;
}

RS_HD float rs_filter_max0(float x) { return x > 0.0f ? x : 0.0f; }

/* One axis: the offset in pixels from the pixel's centre drawn with u in [0, 1); *dens: the
 * density it was drawn with (per pixel of offset). */
RS_HD float rs_filter_draw(const rs_filter *f, float u, float *dens)
{
    uint32_t k = rs_filter_bin(f, u);
    float t = (u - f->cdf[k]) * f->inv_p[k], s;
    t = t < 0.0f ? 0.0f : t > 1.0f ? 1.0f : t;
    /* alpha s + beta s^2 / 2 = t; no division: a camera ray takes two of these */
    s = f->inv_beta[k] != 0.0f
            ? (sqrtf(rs_filter_max0(f->alpha[k] * f->alpha[k] + 2.0f * f->beta[k] * t)) -
               f->alpha[k]) * f->inv_beta[k]
            : t;
    s = s < 0.0f ? 0.0f : s > 1.0f ? 1.0f : s;
    *dens = (f->alpha[k] + f->beta[k] * s) * f->pdf[k];
    return f->edge[k] + s * (f->edge[k + 1] - f->edge[k]);
}

RS_HD float rs_filter_offset(const rs_filter *f, float u)
{
    float dens;
    if (f->kind == RS_FILTER_BOX)
        return (u - 0.5f) * f->width;
    return rs_filter_draw(f, u, &dens);
}

/* Where in its pixel's frame (0..1 is the pixel; a wide filter reaches past it) the sample drawn
 * with (u, v) lands: *jx, *jy. */
RS_HD void rs_filter_sample(const rs_filter *f, float u, float v, float *jx, float *jy)
{
    if (rs_filter_is_identity(f)) {
        *jx = u;
        *jy = v;
        return;
    }
    *jx = 0.5f + rs_filter_offset(f, u);
    *jy = 0.5f + rs_filter_offset(f, v);
}

/* Mitchell-Netravali, B = C = 1/3, at t in [-2, 2]. */
RS_HD float rs_filter_mitchell(float t)
{
    t = t < 0.0f ? -t : t;
    if (t < 1.0f)
        return (7.0f * t * t * t - 12.0f * t * t + 16.0f / 3.0f) * (1.0f / 6.0f);
    if (t < 2.0f)
        return (-7.0f / 3.0f * t * t * t + 12.0f * t * t - 20.0f * t + 32.0f / 3.0f) *
               (1.0f / 6.0f);
    return 0.0f;
}

/* One axis's weight f(x) / (p(x) int f): f at the drawn offset over the density it was drawn
 * with (the table's), so that the estimate is unbiased for f itself, not only for the table. */
RS_HD float rs_filter_axis_weight(const rs_filter *f, float u)
{
    float dens, x = rs_filter_draw(f, u, &dens);
    return dens > 0.0f ? rs_filter_mitchell(4.0f * x / f->width) * f->weight / dens : 0.0f;
}

/* The weight of the sample drawn with (u, v): 1 for every filter without negative lobes; for
 * Mitchell the product of the axes' weights, negative under one negative lobe. */
RS_HD float rs_filter_weight(const rs_filter *f, float u, float v)
{
    if (f->kind != RS_FILTER_MITCHELL)
        return 1.0f;
    return rs_filter_axis_weight(f, u) * rs_filter_axis_weight(f, v);
}

#ifdef __cplusplus
extern "C" {
#endif

/* The 1D filter function f(x), x in pixels from the centre (0 outside the support). */
double rs_filter_eval(rs_filter_kind kind, double width, double x);

/* Builds the filter's table.  width <= 0: the kind's default.  0 and a message (rs_error) when
 * the width is outside (0, 16]. */
int rs_filter_make(rs_filter_kind kind, float width, rs_filter *out);

/* Parses "box", "gaussian", "blackman-harris", "mitchell", each optionally ":WIDTH" in pixels
 * (0 < WIDTH <= 16), into a built filter.  1, or 0 with one line in why[n]. */
int rs_filter_parse(const char *text, rs_filter *out, char *why, size_t n);

/* "blackman-harris:1.5" into buf[n]. */
void rs_filter_describe(const rs_filter *f, char *buf, size_t n);

/* The default filter: Blackman-Harris 1.5 pixels wide, as Cycles. */
void rs_filter_default(rs_filter *out);

#ifdef __cplusplus
}
#endif

#endif
