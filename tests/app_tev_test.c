/* tests/app_tev_test.c — `raystream render --tev [HOST:]PORT` against a fake tev: a thread of
 * this test listening on a loopback port, taking every byte the command sends.  The packets are
 * checked field by field against tev's protocol (its scripts/ipc.py): a CreateImage (type 4:
 * grab-focus byte, the name, width, height, 3 channels R, G, B), then UpdateImage tiles (type 6:
 * the name, the channels, x, y, w, h inside the image, offsets 0, 1, 2 and strides 3, then
 * w * h * 3 floats), each packet's length its first four bytes.  The last update of every tile,
 * put together, is the command's output image bit for bit.  A tev that is not there, or that
 * goes away during the render, costs one warning line and the render finishes as it would
 * have; a malformed --tev is a usage error. */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <netinet/in.h>
#include <sys/socket.h>

#define RS_HARNESS_NAME "app_tev_test.c"
#include "cli_harness.h"

#define W 160
#define H 100

/* ---- the fake tev ------------------------------------------------------------------------- */

typedef struct fake_tev {
    int listen_fd;
    int port;
    size_t close_after; /* bytes to take before closing the connection (0: all) */
    buf got;            /* every byte received */
    pthread_t thread;
} fake_tev;

static void *serve(void *arg)
{
    fake_tev *t = (fake_tev *)arg;
    char chunk[65536];
    ssize_t n;
    int fd = accept(t->listen_fd, NULL, NULL);
    if (fd < 0)
        return NULL;
    while ((n = read(fd, chunk, sizeof chunk)) > 0) {
        buf_append(&t->got, chunk, (size_t)n);
        if (t->close_after && t->got.len >= t->close_after)
            break;
    }
    close(fd);
    return NULL;
}

