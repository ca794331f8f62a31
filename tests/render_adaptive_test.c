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

/* The Cornell box on one CPU device and an engine for `st` over it (or the engine's status). */
typedef struct engine_rig {
    rt_rig g;
    rs_engine *e;
} engine_rig;

static rs_status rig_make(engine_rig *g, const rs_render_settings *st)
{
    g->e = NULL;
    assert_true(rt_rig_up(&g->g, "cornell"));
    return rs_engine_create(g->g.scene, st, g->g.sched, NULL, &g->e);
}

static void rig_free(engine_rig *g)
{
    rs_engine_destroy(g->e);
    rt_rig_down(&g->g);
}

static void test_bad_settings(void **state)
{
    engine_rig g;
    rs_film *film;
    rs_render_settings st;
    rs_render_stats stats;
    rs_adaptive a = {0.01, 1, 0.0}; /* too few first samples */
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

/* Stops the render (cancel) at the film_ready call number `stop_at`, and counts the calls. */
typedef struct stopper {
    atomic_int cancel;
    int calls, stop_at;
} stopper;

static void stop_at_call(void *user, const rs_film *film, const rs_path_ranges *done)
{
    stopper *k = (stopper *)user;
    (void)film;
    (void)done;
    if (++k->calls == k->stop_at)
        atomic_store(&k->cancel, 1);
}

static rs_render_settings split_settings(void)
{
    rs_render_settings st;
    memset(&st, 0, sizeof st);
    st.width = st.height = SIZE;
    st.spp = SPP;
    st.max_depth = 8;
    st.seed = 5;
    st.sampler = RS_SAMPLER_SOBOL;
    st.threads = 1;
    st.wave_paths = 500; /* many waves: many places to stop */
    return st;
}

/* An adaptive render stopped at film_ready call `stop_at` (0: never), its film and state
 * copied (as a checkpoint keeps them), then continued on a new engine to the end. */
static rs_film *render_split(int stop_at, rs_adaptive_stats *out, int *calls)
{
    rs_render_settings st = split_settings();
    rs_adaptive a = {0.08, 8, 0.0};
    rs_adaptive_state s;
    rs_render_hooks h;
    rs_render_stats stats;
    rs_film *film = NULL, *copy = NULL;
    engine_rig g;
    stopper k;
    rs_status rst;
    memset(&s, 0, sizeof s);
    memset(&h, 0, sizeof h);
    k.calls = 0;
    k.stop_at = stop_at;
    atomic_init(&k.cancel, 0);
    h.cancel = &k.cancel;
    h.film_ready = stop_at_call;
    h.user = &k;
    assert_int_equal(rs_film_create(SIZE, SIZE, &film), RS_OK);
    assert_int_equal(rig_make(&g, &st), RS_OK);
    rst = rs_adaptive_run(g.e, &a, &s, &h, film, &stats);
    rig_free(&g);
    *calls = k.calls;
    if (rst == RS_OK) {
        *out = s.stats;
        rs_adaptive_state_free(&s);
        return film;
    }
    assert_int_equal(rst, RS_ERR_CANCELLED);
    rs_error_clear();
    /* what a checkpoint keeps: the film's sums, counts and squared luminance, and the state */
    assert_int_equal(rs_film_create(SIZE, SIZE, &copy), RS_OK);
    assert_int_equal(rs_film_track_variance(copy), RS_OK);
    assert_int_equal(rs_film_merge(copy, film), RS_OK);
    rs_film_destroy(film);
    assert_true(rs_adaptive_state_fits(&s, copy->count, SIZE * SIZE, SPP));
    assert_int_equal(rig_make(&g, &st), RS_OK);
    assert_int_equal(rs_adaptive_run(g.e, &a, &s, NULL, copy, &stats), RS_OK);
    rig_free(&g);
    *out = s.stats;
    rs_adaptive_state_free(&s);
    return copy;
}

static void assert_same_film(const rs_film *x, const rs_film *y)
{
    size_t n = (size_t)SIZE * SIZE;
    assert_memory_equal(x->sum, y->sum, 3 * n * sizeof *x->sum);
    assert_memory_equal(x->count, y->count, n * sizeof *x->count);
    assert_memory_equal(x->sum_l2, y->sum_l2, n * sizeof *x->sum_l2);
}

/* An adaptive render is a sequence of plans that can stop after any wave: stopped in the first
 * round, within a later one, and at every tenth wave, and continued from its film and state, it
 * is the uninterrupted render bit for bit (the same pixels stop, with the same samples). */
static void test_stopped_and_continued_is_the_same(void **state)
{
    rs_adaptive_stats whole, part;
    rs_film *ref, *film;
    int calls, c, stops[8], n = 0;
    (void)state;
    ref = render_split(0, &whole, &calls);
    print_message("%d waves in %u rounds, %u pixels stopped\n", calls, whole.rounds, whole.stopped);
    assert_true(whole.rounds >= 3 && whole.stopped > 0 && calls > 20);
    stops[n++] = 1;
    stops[n++] = calls - 1;
    for (c = calls / 7; c < calls - 1 && n < 8; c += calls / 7)
        stops[n++] = c;
    for (c = 0; c < n; ++c) {
        int calls2;
        film = render_split(stops[c], &part, &calls2);
        assert_same_film(film, ref);
        assert_int_equal(part.stopped, whole.stopped);
        assert_int_equal(part.samples, whole.samples);
        rs_film_destroy(film);
    }
    rs_film_destroy(ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stopped_pixel_is_the_short_render),
        cmocka_unit_test(test_unmet_threshold_is_the_full_render),
        cmocka_unit_test(test_devices_and_chunks_change_nothing),
        cmocka_unit_test(test_bad_settings),
        cmocka_unit_test(test_stopped_and_continued_is_the_same),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
