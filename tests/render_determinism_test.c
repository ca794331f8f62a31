/* tests/render_determinism_test.c — the image is a function of the seed and the settings only:
 * bit-identical for any thread count, chunk size, wave size and device set (DESIGN rule 1). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "render_util.h"

#define SIZE 40
#define SPP  8
#define NF   (SIZE * SIZE * 3)

static float *g_ref;

static int setup(void **state)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    (void)state;
    g_ref = rt_render(&a, NULL);
    return g_ref ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    free(g_ref);
    return 0;
}

static void expect_identical(const rt_args *a)
{
    float *img = rt_render(a, NULL);
    assert_non_null(img);
    assert_memory_equal(img, g_ref, NF * sizeof(float));
    free(img);
}

static void test_threads(void **state)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    (void)state;
    a.threads = 2;
    expect_identical(&a);
}

static void test_chunk_sizes(void **state)
{
    static const uint32_t sizes[] = {1, 7, 4096, 1u << 24};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
        rt_args a = rt_defaults("cornell", SIZE, SPP);
        a.chunk_size = sizes[i];
        a.threads = 2;
        expect_identical(&a);
    }
}

static void test_wave_sizes(void **state)
{
    static const uint32_t sizes[] = {7, 333, 1000, SIZE * SIZE, SIZE * SIZE * SPP + 5};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof sizes / sizeof sizes[0]; ++i) {
        rt_args a = rt_defaults("cornell", SIZE, SPP);
        a.wave_paths = sizes[i];
        expect_identical(&a);
    }
}

static void test_two_devices(void **state)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    (void)state;
    a.with_fallback = 1;
    a.chunk_size = 97; /* many chunks, so both devices take some */
    expect_identical(&a);
}

/* Waves in flight (the pipelined loop, films added in wave order) at several wave sizes. */
static void test_waves_in_flight(void **state)
{
    static const uint32_t waves[] = {1, 2, 3, 4};
    static const uint32_t sizes[] = {0, 7, 1000};
    size_t i, j;
    (void)state;
    for (i = 0; i < sizeof waves / sizeof waves[0]; ++i)
        for (j = 0; j < sizeof sizes / sizeof sizes[0]; ++j) {
            rt_args a = rt_defaults("cornell", SIZE, SPP);
            a.waves = waves[i];
            a.wave_paths = sizes[j];
            a.threads = 2;
            a.shared_cores = 1;
            expect_identical(&a);
        }
}

/* --devices cpu, gpu (the fallback, with its staging buffers) and cpu,gpu: the same image, at
 * adaptive and fixed chunk sizes, one and two waves in flight, cores shared. */
static void test_device_sets(void **state)
{
    static const uint32_t chunks[] = {0, 61};
    int set;
    size_t c;
    (void)state;
    for (set = 0; set < 3; ++set)
        for (c = 0; c < sizeof chunks / sizeof chunks[0]; ++c) {
            rt_args a = rt_defaults("cornell", SIZE, SPP);
            a.threads = 2;
            a.fallback_only = set == 1;
            a.with_fallback = set == 2;
            a.chunk_size = chunks[c];
            a.waves = 1 + (uint32_t)c;
            a.shared_cores = 1;
            expect_identical(&a);
        }
}

/* A device that fails mid-render while three waves are in flight: its chunk is retried on the
 * other, every job of every wave completes, and the image is unchanged. */
static void test_failure_with_waves_in_flight(void **state)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    (void)state;
    a.threads = 2;
    a.with_fallback = 1;
    a.fail_after = 5;
    a.waves = 3;
    a.chunk_size = 97;
    a.shared_cores = 1;
    expect_identical(&a);
}

/* The thesis's three OpenMP strategies, in the CPU device and the shading, and the per-pixel
 * megakernel under each (rs_path_step: the stages' own per-path code, each pixel's samples
 * added in order), on the CPU and as the GPU megakernel's passes on host threads (its fallback:
 * one sample of every pixel per pass, the binary BVH); and no BVH at all (one leaf: brute force)
 * under both integrators. */
static void test_strategies_and_megakernel(void **state)
{
    int s, mk;
    (void)state;
    for (s = 0; s < 3; ++s)
        for (mk = 0; mk < 3; ++mk) {
            rt_args a = rt_defaults("cornell", SIZE, SPP);
            a.threads = 2;
            a.strategy = (rs_par_strategy)s;
            a.megakernel = mk > 0;
            a.fallback_only = mk == 2;
            a.chunk_size = 2000; /* chunks big enough for a team: the strategy splits them */
            expect_identical(&a);
        }
    for (mk = 0; mk < 2; ++mk) {
        rt_args a = rt_defaults("cornell", SIZE, SPP);
        a.threads = 2;
        a.no_bvh = 1;
        a.megakernel = mk;
        expect_identical(&a);
    }
}

