/* tests/render_cpu_waves_test.c — the CPU device's render_paths (cpu/cpu_paths.c: each thread
 * runs waves of its own through every stage, traversal inline) against the stream engine on the
 * render thread, which shades while the device traces (scheduler/stream_engine.c).
 *
 * - Images: builtin:gpucheck in every sampling mode and sampler, on 1, 2 and 3 threads;
 *   builtin:many-lights with the light BVH; adaptive sampling (plans over some pixels); each of
 *   the CPU's traversals (binary, 4-wide, 8-wide where the CPU has AVX2) and the 8-wide tree's
 *   walks (rays alone, packets of eight, the measured choice): bit for bit.
 * - Calls that end inside waves and passes (plans cut at odd paths, run last first), and a call
 *   cancelled part way: what it says it did is a prefix of its paths, and the film holds exactly
 *   those (the stream engine's film of that prefix, byte for byte), every thread's wave included.
 * - The CPU device and the GPU fallback both running paths whole, the plan dealt between them. */
#include <setjmp.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "accel/bvh8.h"
#include "gpucheck_util.h"

static float *render_or_fail(const rt_args *a)
{
    float *img = rt_render(a, NULL);
    assert_non_null(img);
    return img;
}

/* `a` on the stream engine, then on the CPU device's own waves: one image. */
static void same_as_stream(const char *what, rt_args a)
{
    float *ref, *img;
    char label[160];
    ref = render_or_fail(&a);
    assert_true(gc_image_sane(ref, a.width, a.height));
    a.wavefront = 1; /* rs_engine_create_paths over the CPU device alone */
    img = render_or_fail(&a);
    snprintf(label, sizeof label, "%s: stream engine vs the CPU's waves (%d threads)", what,
             a.threads);
    assert_int_equal(gc_diff_pixels(label, ref, img, a.width, a.height), 0);
    free(ref);
    free(img);
}

static void test_gpucheck_every_mode(void **state)
{
    int c, t;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c)
        for (t = 1; t <= 3; ++t) {
            rt_args a = gc_args(&gc_cases[c]);
            a.threads = t;
            same_as_stream(gc_cases[c].name, a);
        }
}

static void test_many_lights_bvh(void **state)
{
    (void)state;
    same_as_stream("many-lights, light BVH", gc_many_lights_bvh_args());
}

static void test_adaptive(void **state)
{
    rs_adaptive_stats st;
    (void)state;
    same_as_stream("cornell, adaptive", gc_adaptive_args(&st));
    assert_true(st.rounds > 1); /* plans over some pixels were run */
}

static void test_every_traversal(void **state)
{
    static const uint32_t widths[] = {2, 4, 8};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof widths / sizeof widths[0]; ++k) {
        rt_args a = rt_defaults("rtiow-final", 48, 4);
        char what[64];
        if (widths[k] == 8 && !rs_bvh8_supported()) {
            print_message("no AVX2: the 8-wide traversal is not compared\n");
            continue;
        }
        a.threads = 2;
        a.sampler = RS_SAMPLER_SOBOL;
        a.bvh_width = widths[k];
        snprintf(what, sizeof what, "rtiow-final, %u-wide traversal", widths[k]);
        same_as_stream(what, a);
    }
}

/* The CPU's waves on the 8-wide tree with each walk (rays alone, packets of eight, the measured
 * choice): the stream engine's image each time, on scenes of triangles, parallelograms and
 * spheres (gpucheck's cases, motion blur among them) and on the CLI's tree. */
static void test_every_walk(void **state)
{
    static const rs_cpu_walk walks[] = {RS_CPU_WALK_SINGLE, RS_CPU_WALK_PACKETS, RS_CPU_WALK_AUTO};
    size_t k;
    int c;
    (void)state;
    if (!rs_bvh8_supported()) {
        print_message("no AVX2: the 8-wide walks are not compared\n");
        return;
    }
    for (k = 0; k < sizeof walks / sizeof walks[0]; ++k) {
        char what[96];
        rt_args a = rt_defaults("rtiow-final", 48, 4);
        a.threads = 2;
        a.sampler = RS_SAMPLER_SOBOL;
        a.cli_bvh = 1;
        a.cpu_walk = walks[k];
        snprintf(what, sizeof what, "rtiow-final, CLI tree, walk %s", rs_cpu_walk_name(walks[k]));
        same_as_stream(what, a);
        for (c = 0; c < GC_N_CASES; ++c) {
            a = gc_args(&gc_cases[c]);
            a.threads = 1 + (int)k % 2;
            a.bvh_width = 8;
            a.cpu_walk = walks[k];
            snprintf(what, sizeof what, "%s, walk %s", gc_cases[c].name,
                     rs_cpu_walk_name(walks[k]));
            same_as_stream(what, a);
        }
    }
}

