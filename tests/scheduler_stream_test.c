/* tests/scheduler_stream_test.c — no ray lost (DESIGN rule 3): every ray submitted to the
 * scheduler is answered exactly once, whatever the chunk size, the number and speed of devices,
 * and device failures; answers from the CPU device equal direct traversal. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/alloc.h"
#include "core/rng.h"
#include "core/cores.h"
#include "core/parallel.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "scenes/builtin.h"
#include "scheduler/sched.h"

/* ---- a test device: counts how often each ray is answered --------------------------------- */

typedef struct counting {
    atomic_uint *answers; /* per ray of the batch; NULL: count in batch->occluded only */
    int sleep_us;         /* per chunk, to make devices slow */
    int ns_per_ray;       /* and per ray: a device of a given throughput */
    long fail_on_chunk;   /* fail the n-th trace call (1-based); 0 = never */
    long calls;           /* only touched by this device's dispatch thread */
} counting;

static rs_status counting_upload(rs_device *d, const rs_geom *g, const rs_bvh *b)
{
    (void)d;
    (void)g;
    (void)b;
    return RS_OK;
}

static rs_status counting_trace(rs_device *d, const rs_trace_batch *batch, uint32_t begin,
                                uint32_t end)
{
    counting *c = (counting *)d->impl;
    uint32_t i;
    c->calls++;
    if (c->fail_on_chunk && c->calls >= c->fail_on_chunk)
        return rs_error_set(RS_ERR_DEVICE_LOST, "injected failure");
    if (c->sleep_us || c->ns_per_ray) {
        long ns = (long)c->sleep_us * 1000L + (long)c->ns_per_ray * (long)(end - begin);
        struct timespec ts = {ns / 1000000000L, ns % 1000000000L};
        nanosleep(&ts, NULL);
    }
    for (i = begin; i < end; ++i) {
        if (c->answers) {
            atomic_fetch_add(&c->answers[i], 1u);
            if (batch->kind == RS_TRACE_CLOSEST)
                batch->hits.prim[i] = i;
            else
                batch->occluded[i] = 1;
        } else {
            batch->hits.prim[i] = i;
            batch->occluded[i]++; /* a ray answered twice shows as 2 (or as a race under TSan) */
        }
    }
    return RS_OK;
}

static void counting_destroy(rs_device *d) { free(d); }

static const rs_device_ops counting_ops = {
    .upload = counting_upload, .trace = counting_trace, .destroy = counting_destroy};

static rs_device *counting_device(counting *c, const char *name)
{
    rs_device *d = (rs_device *)calloc(1, sizeof *d);
    d->ops = &counting_ops;
    d->impl = c;
    d->threads = 1;
    strcpy(d->name, name);
    return d;
}

typedef struct batch_fixture {
    rs_ray_soa rays;
    rs_hit_soa hits;
    uint8_t *occluded;
    atomic_uint *answers;
    uint32_t n;
} batch_fixture;

static void fixture_init(batch_fixture *f, uint32_t n)
{
    uint32_t i;
    assert_int_equal(rs_ray_soa_init(&f->rays, n), RS_OK);
    assert_int_equal(rs_hit_soa_init(&f->hits, n), RS_OK);
    f->occluded = (uint8_t *)calloc(n ? n : 1, 1);
    f->answers = (atomic_uint *)calloc(n ? n : 1, sizeof *f->answers);
    f->n = n;
    for (i = 0; i < n; ++i)
        f->hits.prim[i] = RS_NO_HIT;
    f->rays.count = n;
}

static void fixture_free(batch_fixture *f)
{
    rs_ray_soa_free(&f->rays);
    rs_hit_soa_free(&f->hits);
    free(f->occluded);
    free(f->answers);
}

static rs_trace_batch fixture_batch(batch_fixture *f, rs_trace_kind kind)
{
    rs_trace_batch b;
    memset(&b, 0, sizeof b);
    b.kind = kind;
    b.count = f->n;
    b.rays = f->rays;
    b.hits = f->hits;
    b.occluded = f->occluded;
    return b;
}