/* Every integrator on every device set, with every sampler, on scenes with every kind of scene
 * array the devices copy: textures and images (materials), moving spheres (bouncing-spheres), glass
 * (cornell-glass). The fallback traces and shades in copies of its own (scheduler/device_copy.c),
 * so an array copied short or wrong changes its image (one left out of the copy is
 * scenes_mirror_test's). */
static void test_integrators_and_device_sets(void **state)
{
    static const char *const scenes[] = {"materials", "bouncing-spheres", "cornell-glass"};
    size_t k;
    int cfg;
    (void)state;
    for (k = 0; k < 3 * sizeof scenes / sizeof scenes[0]; ++k) {
        rt_args ref = rt_defaults(scenes[k / 3], 24, 4);
        float *want;
        ref.threads = 2;
        ref.sampler = (rs_sampler)(k % 3); /* every sampler: independent, sobol, zsobol */
        want = rt_render(&ref, NULL);
        assert_non_null(want);
        for (cfg = 0; cfg < 4; ++cfg) {
            rt_args a = ref;
            float *img;
            a.megakernel = cfg >= 2;    /* stream, stream, megakernel, megakernel */
            a.fallback_only = cfg & 1;  /* on the CPU device / the GPU's fallback */
            a.with_fallback = cfg == 0; /* the stream on cpu + fallback */
            img = rt_render(&a, NULL);
            assert_non_null(img);
            if (memcmp(img, want, 24 * 24 * 3 * sizeof(float)) != 0)
                fail_msg("%s, %s sampler: configuration %d differs from the cpu stream render",
                         scenes[k / 3], rs_sampler_name(ref.sampler), cfg);
            free(img);
        }
        free(want);
    }
}

/* The zsobol sampler's index needs the render's whole spp and size (its blocks per pixel, its
 * Morton square): a 40x27 image (not a power of two, not square) at 6 spp (rounded up to 8, an
 * odd log2) must not depend on threads, chunks, waves, devices or integrator either, although
 * the megakernel's fallback passes render one sample of every pixel at a time. */
static void test_zsobol_settings(void **state)
{
    rt_args ref = rt_defaults("cornell", 40, 6);
    float *want;
    int cfg;
    (void)state;
    ref.height = 27;
    ref.sampler = RS_SAMPLER_ZSOBOL;
    want = rt_render(&ref, NULL);
    assert_non_null(want);
    for (cfg = 0; cfg < 6; ++cfg) {
        rt_args a = ref;
        float *img;
        a.threads = 2;
        a.chunk_size = cfg == 1 ? 7 : cfg == 2 ? 61 : 0;
        a.wave_paths = cfg == 2 ? 333 : 0;
        a.waves = cfg == 3 ? 3 : 0;
        a.with_fallback = cfg == 3;
        a.fallback_only = cfg == 5;
        a.megakernel = cfg >= 4;
        a.shared_cores = cfg == 3;
        img = rt_render(&a, NULL);
        assert_non_null(img);
        if (memcmp(img, want, 40 * 27 * 3 * sizeof(float)) != 0)
            fail_msg("zsobol: configuration %d differs from the one-thread cpu render", cfg);
        free(img);
    }
    free(want);
}

/* A CPU device that offers host memory (scheduler/device.h host_alloc) as a GPU does: from
 * rs_alloc_aligned, counted, or failing every time (g_host_fail).  Its trace counts the chunks
 * whose batch says it came from that memory. */
static rs_device_ops g_host_ops;
static const rs_device_ops *g_inner_ops;
static int g_host_fail, g_host_blocks, g_host_allocs, g_pinned_chunks;

static void *host_alloc_counted(rs_device *d, size_t bytes)
{
    (void)d;
    if (g_host_fail)
        return NULL;
    g_host_blocks++;
    g_host_allocs++;
    return rs_alloc_aligned(bytes, 1);
}

static void host_free_counted(rs_device *d, void *p)
{
    (void)d;
    g_host_blocks--;
    rs_free(p);
}