/* The scene, its tree and a CPU device of `threads` threads, uploaded. */
typedef struct cpu_setup {
    rs_scene *scene;
    rs_bvh *bvh;
    rs_device *d;
} cpu_setup;

static cpu_setup setup_cpu(const char *name, int threads)
{
    cpu_setup s;
    rs_geom g;
    memset(&s, 0, sizeof s);
    assert_int_equal(rs_builtin_create(name, &s.scene), RS_OK);
    g = rs_scene_geom(s.scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &s.bvh), RS_OK);
    assert_int_equal(rs_cpu_device_create(threads, "cpu", &s.d), RS_OK);
    assert_int_equal(rs_device_upload(s.d, &g, s.bvh), RS_OK);
    return s;
}

static void release_cpu(cpu_setup *s)
{
    rs_device_destroy(s->d);
    rs_bvh_destroy(s->bvh);
    rs_scene_destroy(s->scene);
}

/* Three plans cut at odd paths (inside waves of RS_RENDER_HOST_WAVE and inside passes), the last
 * first: the one-plan stream image. */
static void test_split_runs(void **state)
{
    const uint32_t w = 96, h = 64, spp = 13;
    const uint64_t all = (uint64_t)w * h * spp, cut[4] = {0, 12345, 70001, all};
    rt_args a = rt_defaults("gpucheck", w, spp);
    cpu_setup s = setup_cpu("gpucheck", 2);
    rs_engine *e = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    float *ref, *img;
    int k;
    (void)state;
    a.height = h;
    a.threads = 2;
    a.sampler = RS_SAMPLER_SOBOL;
    ref = render_or_fail(&a);
    st = rt_settings(&a);
    st.threads = 2;
    assert_int_equal(rs_engine_create_paths(s.scene, &st, NULL, &s.d, 1, &e), RS_OK);
    assert_int_equal(rs_film_create(w, h, &film), RS_OK);
    for (k = 2; k >= 0; --k) {
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
    assert_int_equal(gc_diff_pixels("gpucheck in three plans: stream vs CPU waves", ref, img, w, h),
                     0);
    free(ref);
    free(img);
    rs_film_destroy(film);
    rs_engine_destroy(e);
    release_cpu(&s);
}

/* A job that says stop after `after` polls (each thread polls before each wave it takes). */
typedef struct stopper {
    atomic_int polls;
    int after;
} stopper;

static int stop_after(void *user)
{
    stopper *s = (stopper *)user;
    return atomic_fetch_add(&s->polls, 1) >= s->after;
}

/* render_paths cancelled part way, on 1 and 3 threads: *done is a prefix of the call's paths
 * (more than none, fewer than all), and the film is the stream engine's film of that prefix
 * byte for byte: no wave lost, none half on the film, none outside the prefix. */
static void test_cancel_leaves_a_prefix(void **state)
{
    const uint32_t w = 64, h = 48, spp = 64; /* 196608 paths: many waves */
    int t;
    (void)state;
    for (t = 1; t <= 3; t += 2) {
        rt_args a = rt_defaults("cornell", w, spp);
        cpu_setup s = setup_cpu("cornell", t);
        rs_render_consts it;
        rs_render_settings st;
        rs_paths_job job;
        rs_path_counts counts;
        rs_film *film = NULL, *ref = NULL;
        rs_engine *e = NULL;
        rs_work_plan plan;
        rs_render_stats rs;
        stopper stop;
        uint64_t done = 0, p0 = 1000, p1 = (uint64_t)w * h * spp;
        a.height = h;
        a.sampler = RS_SAMPLER_SOBOL;
        st = rt_settings(&a);
        st.threads = t;
        assert_int_equal(rs_render_constants(s.scene, &st, &it), RS_OK);
        assert_int_equal(rs_film_create(w, h, &film), RS_OK);
        atomic_init(&stop.polls, 0);
        stop.after = 4;
        memset(&job, 0, sizeof job);
        memset(&counts, 0, sizeof counts);
        job.it = &it;
        job.n_active = w * h;
        job.film = film;
        job.cancelled = stop_after;
        job.user = &stop;
        assert_int_equal(s.d->ops->render_paths(s.d, &job, p0, p1, &done, &counts), RS_OK);
        print_message("%d thread%s: cancelled after %llu of %llu paths\n", t, t > 1 ? "s" : "",
                      (unsigned long long)done, (unsigned long long)(p1 - p0));
        assert_true(done > 0 && done < p1 - p0);
        assert_int_equal(rs_film_samples(film), done);
        assert_true(counts.closest >= done);
        /* the stream engine's film of [p0, p0 + done) */
        assert_int_equal(rs_film_create(w, h, &ref), RS_OK);
        {
            rs_sched *sched = NULL;
            rs_device *trace = NULL;
            rs_geom g = rs_scene_geom(s.scene);
            assert_int_equal(rs_cpu_device_create(1, "cpu", &trace), RS_OK);
            assert_int_equal(rs_device_upload(trace, &g, s.bvh), RS_OK);
            assert_int_equal(rs_sched_create(&trace, 1, NULL, &sched), RS_OK);
            assert_int_equal(rs_engine_create(s.scene, &st, sched, NULL, &e), RS_OK);
            memset(&plan, 0, sizeof plan);
            assert_true(rs_path_ranges_add(&plan.todo, p0, p0 + done));
            assert_int_equal(rs_engine_run(e, &plan, NULL, ref, &rs), RS_OK);
            rs_work_plan_free(&plan);
            rs_engine_destroy(e);
            rs_sched_destroy(sched);
            rs_device_destroy(trace);
        }
        assert_memory_equal(film->count, ref->count, (size_t)w * h * sizeof *ref->count);
        assert_memory_equal(film->sum, ref->sum, (size_t)w * h * 3 * sizeof *ref->sum);
        rs_film_destroy(film);
        rs_film_destroy(ref);
        release_cpu(&s);
    }
}

/* The CPU device and the GPU fallback, both running paths whole on threads of their own, the
 * plan dealt between them by their rates: the stream engine's image. */
static void test_beside_the_fallback(void **state)
{
    const uint32_t w = 80, h = 60, spp = 16;
    rt_args a = rt_defaults("gpucheck", w, spp);
    cpu_setup s = setup_cpu("gpucheck", 1);
    rs_device *devs[2], *fb = NULL;
    rs_engine *e = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats rs;
    rs_work_plan plan;
    rs_geom g = rs_scene_geom(s.scene);
    float *ref, *img;
    (void)state;
    a.height = h;
    a.threads = 2;
    a.sampler = RS_SAMPLER_SOBOL;
    ref = render_or_fail(&a);
    assert_int_equal(rs_gpu_fallback_create(1, 0, NULL, &fb), RS_OK);
    assert_int_equal(rs_device_upload(fb, &g, s.bvh), RS_OK);
    devs[0] = s.d;
    devs[1] = fb;
    st = rt_settings(&a);
    st.threads = 2;
    assert_int_equal(rs_engine_create_paths(s.scene, &st, NULL, devs, 2, &e), RS_OK);
    assert_int_equal(rs_film_create(w, h, &film), RS_OK);
    memset(&plan, 0, sizeof plan);
    assert_true(rs_path_ranges_add(&plan.todo, 0, (uint64_t)w * h * spp));
    assert_int_equal(rs_engine_run(e, &plan, NULL, film, &rs), RS_OK);
    assert_int_equal(rs.paths_done, (uint64_t)w * h * spp);
    img = (float *)malloc((size_t)w * h * 3 * sizeof *img);
    assert_non_null(img);
    rs_film_resolve(film, img);
    assert_int_equal(gc_diff_pixels("gpucheck: stream vs CPU waves + fallback", ref, img, w, h), 0);
    print_message("cpu: %llu rays in %llu calls, gpu-fallback: %llu rays in %llu calls\n",
                  (unsigned long long)s.d->stats.rays, (unsigned long long)s.d->stats.chunks,
                  (unsigned long long)fb->stats.rays, (unsigned long long)fb->stats.chunks);
    assert_true(s.d->stats.rays > 0 && fb->stats.rays > 0); /* both took a share */
    free(ref);
    free(img);
    rs_work_plan_free(&plan);
    rs_film_destroy(film);
    rs_engine_destroy(e);
    rs_device_destroy(fb);
    release_cpu(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpucheck_every_mode),
        cmocka_unit_test(test_many_lights_bvh),
        cmocka_unit_test(test_adaptive),
        cmocka_unit_test(test_every_traversal),
        cmocka_unit_test(test_every_walk),
        cmocka_unit_test(test_split_runs),
        cmocka_unit_test(test_cancel_leaves_a_prefix),
        cmocka_unit_test(test_beside_the_fallback),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
