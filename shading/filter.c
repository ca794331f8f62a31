/* shading/filter.c — the pixel filters' functions and tables (shading/filter.h). */
#include "shading/filter.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/status.h"

static const char *const k_names[4] = {"box", "gaussian", "blackman-harris", "mitchell"};
static const float k_default_width[4] = {1.0f, 3.0f, 1.5f, 4.0f};

#define PI_D 3.14159265358979323846

/* Mitchell-Netravali with B = C = 1/3 on t in [-2, 2]. */
static double mitchell(double t)
{
    const double b = 1.0 / 3.0, c = 1.0 / 3.0;
    t = fabs(t);
    if (t <= 1.0)
        return ((12 - 9 * b - 6 * c) * t * t * t + (-18 + 12 * b + 6 * c) * t * t + (6 - 2 * b)) /
               6.0;
    if (t <= 2.0)
        return ((-b - 6 * c) * t * t * t + (6 * b + 30 * c) * t * t + (-12 * b - 48 * c) * t +
                (8 * b + 24 * c)) /
               6.0;
    return 0.0;
}

double rs_filter_eval(rs_filter_kind kind, double width, double x)
{
    double r = 0.5 * width;
    if (!(fabs(x) <= r))
        return 0.0;
    switch (kind) {
    case RS_FILTER_GAUSSIAN: {
        double s = width / 6.0;
        return exp(-x * x / (2 * s * s)) - exp(-r * r / (2 * s * s));
    }
    case RS_FILTER_BLACKMAN_HARRIS: {
        double t = x / width + 0.5;
        return 0.35875 - 0.48829 * cos(2 * PI_D * t) + 0.14128 * cos(4 * PI_D * t) -
               0.01168 * cos(6 * PI_D * t);
    }
    case RS_FILTER_MITCHELL:
        return mitchell(4.0 * x / width);
    default:
        return 1.0;
    }
}

/* The bins' edges: RS_FILTER_BINS equal bins, or for Mitchell RS_FILTER_BINS - 2 equal ones
 * and its two zero crossings, t = +-1.1736 of [-2, 2] (found by bisection), so that no bin
 * straddles a change of sign. */
static void make_edges(rs_filter_kind kind, double width, double *e)
{
    int k, n = kind == RS_FILTER_MITCHELL ? RS_FILTER_BINS - 2 : RS_FILTER_BINS;
    double lo = 0.25 * width, hi = 0.5 * width;
    for (k = 0; k <= n; ++k)
        e[k] = -0.5 * width + width * k / n;
    if (kind != RS_FILTER_MITCHELL)
        return;
    for (k = 0; k < 60; ++k) { /* f > 0 at t = 1, f < 0 at t = 2 - a little: one root between */
        double mid = 0.5 * (lo + hi);
        if (rs_filter_eval(kind, width, mid) > 0.0)
            lo = mid;
        else
            hi = mid;
    }
    e[n + 1] = -0.5 * (lo + hi);
    e[n + 2] = 0.5 * (lo + hi);
    for (k = n + 1; k <= n + 2; ++k) { /* insertion into the sorted edges */
        int j = k;
        while (j > 0 && e[j - 1] > e[j]) {
            double t = e[j - 1];
            e[j - 1] = e[j];
            e[j] = t;
            --j;
        }
    }
}