static void expect_each_once(const batch_fixture *f)
{
    uint32_t i;
    for (i = 0; i < f->n; ++i) {
        if (atomic_load(&f->answers[i]) != 1u)
            fail_msg("ray %u answered %u times", i, atomic_load(&f->answers[i]));
        assert_int_equal(f->hits.prim[i], i);
    }
}

/* One device, every chunk size of the acceptance list (including one larger than the stream). */
static void test_chunk_sizes(void **state)
{
    static const uint32_t sizes[] = {1, 7, 4096, 20000};
    const uint32_t n = 10007;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; ++k) {
        counting c = {0};
        batch_fixture f;
        rs_device *d;
        rs_sched *s;
        rs_sched_config cfg = {sizes[k], 0, NULL};
        rs_trace_batch b;
        rs_device_stats ds;
        uint64_t sub, ans;
        int alive;
        fixture_init(&f, n);
        c.answers = f.answers;
        d = counting_device(&c, "count");
        assert_int_equal(rs_sched_create(&d, 1, &cfg, &s), RS_OK);
        b = fixture_batch(&f, RS_TRACE_CLOSEST);
        assert_int_equal(rs_sched_trace(s, &b), RS_OK);
        expect_each_once(&f);
        rs_sched_device_stats(s, 0, &ds, &alive);
        assert_int_equal(ds.rays, n);
        assert_int_equal(ds.chunks, (n + sizes[k] - 1) / sizes[k]);
        assert_true(alive);
        rs_sched_totals(s, &sub, &ans);
        assert_int_equal(sub, n);
        assert_int_equal(ans, n);
        rs_sched_destroy(s);
        rs_device_destroy(d);
        fixture_free(&f);
    }
}

/* Three devices of different speeds pull from one queue; with a small queue the producer must
 * also wait for room.  Every ray once, and the device counts add up. */
static void test_many_devices_queue_pressure(void **state)
{
    const uint32_t n = 50000;
    counting c[3] = {{0}, {0}, {0}};
    rs_device *d[3];
    batch_fixture f;
    rs_sched *s;
    rs_sched_config cfg = {113, 4, NULL};
    rs_trace_batch b;
    uint64_t total = 0;
    int i, rep;
    (void)state;
    fixture_init(&f, n);
    for (i = 0; i < 3; ++i) {
        c[i].answers = f.answers;
        c[i].sleep_us = i * 150;
        d[i] = counting_device(&c[i], i == 0 ? "fast" : (i == 1 ? "mid" : "slow"));
    }
    assert_int_equal(rs_sched_create(d, 3, &cfg, &s), RS_OK);
    for (rep = 0; rep < 2; ++rep) {
        b = fixture_batch(&f, rep == 0 ? RS_TRACE_CLOSEST : RS_TRACE_OCCLUDED);
        if (rep == 1)
            memset((void *)f.answers, 0, n * sizeof *f.answers);
        assert_int_equal(rs_sched_trace(s, &b), RS_OK);
        expect_each_once(&f);
    }
    for (i = 0; i < 3; ++i) {
        rs_device_stats ds;
        int alive;
        rs_sched_device_stats(s, i, &ds, &alive);
        total += ds.rays;
    }
    assert_int_equal(total, 2u * n);
    rs_sched_destroy(s);
    for (i = 0; i < 3; ++i)
        rs_device_destroy(d[i]);
    fixture_free(&f);
}

static void test_empty_and_single(void **state)
{
    counting c = {0};
    batch_fixture f;
    rs_device *d;
    rs_sched *s;
    rs_trace_batch b;
    (void)state;
    fixture_init(&f, 1);
    c.answers = f.answers;
    d = counting_device(&c, "count");
    assert_int_equal(rs_sched_create(&d, 1, NULL, &s), RS_OK);
    b = fixture_batch(&f, RS_TRACE_CLOSEST);
    b.count = 0;
    assert_int_equal(rs_sched_trace(s, &b), RS_OK);
    assert_int_equal(atomic_load(&f.answers[0]), 0u);
    b.count = 1;
    assert_int_equal(rs_sched_trace(s, &b), RS_OK);
    expect_each_once(&f);
    rs_sched_destroy(s);
    rs_device_destroy(d);
    fixture_free(&f);
}

