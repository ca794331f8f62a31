/* tests/app_timeline_test.c — the span log (scheduler/timeline.c) and its SVG (app/timeline_svg.c):
 *   - a known set of spans on 3 lanes (2 devices + the render thread) gives an SVG that starts
 *     with <svg and ends with </svg>, has exactly one rectangle per span in its stage's colour
 *     and on its lane, names the lanes XML-escaped, and a legend of exactly the stages used;
 *   - very many spans are merged so the file stays small;
 *   - the log keeps its first `capacity` spans and counts the rest in `dropped` (however many,
 *     without overwriting a kept span), also when 4 threads add at once; adding to, reading or
 *     asking the time of no timeline is a no-op; create refuses a missing out pointer and
 *     reports either allocation failing (RS_ERR_NOMEM, *out NULL);
 *   - a path in a folder that does not exist is RS_ERR_IO and leaves no file (nor its .tmp).
 * Every test writes into its own mkdtemp folder, removed afterwards. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/timeline_svg.h"
#include "core/alloc.h"
#include "core/status.h"
#include "scheduler/timeline.h"

typedef struct tmp_dir {
    char dir[64];
    char path[128];
} tmp_dir;

static void dir_open(tmp_dir *d)
{
    strcpy(d->dir, "/tmp/rs_timeline_XXXXXX");
    assert_non_null(mkdtemp(d->dir));
    snprintf(d->path, sizeof d->path, "%s/timeline.svg", d->dir);
}

static void dir_close(tmp_dir *d)
{
    char tmp[160];
    snprintf(tmp, sizeof tmp, "%s.tmp", d->path);
    remove(d->path);
    remove(tmp);
    assert_int_equal(rmdir(d->dir), 0); /* fails if anything else was left there */
}

/* The whole file, NUL-terminated (free with free), or NULL. */
static char *read_all(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long n;
    if (!f)
        return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = (char *)malloc((size_t)n + 1);
    if (buf && fread(buf, 1, (size_t)n, f) != (size_t)n) {
        free(buf);
        buf = NULL;
    }
    fclose(f);
    if (buf) {
        buf[n] = '\0';
        if (size)
            *size = (size_t)n;
    }
    return buf;
}

static int count_in(const char *begin, const char *end, const char *needle)
{
    int n = 0;
    size_t len = strlen(needle);
    const char *p = begin;
    while ((p = strstr(p, needle)) != NULL && (!end || p + len <= end)) {
        ++n;
        p += len;
    }
    return n;
}

static int file_exists(const char *path) { return access(path, F_OK) == 0; }

/* The slice of `svg` from `<g id="name">` to its `</g>` (groups are not nested). */
static const char *group(const char *svg, const char *name, const char **end)
{
    char open[64];
    const char *p;
    snprintf(open, sizeof open, "<g id=\"%s\"", name);
    p = strstr(svg, open);
    assert_non_null(p);
    *end = strstr(p, "</g>");
    assert_non_null(*end);
    return p;
}

/* A span rectangle: its stage's fill, then its tooltip (legend swatches have none). */
static void span_needle(rs_stage s, char *buf, size_t size)
{
    snprintf(buf, size, "fill=\"%s\"><title>%s, wave ", rs_timeline_stage_color(s),
             rs_stage_name(s));
}

static void test_stage_names_and_colors(void **state)
{
    int a, b;
    (void)state;
    for (a = 0; a < RS_STAGE_COUNT; ++a) {
        assert_string_not_equal(rs_stage_name((rs_stage)a), "unknown");
        for (b = 0; b < a; ++b) {
            assert_string_not_equal(rs_stage_name((rs_stage)a), rs_stage_name((rs_stage)b));
            assert_string_not_equal(rs_timeline_stage_color((rs_stage)a),
                                    rs_timeline_stage_color((rs_stage)b));
        }
    }
    assert_string_equal(rs_stage_name(RS_STAGE_RAYGEN), "raygen");
    assert_string_equal(rs_stage_name(RS_STAGE_TRACE_CLOSEST), "trace-closest");
    assert_string_equal(rs_stage_name(RS_STAGE_SHADE), "shade");
    assert_string_equal(rs_stage_name(RS_STAGE_TRACE_SHADOW), "trace-shadow");
    assert_string_equal(rs_stage_name(RS_STAGE_RESOLVE_SHADOWS), "resolve-shadows");
    assert_string_equal(rs_stage_name(RS_STAGE_COMPACT), "compact");
    assert_string_equal(rs_stage_name(RS_STAGE_FILM), "film");
    assert_string_equal(rs_stage_name(RS_STAGE_PASS), "pass");
}

