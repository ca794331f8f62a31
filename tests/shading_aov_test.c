/* tests/shading_aov_test.c — the direct emission pass (shading/aov.h rs_aov_emission) that
 * --denoise keeps out of the denoiser.
 *
 * 1. e_render is what the render's camera rays' first hits added: a render with max_depth 1 adds
 *    nothing else, so it must equal e_render to float rounding, for the box, Blackman-Harris and
 *    Mitchell (negative lobes: signed samples) filters, an emitter scene (the Cornell box) and a
 *    sky one (rtiow-final: every miss sees the gradient), and for an adaptive render whose pixels
 *    got different sample counts (the counts passed in).
 * 2. e_fine is better where it was refined: against a 4096-sample estimate of the same integral,
 *    its RMSE over the pixels it changed is at least 3x below e_render's; the others are
 *    e_render bit for bit, and were already right (within 1% of the emitter's radiance).
 *    Only the emitter's outline is refined (a few percent of the image, not none). */
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
#include "shading/aov.h"
#include "shading/filter.h"

#define SIZE 24u

/* The emission pass of `scene` for settings st (count: per-pixel samples or NULL). */
static size_t emission(const char *scene_name, const rs_render_settings *st, const uint32_t *count,
                       float *er, float *ef)
{
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_geom g;
    rs_render_consts it;
    rs_bvh_view v;
    size_t refined;
    assert_int_equal(rs_builtin_create(scene_name, &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    rs_bvh_attach(bvh, &g);
    v = rs_bvh_view_of(bvh);
    assert_int_equal(rs_render_constants(scene, st, &it), RS_OK);
    refined = rs_aov_emission(&it, &v, &g, count, st->spp, 2, er, ef);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    return refined;
}

static float *render_depth1(const rt_args *a)
{
    rs_scene *scene = NULL;
    float *rgb;
    assert_int_equal(rs_builtin_create(a->scene, &scene), RS_OK);
    rgb = rt_render_scene(scene, a, NULL);
    assert_non_null(rgb);
    rs_scene_destroy(scene);
    return rgb;
}

/* max |a - b| relative to max(1, |b|) */
static double max_rel_diff(const float *a, const float *b, size_t n)
{
    double m = 0;
    size_t i;
    for (i = 0; i < n; ++i) {
        double d = fabs((double)a[i] - b[i]) / fmax(1.0, fabs((double)b[i]));
        m = d > m ? d : m;
    }
    return m;
}

static void check_depth1(const char *scene, const char *filter, int adaptive)
{
    size_t n = (size_t)SIZE * SIZE * 3, i, bright = 0, dark = 0;
    float *er = malloc(n * sizeof(float)), *ef = malloc(n * sizeof(float)), *rgb;
    uint32_t *counts = calloc((size_t)SIZE * SIZE, sizeof(uint32_t));
    uint32_t cmin = UINT32_MAX, cmax = 0;
    rs_filter f;
    char why[128];
    rt_args a = rt_defaults(scene, SIZE, adaptive ? 64 : 8);
    rs_render_settings st;
    double d;
    assert_true(er && ef && counts);
    assert_true(rs_filter_parse(filter, &f, why, sizeof why));
    a.max_depth = 1;
    a.sampler = RS_SAMPLER_SOBOL;
    a.filter = &f;
    a.counts_out = counts;
    if (adaptive) {
        a.adaptive.threshold = 0.05f;
        a.adaptive.min_spp = 4;
    }
    rgb = render_depth1(&a);
    for (i = 0; i < (size_t)SIZE * SIZE; ++i) {
        cmin = counts[i] < cmin ? counts[i] : cmin;
        cmax = counts[i] > cmax ? counts[i] : cmax;
    }
    st = rt_settings(&a);
    emission(scene, &st, counts, er, ef);
    d = max_rel_diff(er, rgb, n);
    for (i = 0; i < n; ++i) {
        bright += rgb[i] > 0.5f;
        dark += rgb[i] == 0.0f;
    }
    printf("  %s, %s%s: samples %u..%u, %zu bright and %zu black values; e_render against the "
           "depth-1 render: %.2g\n",
           scene, filter, adaptive ? ", adaptive" : "", cmin, cmax, bright, dark, d);
    assert_true(bright > 0); /* it sees light */
    if (adaptive)
        assert_true(cmin < cmax); /* the counts differ, so passing them matters */
    assert_true(d < 1e-5);
    free(er);
    free(ef);
    free(rgb);
    free(counts);
}

static void test_depth1_render_is_e_render(void **state)
{
    (void)state;
    check_depth1("cornell", "box", 0);
    check_depth1("cornell", "blackman-harris:1.5", 0);
    check_depth1("cornell", "mitchell:2", 0);
    check_depth1("rtiow-final", "blackman-harris:1.5", 0);
    check_depth1("cornell", "blackman-harris:1.5", 1);
}

static void test_fine_where_refined(void **state)
{
    const uint32_t size = 48;
    size_t npix = (size_t)size * size, n = npix * 3, i, refined, n_ref = 0;
    float *er = malloc(n * sizeof(float)), *ef = malloc(n * sizeof(float));
    float *ref = malloc(n * sizeof(float)), *unused = malloc(n * sizeof(float));
    double se_r = 0, se_f = 0, worst_else = 0;
    rs_filter f;
    rt_args a = rt_defaults("cornell", size, 16);
    rs_render_settings st;
    (void)state;
    assert_true(er && ef && ref && unused);
    rs_filter_default(&f);
    a.sampler = RS_SAMPLER_SOBOL;
    a.filter = &f;
    st = rt_settings(&a);
    refined = emission("cornell", &st, NULL, er, ef);
    /* the reference: 4096 of the render's own samples */
    st.spp = 4096;
    emission("cornell", &st, NULL, ref, unused);
    for (i = 0; i < npix; ++i) {
        int c, differs = memcmp(er + 3 * i, ef + 3 * i, 3 * sizeof(float)) != 0;
        n_ref += (size_t)differs;
        for (c = 0; c < 3; ++c) {
            double dr = (double)er[3 * i + c] - ref[3 * i + c];
            double df = (double)ef[3 * i + c] - ref[3 * i + c];
            if (differs) {
                se_r += dr * dr;
                se_f += df * df;
            } else if (fabs(dr) > worst_else) {
                worst_else = fabs(dr);
            }
        }
    }
    printf("  cornell %ux%u, 16 spp: %zu of %zu pixels refined, %zu changed; their RMSE against "
           "4096 samples %.4f -> %.4f; elsewhere at most %.4f off\n",
           size, size, refined, npix, n_ref, sqrt(se_r / (3.0 * (double)n_ref)),
           sqrt(se_f / (3.0 * (double)n_ref)), worst_else);
    assert_true(n_ref <= refined); /* a refined pixel far enough out stays 0 */
    assert_true(refined > 0 && refined < npix / 10);
    assert_true(se_f * 9.0 < se_r);
    assert_true(worst_else < 0.01 * 15.0); /* the emitter's radiance is 15 */
    free(er);
    free(ef);
    free(ref);
    free(unused);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_depth1_render_is_e_render),
        cmocka_unit_test(test_fine_where_refined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
