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
#include "cpu/cpu_device.h"
#include "scenes/builtin.h"
#include "scheduler/sched.h"

/* ---- a test device: counts how often each ray is answered --------------------------------- */

typedef struct counting {
    atomic_uint *answers; /* per ray of the batch */
    int sleep_us;         /* per chunk, to make devices slow */
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
    if (c->sleep_us) {
        struct timespec ts = {0, (long)c->sleep_us * 1000L};
        nanosleep(&ts, NULL);
    }
    for (i = begin; i < end; ++i) {
        atomic_fetch_add(&c->answers[i], 1u);
        if (batch->kind == RS_TRACE_CLOSEST)
            batch->hits.prim[i] = i;
        else
            batch->occluded[i] = 1;
    }
    return RS_OK;
}

static void counting_destroy(rs_device *d) { free(d); }

static const rs_device_ops counting_ops = {counting_upload, counting_trace, counting_destroy};

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
        rs_sched_config cfg = {sizes[k], 0};
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
    rs_sched_config cfg = {113, 4};
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
    rs_sched_config cfg = {100, 8};
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
    rs_sched_config cfg = {10, 2};
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

/* The real CPU device behind the scheduler gives exactly what direct traversal gives. */
static void test_cpu_device_matches_direct(void **state)
{
    static const uint32_t sizes[] = {1, 7, 4096, 1u << 20};
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
        for (kind = 0; kind < 2; ++kind) {
            rs_device *d;
            rs_sched *s;
            rs_sched_config cfg = {sizes[k], 0};
            rs_trace_batch b = fixture_batch(&f, (rs_trace_kind)kind);
            memset(f.occluded, 0xAB, n);
            for (i = 0; i < n; ++i)
                f.hits.prim[i] = 0xDEADBEEFu;
            assert_int_equal(rs_cpu_device_create(2, "cpu", &d), RS_OK);
            assert_int_equal(rs_device_upload(d, &g, bvh), RS_OK);
            assert_int_equal(rs_sched_create(&d, 1, &cfg, &s), RS_OK);
            assert_int_equal(rs_sched_trace(s, &b), RS_OK);
            for (i = 0; i < n; ++i) {
                rs_ray ray = rs_ray_soa_get(&f.rays, i);
                rs_hit h;
                int hit = rs_bvh_closest(&bv, &g, ray, &h);
                if (kind == RS_TRACE_CLOSEST) {
                    assert_int_equal(f.hits.prim[i], h.prim);
                    if (hit)
                        assert_true(f.hits.t[i] == h.t);
                } else {
                    assert_int_equal(f.occluded[i], rs_bvh_occluded(&bv, &g, ray));
                    assert_int_equal(f.occluded[i], hit);
                }
            }
            rs_sched_destroy(s);
            rs_device_destroy(d);
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
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
