/* tests/render_wavefront_test.c — the GPU wavefront (gpu/wavefront.h: the CUDA device's
 * render_paths kernels, run by the host fallback as loops) against the CPU stream engine.
 *
 * - The device film's exact sums: rs_wf_film_add from two threads in another order, merged into
 *   an empty film, is rs_film_add's film byte for byte, with samples chosen to wrap the 64-bit
 *   words both ways (the 128-bit carries), past 2^62 film units (the other rounding branch),
 *   negative (signed filters), non-finite and beyond RS_FILM_MAX_SAMPLE, and the 192-bit
 *   squared-luminance sums.
 * - Images: builtin:gpucheck in every sampling mode and sampler, builtin:many-lights with the
 *   light BVH, adaptive sampling (plans over some pixels), a render split into runs that start
 *   and end inside passes, and the living room (../shared/models, skipped with a message when
 *   absent): the fallback's wavefront gives the CPU stream engine's image bit for bit.
 * tests/gpu_trace_test.c holds the same comparisons with a real CUDA device. */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "core/image_io.h"
#include "gpu/wavefront.h"
#include "gpucheck_util.h"
#ifdef RS_TEST_SCENE_FILES
#include "scenes/scene_json.h"
#endif

/* ---- the film ---------------------------------------------------------------------------- */

static uint64_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return *s >> 11;
}

static float uniform(uint64_t *s) { return (float)((double)lcg(s) * 0x1p-53); }

#define FILM_W 4
#define FILM_H 3
#define N_SAMPLES 20000

typedef struct film_job {
    const rs_wf_film *f;
    const uint32_t *pixel;
    const rs_vec3 *c;
    int from, step;
} film_job;

static void *add_some(void *arg)
{
    const film_job *j = (const film_job *)arg;
    int i;
    for (i = N_SAMPLES - 1 - j->from; i >= 0; i -= j->step) /* backwards: another order */
        rs_wf_film_add(j->f, j->pixel[i], j->c[i]);
    return NULL;
}

static void test_film_exact(void **state)
{
    static uint32_t pixel[N_SAMPLES];
    static rs_vec3 c[N_SAMPLES];
    const size_t npix = FILM_W * FILM_H;
    rs_film *ref = NULL, *got = NULL, view;
    rs_wf_film wf;
    rs_wf_u64 nonfinite = 0;
    uint64_t seed = 7;
    pthread_t th[2];
    film_job jobs[2];
    int i, k;
    (void)state;
    for (i = 0; i < N_SAMPLES; ++i) {
        float u = uniform(&seed), sign = uniform(&seed) < 0.4f ? -1.0f : 1.0f;
        pixel[i] = (uint32_t)(lcg(&seed) % npix);
        if (u < 0.3f) /* past 2^62 units (4.19e6): 2^62..2^88 units, wraps the low word */
            c[i] = rs_v3(sign * 4.2e6f * (1.0f + 1e7f * uniform(&seed)), sign * 3.9e6f,
                         -sign * 5e6f * uniform(&seed));
        else if (u < 0.9f) /* ordinary light, with signed filter weights */
            c[i] = rs_v3(sign * uniform(&seed), uniform(&seed) * 3.0f, sign * 1e-9f * uniform(&seed));
        else if (u < 0.94f)
            c[i] = rs_v3(NAN, 1.0f, 1.0f);
        else if (u < 0.97f)
            c[i] = rs_v3(1.0f, INFINITY, 1.0f);
        else /* finite but past RS_FILM_MAX_SAMPLE: counted as non-finite */
            c[i] = rs_v3(1.0f, 1.0f, sign * 3e14f);
    }
    assert_int_equal(rs_film_create(FILM_W, FILM_H, &ref), RS_OK);
    assert_int_equal(rs_film_track_variance(ref), RS_OK);
    for (i = 0; i < N_SAMPLES; ++i)
        rs_film_add(ref, pixel[i], c[i]);
    wf.sum = (rs_wf_u64 *)calloc(6 * npix, sizeof *wf.sum);
    wf.count = (unsigned int *)calloc(npix, sizeof *wf.count);
    wf.sum_l2 = (rs_wf_u64 *)calloc(3 * npix, sizeof *wf.sum_l2);
    wf.nonfinite = &nonfinite;
    assert_non_null(wf.sum);
    assert_non_null(wf.count);
    assert_non_null(wf.sum_l2);
    for (k = 0; k < 2; ++k) {
        jobs[k].f = &wf;
        jobs[k].pixel = pixel;
        jobs[k].c = c;
        jobs[k].from = k;
        jobs[k].step = 2;
        assert_int_equal(pthread_create(&th[k], NULL, add_some, &jobs[k]), 0);
    }
    for (k = 0; k < 2; ++k)
        pthread_join(th[k], NULL);
    assert_int_equal(rs_film_create(FILM_W, FILM_H, &got), RS_OK);
    assert_int_equal(rs_film_track_variance(got), RS_OK);
    view = rs_wf_film_view(&wf, FILM_W, FILM_H);
    assert_int_equal(rs_film_merge(got, &view), RS_OK);
    assert_true(ref->nonfinite > N_SAMPLES / 20); /* the cases above were all reached */
    assert_int_equal(got->nonfinite, ref->nonfinite);
    assert_memory_equal(got->count, ref->count, npix * sizeof *ref->count);
    assert_memory_equal(got->sum, ref->sum, 3 * npix * sizeof *ref->sum);
    assert_memory_equal(got->sum_l2, ref->sum_l2, npix * sizeof *ref->sum_l2);
    /* the large samples did carry: some channel's sum needs more than 64 bits */
    for (i = 0, k = 0; i < (int)(3 * npix); ++i)
        k |= ref->sum[i] > (rs_film_sum)INT64_MAX || ref->sum[i] < (rs_film_sum)INT64_MIN;
    assert_true(k);
    rs_film_destroy(ref);
    rs_film_destroy(got);
    free(wf.sum);
    free(wf.count);
    free(wf.sum_l2);
}