static void test_svg_known_spans(void **state)
{
    static const char *const names[3] = {"cpu (2 threads) & co", "cuda:0 <NVIDIA 'H100'>",
                                         "shading (render thread)"};
    /* two pipelined waves: the render thread's stages, the devices' chunks in between */
    static const rs_stage render_stages[5] = {
        RS_STAGE_RAYGEN, RS_STAGE_SHADE, RS_STAGE_RESOLVE_SHADOWS, RS_STAGE_COMPACT, RS_STAGE_FILM};
    int per_stage[RS_STAGE_COUNT] = {0}, per_lane[3] = {0};
    rs_timeline *t;
    tmp_dir d;
    char *svg, needle[128], tmp[160];
    const char *g, *end;
    size_t size, len;
    uint32_t w;
    int k, s, lane;
    (void)state;
    dir_open(&d);
    assert_int_equal(rs_timeline_create(64, &t), RS_OK);
    for (w = 0; w < 2; ++w) {
        double base = 0.010 + 0.050 * w;
        for (k = 0; k < 5; ++k) {
            rs_timeline_add(t, 2, render_stages[k], w, base + 0.008 * k, base + 0.008 * k + 0.004);
            ++per_stage[render_stages[k]];
            ++per_lane[2];
        }
        for (k = 0; k < 3; ++k) { /* lane 0: 3 closest chunks, lane 1: 2 (+ shadows below) */
            for (lane = 0; lane < 2; ++lane) {
                if (lane == 1 && k == 2)
                    continue;
                rs_timeline_add(t, (uint16_t)lane, RS_STAGE_TRACE_CLOSEST, w,
                                base + 0.004 + 0.001 * k, base + 0.0045 + 0.001 * k);
                ++per_stage[RS_STAGE_TRACE_CLOSEST];
                ++per_lane[lane];
            }
        }
        rs_timeline_add(t, 0, RS_STAGE_TRACE_SHADOW, w, base + 0.013, base + 0.015);
        rs_timeline_add(t, 1, RS_STAGE_TRACE_SHADOW, w, base + 0.0125, base + 0.016);
        per_stage[RS_STAGE_TRACE_SHADOW] += 2;
        ++per_lane[0];
        ++per_lane[1];
    }
    assert_int_equal(rs_timeline_write_svg(d.path, t, names, 3, "test <timeline>"), RS_OK);
    snprintf(tmp, sizeof tmp, "%s.tmp", d.path);
    assert_false(file_exists(tmp));
    svg = read_all(d.path, &size);
    assert_non_null(svg);

    /* a whole SVG document */
    assert_int_equal(strncmp(svg, "<svg", 4), 0);
    len = size;
    while (len > 0 && (svg[len - 1] == '\n' || svg[len - 1] == ' '))
        --len;
    assert_true(len >= 6);
    assert_int_equal(strncmp(svg + len - 6, "</svg>", 6), 0);
    assert_null(strstr(svg, "<script"));

    /* one rectangle per span, in its stage's colour, on its lane */
    for (s = 0; s < RS_STAGE_COUNT; ++s) {
        span_needle((rs_stage)s, needle, sizeof needle);
        assert_int_equal(count_in(svg, NULL, needle), per_stage[s]);
    }
    for (lane = 0; lane < 3; ++lane) {
        char id[16];
        snprintf(id, sizeof id, "lane%d", lane);
        g = group(svg, id, &end);
        assert_int_equal(count_in(g, end, "<rect"), per_lane[lane]);
        assert_int_equal(count_in(g, end, "<title>"), per_lane[lane]);
    }
    assert_non_null(strstr(svg, "<title>shade, wave 1, 68.000-72.000 ms</title>"));

    /* names escaped */
    assert_non_null(strstr(svg, ">cpu (2 threads) &amp; co<"));
    assert_non_null(strstr(svg, ">cuda:0 &lt;NVIDIA &apos;H100&apos;&gt;<"));
    assert_non_null(strstr(svg, ">shading (render thread)<"));
    assert_non_null(strstr(svg, "test &lt;timeline&gt;"));
    assert_null(strstr(svg, "<NVIDIA"));
    assert_null(strstr(svg, "& co"));

    /* the legend: exactly the stages used */
    g = group(svg, "legend", &end);
    for (s = 0; s < RS_STAGE_COUNT; ++s) {
        snprintf(needle, sizeof needle, ">%s<", rs_stage_name((rs_stage)s));
        assert_int_equal(count_in(g, end, needle), per_stage[s] ? 1 : 0);
    }
    assert_int_equal(per_stage[RS_STAGE_PASS], 0);

    /* waves marked, the summary present */
    g = group(svg, "waves", &end);
    assert_int_equal(count_in(g, end, ">wave 0</text>"), 1);
    assert_int_equal(count_in(g, end, ">wave 1</text>"), 1);
    assert_non_null(strstr(svg, "total 0.096 s"));

    free(svg);
    rs_timeline_destroy(t);
    dir_close(&d);
}