/* A device fails on its third chunk: its chunk goes back to the queue, the healthy device
 * finishes the batch, every ray is still answered exactly once. */
static void test_device_failure(void **state)
{
    const uint32_t n = 20000;
    counting good = {0}, bad = {0};
    rs_device *d[2];
    batch_fixture f;
    rs_sched *s;
    rs_sched_config cfg = {100, 8, NULL};
    rs_trace_batch b;
    rs_device_stats ds;
    int alive;
    (void)state;
    fixture_init(&f, n);
    good.answers = bad.answers = f.answers;
    good.sleep_us = 200; /* slower, so the bad device surely gets three chunks */
    bad.fail_on_chunk = 3;
    d[0] = counting_device(&good, "good");
    d[1] = counting_device(&bad, "bad");
    assert_int_equal(rs_sched_create(d, 2, &cfg, &s), RS_OK);
    b = fixture_batch(&f, RS_TRACE_CLOSEST);
    assert_int_equal(rs_sched_trace(s, &b), RS_OK);
    expect_each_once(&f);
    rs_sched_device_stats(s, 1, &ds, &alive);
    assert_false(alive);
    assert_int_equal(ds.failures, 1);
    assert_int_equal(ds.rays, 200);
    /* the next batch runs on the survivor alone */
    memset((void *)f.answers, 0, n * sizeof *f.answers);
    assert_int_equal(rs_sched_trace(s, &b), RS_OK);
    expect_each_once(&f);
    rs_sched_destroy(s);
    rs_device_destroy(d[0]);
    rs_device_destroy(d[1]);
    fixture_free(&f);
}

/* When every device fails the trace returns an error instead of hanging. */
static void test_all_devices_fail(void **state)
{
    counting bad = {0};
    batch_fixture f;
    rs_device *d;
    rs_sched *s;
    rs_sched_config cfg = {10, 2, NULL};
    rs_trace_batch b;
    (void)state;
    fixture_init(&f, 1000);
    bad.answers = f.answers;
    bad.fail_on_chunk = 5;
    d = counting_device(&bad, "bad");
    assert_int_equal(rs_sched_create(&d, 1, &cfg, &s), RS_OK);
    b = fixture_batch(&f, RS_TRACE_CLOSEST);
    rs_error_clear();
    assert_int_equal(rs_sched_trace(s, &b), RS_ERR_DEVICE_LOST);
    assert_non_null(strstr(rs_error_message(), "injected failure"));
    rs_error_clear();
    assert_int_equal(rs_sched_trace(s, &b), RS_ERR_DEVICE_LOST);
    rs_error_clear();
    rs_sched_destroy(s);
    rs_device_destroy(d);
    fixture_free(&f);
}

static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* The property behind DESIGN rule 3, over random configurations (fixed seed, 40 trials): 1 to 4
 * devices of random speeds (per-chunk and per-ray sleeps), fixed or adaptive chunk sizes, every
 * device but one failing at a random chunk, and 1 to 3 jobs of random sizes (0 and 1 included)
 * in flight at once.  Every ray of every job is answered exactly once; the device counters add
 * up to the rays submitted. */