static void fake_start(fake_tev *t, size_t close_after)
{
    struct sockaddr_in a;
    socklen_t len = sizeof a;
    memset(t, 0, sizeof *t);
    t->close_after = close_after;
    t->listen_fd = socket(AF_INET, SOCK_STREAM, 0);
    assert_true(t->listen_fd >= 0);
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(t->listen_fd, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(listen(t->listen_fd, 1), 0);
    assert_int_equal(getsockname(t->listen_fd, (struct sockaddr *)&a, &len), 0);
    t->port = ntohs(a.sin_port);
    assert_int_equal(pthread_create(&t->thread, NULL, serve, t), 0);
}

static void fake_stop(fake_tev *t)
{
    shutdown(t->listen_fd, SHUT_RDWR); /* an accept() still waiting returns */
    pthread_join(t->thread, NULL);
    close(t->listen_fd);
}

static void fake_free(fake_tev *t) { free(t->got.data); }

/* A port nothing listens on: bound, then closed. */
static int free_port(void)
{
    struct sockaddr_in a;
    socklen_t len = sizeof a;
    int fd = socket(AF_INET, SOCK_STREAM, 0), port;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    assert_int_equal(bind(fd, (struct sockaddr *)&a, sizeof a), 0);
    assert_int_equal(getsockname(fd, (struct sockaddr *)&a, &len), 0);
    port = ntohs(a.sin_port);
    close(fd);
    return port;
}

/* ---- reading the packets ------------------------------------------------------------------ */

typedef struct reader {
    const unsigned char *p, *end;
} reader;

static uint32_t rd_u32(reader *r)
{
    uint32_t v;
    assert_true(r->end - r->p >= 4);
    v = (uint32_t)r->p[0] | (uint32_t)r->p[1] << 8 | (uint32_t)r->p[2] << 16 |
        (uint32_t)r->p[3] << 24;
    r->p += 4;
    return v;
}

static int64_t rd_i64(reader *r)
{
    uint64_t lo = rd_u32(r), hi = rd_u32(r);
    return (int64_t)(lo | hi << 32);
}

static unsigned rd_u8(reader *r)
{
    assert_true(r->p < r->end);
    return *r->p++;
}

static const char *rd_str(reader *r)
{
    const char *s = (const char *)r->p;
    const unsigned char *z = memchr(r->p, 0, (size_t)(r->end - r->p));
    assert_non_null(z);
    r->p = z + 1;
    return s;
}

static void expect_rgb_channels(reader *r)
{
    assert_int_equal(rd_u32(r), 3);
    assert_string_equal(rd_str(r), "R");
    assert_string_equal(rd_str(r), "G");
    assert_string_equal(rd_str(r), "B");
}

/* Checks every packet in `got`; puts the tiles into img (W x H RGB); returns the number of
 * updates of the tile at (0, 0), i.e. how many images were sent. */
static int read_packets(const buf *got, const char *name, float *img)
{
    reader all = {(const unsigned char *)got->data, (const unsigned char *)got->data + got->len};
    int first = 1, images = 0;
    while (all.p < all.end) {
        reader r;
        uint32_t len = rd_u32(&all), type;
        all.p -= 4;
        assert_true(len >= 6 && len <= (size_t)(all.end - all.p));
        r.p = all.p + 4;
        r.end = all.p + len;
        all.p += len;
        type = rd_u8(&r);
        if (first) { /* CreateImage */
            assert_int_equal(type, 4);
            rd_u8(&r);
            assert_string_equal(rd_str(&r), name);
            assert_int_equal(rd_u32(&r), W);
            assert_int_equal(rd_u32(&r), H);
            expect_rgb_channels(&r);
            assert_true(r.p == r.end);
            first = 0;
            continue;
        }
        assert_int_equal(type, 6); /* UpdateImage */
        {
            uint32_t x, y, w, h, row, c;
            rd_u8(&r);
            assert_string_equal(rd_str(&r), name);
            expect_rgb_channels(&r);
            x = rd_u32(&r), y = rd_u32(&r), w = rd_u32(&r), h = rd_u32(&r);
            assert_true(w >= 1 && h >= 1 && x + w <= W && y + h <= H);
            for (c = 0; c < 3; ++c)
                assert_int_equal(rd_i64(&r), c);
            for (c = 0; c < 3; ++c)
                assert_int_equal(rd_i64(&r), 3);
            assert_int_equal((size_t)(r.end - r.p), (size_t)w * h * 3 * sizeof(float));
            for (row = 0; row < h; ++row)
                memcpy(img + 3 * ((size_t)(y + row) * W + x), r.p + (size_t)row * w * 12,
                       (size_t)w * 12);
            images += x == 0 && y == 0;
        }
    }
    assert_false(first);
    return images;
}

/* ---- the tests ---------------------------------------------------------------------------- */

static void test_tev_packets(void **state)
{
    const fixture *f = (const fixture *)*state;
    fake_tev t;
    char spec[32];
    float *img = (float *)calloc((size_t)W * H * 3, sizeof(float));
    image out;
    proc p;
    int images;
    fake_start(&t, 0);
    snprintf(spec, sizeof spec, "127.0.0.1:%d", t.port);
    {
        const char *args[] = {"render",  "builtin:cornell", "--width", "160", "--height",
                              "100",     "--spp",           "48",      "-q",  "-o",
                              "out.pfm", "--tev",           spec,      NULL};
        run_expect(f, args, 0, &p);
    }
    fake_stop(&t);
    EXPECT(&p, p.err.len == 0, "a render with tev there warns of nothing");
    images = read_packets(&t.got, "raystream: cornell", img);
    EXPECT(&p, images >= 1, "no image was sent");
    out = read_image(&p, f, "out.pfm");
    EXPECT(&p,
           out.w == W && out.h == H && memcmp(out.rgb, img, (size_t)W * H * 3 * sizeof(float)) == 0,
           "the last image sent to tev is not the output image");
    rs_free(out.rgb);
    free(img);
    fake_free(&t);
    proc_free(&p);
}

static void expect_warning_and_image(const proc *p, const fixture *f, const char *what,
                                     const char *spp)
{
    image out, ref;
    const char *args[] = {
        "render", "builtin:cornell", "--width", "160", "--height", "100", "--spp", spp, "-q",
        "-o",     "ref.pfm",         NULL};
    proc q;
    EXPECT(p, exited_with(p, 0), "the render must go on without tev");
    EXPECT(p,
           one_line(&p->err) && strstr(p->err.data, "warning: --tev") && strstr(p->err.data, what),
           "one warning line saying '%s'", what);
    run_expect(f, args, 0, &q);
    out = read_image(p, f, "out.pfm");
    ref = read_image(&q, f, "ref.pfm");
    EXPECT(p, same_image(&out, &ref), "the image differs from a render without --tev");
    rs_free(out.rgb);
    rs_free(ref.rgb);
    proc_free(&q);
}

static void test_tev_absent(void **state)
{
    const fixture *f = (const fixture *)*state;
    char spec[32];
    proc p;
    snprintf(spec, sizeof spec, "%d", free_port()); /* PORT alone: 127.0.0.1 */
    {
        const char *args[] = {"render",  "builtin:cornell", "--width", "160", "--height",
                              "100",     "--spp",           "48",      "-q",  "-o",
                              "out.pfm", "--tev",           spec,      NULL};
        run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
    }
    expect_warning_and_image(&p, f, "cannot reach tev", "48");
    proc_free(&p);
}

static void test_tev_goes_away(void **state)
{
    const fixture *f = (const fixture *)*state;
    fake_tev t;
    char spec[32];
    proc p;
    fake_start(&t, 1); /* closes after the first bytes */
    snprintf(spec, sizeof spec, "localhost:%d", t.port);
    { /* long enough for several updates after tev left */
        const char *args[] = {"render",  "builtin:cornell", "--width", "160", "--height",
                              "100",     "--spp",           "200",     "-q",  "-o",
                              "out.pfm", "--tev",           spec,      NULL};
        run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
    }
    fake_stop(&t);
    expect_warning_and_image(&p, f, "tev went away", "200");
    fake_free(&t);
    proc_free(&p);
}

static void test_tev_bad_spec(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const bad[] = {"", "host:", "70000", "x:0", "abc"};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        const char *args[] = {"render", "builtin:cornell", "--tev", bad[i], NULL};
        proc p;
        run(&p, f->dir, EARLY_FAIL_LIMIT_S, args);
        EXPECT(&p, exited_with(&p, 2) && one_line(&p.err) && strstr(p.err.data, "--tev"),
               "--tev '%s' is a usage error of one line", bad[i]);
        proc_free(&p);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_tev_packets, setup, teardown),
        cmocka_unit_test_setup_teardown(test_tev_absent, setup, teardown),
        cmocka_unit_test_setup_teardown(test_tev_goes_away, setup, teardown),
        cmocka_unit_test_setup_teardown(test_tev_bad_spec, setup, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
