/* tests/shading_filter_test.c — shading/filter.h: the pixel filters drawn by filter importance
 * sampling.
 *
 * The filters are written out again here from their published formulas (pbrt-v4's Gaussian and
 * Mitchell, Cycles' Blackman-Harris), independently of shading/filter.c, and integrated by a
 * fine midpoint rule.  What is checked, with fixed seeds:
 *   - chi-square of 10^6 drawn offsets against the filter's exact integrals over the table's 64
 *     bins (|f| for Mitchell), and over 10 bins that do not line up with the table's (the
 *     offsets are uniform within a table bin: this is how close that comes to f itself); each
 *     at significance 10^-3, the filter's own width and a non-default one;
 *   - Mitchell's signed weights: the mean of w g(x) over the drawn samples equals
 *     int f g / int f for a test function g (within 4 standard errors), the plain mean does not;
 *   - box:1 hands the uniform numbers through unchanged (the old images, bit for bit) and
 *     weights 1; positive filters weight 1; offsets stay within the support;
 *   - parsing: names, widths, the default, and refusals. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rng.h"
#include "shading/filter.h"

#define PI_D 3.14159265358979323846
#define N_DRAWS 1000000

/* The filters as published, x in pixels from the centre, width w (the full support). */
static double ref_filter(int kind, double w, double x)
{
    double r = w / 2;
    if (fabs(x) > r)
        return 0.0;
    if (kind == RS_FILTER_GAUSSIAN) { /* pbrt-v4 GaussianFilter, sigma = radius / 3 */
        double s = r / 3;
        return exp(-x * x / (2 * s * s)) - exp(-r * r / (2 * s * s));
    }
    if (kind == RS_FILTER_BLACKMAN_HARRIS) { /* Cycles filter_func_blackman_harris, 1D */
        double t = 2 * PI_D * (x / w + 0.5);
        return 0.35875 - 0.48829 * cos(t) + 0.14128 * cos(2 * t) - 0.01168 * cos(3 * t);
    }
    if (kind == RS_FILTER_MITCHELL) { /* Mitchell-Netravali, B = C = 1/3, on [-2, 2] */
        double t = fabs(4 * x / w);
        if (t < 1)
            return (7 * t * t * t - 12 * t * t + 16.0 / 3) / 6;
        return (-7.0 / 3 * t * t * t + 12 * t * t - 20 * t + 32.0 / 3) / 6;
    }
    return 1.0;
}

/* The integral of f (absolute: of |f|) over [a, b] by 4000 midpoints. */
static double integral(int kind, double w, double a, double b, int absolute)
{
    const int n = 4000;
    double h = (b - a) / n, s = 0.0;
    int i;
    for (i = 0; i < n; ++i) {
        double f = ref_filter(kind, w, a + (i + 0.5) * h);
        s += absolute ? fabs(f) : f;
    }
    return s * h;
}

/* The chi-square statistic of n_draws offsets drawn with f against |f|'s integrals over `bins`
 * equal bins of the support. */
static double chi_square(const rs_filter *f, int kind, int bins)
{
    static unsigned counts[256];
    double w = f->width, total = integral(kind, w, -w / 2, w / 2, 1), chi = 0.0;
    uint32_t i;
    int k;
    memset(counts, 0, sizeof counts);
    for (i = 0; i < N_DRAWS / 2; ++i) {
        rs_rng_f4 r = rs_rng_float4(7, i, 0, 0, 0);
        float x[2];
        x[0] = rs_filter_offset(f, r.v[0]);
        x[1] = rs_filter_offset(f, r.v[1]);
        for (k = 0; k < 2; ++k) {
            int b = (int)floor((x[k] / w + 0.5) * bins);
            assert_true(fabs(x[k]) <= w / 2 + 1e-5);
            counts[b < 0 ? 0 : b >= bins ? bins - 1 : b]++;
        }
    }
    for (k = 0; k < bins; ++k) {
        double a = -w / 2 + k * w / bins, e = N_DRAWS * integral(kind, w, a, a + w / bins, 1) / total;
        chi += (counts[k] - e) * (counts[k] - e) / e;
    }
    return chi;
}

/* The 0.999 quantile of chi-square with df degrees of freedom (Wilson-Hilferty). */
static double chi_critical(int df)
{
    double z = 3.0902, a = 2.0 / (9.0 * df), c = 1 - a + z * sqrt(a);
    return df * c * c * c;
}

static void check_kind(int kind, float width)
{
    rs_filter f;
    double chi64, chi10;
    assert_int_equal(rs_filter_make((rs_filter_kind)kind, width, &f), 1);
    chi64 = chi_square(&f, kind, RS_FILTER_BINS);
    chi10 = chi_square(&f, kind, 10);
    printf("  filter %d width %.2f: chi-square %.1f over 64 bins (critical %.1f), %.1f over 10 "
           "(critical %.1f)\n",
           kind, (double)f.width, chi64, chi_critical(63), chi10, chi_critical(9));
    assert_true(chi64 < chi_critical(63));
    assert_true(chi10 < chi_critical(9));
}

static void test_chi_square_each_filter(void **state)
{
    (void)state;
    check_kind(RS_FILTER_BOX, 2.5f);
    check_kind(RS_FILTER_GAUSSIAN, 0.0f);
    check_kind(RS_FILTER_GAUSSIAN, 2.0f);
    check_kind(RS_FILTER_BLACKMAN_HARRIS, 0.0f);
    check_kind(RS_FILTER_BLACKMAN_HARRIS, 3.0f);
    check_kind(RS_FILTER_MITCHELL, 0.0f);
    check_kind(RS_FILTER_MITCHELL, 2.0f);
}