static void test_random_property(void **state)
{
    enum { TRIALS = 40, MAX_DEV = 4, MAX_JOBS = 3 };
    uint64_t seed = 0x51ed;
    int trial;
    (void)state;
    for (trial = 0; trial < TRIALS; ++trial) {
        counting c[MAX_DEV];
        rs_device *d[MAX_DEV];
        batch_fixture f[MAX_JOBS];
        rs_trace_batch b[MAX_JOBS];
        rs_sched_job jobs[MAX_JOBS];
        rs_sched *s;
        rs_sched_config cfg;
        uint64_t sum = 0, sub, ans, expect = 0;
        int n_dev, n_jobs, i, healthy;
        uint32_t k;
#define RND(n) ((uint32_t)(splitmix64(&seed) % (uint64_t)(n)))
        n_dev = 1 + (int)RND(MAX_DEV);
        n_jobs = 1 + (int)RND(MAX_JOBS);
        healthy = (int)RND((uint32_t)n_dev);
        memset(c, 0, sizeof c);
        memset(&cfg, 0, sizeof cfg);
        for (i = 0; i < n_dev; ++i) {
            c[i].sleep_us = (int)RND(200);
            c[i].ns_per_ray = (int)RND(300);
            c[i].fail_on_chunk = i == healthy || RND(2) == 0 ? 0 : 1 + (long)RND(20);
            d[i] = counting_device(&c[i], "rnd");
            if (RND(4) == 0) { /* now and then a "GPU": other chunk sizes */
                d[i]->threads = 0;
                d[i]->flags = RS_DEVICE_OWN_MEMORY;
            }
        }
        cfg.chunk_size = RND(2) == 0 ? 0 : 1 + RND(5000);
        cfg.queue_capacity = 1 + RND(4);
        assert_int_equal(rs_sched_create(d, n_dev, &cfg, &s), RS_OK);
        for (i = 0; i < n_jobs; ++i) {
            uint32_t pick = RND(8), n = pick == 0 ? 0 : pick == 1 ? 1 : 1 + RND(60000);
            fixture_init(&f[i], n);
            b[i] = fixture_batch(&f[i], RND(2) ? RS_TRACE_CLOSEST : RS_TRACE_OCCLUDED);
            expect += n;
        }
        for (i = 0; i < n_jobs; ++i)
            rs_sched_submit(s, &b[i], &jobs[i]);
        for (i = n_jobs - 1; i >= 0; --i) /* waiting out of order is allowed too */
            assert_int_equal(rs_sched_wait(s, &jobs[i]), RS_OK);
        for (i = 0; i < n_jobs; ++i)
            for (k = 0; k < f[i].n; ++k)
                if (f[i].occluded[k] != 1 || f[i].hits.prim[k] != k)
                    fail_msg("trial %d job %d ray %u: answered %u times", trial, i, k,
                             f[i].occluded[k]);
        for (i = 0; i < n_dev; ++i) {
            rs_device_stats ds;
            int alive;
            rs_sched_device_stats(s, i, &ds, &alive);
            sum += ds.rays;
            if (i == healthy)
                assert_true(alive);
        }
        rs_sched_totals(s, &sub, &ans);
        assert_int_equal(sub, expect);
        assert_int_equal(ans, expect);
        assert_int_equal(sum, expect);
        rs_sched_destroy(s);
        for (i = 0; i < n_dev; ++i)
            rs_device_destroy(d[i]);
        for (i = 0; i < n_jobs; ++i)
            fixture_free(&f[i]);
#undef RND
    }
}

/* Adaptive chunk sizes: a device ten times faster (per ray) gets larger chunks and most of the
 * rays, and both grow past their first chunk. */
static void test_adaptive_chunks(void **state)
{
    const uint32_t n = 300000;
    counting fast = {0}, slow = {0};
    rs_device *d[2];
    batch_fixture f;
    rs_sched *s;
    rs_trace_batch b;
    rs_device_stats st[2];
    double mean[2];
    int i, alive;
    (void)state;
    fixture_init(&f, n);
    /* 50x apart in their sleeps, so that what a ray costs besides (the answer loop, several
     * times slower under ThreadSanitizer, which once brought 10x down to 2.9x) cannot undo the
     * order */
    fast.ns_per_ray = 20;
    slow.ns_per_ray = 1000;
    d[0] = counting_device(&fast, "fast");
    d[1] = counting_device(&slow, "slow");
    assert_int_equal(rs_sched_create(d, 2, NULL, &s), RS_OK);
    b = fixture_batch(&f, RS_TRACE_CLOSEST);
    assert_int_equal(rs_sched_trace(s, &b), RS_OK);
    for (i = 0; i < (int)n; ++i)
        assert_int_equal(f.occluded[i], 1);
    for (i = 0; i < 2; ++i) {
        rs_sched_device_stats(s, i, &st[i], &alive);
        mean[i] = (double)st[i].rays / (double)st[i].chunks;
    }
    print_message("adaptive: fast %llu rays in %llu chunks, slow %llu rays in %llu chunks\n",
                  (unsigned long long)st[0].rays, (unsigned long long)st[0].chunks,
                  (unsigned long long)st[1].rays, (unsigned long long)st[1].chunks);
    assert_int_equal(st[0].rays + st[1].rays, n);
    /* ideal share 50/51; sleeps overshoot, so only the order and a loose bound are checked */
    assert_true(st[0].rays > 3 * st[1].rays);
    assert_true(mean[0] > mean[1]);
    assert_true(mean[0] > RS_SCHED_FIRST_HOST);
    rs_sched_destroy(s);
    rs_device_destroy(d[0]);
    rs_device_destroy(d[1]);
    fixture_free(&f);
}

