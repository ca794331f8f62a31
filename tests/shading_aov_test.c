/* tests/shading_aov_test.c — the film's passes (shading/film.h), which the devices write as they
 * render (shading/aov.h rs_path_aux_at at each path's camera-ray hit), and the direct emission's
 * refinement --denoise adds back (rs_aov_refine).
 *
 * 1. The passes are the render's own samples, brute force: for every pixel, the mean over all
 *    its samples of what rs_path_aov gives for the very camera rays the render traced
 *    (rs_path_begin_at, traced here on the host's binary BVH, summed in doubles), within 1e-5;
 *    on the Cornell box (flat walls), rtiow-final (spheres: normals that change across a pixel,
 *    a sky) and the materials scene (textures), with the CLI's Blackman-Harris filter.
 * 2. The emission pass is what the camera rays' first hits added: a render with max_depth 1 adds
 *    nothing else, so the emission pass of a full-depth render must equal the depth-1 render to
 *    float rounding, for the box, Blackman-Harris and Mitchell (negative lobes: signed samples)
 *    filters, an emitter scene and a sky one, and for an adaptive render whose pixels got
 *    different sample counts.
 * 3. The same bits on every device set: the CPU stream engine, its megakernel, the GPU
 *    fallback's megakernel and wavefront, the CPU beside the fallback (tracing, and running its
 *    wavefront) give passes and images identical to the CPU's, byte for byte.
 * 4. rs_aov_refine is better where it refined: against a 4096-sample estimate of the same
 *    integral, its RMSE over the pixels it changed is at least 3x below the render's pass; the
 *    others are the pass bit for bit, and were already right (within 1% of the emitter's
 *    radiance).  Only the emitter's outline is refined (a few percent of the image, not none). */
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

/* Renders a with its passes into passes (10 floats a pixel, rt_args.passes_out's planes);
 * returns the image. */
static float *render_passes(rt_args *a, float *passes)
{
    float *rgb;
    a->passes_out = passes;
    rgb = rt_render(a, NULL);
    assert_non_null(rgb);
    a->passes_out = NULL;
    return rgb;
}