/* Mitchell's estimate of int f(x) f(y) g(x, y) / (int f)^2 with its signed weights. */
static void test_mitchell_weights_unbiased(void **state)
{
    rs_filter f;
    double w, sum = 0.0, sum2 = 0.0, plain = 0.0, want, gx, f1, se;
    uint32_t i;
    int k;
    (void)state;
    assert_int_equal(rs_filter_make(RS_FILTER_MITCHELL, 0.0f, &f), 1);
    w = f.width;
    assert_true(f.weight > 0.0f);
    /* g(x, y) = cos(2 x) cos(2 y), separable: the reference is (int f cos(2x) / int f)^2 */
    gx = 0.0;
    f1 = 0.0;
    for (k = 0; k < 200000; ++k) {
        double x = -w / 2 + (k + 0.5) * w / 200000;
        gx += ref_filter(RS_FILTER_MITCHELL, w, x) * cos(2 * x);
        f1 += ref_filter(RS_FILTER_MITCHELL, w, x);
    }
    want = (gx / f1) * (gx / f1);
    for (i = 0; i < N_DRAWS; ++i) {
        rs_rng_f4 r = rs_rng_float4(11, i, 0, 0, 0);
        double x = rs_filter_offset(&f, r.v[0]), y = rs_filter_offset(&f, r.v[1]);
        double v = rs_filter_weight(&f, r.v[0], r.v[1]) * cos(2 * x) * cos(2 * y);
        sum += v;
        sum2 += v * v;
        plain += cos(2 * x) * cos(2 * y);
    }
    sum /= N_DRAWS;
    se = sqrt((sum2 / N_DRAWS - sum * sum) / N_DRAWS);
    printf("  mitchell: weighted mean %.5f, exact %.5f (standard error %.5f); unweighted %.5f\n",
           sum, want, se, plain / N_DRAWS);
    assert_true(fabs(sum - want) < 4 * se);
    assert_true(fabs(plain / N_DRAWS - want) > 4 * se); /* the weights matter */
}

static void test_box_one_is_identity(void **state)
{
    rs_filter f;
    uint32_t i;
    (void)state;
    assert_int_equal(rs_filter_make(RS_FILTER_BOX, 0.0f, &f), 1);
    assert_true(rs_filter_is_identity(&f));
    for (i = 0; i < 10000; ++i) {
        rs_rng_f4 r = rs_rng_float4(3, i, 0, 0, 0);
        float jx, jy;
        rs_filter_sample(&f, r.v[0], r.v[1], &jx, &jy);
        assert_true(jx == r.v[0] && jy == r.v[1]);
        assert_true(rs_filter_weight(&f, r.v[0], r.v[1]) == 1.0f);
    }
    assert_int_equal(rs_filter_make(RS_FILTER_GAUSSIAN, 0.0f, &f), 1);
    for (i = 0; i < 10000; ++i) {
        rs_rng_f4 r = rs_rng_float4(3, i, 0, 0, 0);
        assert_true(rs_filter_weight(&f, r.v[0], r.v[1]) == 1.0f);
    }
}

static void test_parse(void **state)
{
    rs_filter f;
    char why[200], name[40];
    (void)state;
    rs_filter_default(&f);
    rs_filter_describe(&f, name, sizeof name);
    assert_string_equal(name, "blackman-harris:1.5");
    assert_int_equal(rs_filter_parse("gaussian", &f, why, sizeof why), 1);
    rs_filter_describe(&f, name, sizeof name);
    assert_string_equal(name, "gaussian:3");
    assert_int_equal(rs_filter_parse("mitchell:2.5", &f, why, sizeof why), 1);
    assert_true(f.kind == RS_FILTER_MITCHELL && f.width == 2.5f);
    assert_int_equal(rs_filter_parse("box", &f, why, sizeof why), 1);
    assert_true(rs_filter_is_identity(&f));
    assert_int_equal(rs_filter_parse("lanczos", &f, why, sizeof why), 0);
    assert_non_null(strstr(why, "'lanczos' is not a filter"));
    assert_int_equal(rs_filter_parse("box:0", &f, why, sizeof why), 0);
    assert_non_null(strstr(why, "width '0'"));
    assert_int_equal(rs_filter_parse("gaussian:17", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("gaussian:", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("gaussian:1x", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("gaussian:nan", &f, why, sizeof why), 0);
    /* issue 39: widths that rendered something else without a word: mitchell:1e-38 black (its
     * weights overflowed), box:1e-50 as box:1 (the float is 0, the default), and widths a
     * checkpoint (thousandths of a pixel) cannot tell apart: box:0.0004 resumed as box:1 */
    assert_int_equal(rs_filter_parse("mitchell:1e-38", &f, why, sizeof why), 0);
    assert_non_null(strstr(why, "from 0.01 to 16 in steps of 0.001"));
    assert_int_equal(rs_filter_parse("box:1e-50", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("box:0.0004", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("box:1.0004", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("box:0.009", &f, why, sizeof why), 0);
    assert_int_equal(rs_filter_parse("box:0.01", &f, why, sizeof why), 1);
    assert_true(f.width == 0.01f);
    assert_int_equal(rs_filter_parse("gaussian:2.125", &f, why, sizeof why), 1);
    assert_int_equal(rs_filter_parse("mitchell:15.999", &f, why, sizeof why), 1);
    assert_int_equal(rs_filter_parse("blackman-harris:16", &f, why, sizeof why), 1);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chi_square_each_filter),
        cmocka_unit_test(test_mitchell_weights_unbiased),
        cmocka_unit_test(test_box_one_is_identity),
        cmocka_unit_test(test_parse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