/* ---- images ------------------------------------------------------------------------------ */

static float *render_or_fail(const rt_args *a)
{
    float *img = rt_render(a, NULL);
    assert_non_null(img);
    return img;
}

/* `a` on the CPU stream engine, then on the fallback's wavefront alone, then on both at once
 * (the CPU device's stream engine on the render thread, the wavefront on its own, the plan dealt
 * between them by their rates): one image. */
static void same_as_cpu(const char *what, rt_args a)
{
    float *ref, *img;
    char label[160];
    ref = render_or_fail(&a);
    assert_true(gc_image_sane(ref, a.width, a.height));
    a.fallback_only = 1;
    a.wavefront = 1;
    img = render_or_fail(&a);
    snprintf(label, sizeof label, "%s: cpu stream vs wavefront (gpu-fallback)", what);
    assert_int_equal(gc_diff_pixels(label, ref, img, a.width, a.height), 0);
    free(img);
    a.fallback_only = 0;
    a.with_fallback = 1;
    img = render_or_fail(&a);
    snprintf(label, sizeof label, "%s: cpu stream vs cpu + wavefront", what);
    assert_int_equal(gc_diff_pixels(label, ref, img, a.width, a.height), 0);
    free(ref);
    free(img);
}

static void test_gpucheck_every_mode(void **state)
{
    int c;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c)
        same_as_cpu(gc_cases[c].name, gc_args(&gc_cases[c]));
}

static void test_many_lights_bvh(void **state)
{
    (void)state;
    same_as_cpu("many-lights, light BVH", gc_many_lights_bvh_args());
}

static void test_adaptive(void **state)
{
    rs_adaptive_stats st;
    (void)state;
    same_as_cpu("cornell, adaptive", gc_adaptive_args(&st));
    assert_true(st.rounds > 1); /* plans over some pixels were run */
}

/* A wave and a render_paths call both end inside passes: the fallback's waves are
 * RS_WF_FALLBACK_WAVE (65536) paths, here a render of 96 x 64 x 13 = 79872 paths (one full wave
 * and a partial one, neither on a pass boundary), run as three plans cut at odd paths. */
