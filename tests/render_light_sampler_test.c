/* tests/render_light_sampler_test.c — --light-sampler bvh estimates the same image as picking by
 * power (both are unbiased; only the noise differs):
 *   - builtin:many-lights (220 lights), 40 x 30 at 128 spp, each sampler twice (seeds 1 and 2:
 *     the pixels' noise variance from the pair): in every 5 x 5-pixel block and over the whole
 *     image the two samplers' means agree within 4.5 standard errors (48 blocks: a correct
 *     sampler fails this about once in 10^4 runs), while the BVH's noise is at least 3x lower
 *     in variance;
 *   - the same image through the megakernel (the per-pixel integrator shades with the same
 *     code) and on the GPU fallback device: bit for bit the stream engine's;
 *   - builtin:cornell (one light: the tree is a leaf whose pick is 1): bit for bit the power
 *     sampler's image. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_util.h"

#define W 40u
#define H 30u

static float *render(const char *scene, uint32_t spp, uint32_t sampler, uint64_t seed,
                     int megakernel, int fallback)
{
    rt_args a = rt_defaults(scene, W, spp);
    rs_scene *s = NULL;
    float *rgb;
    a.height = H;
    a.seed = seed;
    a.sampler = RS_SAMPLER_SOBOL;
    a.light_sampler = sampler;
    a.threads = 2;
    a.megakernel = megakernel;
    a.fallback_only = fallback;
    assert_int_equal(rs_builtin_create(scene, &s), RS_OK);
    rgb = rt_render_scene(s, &a, NULL);
    assert_non_null(rgb);
    rs_scene_destroy(s);
    return rgb;
}

static double lum(const float *p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

static void test_same_image_many_lights(void **state)
{
    float *p1 = render("many-lights", 128, RS_LIGHT_SAMPLER_POWER, 1, 0, 0);
    float *p2 = render("many-lights", 128, RS_LIGHT_SAMPLER_POWER, 2, 0, 0);
    float *b1 = render("many-lights", 128, RS_LIGHT_SAMPLER_BVH, 1, 0, 0);
    float *b2 = render("many-lights", 128, RS_LIGHT_SAMPLER_BVH, 2, 0, 0);
    double worst = 0, var_p = 0, var_b = 0, dsum = 0, vsum = 0;
    uint32_t bx, by, x, y;
    (void)state;
    for (by = 0; by < H / 5; ++by)
        for (bx = 0; bx < W / 5; ++bx) {
            double d = 0, v = 0, z;
            for (y = by * 5; y < by * 5 + 5; ++y)
                for (x = bx * 5; x < bx * 5 + 5; ++x) {
                    size_t i = 3 * ((size_t)y * W + x);
                    double mp = 0.5 * (lum(p1 + i) + lum(p2 + i));
                    double mb = 0.5 * (lum(b1 + i) + lum(b2 + i));
                    /* each mean of two renders: variance (a - b)^2 / 4 */
                    double vp = 0.25 * (lum(p1 + i) - lum(p2 + i)) * (lum(p1 + i) - lum(p2 + i));
                    double vb = 0.25 * (lum(b1 + i) - lum(b2 + i)) * (lum(b1 + i) - lum(b2 + i));
                    d += mp - mb;
                    v += vp + vb;
                    var_p += vp;
                    var_b += vb;
                }
            dsum += d;
            vsum += v;
            z = v > 0 ? fabs(d) / sqrt(v) : 0.0;
            worst = z > worst ? z : worst;
        }
    print_message("many-lights 40x30, 128 spp: the worst of 48 blocks differs by %.2f standard "
                  "errors, the whole image by %.2f; noise variance power/bvh %.1fx\n",
                  worst, fabs(dsum) / sqrt(vsum), var_p / var_b);
    assert_true(worst < 4.5);
    assert_true(fabs(dsum) / sqrt(vsum) < 4.5);
    assert_true(var_p > 3.0 * var_b);
    {
        /* the megakernel and the GPU fallback shade with the same code: the same image */
        float *mk = render("many-lights", 128, RS_LIGHT_SAMPLER_BVH, 1, 1, 0);
        float *fb = render("many-lights", 128, RS_LIGHT_SAMPLER_BVH, 1, 0, 1);
        assert_memory_equal(mk, b1, W * H * 3 * sizeof(float));
        assert_memory_equal(fb, b1, W * H * 3 * sizeof(float));
        free(mk);
        free(fb);
    }
    free(p1);
    free(p2);
    free(b1);
    free(b2);
}

static void test_cornell_unchanged(void **state)
{
    float *p = render("cornell", 16, RS_LIGHT_SAMPLER_POWER, 1, 0, 0);
    float *b = render("cornell", 16, RS_LIGHT_SAMPLER_BVH, 1, 0, 0);
    (void)state;
    assert_memory_equal(p, b, W * H * 3 * sizeof(float));
    free(p);
    free(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_same_image_many_lights),
        cmocka_unit_test(test_cornell_unchanged),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
