/* tests/test_sampler.h — checks that the Sobol samplers' tests share (core_sobol_test,
 * core_zsobol_test): the net property of a point set and the independence of the numbers a
 * sampler gives different decisions.  Include after cmocka.h and test_rand.h. */
#ifndef RS_TESTS_TEST_SAMPLER_H
#define RS_TESTS_TEST_SAMPLER_H

#include <math.h>
#include <stdint.h>
#include <string.h>

#include "core/rng.h"

/* chi-square critical value at alpha = 0.01 for 99 degrees of freedom */
#define CHI2_99DOF_P01 134.642

/* Exactly one of the n = 2^m (m <= 12) points in every elementary interval 2^-a x 2^-b,
 * a + b = m. */
static void expect_net(const float *x, const float *y, int m, const char *what)
{
    static unsigned char cell[1u << 12];
    uint32_t n = 1u << m, i;
    int a;
    for (a = 0; a <= m; ++a) {
        memset(cell, 0, n);
        for (i = 0; i < n; ++i) {
            uint32_t cx = (uint32_t)(x[i] * (float)(1u << a)),
                     cy = (uint32_t)(y[i] * (float)(1u << (m - a)));
            uint32_t c = (cx << (m - a)) | cy;
            if (cell[c])
                fail_msg("%s: 2^%d points, intervals 2^-%d x 2^-%d: two points in one", what, m, a,
                         m - a);
            cell[c] = 1;
        }
    }
}

/* The sampler under test: four numbers of decision group `group` of (pixel, sample) at segment
 * `bounce`. */
typedef rs_rng_f4 (*ts_draw_fn)(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t group);
static ts_draw_fn ts_draw;

/* Pair i: pixel i / 64, sample i % 64. */
static void ts_lanes_0_2(uint32_t i, float *a, float *b) /* the first of each pair of one call */
{
    rs_rng_f4 f = ts_draw(i / 64, i % 64, 0, 1);
    *a = f.v[0];
    *b = f.v[2];
}

static void ts_groups_1_2(uint32_t i, float *a, float *b) /* one lane of two groups */
{
    *a = ts_draw(i / 64, i % 64, 3, 1).v[0];
    *b = ts_draw(i / 64, i % 64, 3, 2).v[0];
}

static void ts_pixels(uint32_t i, float *a, float *b) /* neighbouring pixels, same sample */
{
    *a = ts_draw(2 * (i / 64), i % 64, 0, 0).v[1];
    *b = ts_draw(2 * (i / 64) + 1, i % 64, 0, 0).v[1];
}

static void ts_bounces(uint32_t i, float *a, float *b) /* one lane at two bounces */
{
    *a = ts_draw(i / 64, i % 64, 1, 1).v[0];
    *b = ts_draw(i / 64, i % 64, 2, 1).v[0];
}

/* 10 x 10 histogram of 10^5 pairs (a, b) from `pair`; chi-square against independence. */
static double pair_chi_square(void (*pair)(uint32_t i, float *a, float *b))
{
    double h[100];
    uint32_t i;
    memset(h, 0, sizeof h);
    for (i = 0; i < 100000; ++i) {
        float a, b;
        pair(i, &a, &b);
        h[(int)(a * 10.0f) * 10 + (int)(b * 10.0f)] += 1.0;
    }
    return chi_square(h, 100, 1000.0);
}

/* Two numbers that different decisions, pixels or bounces take are independent: each pair's
 * chi-square below the 0.01 critical value. */
static void expect_independent_decisions(ts_draw_fn draw)
{
    static void (*const fns[])(uint32_t, float *, float *) = {ts_lanes_0_2, ts_groups_1_2,
                                                              ts_pixels, ts_bounces};
    static const char *const names[] = {"two pairs of a call", "two groups", "two pixels",
                                        "two bounces"};
    size_t k;
    ts_draw = draw;
    for (k = 0; k < sizeof fns / sizeof fns[0]; ++k) {
        double c = pair_chi_square(fns[k]);
        print_message("%s: chi-square %.1f (99 dof, 0.01 critical %.1f)\n", names[k], c,
                      CHI2_99DOF_P01);
        assert_true(c < CHI2_99DOF_P01);
    }
}

/* A smooth integrand for the convergence checks. */
/* f(x, y) = x e^y + sin(pi x y): its integral over the unit square, by series:
 * (e - 1) / 2 + sum_k (-1)^k pi^(2k+1) / ((2k+1)! (2k+2)^2). */
static double smooth(double x, double y) { return x * exp(y) + sin(3.14159265358979 * x * y); }

static double smooth_integral(void)
{
    double s = 0.0, term = 3.14159265358979, fact = 1.0;
    int k;
    for (k = 0; k < 20; ++k) {
        if (k > 0) {
            term *= -3.14159265358979 * 3.14159265358979;
            fact *= (double)(2 * k) * (double)(2 * k + 1);
        }
        s += term / fact / ((2.0 * k + 2.0) * (2.0 * k + 2.0));
    }
    return (exp(1.0) - 1.0) / 2.0 + s;
}

#endif