/* The tests' renders: Sobol, the CLI's pixel filter (into *f), two threads. */
static rt_args sobol_args(const char *scene, uint32_t size, uint32_t spp, rs_filter *f)
{
    rt_args a = rt_defaults(scene, size, spp);
    rs_filter_default(f);
    a.sampler = RS_SAMPLER_SOBOL;
    a.filter = f;
    a.threads = 2;
    return a;
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

/* The passes brute force, as test 1 says: albedo, normal, depth of scene_name for settings a. */
static void brute_passes(const rt_args *a, float *albedo, float *normal, float *depth)
{
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_geom g;
    rs_render_consts it;
    rs_render_settings st = rt_settings(a);
    rs_bvh_view v;
    uint32_t p, s, npix = a->width * a->height;
    assert_int_equal(rs_builtin_create(a->scene, &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    rs_bvh_attach(bvh, &g);
    v = rs_bvh_view_of(bvh);
    assert_int_equal(rs_render_constants(scene, &st, &it), RS_OK);
    for (p = 0; p < npix; ++p) {
        double al[3] = {0, 0, 0}, nr[3] = {0, 0, 0}, d = 0, l;
        uint32_t hits = 0, c;
        for (s = 0; s < a->spp; ++s) {
            rs_path_state ps;
            rs_ray r = rs_path_begin_at(&it, p, s, NULL, &ps);
            rs_hit h;
            rs_vec3 va, vn;
            float vd;
            rs_bvh_closest(&v, &g, r, &h);
            rs_path_aov(&it, &r, &h, &va, &vn, &vd);
            al[0] += va.x, al[1] += va.y, al[2] += va.z;
            nr[0] += vn.x, nr[1] += vn.y, nr[2] += vn.z;
            if (isfinite(vd)) {
                d += vd;
                ++hits;
            }
        }
        l = sqrt(nr[0] * nr[0] + nr[1] * nr[1] + nr[2] * nr[2]);
        for (c = 0; c < 3; ++c) {
            albedo[3 * p + c] = (float)(al[c] / a->spp);
            normal[3 * p + c] = l > 0 ? (float)(nr[c] / l) : 0.0f;
        }
        depth[p] = hits ? (float)(d / hits) : INFINITY;
    }
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
}

static void check_brute(const char *scene)
{
    size_t npix = (size_t)SIZE * SIZE, i;
    float *passes = malloc(npix * 10 * sizeof(float)), *ref = malloc(npix * 7 * sizeof(float));
    float *rgb;
    rs_filter f;
    rt_args a = sobol_args(scene, SIZE, 8, &f);
    double da, dn, dd = 0;
    size_t hits = 0, misses = 0, tilted = 0;
    assert_true(passes && ref);
    rgb = render_passes(&a, passes);
    brute_passes(&a, ref, ref + 3 * npix, ref + 6 * npix);
    da = max_rel_diff(passes, ref, 3 * npix);
    dn = max_rel_diff(passes + 3 * npix, ref + 3 * npix, 3 * npix);
    for (i = 0; i < npix; ++i) {
        float d = passes[9 * npix + i], r = ref[6 * npix + i];
        const float *n = passes + 3 * npix + 3 * i;
        if (isinf(r)) {
            assert_true(isinf(d));
            ++misses;
            continue;
        }
        ++hits;
        dd = fmax(dd, fabs((double)d - r) / fmax(1.0, fabs((double)r)));
        /* a normal no axis holds */
        tilted += fabsf(n[0]) < 0.99f && fabsf(n[1]) < 0.99f && fabsf(n[2]) < 0.99f;
    }
    printf("  %s: %zu pixels hit, %zu miss, %zu with a tilted normal; against brute force: "
           "albedo %.2g, normal %.2g, depth %.2g\n",
           scene, hits, misses, tilted, da, dn, dd);
    assert_true(hits > 0);
    assert_true(da < 1e-5 && dn < 1e-5 && dd < 1e-5);
    free(passes);
    free(ref);
    free(rgb);
}

static void test_passes_brute_force(void **state)
{
    (void)state;
    check_brute("cornell");
    check_brute("rtiow-final");
    check_brute("materials");
}

static void check_depth1(const char *scene, const char *filter, int adaptive)
{
    size_t npix = (size_t)SIZE * SIZE, n = npix * 3, i, bright = 0;
    float *passes = malloc(npix * 10 * sizeof(float)), *rgb, *rgb1;
    uint32_t *counts = calloc(npix, sizeof(uint32_t));
    uint32_t cmin = UINT32_MAX, cmax = 0;
    rs_filter f;
    char why[128];
    rt_args a = rt_defaults(scene, SIZE, adaptive ? 64 : 8);
    double d;
    assert_true(passes && counts);
    assert_true(rs_filter_parse(filter, &f, why, sizeof why));
    a.sampler = RS_SAMPLER_SOBOL;
    a.filter = &f;
    a.counts_out = counts;
    if (adaptive) { /* the counts follow the image's noise: depth 1 for both */
        a.max_depth = 1;
        a.adaptive.threshold = 0.05f;
        a.adaptive.min_spp = 4;
    }
    rgb = render_passes(&a, passes);
    a.max_depth = 1;
    rgb1 = rt_render(&a, NULL);
    assert_non_null(rgb1);
    for (i = 0; i < npix; ++i) {
        cmin = counts[i] < cmin ? counts[i] : cmin;
        cmax = counts[i] > cmax ? counts[i] : cmax;
    }
    d = max_rel_diff(passes + 6 * npix, rgb1, n);
    for (i = 0; i < n; ++i)
        bright += rgb1[i] > 0.5f;
    printf("  %s, %s%s: samples %u..%u, %zu bright values; the emission pass against the "
           "depth-1 render: %.2g\n",
           scene, filter, adaptive ? ", adaptive" : "", cmin, cmax, bright, d);
    assert_true(bright > 0); /* it sees light */
    if (adaptive)
        assert_true(cmin < cmax); /* the counts differ: the pass divides by each pixel's */
    assert_true(d < 1e-5);
    free(passes);
    free(rgb);
    free(rgb1);
    free(counts);
}

static void test_emission_pass_is_depth1_render(void **state)
{
    (void)state;
    check_depth1("cornell", "box", 0);
    check_depth1("cornell", "blackman-harris:1.5", 0);
    check_depth1("cornell", "mitchell:2", 0);
    check_depth1("rtiow-final", "blackman-harris:1.5", 0);
    check_depth1("cornell", "blackman-harris:1.5", 1);
}

typedef struct device_set {
    const char *name;
    int megakernel, fallback_only, with_fallback, wavefront, adaptive;
} device_set;

static void check_devices(const char *scene)
{
    static const device_set sets[] = {
        {"cpu megakernel", 1, 0, 0, 0, 0},
        {"gpu-fallback megakernel", 1, 1, 0, 0, 0},
        {"gpu-fallback wavefront", 0, 1, 0, 1, 0},
        {"cpu + gpu-fallback tracing", 0, 0, 1, 0, 0},
        {"cpu + gpu-fallback wavefront", 0, 0, 1, 1, 0},
    };
    size_t npix = (size_t)SIZE * SIZE, k;
    float *ref = malloc(npix * 10 * sizeof(float)), *got = malloc(npix * 10 * sizeof(float));
    float *rgb_ref, *rgb;
    rs_filter f;
    rt_args a = sobol_args(scene, SIZE, 4, &f);
    assert_true(ref && got);
    rgb_ref = render_passes(&a, ref);
    for (k = 0; k < sizeof sets / sizeof sets[0]; ++k) {
        rt_args b = a;
        int same_passes, same_image;
        b.megakernel = sets[k].megakernel;
        b.fallback_only = sets[k].fallback_only;
        b.with_fallback = sets[k].with_fallback;
        b.wavefront = sets[k].wavefront;
        b.chunk_size = 97; /* many chunks, dealt between the devices */
        rgb = render_passes(&b, got);
        same_passes = memcmp(got, ref, npix * 10 * sizeof(float)) == 0;
        same_image = memcmp(rgb, rgb_ref, npix * 3 * sizeof(float)) == 0;
        printf("  %s, %s: passes %s, image %s\n", scene, sets[k].name,
               same_passes ? "the same" : "DIFFER", same_image ? "the same" : "DIFFERS");
        assert_true(same_passes && same_image);
        free(rgb);
    }
    free(rgb_ref);
    free(ref);
    free(got);
}

static void test_same_on_every_device(void **state)
{
    (void)state;
    check_devices("cornell");
    check_devices("materials");
}

static void test_fine_where_refined(void **state)
{
    const uint32_t size = 48;
    size_t npix = (size_t)size * size, n = npix * 3, i, refined, n_ref = 0;
    float *passes = malloc(npix * 10 * sizeof(float)), *ef = malloc(n * sizeof(float)), *ref, *rgb;
    uint32_t *counts = calloc(npix, sizeof(uint32_t));
    double se_r = 0, se_f = 0, worst_else = 0;
    rs_filter f;
    rt_args a = sobol_args("cornell", size, 16, &f);
    rs_render_settings st;
    rs_render_consts it;
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_bvh_view v;
    rs_geom g;
    const float *er;
    (void)state;
    assert_true(passes && ef && counts);
    a.counts_out = counts;
    rgb = render_passes(&a, passes);
    er = passes + 6 * npix;
    assert_int_equal(rs_builtin_create("cornell", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    rs_bvh_attach(bvh, &g);
    v = rs_bvh_view_of(bvh);
    st = rt_settings(&a);
    assert_int_equal(rs_render_constants(scene, &st, &it), RS_OK);
    refined = rs_aov_refine(&it, &v, &g, counts, 2, er, ef);
    /* the reference: 4096 of the render's own samples at depth 1 (the direct emission alone) */
    a.spp = 4096;
    a.max_depth = 1;
    a.counts_out = NULL;
    ref = rt_render(&a, NULL);
    assert_non_null(ref);
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
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    free(passes);
    free(ef);
    free(ref);
    free(rgb);
    free(counts);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_passes_brute_force),
        cmocka_unit_test(test_emission_pass_is_depth1_render),
        cmocka_unit_test(test_same_on_every_device),
        cmocka_unit_test(test_fine_where_refined),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