/* rs_parallel_range: every strategy covers each index exactly once, for any thread count, grain
 * and range (empty, one item, uneven). */
static void count_range(void *ctx, uint32_t begin, uint32_t end)
{
    atomic_uint *seen = (atomic_uint *)ctx;
    uint32_t i;
    assert_true(begin < end);
    for (i = begin; i < end; ++i)
        atomic_fetch_add(&seen[i], 1u);
}

static void test_parallel_range(void **state)
{
    static const uint32_t ranges[][2] = {{0, 0}, {5, 6}, {0, 1000}, {17, 10007}};
    static const uint32_t grains[] = {0, 1, 7, 512, 100000};
    atomic_uint *seen = (atomic_uint *)calloc(10007, sizeof *seen);
    int s, t;
    size_t r, g;
    uint32_t i;
    (void)state;
    for (s = 0; s < 3; ++s)
        for (t = 1; t <= 3; ++t)
            for (r = 0; r < sizeof ranges / sizeof ranges[0]; ++r)
                for (g = 0; g < sizeof grains / sizeof grains[0]; ++g) {
                    for (i = 0; i < 10007; ++i)
                        atomic_store(&seen[i], 0u);
                    rs_parallel_range((rs_par_strategy)s, t, ranges[r][0], ranges[r][1], grains[g],
                                      count_range, seen);
                    for (i = 0; i < 10007; ++i) {
                        unsigned want = i >= ranges[r][0] && i < ranges[r][1];
                        if (atomic_load(&seen[i]) != want)
                            fail_msg("%s, %d threads, [%u, %u), grain %u: index %u seen %u times",
                                     rs_par_strategy_name((rs_par_strategy)s), t, ranges[r][0],
                                     ranges[r][1], grains[g], i, atomic_load(&seen[i]));
                    }
                }
    free(seen);
}

/* The core budget: grants at most what is asked, at least one, never more than is free beyond
 * that one, and gives everything back. */
static void test_core_budget(void **state)
{
    rs_cores c;
    int a, b, d;
    (void)state;
    rs_cores_init(&c, 4);
    a = rs_cores_acquire(&c, 3);
    assert_int_equal(a, 3);
    b = rs_cores_acquire(&c, 4);
    assert_int_equal(b, 1); /* one left */
    d = rs_cores_acquire(&c, 2);
    assert_int_equal(d, 1); /* none left: still one, the caller's own thread */
    assert_int_equal(atomic_load(&c.free), -1);
    rs_cores_release(&c, a);
    rs_cores_release(&c, b);
    rs_cores_release(&c, d);
    assert_int_equal(atomic_load(&c.free), 4);
    assert_int_equal(rs_cores_acquire(NULL, 7), 7);
    assert_int_equal(rs_cores_acquire(&c, 0), 1);
}

/* The real CPU device and the GPU fallback (staging buffers), alone and together, behind the
 * scheduler give exactly what direct traversal gives, at fixed and adaptive chunk sizes. */
