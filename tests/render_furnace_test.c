/* tests/render_furnace_test.c — energy is neither gained nor lost: the white furnace.
 *
 * builtin:furnace is a diffuse sphere of albedo 0.5 filling the view under a uniform white sky
 * of radiance 1.  A path hits the sphere (throughput 0.5), bounces, and sees the sky, so every
 * pixel's expected value is exactly 0.5 for every sampling strategy. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <cmocka.h>

#include "render_util.h"

#define SIZE 64
#define NF   (SIZE * SIZE * 3)

static void furnace(rs_sampling sampling, uint32_t spp, double pixel_tol)
{
    rt_args a = rt_defaults("furnace", SIZE, spp);
    float *img;
    double mean;
    size_t i;
    a.sampling = sampling;
    a.threads = 2;
    img = rt_render(&a, NULL);
    assert_non_null(img);
    mean = rt_mean(img, NF);
    print_message("furnace %-8s mean %.6f\n", rs_sampling_name(sampling), mean);
    /* 0.5 +- 1% for the image mean (the acceptance bound) */
    assert_true(fabs(mean - 0.5) <= 0.005);
    for (i = 0; i < NF; ++i)
        assert_true(fabs(img[i] - 0.5) <= pixel_tol);
    free(img);
}

/* Cosine-weighted sampling of a Lambertian BSDF carries weight exactly albedo: each sample is
 * 0.5 up to float rounding, so every pixel must be within 1e-5 of 0.5. */
static void test_mis(void **state)
{
    (void)state;
    furnace(RS_SAMPLING_MIS, 16, 1e-5);
}

static void test_bsdf(void **state)
{
    (void)state;
    furnace(RS_SAMPLING_BSDF, 16, 1e-5);
}

/* No lights in the scene: the mixture degenerates to the BSDF pdf, again exact. */
static void test_mixture(void **state)
{
    (void)state;
    furnace(RS_SAMPLING_MIXTURE, 16, 1e-5);
}

/* Uniform hemisphere sampling: each sample is 2 * 0.5 * cos(theta) with cos uniform in [0, 1]
 * (mean 0.5, standard deviation 0.289).  64 spp per pixel: a pixel's standard error is 0.036,
 * so a per-pixel bound of 0.2 is > 5 sigma; the image mean over 64*64*64 samples has standard
 * error 0.00056, and the 1% bound (0.005) is ~9 sigma. */
static void test_uniform(void **state)
{
    (void)state;
    furnace(RS_SAMPLING_UNIFORM, 64, 0.2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mis),
        cmocka_unit_test(test_bsdf),
        cmocka_unit_test(test_mixture),
        cmocka_unit_test(test_uniform),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