static void test_split_runs(void **state)
{
    const uint32_t w = 96, h = 64, spp = 13;
    const uint64_t all = (uint64_t)w * h * spp, cut[4] = {0, 12345, 70001, all};
    rt_args a = rt_defaults("gpucheck", w, spp);
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_device *d = NULL;
    rs_engine *e = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    float *ref, *img;
    rs_geom g;
    int k;
    (void)state;
    a.height = h;
    a.threads = 2;
    a.sampler = RS_SAMPLER_SOBOL;
    ref = render_or_fail(&a);
    assert_int_equal(rs_builtin_create("gpucheck", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    assert_int_equal(rs_gpu_fallback_create(2, 0, NULL, &d), RS_OK);
    assert_int_equal(rs_device_upload(d, &g, bvh), RS_OK);
    st = rt_settings(&a);
    st.threads = 2;
    assert_int_equal(rs_engine_create_paths(scene, &st, NULL, &d, 1, &e), RS_OK);
    assert_int_equal(rs_film_create(w, h, &film), RS_OK);
    for (k = 2; k >= 0; --k) { /* the last plan first: the film's sums do not mind */
        rs_work_plan plan;
        rs_render_stats rs;
        memset(&plan, 0, sizeof plan);
        assert_true(rs_path_ranges_add(&plan.todo, cut[k], cut[k + 1]));
        assert_int_equal(rs_engine_run(e, &plan, NULL, film, &rs), RS_OK);
        assert_int_equal(rs.paths_done, cut[k + 1] - cut[k]);
        rs_work_plan_free(&plan);
    }
    img = (float *)malloc((size_t)w * h * 3 * sizeof *img);
    assert_non_null(img);
    rs_film_resolve(film, img);
    assert_int_equal(gc_diff_pixels("gpucheck in three plans: cpu vs wavefront", ref, img, w, h), 0);
    free(ref);
    free(img);
    rs_film_destroy(film);
    rs_engine_destroy(e);
    rs_device_destroy(d);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
}

/* The time limit over a film with gaps (a checkpoint of devices that finished ranges out of
 * order): the film holds paths [1000, 3000) of a 40x30 render (1200 paths a pass), the plan is
 * the rest, [0, 1000) and [3000, 4800), and the limit has passed before the first range is
 * taken.  The run must finish every pass that holds a path of the film: [0, 3600), 3 samples in
 * every pixel, the 3-spp render's film exactly (not the first pass alone, which would leave
 * pixels with 2 and 3 samples). */
static void test_time_cut_over_gaps(void **state)
{
    const uint32_t w = 40, h = 30;
    rt_args a = rt_defaults("cornell", w, 4);
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_device *d = NULL;
    rs_engine *e = NULL;
    rs_film *film = NULL, *ref = NULL;
    rs_render_settings st;
    rs_render_stats rs;
    rs_work_plan plan;
    rs_geom g;
    int pass;
    (void)state;
    a.height = h;
    a.sampler = RS_SAMPLER_SOBOL;
    assert_int_equal(rs_builtin_create("cornell", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    assert_int_equal(rs_gpu_fallback_create(2, 0, NULL, &d), RS_OK);
    assert_int_equal(rs_device_upload(d, &g, bvh), RS_OK);
    assert_int_equal(rs_film_create(w, h, &film), RS_OK);
    assert_int_equal(rs_film_create(w, h, &ref), RS_OK);
    st = rt_settings(&a);
    st.threads = 2;
    for (pass = 0; pass < 3; ++pass) {
        memset(&plan, 0, sizeof plan);
        if (pass == 0) { /* the reference: 3 whole samples */
            assert_true(rs_path_ranges_add(&plan.todo, 0, 3600));
        } else if (pass == 1) { /* what the "checkpoint" holds */
            assert_true(rs_path_ranges_add(&plan.todo, 1000, 3000));
        } else { /* the rest, with the time limit already passed */
            assert_true(rs_path_ranges_add(&plan.todo, 0, 1000));
            assert_true(rs_path_ranges_add(&plan.todo, 3000, 4800));
            plan.time_limit_s = 1e-9; /* the plan's budget (scheduler/plan.h) */
        }
        assert_int_equal(rs_engine_create_paths(scene, &st, NULL, &d, 1, &e), RS_OK);
        assert_int_equal(rs_engine_run(e, &plan, NULL, pass == 0 ? ref : film, &rs), RS_OK);
        if (pass == 2) {
            assert_true(rs.time_limited);
            assert_int_equal(rs.paths_done, 1000 + 600);
        }
        rs_engine_destroy(e);
        rs_work_plan_free(&plan);
    }
    assert_int_equal(rs_film_min_count(film), 3);
    assert_memory_equal(film->count, ref->count, (size_t)w * h * sizeof *ref->count);
    assert_memory_equal(film->sum, ref->sum, (size_t)w * h * 3 * sizeof *ref->sum);
    rs_film_destroy(film);
    rs_film_destroy(ref);
    rs_device_destroy(d);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
}

/* The living room (143k triangles, textures, glass), small: ../shared/models. */
static void test_living_room(void **state)
{
#ifdef RS_TEST_SCENE_FILES
    const char *path = RS_SOURCE_DIR "/../shared/models/living-room/living-room.raystream.json";
    rs_scene *scene = NULL;
    rt_args a = rt_defaults("living-room", 48, 2);
    float *ref, *img;
    FILE *f = fopen(path, "r");
    (void)state;
    if (!f) {
        print_message("skipped: %s is absent (the shared models)\n", path);
        skip();
    }
    fclose(f);
    if (rs_scene_load_json(path, &scene) != RS_OK &&
        strncmp(rs_image_library_version(), "none", 4) == 0) {
        print_message("skipped: this build has no OpenImageIO for the living room's PNG "
                      "textures: %s\n", rs_error_message());
        skip();
    }
    assert_non_null(scene);
    a.height = 27;
    a.threads = 2;
    a.max_depth = 8;
    a.sampler = RS_SAMPLER_SOBOL;
    ref = rt_render_scene(scene, &a, NULL);
    assert_non_null(ref);
    a.fallback_only = 1;
    a.wavefront = 1;
    img = rt_render_scene(scene, &a, NULL);
    assert_non_null(img);
    assert_true(gc_image_sane(ref, a.width, a.height));
    assert_int_equal(gc_diff_pixels("living room: cpu stream vs wavefront", ref, img, a.width,
                                    a.height),
                     0);
    free(ref);
    free(img);
    rs_scene_destroy(scene);
#else
    (void)state;
    print_message("skipped: this build reads no scene files (no cJSON)\n");
    skip();
#endif
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_film_exact),        cmocka_unit_test(test_gpucheck_every_mode),
        cmocka_unit_test(test_many_lights_bvh),   cmocka_unit_test(test_adaptive),
        cmocka_unit_test(test_split_runs),        cmocka_unit_test(test_time_cut_over_gaps),
        cmocka_unit_test(test_living_room),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