static void test_cpu_device_matches_direct(void **state)
{
    static const uint32_t sizes[] = {1, 7, 4096, 1u << 20, 0};
    const uint32_t n = 30000;
    rs_scene *scene;
    rs_bvh *bvh;
    rs_geom g;
    rs_bvh_view bv;
    batch_fixture f;
    uint32_t i;
    size_t k;
    (void)state;
    assert_int_equal(rs_builtin_create("cornell", &scene), RS_OK);
    g = rs_scene_geom(scene);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    bv = rs_bvh_view_of(bvh);
    fixture_init(&f, n);
    for (i = 0; i < n; ++i) {
        rs_rng_f4 r = rs_rng_float4(42, i, 0, 0, 0);
        rs_ray ray;
        ray.o = rs_v3(50.0f + 450.0f * r.v[0], 50.0f + 450.0f * r.v[1], -100.0f + 600.0f * r.v[2]);
        ray.d = rs_v3_normalize(rs_v3(r.v[3] - 0.5f, r.v[1] - 0.5f, r.v[0] - 0.3f));
        ray.tmin = 0.0f;
        ray.time = 0.0f;
        ray.tmax = (i % 3 == 0) ? 200.0f : 3.4e38f;
        rs_ray_soa_set(&f.rays, i, &ray, i);
    }
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; ++k) {
        int kind;
        for (kind = 0; kind < 6; ++kind) {
            rs_device *d[2];
            rs_sched *s;
            rs_sched_config cfg = {sizes[k], 0, NULL};
            rs_trace_batch b = fixture_batch(&f, (rs_trace_kind)(kind & 1));
            int set = kind >> 1, n_dev = set == 2 ? 2 : 1, j; /* cpu, fallback, both */
            rs_cores cores;
            rs_cpu_device_opts co;
            memset(f.occluded, 0xAB, n);
            for (i = 0; i < n; ++i)
                f.hits.prim[i] = 0xDEADBEEFu;
            rs_cores_init(&cores, 2);
            memset(&co, 0, sizeof co);
            co.threads = 2;
            co.cores = &cores;
            if (set == 1)
                assert_int_equal(rs_gpu_fallback_create(2, 0, &cores, &d[0]), RS_OK);
            else
                assert_int_equal(rs_cpu_device_create_opts(&co, &d[0]), RS_OK);
            if (set == 2)
                assert_int_equal(rs_gpu_fallback_create(1, 0, &cores, &d[1]), RS_OK);
            for (j = 0; j < n_dev; ++j)
                assert_int_equal(rs_device_upload(d[j], &g, bvh), RS_OK);
            assert_int_equal(rs_sched_create(d, n_dev, &cfg, &s), RS_OK);
            assert_int_equal(rs_sched_trace(s, &b), RS_OK);
            if (set == 1) { /* the fallback stages every ray in and every answer out */
                rs_device_stats ds;
                int alive;
                rs_sched_device_stats(s, 0, &ds, &alive);
                assert_int_equal(ds.bytes_to_device, (uint64_t)n * RS_RAY_BYTES);
                assert_int_equal(ds.bytes_from_device,
                                 (uint64_t)n * ((kind & 1) == RS_TRACE_CLOSEST ? RS_HIT_BYTES : 1));
            }
            for (i = 0; i < n; ++i) {
                rs_ray ray = rs_ray_soa_get(&f.rays, i);
                rs_hit h;
                int hit = rs_bvh_closest(&bv, &g, ray, &h);
                if ((kind & 1) == RS_TRACE_CLOSEST) {
                    assert_int_equal(f.hits.prim[i], h.prim);
                    if (hit)
                        assert_true(f.hits.t[i] == h.t);
                } else {
                    assert_int_equal(f.occluded[i], rs_bvh_occluded(&bv, &g, ray));
                    assert_int_equal(f.occluded[i], hit);
                }
            }
            rs_sched_destroy(s);
            for (j = 0; j < n_dev; ++j)
                rs_device_destroy(d[j]);
            assert_int_equal(atomic_load(&cores.free), 2); /* every team given back */
        }
    }
    fixture_free(&f);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chunk_sizes),      cmocka_unit_test(test_many_devices_queue_pressure),
        cmocka_unit_test(test_empty_and_single), cmocka_unit_test(test_device_failure),
        cmocka_unit_test(test_all_devices_fail), cmocka_unit_test(test_cpu_device_matches_direct),
        cmocka_unit_test(test_random_property),  cmocka_unit_test(test_adaptive_chunks),
        cmocka_unit_test(test_core_budget),      cmocka_unit_test(test_parallel_range),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