int rs_filter_make(rs_filter_kind kind, float width, rs_filter *out)
{
    double h[RS_FILTER_BINS], e[RS_FILTER_BINS + 1], v[RS_FILTER_BINS + 1], sum_abs = 0.0,
           run = 0.0;
    int k;
    if ((unsigned)kind > RS_FILTER_MITCHELL) {
        rs_error_set(RS_ERR_ARG, "unknown filter %u", (unsigned)kind);
        return 0;
    }
    if (width <= 0.0f)
        width = k_default_width[kind];
    if (!(width <= 16.0f)) {
        rs_error_set(RS_ERR_ARG, "a filter width of %g pixels: use one in (0, 16]", (double)width);
        return 0;
    }
    memset(out, 0, sizeof *out);
    out->kind = (uint32_t)kind;
    out->width = width;
    out->weight = 1.0f;
    make_edges(kind, width, e);
    for (k = 0; k <= RS_FILTER_BINS; ++k) {
        v[k] = fabs(rs_filter_eval(kind, width, e[k]));
        if (k == 0 || k == RS_FILTER_BINS) /* the support's ends: f's limit from inside */
            v[k] = fabs(rs_filter_eval(kind, width, e[k] * (1.0 - 1e-12)));
        out->edge[k] = (float)e[k];
    }
    if (kind == RS_FILTER_BOX)
        for (k = 0; k <= RS_FILTER_BINS; ++k)
            v[k] = 1.0;
    for (k = 0; k < RS_FILTER_BINS; ++k) /* the bin's area under the linear |f| */
        sum_abs += h[k] = 0.5 * (v[k] + v[k + 1]) * (e[k + 1] - e[k]);
    for (k = 0; k < RS_FILTER_BINS; ++k) {
        double ab = v[k] + v[k + 1], beta = ab > 0.0 ? 2.0 * (v[k + 1] - v[k]) / ab : 0.0;
        double prob = h[k] / sum_abs;
        out->cdf[k] = (float)(run / sum_abs);
        run += h[k];
        out->alpha[k] = (float)(ab > 0.0 ? 2.0 * v[k] / ab : 1.0);
        out->beta[k] = (float)beta;
        out->inv_beta[k] = fabs(beta) >= 1e-3 ? (float)(1.0 / beta) : 0.0f;
        out->inv_p[k] = prob > 0.0 ? (float)(1.0 / prob) : 0.0f;
        out->pdf[k] = e[k + 1] > e[k] ? (float)(prob / (e[k + 1] - e[k])) : 0.0f;
    }
    out->cdf[RS_FILTER_BINS] = 1.0f;
    if (kind == RS_FILTER_MITCHELL) { /* int f exactly: f's pieces are cubics, 4000 midpoints */
        double exact = 0.0;
        for (k = 0; k < 4000; ++k)
            exact += rs_filter_eval(kind, width, -0.5 * width + (k + 0.5) * width / 4000);
        out->weight = (float)(1.0 / (exact * width / 4000));
    }
    return 1;
}

void rs_filter_default(rs_filter *out) { rs_filter_make(RS_FILTER_BLACKMAN_HARRIS, 1.5f, out); }

int rs_filter_parse(const char *text, rs_filter *out, char *why, size_t n)
{
    const char *colon = strchr(text, ':');
    size_t len = colon ? (size_t)(colon - text) : strlen(text);
    float width = 0.0f;
    int kind = -1, k;
    for (k = 0; k < 4; ++k)
        if (strlen(k_names[k]) == len && strncmp(text, k_names[k], len) == 0)
            kind = k;
    if (kind < 0) {
        snprintf(why, n, "'%.*s' is not a filter (use box, gaussian, blackman-harris or mitchell, "
                 "optionally :WIDTH in pixels)", (int)len, text);
        return 0;
    }
    if (colon) {
        char *end;
        double w = strtod(colon + 1, &end);
        /* in thousandths of a pixel (what a checkpoint records), from 0.01: a narrower
         * filter is a point, and Mitchell's weights (1 / width^2) overflowed at 1e-38 */
        if (end == colon + 1 || *end || !(w >= 0.01 && w <= 16.0) ||
            fabs(w * 1000.0 - nearbyint(w * 1000.0)) > 1e-6 * w * 1000.0) {
            snprintf(why, n,
                     "the %s filter's width '%s' is not a number of pixels from 0.01 to 16 in "
                     "steps of 0.001",
                     k_names[kind], colon + 1);
            return 0;
        }
        width = (float)w;
    }
    if (!rs_filter_make((rs_filter_kind)kind, width, out)) {
        snprintf(why, n, "%s", rs_error_message());
        return 0;
    }
    return 1;
}

void rs_filter_describe(const rs_filter *f, char *buf, size_t n)
{
    snprintf(buf, n, "%s:%g", k_names[f->kind <= RS_FILTER_MITCHELL ? f->kind : 0],
             (double)f->width);
}