static void test_svg_many_spans_merged(void **state)
{
    static const char *const names[2] = {"cpu", "shading (render thread)"};
    enum { N = 60000 };
    rs_timeline *t;
    tmp_dir d;
    char *svg, needle[128];
    size_t size;
    uint32_t i;
    int rects = 0, s;
    (void)state;
    dir_open(&d);
    assert_int_equal(rs_timeline_create(N, &t), RS_OK);
    for (i = 0; i < N / 2; ++i) {
        double t0 = 1e-5 * i;
        rs_timeline_add(t, 1, (rs_stage)(i % 3 == 0 ? RS_STAGE_RAYGEN : RS_STAGE_SHADE), i / 3, t0,
                        t0 + 5e-6);
        rs_timeline_add(t, 0, RS_STAGE_TRACE_CLOSEST, i / 3, t0 + 5e-6, t0 + 9e-6);
    }
    assert_int_equal(rs_timeline_write_svg(d.path, t, names, 2, NULL), RS_OK);
    svg = read_all(d.path, &size);
    assert_non_null(svg);
    for (s = 0; s < RS_STAGE_COUNT; ++s) {
        snprintf(needle, sizeof needle, "fill=\"%s\"><title>",
                 rs_timeline_stage_color((rs_stage)s));
        rects += count_in(svg, NULL, needle);
    }
    assert_true(rects > 0);
    assert_true(rects < N / 10);
    assert_true(size < 3u << 20);
    assert_non_null(strstr(svg, "spans, waves "));
    free(svg);
    rs_timeline_destroy(t);
    dir_close(&d);
}

static void test_capacity_overflow(void **state)
{
    rs_timeline *t;
    const rs_span *sp;
    uint32_t n, i;
    uint64_t dropped;
    (void)state;
    assert_int_equal(rs_timeline_create(5, &t), RS_OK);
    for (i = 0; i < 8; ++i)
        rs_timeline_add(t, 0, RS_STAGE_SHADE, i, i, i + 0.5);
    sp = rs_timeline_spans(t, &n, &dropped);
    assert_int_equal(n, 5);
    assert_int_equal(dropped, 3);
    for (i = 0; i < 5; ++i) {
        assert_int_equal(sp[i].wave, i);
        assert_true(sp[i].t0 == (double)i && sp[i].t1 == i + 0.5);
        assert_int_equal(sp[i].stage, RS_STAGE_SHADE);
    }
    rs_timeline_destroy(t);

    /* capacity 0: everything is dropped, and the SVG still writes */
    assert_int_equal(rs_timeline_create(0, &t), RS_OK);
    rs_timeline_add(t, 0, RS_STAGE_PASS, 0, 0.0, 1.0);
    sp = rs_timeline_spans(t, &n, &dropped);
    assert_int_equal(n, 0);
    assert_int_equal(dropped, 1);
    {
        tmp_dir d;
        char *svg;
        dir_open(&d);
        assert_int_equal(rs_timeline_write_svg(d.path, t, NULL, 1, NULL), RS_OK);
        svg = read_all(d.path, NULL);
        assert_non_null(svg);
        assert_non_null(strstr(svg, "1 dropped"));
        free(svg);
        dir_close(&d);
    }
    rs_timeline_destroy(t);
}