static rs_status trace_counting_pinned(rs_device *d, const rs_trace_batch *b, uint32_t lo,
                                       uint32_t hi)
{
    g_pinned_chunks += b->pinned != 0;
    return g_inner_ops->trace(d, b, lo, hi);
}

/* The render on one engine as plans of samples [0, cut[0]), [cut[0], cut[1]), ...,
 * [cut[n_cuts - 1], SPP); n_cuts 0: one plan. */
static float *render_with_host_memory_in(const uint32_t *cut, int n_cuts)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_device *dev = NULL;
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rs_geom g;
    float *rgb = (float *)malloc(NF * sizeof *rgb);
    assert_int_equal(rs_builtin_create("cornell", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    assert_int_equal(rs_cpu_device_create(1, "cpu", &dev), RS_OK);
    g_inner_ops = dev->ops;
    g_host_ops = *dev->ops;
    g_host_ops.host_alloc = host_alloc_counted;
    g_host_ops.host_free = host_free_counted;
    g_host_ops.trace = trace_counting_pinned;
    dev->ops = &g_host_ops;
    assert_int_equal(rs_device_upload(dev, &g, bvh), RS_OK);
    assert_int_equal(rs_sched_create(&dev, 1, NULL, &sched), RS_OK);
    assert_int_equal(rs_film_create(SIZE, SIZE, &film), RS_OK);
    a.wave_paths = 3000; /* several waves through the buffers of each slot */
    st = rt_settings(&a);
    {
        rs_engine *e = NULL;
        int k;
        assert_int_equal(rs_engine_create(scene, &st, sched, NULL, &e), RS_OK);
        for (k = 0; k <= n_cuts; ++k) {
            rs_work_plan plan;
            assert_true(rs_work_plan_samples(&plan, (uint64_t)SIZE * SIZE, k ? cut[k - 1] : 0,
                                             k < n_cuts ? cut[k] : SPP));
            assert_int_equal(rs_engine_run(e, &plan, NULL, film, &stats), RS_OK);
            rs_work_plan_free(&plan);
        }
        rs_engine_destroy(e);
    }
    rs_film_resolve(film, rgb);
    rs_sched_destroy(sched);
    rs_device_destroy(dev);
    rs_film_destroy(film);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    return rgb;
}

static float *render_with_host_memory(void) { return render_with_host_memory_in(NULL, 0); }

/* Wave buffers from a device's host_alloc: every chunk says so (a GPU then copies it by DMA
 * without staging), every block is given back, and the image is unchanged; where host_alloc
 * fails the render falls back to plain memory, unpinned, with the same image. */
static void test_wave_buffers_in_device_memory(void **state)
{
    float *img;
    (void)state;
    g_host_fail = 0;
    g_host_blocks = g_pinned_chunks = 0;
    img = render_with_host_memory();
    assert_memory_equal(img, g_ref, NF * sizeof(float));
    assert_true(g_pinned_chunks > 0);
    assert_int_equal(g_host_blocks, 0);
    free(img);
    g_host_fail = 1;
    g_pinned_chunks = 0;
    img = render_with_host_memory();
    assert_memory_equal(img, g_ref, NF * sizeof(float));
    assert_int_equal(g_pinned_chunks, 0);
    free(img);
}

/* One engine, many plans: the wave buffers are allocated once per render (with a GPU each is
 * page-locked memory, costly to get), however many plans run on it, and the image is the one
 * plan's bit for bit. */
static void test_plans_share_the_buffers(void **state)
{
    static const uint32_t cuts[] = {1, 2, 5, 6};
    float *img;
    int one;
    (void)state;
    g_host_fail = 0;
    g_host_blocks = g_host_allocs = 0;
    img = render_with_host_memory_in(NULL, 0);
    one = g_host_allocs;
    assert_true(one > 0);
    free(img);
    g_host_allocs = 0;
    img = render_with_host_memory_in(cuts, 4); /* five plans */
    assert_memory_equal(img, g_ref, NF * sizeof(float));
    assert_int_equal(g_host_allocs, one);
    assert_int_equal(g_host_blocks, 0);
    free(img);
}

/* A megakernel device that counts its scene copies (upload_scene) and uploads. */
static rs_device_ops g_count_ops;
static const rs_device_ops *g_count_inner;
static int g_scene_uploads, g_uploads;

static rs_status upload_scene_counted(rs_device *d, const rs_scene *s, const rs_render_consts *it)
{
    g_scene_uploads++;
    return g_count_inner->upload_scene(d, s, it);
}

static rs_status upload_counted(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    g_uploads++;
    return g_count_inner->upload(d, g, bvh);
}

/* The megakernel on the GPU fallback (which copies the scene at upload_scene as the CUDA device
 * copies it to the GPU): one upload and one scene copy per render, whatever the plans, and the
 * image of the stream engine's one plan. */
static void test_megakernel_copies_the_scene_once(void **state)
{
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_device *dev = NULL;
    rs_film *film = NULL;
    rs_engine *e = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    rs_geom g;
    float *rgb = (float *)malloc(NF * sizeof *rgb);
    uint32_t s;
    (void)state;
    assert_int_equal(rs_builtin_create("cornell", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    assert_int_equal(rs_gpu_fallback_create(1, 0, NULL, &dev), RS_OK);
    g_count_inner = dev->ops;
    g_count_ops = *dev->ops;
    g_count_ops.upload_scene = upload_scene_counted;
    g_count_ops.upload = upload_counted;
    dev->ops = &g_count_ops;
    g_scene_uploads = g_uploads = 0;
    assert_int_equal(rs_device_upload(dev, &g, bvh), RS_OK);
    assert_int_equal(rs_film_create(SIZE, SIZE, &film), RS_OK);
    st = rt_settings(&a);
    assert_int_equal(rs_engine_create(scene, &st, NULL, dev, &e), RS_OK);
    for (s = 0; s < SPP; s += 3) { /* plans of 3, 3 and 2 samples, as an MPI rank's passes */
        rs_work_plan plan;
        assert_true(
            rs_work_plan_samples(&plan, (uint64_t)SIZE * SIZE, s, s + 3 < SPP ? s + 3 : SPP));
        assert_int_equal(rs_engine_run(e, &plan, NULL, film, &stats), RS_OK);
        rs_work_plan_free(&plan);
    }
    assert_int_equal(g_uploads, 1);
    assert_int_equal(g_scene_uploads, 1);
    rs_film_resolve(film, rgb);
    assert_memory_equal(rgb, g_ref, NF * sizeof(float));
    rs_engine_destroy(e);
    rs_device_destroy(dev);
    rs_film_destroy(film);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    free(rgb);
}

/* ---- film pieces: a film rendered in pieces and merged in any order is the one film ------ */

/* samples [s0, s0 + n) of every pixel of a `spp`-sample render, onto a fresh film, by the stream
 * engine (waves of `wave` paths) or the megakernel */
static rs_film *render_piece(rt_rig *g, uint32_t s0, uint32_t n, uint32_t spp, uint32_t wave,
                             int megakernel, rs_sampler sampler)
{
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rs_engine *e = NULL;
    rs_work_plan plan;
    assert_int_equal(rs_film_create(SIZE, SIZE, &film), RS_OK);
    memset(&st, 0, sizeof st);
    st.width = st.height = SIZE;
    st.spp = spp;
    st.max_depth = 8;
    st.seed = 7;
    st.sampler = sampler;
    st.threads = 1;
    st.wave_paths = wave;
    assert_int_equal(rs_engine_create(g->scene, &st, megakernel ? NULL : g->sched,
                                      megakernel ? g->dev : NULL, &e),
                     RS_OK);
    assert_true(rs_work_plan_samples(&plan, (uint64_t)SIZE * SIZE, s0, s0 + n));
    assert_int_equal(rs_engine_run(e, &plan, NULL, film, &stats), RS_OK);
    rs_work_plan_free(&plan);
    rs_engine_destroy(e);
    return film;
}

static void assert_films_equal(const rs_film *a, const rs_film *b)
{
    size_t n = (size_t)SIZE * SIZE;
    assert_memory_equal(a->sum, b->sum, 3 * n * sizeof *a->sum);
    assert_memory_equal(a->count, b->count, n * sizeof *a->count);
    assert_int_equal(a->nonfinite, b->nonfinite);
}

/* The split over passes that an MPI job makes, on one process: 11 samples rendered as one film
 * and as pieces [7, 11), [0, 3), [3, 7) (other wave sizes, the megakernel for one of them),
 * merged in that order and in reverse, give the one film's sums and counts bit for bit, on both
 * samplers.  Summing the pieces' resolved images in floating point instead does not (checked
 * below), so the test sees a film that is not exact. */
static void test_film_pieces_merge_exactly(void **state)
{
    static const rs_sampler samplers[] = {RS_SAMPLER_SOBOL, RS_SAMPLER_ZSOBOL};
    size_t k;
    rt_rig g;
    (void)state;
    assert_true(rt_rig_up(&g, "cornell"));
    for (k = 0; k < sizeof samplers / sizeof samplers[0]; ++k) {
        rs_film *one = render_piece(&g, 0, 11, 11, 0, 0, samplers[k]);
        rs_film *p[3], *fwd = NULL, *rev = NULL;
        int i;
        p[0] = render_piece(&g, 7, 4, 11, 999, 0, samplers[k]);
        p[1] = render_piece(&g, 0, 3, 11, 0, 1, samplers[k]);
        p[2] = render_piece(&g, 3, 4, 11, 4096, 0, samplers[k]);
        assert_int_equal(rs_film_create(SIZE, SIZE, &fwd), RS_OK);
        assert_int_equal(rs_film_create(SIZE, SIZE, &rev), RS_OK);
        for (i = 0; i < 3; ++i)
            assert_int_equal(rs_film_merge(fwd, p[i]), RS_OK);
        for (i = 2; i >= 0; --i)
            assert_int_equal(rs_film_merge(rev, p[i]), RS_OK);
        assert_films_equal(one, fwd);
        assert_films_equal(one, rev);
        /* the pieces are not the same samples: any one of them differs from the whole */
        assert_true(memcmp(p[0]->sum, one->sum, 3 * SIZE * SIZE * sizeof *one->sum) != 0);
        /* the piece's samples are its own: clearing and re-rendering gives it again */
        rs_film_clear(fwd);
        assert_int_equal(rs_film_merge(fwd, p[1]), RS_OK);
        assert_films_equal(p[1], fwd);
        for (i = 0; i < 3; ++i)
            rs_film_destroy(p[i]);
        rs_film_destroy(one);
        rs_film_destroy(fwd);
        rs_film_destroy(rev);
    }
    rt_rig_down(&g);
}

/* Why the sums are integers: the same samples summed as doubles in two groupings differ, where
 * the film's fixed point does not (a check that the test above could fail with doubles). */
static void test_film_fixed_point_is_order_free(void **state)
{
    rs_film *a = NULL, *b = NULL, *c = NULL;
    double x[3] = {0.1, 0.2, 0.3}, dsum1, dsum2;
    rs_vec3 v;
    int i;
    (void)state;
    dsum1 = (x[0] + x[1]) + x[2];
    dsum2 = x[0] + (x[1] + x[2]);
    assert_true(dsum1 != dsum2); /* doubles: the grouping shows */
    assert_int_equal(rs_film_create(1, 1, &a), RS_OK);
    assert_int_equal(rs_film_create(1, 1, &b), RS_OK);
    assert_int_equal(rs_film_create(1, 1, &c), RS_OK);
    for (i = 0; i < 3; ++i) {
        v.x = v.y = v.z = x[i];
        rs_film_add(a, 0, v);
        rs_film_add(i == 0 ? b : c, 0, v);
    }
    assert_int_equal(rs_film_merge(c, b), RS_OK); /* x0 + (x1 + x2) */
    assert_memory_equal(a->sum, c->sum, 3 * sizeof *a->sum);
    assert_int_equal(c->count[0], 3);
    /* huge and non-finite samples: counted, not summed; a mismatched size is refused */
    v.x = 1e300;
    rs_film_add(c, 0, v);
    v.x = 0.0 / 0.0;
    rs_film_add(c, 0, v);
    assert_int_equal(c->nonfinite, 2);
    assert_int_equal(c->count[0], 5);
    assert_memory_equal(a->sum, c->sum, 3 * sizeof *a->sum);
    rs_film_destroy(b);
    assert_int_equal(rs_film_create(2, 1, &b), RS_OK);
    assert_int_equal(rs_film_merge(a, b), RS_ERR_ARG);
    rs_error_clear();
    rs_film_destroy(a);
    rs_film_destroy(b);
    rs_film_destroy(c);
}

/* rtiow-final, whose ground is a sphere of radius 1000 centred 1000 below the origin: hit points
 * near the origin carry errors of ~1e-4 there, and a bounce ray offset by less could hit the
 * ground again just above it — outside the ground's box, so found by brute force and culled by
 * a BVH, and the images differed in 2 pixels of 320x180 at 8 spp.  Offsets now scale with the
 * sphere (rs_prim_scale, shading/path.h): brute force, median, SAH and LBVH agree bit for bit. */
static void test_bvh_independence(void **state)
{
    static const rs_bvh_method methods[] = {RS_BVH_MEDIAN, RS_BVH_SAH, RS_BVH_LBVH};
    rt_args a = rt_defaults("rtiow-final", 320, 8);
    float *ref, *img;
    size_t k, nf;
    (void)state;
    a.height = 180;
    a.threads = 2;
    a.megakernel = 1;
    a.sampling = RS_SAMPLING_MIXTURE;
    a.no_bvh = 1;
    nf = (size_t)a.width * a.height * 3;
    ref = rt_render(&a, NULL);
    assert_non_null(ref);
    a.no_bvh = 0;
    for (k = 0; k < sizeof methods / sizeof methods[0]; ++k) {
        size_t i, differ = 0;
        a.bvh = methods[k];
        img = rt_render(&a, NULL);
        assert_non_null(img);
        for (i = 0; i < nf; ++i)
            differ += memcmp(&img[i], &ref[i], sizeof *img) != 0;
        if (differ)
            fail_msg("BVH method %d: %zu of %zu values differ from brute force", (int)methods[k],
                     differ, nf);
        free(img);
    }
    free(ref);
}

/* The comparison above could pass vacuously if the image ignored its inputs: a different seed
 * must change it, and the same seed twice must not. */
/* The time limit's one rule (scheduler/plan.h rs_work_plan_time_cut), which the engine's runs
 * and the MPI coordinator both apply: none within the budget or without one; past it the first
 * whole pass at or after the paths begun, and at least the plan's first pass; over a pixel list
 * its passes are the list's. */
static void test_time_cut_rule(void **state)
{
    const uint32_t list[3] = {2, 5, 7};
    rs_work_plan p;
    (void)state;
    memset(&p, 0, sizeof p);
    assert_true(rs_path_ranges_add(&p.todo, 250, 1000)); /* resumed at sample 2 of 100 pixels */
    assert_true(rs_work_plan_time_cut(&p, 100, 5.0, 300, 0) == UINT64_MAX); /* no budget */
    p.time_limit_s = 2.0;
    assert_true(rs_work_plan_time_cut(&p, 100, 1.9, 300, 0) == UINT64_MAX); /* within it */
    assert_true(rs_work_plan_time_cut(&p, 100, 2.0, 301, 1) == 400);        /* the pass under way */
    assert_true(rs_work_plan_time_cut(&p, 100, 2.0, 400, 1) == 400);        /* at a pass's end */
    assert_true(rs_work_plan_time_cut(&p, 100, 9.0, 250, 0) == 300); /* the first pass, at least */
    assert_true(rs_work_plan_time_cut(&p, 100, 9.0, 250, 1) == 300);
    assert_true(rs_work_plan_time_cut(&p, 100, 9.0, 200, 1) == 200); /* nothing begun, one done */
    p.pixels = list;
    p.n_pixels = 3;
    assert_true(rs_work_plan_time_cut(&p, 100, 9.0, 7, 1) == 9);
    rs_work_plan_free(&p);
}

static void test_seed_matters(void **state)
{
    rt_args a = rt_defaults("cornell", SIZE, SPP);
    float *img;
    (void)state;
    a.seed = 2;
    img = rt_render(&a, NULL);
    assert_non_null(img);
    assert_memory_not_equal(img, g_ref, NF * sizeof(float));
    free(img);
    a.seed = 1;
    expect_identical(&a);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_threads),
        cmocka_unit_test(test_chunk_sizes),
        cmocka_unit_test(test_wave_sizes),
        cmocka_unit_test(test_two_devices),
        cmocka_unit_test(test_seed_matters),
        cmocka_unit_test(test_time_cut_rule),
        cmocka_unit_test(test_waves_in_flight),
        cmocka_unit_test(test_device_sets),
        cmocka_unit_test(test_strategies_and_megakernel),
        cmocka_unit_test(test_bvh_independence),
        cmocka_unit_test(test_integrators_and_device_sets),
        cmocka_unit_test(test_zsobol_settings),
        cmocka_unit_test(test_wave_buffers_in_device_memory),
        cmocka_unit_test(test_plans_share_the_buffers),
        cmocka_unit_test(test_megakernel_copies_the_scene_once),
        cmocka_unit_test(test_failure_with_waves_in_flight),
        cmocka_unit_test(test_film_pieces_merge_exactly),
        cmocka_unit_test(test_film_fixed_point_is_order_free),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
