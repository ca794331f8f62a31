/* tests/render_adaptive_test.c — adaptive sampling (scheduler/adaptive.h):
 *   - a pixel that stopped after n samples is, bit for bit, that pixel of the render of n
 *     samples per pixel; every count is one of the rounds' (min, then +max(n/4, 4)); the noisy
 *     pixels get more samples than the flat ones;
 *   - with a threshold no pixel meets, the image is the full render's bit for bit (the rounds
 *     over pixel lists give every path its (pixel, sample) and its random numbers);
 *   - the image does not depend on the devices (CPU, CPU + GPU fallback), chunk sizes or
 *     threads;
 *   - bad settings are refused. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "render_util.h"

#define SIZE 24
#define SPP  64

static rt_args base_args(void)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    a.sampler = RS_SAMPLER_SOBOL;
    a.threads = 2;
    return a;
}

static size_t n_at(const uint32_t *counts, uint32_t c)
{
    size_t i, n = 0;
    for (i = 0; i < SIZE * SIZE; ++i)
        n += counts[i] == c;
    return n;
}

static void test_stopped_pixel_is_the_short_render(void **state)
{
    rt_args a = base_args();
    rs_adaptive_stats as;
    uint32_t counts[SIZE * SIZE], i, k, seen[SPP + 1];
    float *img;
    (void)state;
    memset(seen, 0, sizeof seen);
    a.adaptive.threshold = 0.15;
    a.adaptive.min_spp = 16;
    a.adaptive_out = &as;
    a.counts_out = counts;
    img = rt_render(&a, NULL);
    assert_non_null(img);
    print_message("%u rounds, %llu samples (%.1f a pixel), %u of %u pixels stopped early\n",
                  as.rounds, (unsigned long long)as.samples, (double)as.samples / (SIZE * SIZE),
                  as.stopped, SIZE * SIZE);
    assert_true(as.stopped > 0 && as.stopped < SIZE * SIZE); /* the threshold sorts them */
    for (i = 0; i < SIZE * SIZE; ++i) {
        uint32_t c = counts[i], n = 16;
        while (n < c)
            n += n / 4 > 4 ? n / 4 : 4;
        if (n > SPP)
            n = SPP;
        if (c != n)
            fail_msg("pixel %u has %u samples: not a round's end", i, c);
        seen[c] = 1;
    }
    /* each count: the pixels with it are that render's pixels, bit for bit */
    for (k = 16; k <= SPP; ++k) {
        rt_args u = base_args();
        float *ref;
        if (!seen[k])
            continue;
        u.spp = k;
        ref = rt_render(&u, NULL);
        assert_non_null(ref);
        for (i = 0; i < SIZE * SIZE; ++i)
            if (counts[i] == k && memcmp(&img[3 * i], &ref[3 * i], 3 * sizeof(float)) != 0)
                fail_msg("pixel %u (%u samples): %.9g, the %u-spp render has %.9g", i, k,
                         img[3 * i], k, ref[3 * i]);
        free(ref);
    }
    /* where the samples went: some pixels stopped at the first round (the lamp, seen directly,
     * is the same in every sample), some ran to the end */
    print_message("pixels at 16 samples: %u, at %u: %u\n", (unsigned)n_at(counts, 16), SPP,
                  (unsigned)n_at(counts, SPP));
    assert_true(n_at(counts, 16) > 0 && n_at(counts, SPP) > 0);
    free(img);
}

static void test_unmet_threshold_is_the_full_render(void **state)
{
    rt_args a = base_args(), u = base_args();
    float *img, *ref;
    (void)state;
    a.adaptive.threshold = 1e-12;
    a.adaptive.min_spp = 16;
    img = rt_render(&a, NULL);
    ref = rt_render(&u, NULL);
    assert_non_null(img);
    assert_non_null(ref);
    assert_memory_equal(img, ref, sizeof(float) * 3 * SIZE * SIZE);
    free(img);
    free(ref);
}

static void test_devices_and_chunks_change_nothing(void **state)
{
    rt_args a = base_args();
    float *ref;
    int k;
    (void)state;
    a.adaptive.threshold = 0.05;
    a.adaptive.min_spp = 8;
    ref = rt_render(&a, NULL);
    assert_non_null(ref);
    for (k = 0; k < 3; ++k) {
        rt_args b = a;
        float *img;
        b.with_fallback = k == 0;
        b.chunk_size = k == 0 ? 97 : k == 1 ? 13 : 0;
        b.threads = k == 2 ? 1 : 2;
        b.wave_paths = k == 1 ? 300 : 0;
        img = rt_render(&b, NULL);
        assert_non_null(img);
        if (memcmp(img, ref, sizeof(float) * 3 * SIZE * SIZE) != 0)
            fail_msg("case %d: the adaptive image changed", k);
        free(img);
    }
    free(ref);
}

/* An engine over one CPU device for `st`, or NULL with RS_ERR_ARG from its creation. */
typedef struct engine_rig {
    rs_scene *s;
    rs_bvh *bvh;
    rs_device *dev;
    rs_sched *sched;
    rs_engine *e;
} engine_rig;

static rs_status rig_make(engine_rig *g, const rs_render_settings *st)
{
    rs_geom geom;
    memset(g, 0, sizeof *g);
    assert_int_equal(rs_builtin_create("cornell", &g->s), RS_OK);
    geom = rs_scene_geom(g->s);
    assert_int_equal(rs_bvh_build(&geom, NULL, &g->bvh), RS_OK);
    assert_int_equal(rs_cpu_device_create(1, "cpu", &g->dev), RS_OK);
    assert_int_equal(rs_device_upload(g->dev, &geom, g->bvh), RS_OK);
    assert_int_equal(rs_sched_create(&g->dev, 1, NULL, &g->sched), RS_OK);
    return rs_engine_create(g->s, st, g->sched, NULL, &g->e);
}

static void rig_free(engine_rig *g)
{
    rs_engine_destroy(g->e);
    rs_sched_destroy(g->sched);
    rs_device_destroy(g->dev);
    rs_bvh_destroy(g->bvh);
    rs_scene_destroy(g->s);
}

static void test_bad_settings(void **state)
{
    engine_rig g;
    rs_film *film;
    rs_render_settings st;
    rs_render_stats stats;
    rs_adaptive a = {0.01, 1}; /* too few first samples */
    rs_adaptive_stats as;
    (void)state;
    assert_int_equal(rs_film_create(8, 8, &film), RS_OK);
    memset(&st, 0, sizeof st);
    st.width = st.height = 8;
    st.spp = 4;
    st.max_depth = 4;
    assert_int_equal(rig_make(&g, &st), RS_OK);
    assert_int_equal(rs_render_adaptive(g.e, &a, NULL, film, &stats, &as), RS_ERR_ARG);
    a.min_spp = 4;
    a.threshold = 0;
    assert_int_equal(rs_render_adaptive(g.e, &a, NULL, film, &stats, &as), RS_ERR_ARG);
    rig_free(&g);
    a.threshold = 0.1;
    st.path_begin = 5; /* a film that is not empty */
    assert_int_equal(rig_make(&g, &st), RS_OK);
    assert_int_equal(rs_render_adaptive(g.e, &a, NULL, film, &stats, &as), RS_ERR_ARG);
    rig_free(&g);
    rs_error_clear();
    rs_film_destroy(film);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stopped_pixel_is_the_short_render),
        cmocka_unit_test(test_unmet_threshold_is_the_full_render),
        cmocka_unit_test(test_devices_and_chunks_change_nothing),
        cmocka_unit_test(test_bad_settings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