/* Past capacity the log stays as it was, however many more spans come: each is counted in
 * `dropped` and none overwrites a kept one; exactly `capacity` spans drop none; the counts may be
 * asked for without their pointers. */
static void test_overflow_keeps_counting(void **state)
{
    rs_timeline *t;
    const rs_span *sp, *again;
    uint32_t n, i;
    uint64_t dropped;
    (void)state;
    assert_int_equal(rs_timeline_create(3, &t), RS_OK);
    for (i = 0; i < 3; ++i)
        rs_timeline_add(t, (uint16_t)i, RS_STAGE_RAYGEN, 10 + i, 0.25 * i, 0.25 * i + 0.125);
    sp = rs_timeline_spans(t, &n, &dropped);
    assert_int_equal(n, 3);
    assert_int_equal(dropped, 0); /* full, nothing lost yet */
    for (i = 0; i < 1000; ++i)
        rs_timeline_add(t, 7, RS_STAGE_FILM, 99, 5.0, 6.0);
    again = rs_timeline_spans(t, &n, &dropped);
    assert_ptr_equal(again, sp);
    assert_int_equal(n, 3);
    assert_int_equal(dropped, 1000);
    for (i = 0; i < 3; ++i) {
        assert_int_equal(sp[i].lane, i);
        assert_int_equal(sp[i].wave, 10 + i);
        assert_int_equal(sp[i].stage, RS_STAGE_RAYGEN);
        assert_true(sp[i].t0 == 0.25 * i && sp[i].t1 == 0.25 * i + 0.125);
    }
    /* one more, and the counts alone (no pointers for them) */
    rs_timeline_add(t, 0, RS_STAGE_SHADE, 0, 0.0, 1.0);
    assert_ptr_equal(rs_timeline_spans(t, NULL, NULL), sp);
    assert_ptr_equal(rs_timeline_spans(t, NULL, &dropped), sp);
    assert_int_equal(dropped, 1001);
    assert_ptr_equal(rs_timeline_spans(t, &n, NULL), sp);
    assert_int_equal(n, 3);
    rs_timeline_destroy(t);
}

/* rs_timeline_create refuses a missing out pointer (RS_ERR_ARG), and reports either allocation
 * failing as RS_ERR_NOMEM with *out NULL (whatever it held before) and its own message. */
static void test_create_bad_arguments(void **state)
{
    rs_timeline *t;
    (void)state;
    rs_error_clear();
    assert_int_equal(rs_timeline_create(4, NULL), RS_ERR_ARG);
    assert_non_null(strstr(rs_error_message(), "no out pointer"));
    rs_error_clear();

    t = (rs_timeline *)&t; /* not NULL: create must clear it */
    rs_alloc_fail_after(0); /* the log itself */
    assert_int_equal(rs_timeline_create(4, &t), RS_ERR_NOMEM);
    rs_alloc_fail_after(-1);
    assert_null(t);
    assert_non_null(strstr(rs_error_message(), "out of memory for the timeline"));
    rs_error_clear();

    t = (rs_timeline *)&t;
    rs_alloc_fail_after(1); /* its spans */
    assert_int_equal(rs_timeline_create(4, &t), RS_ERR_NOMEM);
    rs_alloc_fail_after(-1);
    assert_null(t);
    assert_non_null(strstr(rs_error_message(), "a timeline of 4 spans"));
    rs_error_clear();

    /* and after the failures, a create works */
    assert_int_equal(rs_timeline_create(4, &t), RS_OK);
    assert_non_null(t);
    rs_timeline_destroy(t);
}

typedef struct adder {
    rs_timeline *t;
    uint16_t lane;
} adder;

static void *add_many(void *arg)
{
    adder *a = (adder *)arg;
    uint32_t i;
    for (i = 0; i < 1000; ++i) {
        double now = rs_timeline_now(a->t);
        rs_timeline_add(a->t, a->lane, RS_STAGE_TRACE_CLOSEST, i, now, now + 1e-6);
    }
    return NULL;
}

static void test_concurrent_adds(void **state)
{
    enum { THREADS = 4 };
    rs_timeline *t;
    pthread_t th[THREADS];
    adder a[THREADS];
    const rs_span *sp;
    uint32_t n, i, seen[THREADS] = {0};
    int64_t last[THREADS];
    uint64_t dropped;
    int k;
    (void)state;
    assert_int_equal(rs_timeline_create(3000, &t), RS_OK);
    for (k = 0; k < THREADS; ++k) {
        a[k].t = t;
        a[k].lane = (uint16_t)k;
        last[k] = -1;
        assert_int_equal(pthread_create(&th[k], NULL, add_many, &a[k]), 0);
    }
    for (k = 0; k < THREADS; ++k)
        assert_int_equal(pthread_join(th[k], NULL), 0);
    sp = rs_timeline_spans(t, &n, &dropped);
    assert_int_equal(n + dropped, THREADS * 1000);
    assert_int_equal(n, 3000);
    /* whole spans, each thread's in the order it added them */
    for (i = 0; i < n; ++i) {
        assert_true(sp[i].lane < THREADS);
        assert_true((int64_t)sp[i].wave > last[sp[i].lane]);
        assert_true(sp[i].t1 >= sp[i].t0);
        assert_int_equal(sp[i].stage, RS_STAGE_TRACE_CLOSEST);
        last[sp[i].lane] = sp[i].wave;
        ++seen[sp[i].lane];
    }
    for (k = 0; k < THREADS; ++k)
        assert_int_equal(seen[k], (uint32_t)(last[k] + 1)); /* a prefix of each thread's adds */
    rs_timeline_destroy(t);
}

static void test_null_timeline(void **state)
{
    uint32_t n = 7;
    uint64_t dropped = 7;
    rs_timeline *t;
    double a, b;
    (void)state;
    rs_timeline_add(NULL, 0, RS_STAGE_SHADE, 0, 0.0, 1.0);
    rs_timeline_add(NULL, 65535, RS_STAGE_PASS, UINT32_MAX, 1.0, 0.0);
    assert_null(rs_timeline_spans(NULL, &n, &dropped));
    assert_int_equal(n, 0);
    assert_int_equal(dropped, 0);
    assert_null(rs_timeline_spans(NULL, NULL, NULL));
    assert_true(rs_timeline_now(NULL) == 0.0);
    rs_timeline_destroy(NULL);
    assert_int_equal(rs_timeline_write_svg("/tmp/x.svg", NULL, NULL, 1, NULL), RS_ERR_ARG);
    rs_error_clear();

    assert_int_equal(rs_timeline_create(4, &t), RS_OK);
    a = rs_timeline_now(t);
    b = rs_timeline_now(t);
    assert_true(a >= 0.0 && a < 1.0 && b >= a);
    assert_int_equal(rs_timeline_write_svg("/tmp/x.svg", t, NULL, 0, NULL), RS_ERR_ARG);
    rs_error_clear();
    rs_timeline_destroy(t);

    /* out of memory at create: nothing leaks (under ASan), NOMEM reported */
    rs_alloc_fail_after(1);
    assert_int_equal(rs_timeline_create(4, &t), RS_ERR_NOMEM);
    assert_null(t);
    rs_alloc_fail_after(-1);
    rs_error_clear();
}

static void test_missing_folder(void **state)
{
    rs_timeline *t;
    tmp_dir d;
    char path[192], tmp[200];
    (void)state;
    dir_open(&d);
    snprintf(path, sizeof path, "%s/no-such-folder/timeline.svg", d.dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    assert_int_equal(rs_timeline_create(4, &t), RS_OK);
    rs_timeline_add(t, 0, RS_STAGE_RAYGEN, 0, 0.0, 0.001);
    rs_error_clear();
    assert_int_equal(rs_timeline_write_svg(path, t, NULL, 1, "x"), RS_ERR_IO);
    assert_non_null(strstr(rs_error_message(), "cannot write the timeline"));
    assert_non_null(strstr(rs_error_message(), path));
    rs_error_clear();
    assert_false(file_exists(path));
    assert_false(file_exists(tmp));
    rs_timeline_destroy(t);
    dir_close(&d); /* the folder is empty */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_stage_names_and_colors), cmocka_unit_test(test_svg_known_spans),
        cmocka_unit_test(test_svg_many_spans_merged),  cmocka_unit_test(test_capacity_overflow),
        cmocka_unit_test(test_concurrent_adds),        cmocka_unit_test(test_null_timeline),
        cmocka_unit_test(test_missing_folder),         cmocka_unit_test(test_create_bad_arguments),
        cmocka_unit_test(test_overflow_keeps_counting)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
