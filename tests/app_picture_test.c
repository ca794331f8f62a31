/* tests/app_picture_test.c — the finished picture from the command line (issue 28): pixel
 * filters, backgrounds and the default lighting of a glTF file, run through the `raystream`
 * binary.
 *
 *   - --filter: the default is Blackman-Harris 1.5 (the EXR header says so); every filter gives
 *     the same image bit for bit on the stream engine, the megakernel and the CPU + GPU-fallback
 *     device set (the filter is drawn in the one RS_HD camera step); filters differ from each
 *     other; a checkpoint made with one filter is refused with another, naming --filter, and
 *     resumed with its own equals the uninterrupted render;
 *   - --background: a grey is exactly that radiance where rays leave the scene; a glTF file
 *     with no --background is lit by the default sky (the summary and the header say so) where
 *     --background 0 leaves it black; sky parameters are checked before the render (one line
 *     naming the key, status 2); a scene file's "background": {"sky": ...} is read, and a bad
 *     key is named with the file;
 *   - --denoise: without OIDN, one line saying how to get it and no image; with it, the EXR's
 *     layer "noisy" is the render without --denoise bit for bit, the header and summary name the
 *     device, and the denoised image is closer to a 1024-spp reference than the noisy one and
 *     the same bit for bit on cpu:1,gpu (its guides the film's passes). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef RS_SOURCE_DIR
#  define RS_SOURCE_DIR "."
#endif

#include "cli_harness.h"
#include "core/view.h"


/* Renders builtin:cornell small with `filter` and the extra args (NULL-terminated, up to 6)
 * into `out`. */
static void render_cornell(const fixture *f, const char *filter, const char *out,
                           const char *const *extra)
{
    const char *args[24] = {"render", "builtin:cornell", "--width", "40", "--height", "30",
                            "--spp", "4", "-q", "-o", out};
    int n = 11, k;
    proc p;
    if (filter) {
        args[n++] = "--filter";
        args[n++] = filter;
    }
    for (k = 0; extra && extra[k]; ++k)
        args[n++] = extra[k];
    args[n] = NULL;
    run_expect(f, args, 0, &p);
    proc_free(&p);
}

static int same_files_pixels(const fixture *f, const char *a, const char *b)
{
    proc dummy;
    image x, y;
    int same;
    memset(&dummy, 0, sizeof dummy);
    x = read_image(&dummy, f, a);
    y = read_image(&dummy, f, b);
    same = same_image(&x, &y);
    rs_free(x.rgb);
    rs_free(y.rgb);
    return same;
}

static void test_filters_same_on_every_integrator(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const mk[] = {"--integrator", "megakernel", "--devices", "cpu", NULL};
    static const char *const fb[] = {"--devices", "cpu:1,gpu", NULL};
    static const char *const filters[] = {"box:2", "gaussian", "blackman-harris:2", "mitchell"};
    char path[256], value[64];
    proc p;
    size_t k;
    memset(&p, 0, sizeof p);
    render_cornell(f, NULL, "default.exr", NULL);
    render_cornell(f, "blackman-harris:1.5", "bh.exr", NULL);
    path_in(f, "default.exr", path, sizeof path);
    EXPECT(&p, rs_image_read_meta(path, "raystream:filter", value, sizeof value) == RS_OK &&
                   strcmp(value, "blackman-harris:1.5") == 0,
           "the default filter is '%s' in the header, not blackman-harris:1.5", value);
    EXPECT(&p, same_files_pixels(f, "default.exr", "bh.exr"),
           "the default is not blackman-harris:1.5");
    render_cornell(f, "box", "box.exr", NULL);
    EXPECT(&p, !same_files_pixels(f, "default.exr", "box.exr"), "box and blackman-harris agree");
    for (k = 0; k < sizeof filters / sizeof filters[0]; ++k) {
        render_cornell(f, filters[k], "s.exr", NULL);
        render_cornell(f, filters[k], "m.exr", mk);
        render_cornell(f, filters[k], "g.exr", fb);
        EXPECT(&p, same_files_pixels(f, "s.exr", "m.exr"),
               "--filter %s: the megakernel's image is not the stream engine's", filters[k]);
        EXPECT(&p, same_files_pixels(f, "s.exr", "g.exr"),
               "--filter %s: cpu + gpu-fallback is not the cpu's image", filters[k]);
        EXPECT(&p, !same_files_pixels(f, "s.exr", "box.exr"), "--filter %s is the box",
               filters[k]);
    }
}

static void test_filter_in_checkpoint(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const half[] = {"render", "builtin:cornell", "--width", "40", "--height",
                                       "30", "--spp", "2", "--filter", "mitchell", "--checkpoint",
                                       "c.ckpt", "-q", "-o", "half.exr", NULL};
    static const char *const other[] = {"render", "builtin:cornell", "--width", "40", "--height",
                                        "30", "--spp", "4", "--filter", "gaussian", "--resume",
                                        "c.ckpt", "-q", "-o", "r.exr", NULL};
    static const char *const other_tex[] = {"render", "builtin:cornell", "--width", "40",
                                            "--height", "30", "--spp", "4", "--filter",
                                            "mitchell", "--texture-filter", "bilinear",
                                            "--resume", "c.ckpt", "-q", "-o", "r.exr", NULL};
    static const char *const same[] = {"render", "builtin:cornell", "--width", "40", "--height",
                                       "30", "--spp", "4", "--filter", "mitchell", "--resume",
                                       "c.ckpt", "-q", "-o", "r.exr", NULL};
    proc p;
    run_expect(f, half, 0, &p);
    proc_free(&p);
    run_expect(f, other, 2, &p);
    EXPECT(&p, strstr(p.err.data, "--filter") && strstr(p.err.data, "mitchell:4") &&
                   strstr(p.err.data, "gaussian:3"),
           "the resume with another filter does not name both filters");
    proc_free(&p);
    run_expect(f, other_tex, 2, &p);
    EXPECT(&p, strstr(p.err.data, "--texture-filter trilinear") &&
                   strstr(p.err.data, "--texture-filter bilinear"),
           "the resume with another texture filter does not name it with both values");
    proc_free(&p);
    run_expect(f, same, 0, &p);
    proc_free(&p);
    render_cornell(f, "mitchell", "whole.exr", NULL);
    EXPECT(&p, same_files_pixels(f, "r.exr", "whole.exr"),
           "a resumed Mitchell render is not the uninterrupted one");
}

/* The value at pixel (x, y), channel c. */
static float pixel_of(const image *im, uint32_t x, uint32_t y, int c)
{
    return im->rgb[3 * ((size_t)y * im->w + x) + c];
}

static void test_background_and_gltf_default(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const lit[] = {"render", RS_SOURCE_DIR "/tests/data/tri.gltf", "--width",
                                      "32", "--height", "32", "--spp", "4", "-o", "lit.exr", NULL};
    static const char *const dark[] = {"render", RS_SOURCE_DIR "/tests/data/tri.gltf",
                                       "--width", "32", "--height", "32", "--spp", "4",
                                       "--background", "0", "-q", "-o", "dark.exr", NULL};
    static const char *const grey[] = {"render", RS_SOURCE_DIR "/tests/data/tri.gltf",
                                       "--width", "32", "--height", "32", "--spp", "4",
                                       "--background", "0.25,0.5,0.75", "-q", "-o", "grey.exr",
                                       NULL};
    char path[256], value[256];
    image a, b, g;
    proc p;
    run_expect(f, lit, 0, &p);
    EXPECT(&p, strstr(p.err.data, "Lit by the default sky") != NULL,
           "the summary does not say the glTF file was lit by the default sky");
    path_in(f, "lit.exr", path, sizeof path);
    EXPECT(&p, rs_image_read_meta(path, "raystream:lighting", value, sizeof value) == RS_OK &&
                   strstr(value, "default sky") != NULL,
           "the header's raystream:lighting is '%s'", value);
    a = read_image(&p, f, "lit.exr");
    proc_free(&p);
    run_expect(f, dark, 0, &p);
    b = read_image(&p, f, "dark.exr");
    EXPECT(&p, image_mean(&b) == 0.0 && image_mean(&a) > 0.05,
           "the default sky lights the triangle (mean %g) where --background 0 leaves it black "
           "(mean %g)",
           image_mean(&a), image_mean(&b));
    proc_free(&p);
    run_expect(f, grey, 0, &p);
    g = read_image(&p, f, "grey.exr");
    /* the corner sees only the background: every sample is exactly that radiance */
    EXPECT(&p, pixel_of(&g, 0, 0, 0) == 0.25f && pixel_of(&g, 0, 0, 1) == 0.5f &&
                   pixel_of(&g, 0, 0, 2) == 0.75f,
           "--background 0.25,0.5,0.75 gives (%g, %g, %g) where rays leave the scene",
           (double)pixel_of(&g, 0, 0, 0), (double)pixel_of(&g, 0, 0, 1),
           (double)pixel_of(&g, 0, 0, 2));
    proc_free(&p);
    rs_free(a.rgb);
    rs_free(b.rgb);
    rs_free(g.rgb);
}

static void test_sky_options_checked(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const bad_key[] = {"render", "--background", "sky:height=3", "-o",
                                          "x.png", NULL};
    static const char *const bad_value[] = {"render", "--background", "sky:turbidity=20",
                                            "-o", "x.png", NULL};
    static const char *const not_colour[] = {"render", "--background", "-1", "-o", "x.png",
                                             NULL};
    static const char *const twice[] = {"render", "--background", "0.5", "--envmap", "a.exr",
                                        "-o", "x.png", NULL};
    static const char *const json_sky[] = {"render", "sky.json", "--spp", "2", "-q", "-o",
                                           "sky.exr", NULL};
    static const char *const json_bad[] = {"render", "bad.json", "-q", "-o", "bad.exr", NULL};
    static const char *const scene =
        "{\"camera\": {\"from\": [0, 1, 4], \"at\": [0, 0.5, 0], \"vfov\": 40},"
        " \"image\": {\"width\": 24, \"height\": 16},"
        " \"background\": {\"sky\": {\"elevation\": 20, \"azimuth\": 60%s}},"
        " \"materials\": {\"w\": {\"type\": \"lambertian\", \"albedo\": [0.7, 0.7, 0.7]}},"
        " \"objects\": [{\"type\": \"sphere\", \"center\": [0, 0.5, 0], \"radius\": 0.5,"
        " \"material\": \"w\"}]}";
    char text[1024];
    image im;
    proc p;
    run_expect(f, bad_key, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "height"), "a bad sky key is not named");
    proc_free(&p);
    run_expect(f, bad_value, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "turbidity") && strstr(p.err.data, "2..10"),
           "an out-of-range turbidity is not named with its range");
    proc_free(&p);
    run_expect(f, not_colour, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "is not a colour"),
           "a negative grey is not refused as a colour");
    proc_free(&p);
    run_expect(f, twice, 2, &p);
    EXPECT(&p, strstr(p.err.data, "background is given twice") != NULL,
           "two backgrounds are not refused");
    proc_free(&p);
    snprintf(text, sizeof text, scene, "");
    write_in(f, "sky.json", text);
    run_expect(f, json_sky, 0, &p);
    im = read_image(&p, f, "sky.exr");
    EXPECT(&p, image_mean(&im) > 0.05 && first_bad_value(&im) < 0,
           "a scene file's sky lights nothing (mean %g)", image_mean(&im));
    rs_free(im.rgb);
    proc_free(&p);
    snprintf(text, sizeof text, scene, ", \"haze\": 3");
    write_in(f, "bad.json", text);
    run_expect(f, json_bad, 1, &p);
    EXPECT(&p, strstr(p.err.data, "bad.json") && strstr(p.err.data, "background.sky") &&
                   strstr(p.err.data, "haze"),
           "a scene file's bad sky key is not named with the file");
    proc_free(&p);
}

static double clamp01(float x) { return x < 0.0f ? 0.0 : x > 1.0f ? 1.0 : (double)x; }

/* The root mean square difference of two same-size images in the display range [0, 1] (the
 * light itself, 15 against an interior below 1, would weigh its border's few pixels above all
 * the rest: docs/denoise.md). */
static double rmse(const image *a, const image *b)
{
    size_t i, n = (size_t)a->w * a->h * 3;
    double s = 0.0;
    for (i = 0; i < n; ++i)
        s += (clamp01(a->rgb[i]) - clamp01(b->rgb[i])) * (clamp01(a->rgb[i]) - clamp01(b->rgb[i]));
    return sqrt(s / (double)n);
}

static void test_denoise(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const den[] = {"render", "builtin:cornell", "--width", "48", "--height",
                                      "48", "--spp", "16", "--denoise", "-o", "d.exr", NULL};
    static const char *const raw[] = {"render", "builtin:cornell", "--width", "48", "--height",
                                      "48", "--spp", "16", "-q", "-o", "raw.exr", NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "48", "--height",
                                      "48", "--spp", "1024", "-q", "-o", "ref.exr", NULL};
    static const char *const missing[] = {"render", "--denoise", "-q", "-o", "never.png", NULL};
    char path[256], value[200];
    image d, n, r, q;
    float *noisy[3];
    uint32_t w, h;
    int c;
    proc p;
    setenv("RS_OIDN_LIBRARY", "/nonexistent/libOpenImageDenoise.so.2", 1);
    run_expect(f, missing, 1, &p);
    unsetenv("RS_OIDN_LIBRARY");
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "--denoise") &&
                   strstr(p.err.data, "install-deps.sh"),
           "--denoise without OIDN does not say how to get it in one line");
    path_in(f, "never.png", path, sizeof path);
    EXPECT(&p, !file_exists(path), "--denoise without OIDN wrote an image");
    proc_free(&p);
    {
        /* RS_OIDN_LIBRARY naming a FIFO (dlopen blocked for ever) or a library cut short (the
         * loader died of SIGBUS): one line each, before any render (issue 39) */
        char fifo[256], cut[256], buf[65536];
        FILE *in = fopen(RS_FAKE_OIDN, "rb"), *out;
        size_t got;
        path_in(f, "oidn.fifo", fifo, sizeof fifo);
        path_in(f, "libcut.so.2", cut, sizeof cut);
        assert_int_equal(mkfifo(fifo, 0600), 0);
        setenv("RS_OIDN_LIBRARY", fifo, 1);
        run_expect(f, missing, 1, &p);
        EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "oidn.fifo") &&
                       strstr(p.err.data, "regular file"),
               "RS_OIDN_LIBRARY naming a FIFO: %s", p.err.data);
        proc_free(&p);
        assert_non_null(in);
        got = fread(buf, 1, sizeof buf, in);
        fclose(in);
        assert_true(got > 4096);
        out = fopen(cut, "wb");
        assert_non_null(out);
        fwrite(buf, 1, got / 2, out); /* its headers whole, its segments and tables cut */
        fclose(out);
        setenv("RS_OIDN_LIBRARY", cut, 1);
        run_expect(f, missing, 1, &p);
        unsetenv("RS_OIDN_LIBRARY");
        EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "libcut.so.2") &&
                       strstr(p.err.data, "cut short"),
               "RS_OIDN_LIBRARY naming a library cut short: %s", p.err.data);
        proc_free(&p);
        unlink(fifo);
        unlink(cut);
    }
    run(&p, f->dir, DEFAULT_TIMEOUT_S, den);
    if (exited_with(&p, 1) && strstr(p.err.data, "raystream: --denoise: ")) {
        printf("  skipped: %s", p.err.data); /* no OIDN here, or a sanitizer build */
        proc_free(&p);
        skip();
    }
    EXPECT(&p, exited_with(&p, 0), "--denoise failed");
    EXPECT(&p, strstr(p.err.data, "Denoised with Open Image Denoise on CPU") != NULL,
           "the summary does not say the image was denoised on the CPU");
    path_in(f, "d.exr", path, sizeof path);
    EXPECT(&p, rs_image_read_meta(path, "raystream:denoised", value, sizeof value) == RS_OK &&
                   strncmp(value, "CPU", 3) == 0,
           "the header's raystream:denoised is '%s'", value);
    proc_free(&p);
    run_expect(f, raw, 0, &p);
    proc_free(&p);
    run_expect(f, ref, 0, &p);
    d = read_image(&p, f, "d.exr");
    r = read_image(&p, f, "raw.exr");
    q = read_image(&p, f, "ref.exr");
    /* the raw beauty is kept as the layer "noisy", bit for bit the render without --denoise */
    n = r;
    for (c = 0; c < 3; ++c) {
        static const char *const ch[3] = {"noisy.R", "noisy.G", "noisy.B"};
        uint32_t i;
        EXPECT(&p, rs_image_read_channel(path, ch[c], &w, &h, &noisy[c]) == RS_OK,
               "d.exr has no channel %s", ch[c]);
        for (i = 0; i < w * h; ++i)
            EXPECT(&p, memcmp(&noisy[c][i], &r.rgb[3 * i + c], sizeof(float)) == 0,
                   "d.exr's %s differs from the render without --denoise at pixel %u", ch[c], i);
        rs_free(noisy[c]);
    }
    printf("  16 spp against 1024: RMSE %.4f noisy, %.4f denoised\n", rmse(&n, &q), rmse(&d, &q));
    EXPECT(&p, rmse(&d, &q) < 0.7 * rmse(&n, &q) && first_bad_value(&d) < 0,
           "the denoised image (RMSE %g) is not closer to the reference than the noisy one (%g)",
           rmse(&d, &q), rmse(&n, &q));
    {
        /* on cpu + gpu (the fallback here) the same denoised image, bit for bit: its guides and
         * its direct emission are the film's passes, the same bits on any device set */
        static const char *const den2[] = {"render",    "builtin:cornell", "--width", "48",
                                           "--height",  "48",              "--spp",   "16",
                                           "--denoise", "--devices",       "cpu:1,gpu", "-q",
                                           "-o",        "d2.exr",          NULL};
        image d2;
        proc p2;
        run_expect(f, den2, 0, &p2);
        d2 = read_image(&p2, f, "d2.exr");
        EXPECT(&p2, same_image(&d, &d2), "--denoise on cpu:1,gpu is not the cpu's denoised image");
        rs_free(d2.rgb);
        proc_free(&p2);
    }
    rs_free(d.rgb);
    rs_free(r.rgb);
    rs_free(q.rgb);
    proc_free(&p);
    {
        /* (where OIDN itself runs: a sanitizer build refuses every OIDN) an OIDN that loads
         * but makes no device (tests/fake_oidn.c, as without its CPU device module): refused
         * before the render (issue 39: found only after it, the render lost), which this
         * render's million samples a pixel would outlast the test's time limit */
        static const char *const nodev[] = {"render", "--denoise", "--width", "64", "--height",
                                            "64", "--spp", "1000000", "-q", "-o", "never.png",
                                            NULL};
        path_in(f, "never.png", path, sizeof path);
        setenv("RS_OIDN_LIBRARY", RS_FAKE_OIDN, 1);
        run_expect(f, nodev, 1, &p);
        unsetenv("RS_OIDN_LIBRARY");
        EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "--denoise") &&
                       strstr(p.err.data, "cannot make its CPU device") &&
                       strstr(p.err.data, "fake_oidn"),
               "an OIDN without devices is not named in one line: %s", p.err.data);
        EXPECT(&p, !file_exists(path), "--denoise with an OIDN without devices wrote an image");
        proc_free(&p);
    }
    {
        /* a denoise that fails after the render all the same: the image as rendered and the
         * checkpoint are written, then the failure is reported (status 1) */
        static const char *const late[] = {"render", "--denoise", "--width", "16", "--height",
                                           "16", "--spp", "4", "-q", "-o", "late.png",
                                           "--checkpoint", "late.ckpt", NULL};
        char ck[256];
        setenv("RS_OIDN_LIBRARY", RS_FAKE_OIDN, 1);
        setenv("FAKE_OIDN_LATE", "1", 1);
        run_expect(f, late, 1, &p);
        unsetenv("FAKE_OIDN_LATE");
        unsetenv("RS_OIDN_LIBRARY");
        path_in(f, "late.png", path, sizeof path);
        path_in(f, "late.ckpt", ck, sizeof ck);
        EXPECT(&p, strstr(p.err.data, "failed as it ran") &&
                       strstr(p.err.data, "written as rendered, not denoised"),
               "a late denoise failure is not reported: %s", p.err.data);
        EXPECT(&p, file_exists(path) && file_exists(ck),
               "a late denoise failure lost the image or the checkpoint");
        proc_free(&p);
    }
    {
        /* Ctrl-C: the samples so far are written at once as rendered, not denoised (issue 41:
         * the denoiser ran after the interrupt; here it would fail as it ran, status 1) */
        static const char *const stop[] = {"render", "--denoise", "--width", "64", "--height",
                                           "64", "--spp", "1000000", "-o", "stopped.png", NULL};
        int i;
        setenv("RS_OIDN_LIBRARY", RS_FAKE_OIDN, 1);
        setenv("FAKE_OIDN_LATE", "1", 1);
        proc_start(&p, f->dir, stop);
        unsetenv("FAKE_OIDN_LATE");
        unsetenv("RS_OIDN_LIBRARY");
        for (i = 0; i < 15; ++i) /* its handlers installed, rendering */
            proc_pump(&p, 100);
        assert_int_equal(kill(p.pid, SIGINT), 0);
        proc_finish(&p, DEFAULT_TIMEOUT_S);
        path_in(f, "stopped.png", path, sizeof path);
        EXPECT(&p, exited_with(&p, 128 + SIGINT), "Ctrl-C with --denoise: not status 130");
        EXPECT(&p, strstr(p.err.data, "not denoised") && !strstr(p.err.data, "failed as it ran"),
               "Ctrl-C with --denoise: the denoiser ran, or the skip was not said: %s",
               p.err.data);
        EXPECT(&p, file_exists(path), "Ctrl-C with --denoise lost the image");
        proc_free(&p);
    }
}

/* A corrupt PNG texture of a glTF file, beside it or as a data: URI: one line of ours, no
 * line of libpng's own (issue 39 saw a second one; not reproduced since, kept as a guard). */
static void test_corrupt_texture_one_line(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const unsigned char bad_png[] = {
        0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0, 16,
        0,    0,   0,   16,  8,     2,     0,    0,    0, 0x90, 0x91, 0x68, 0x36, 0, 0, 0, 5,
        'I',  'D', 'A', 'T', 'x',   'x',   'x',  'x',  'x'};
    static const char *const args[] = {"render", "bad.gltf", "--spp", "1", "--width", "16",
                                       "--height", "16", "-q", "-o", "never.png", NULL};
    static const char k_uri[] = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAIAAAABCAIAAAB7QOjdAAAADUlEQVR4nGP4zwAE/wEHAAH/4iOeWQAAAABJRU5ErkJggg==";
    static const char k_bad64[] = "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAABAAAAAQCAIAAACQkWg2AAAABUlEQVR4eHh4eA==";
    char *text, *at, path[256], *doc;
    size_t n;
    FILE *in = fopen(RS_SOURCE_DIR "/tests/data/texture_transform.gltf", "rb"), *out;
    int k;
    proc p;
    assert_non_null(in);
    text = (char *)calloc(1, 16384);
    doc = (char *)calloc(1, 16384);
    assert_true(text && doc);
    n = fread(text, 1, 16383, in);
    fclose(in);
    assert_true(n > 0);
    at = strstr(text, k_uri);
    assert_non_null(at);
    path_in(f, "bad.png", path, sizeof path);
    out = fopen(path, "wb");
    assert_non_null(out);
    fwrite(bad_png, 1, sizeof bad_png, out);
    fclose(out);
    for (k = 0; k < 2; ++k) {
        snprintf(doc, 16384, "%.*s%s%s", (int)(at - text), text, k == 0 ? "bad.png" : k_bad64,
                 at + strlen(k_uri));
        write_in(f, "bad.gltf", doc);
        run_expect(f, args, 1, &p);
        EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "bad.gltf") &&
                       strstr(p.err.data, "IDAT"),
               "a corrupt PNG texture (%s) is not one line: %s", k == 0 ? "a file" : "data: URI",
               p.err.data);
        proc_free(&p);
    }
    free(text);
    free(doc);
}

/* $OCIO naming a FIFO: one line, not a hang (issue 39: OpenColorIO's reader blocked for ever). */
static void test_ocio_fifo(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "--view", "Foo", "-q", "-o", "never.png", NULL};
    char fifo[256];
    proc p;
    if (!rs_view_ocio_available()) {
        printf("  skipped: this build's OpenImageIO has no OpenColorIO\n");
        skip();
    }
    path_in(f, "config.fifo", fifo, sizeof fifo);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    setenv("OCIO", fifo, 1);
    run_expect(f, args, 2, &p);
    unsetenv("OCIO");
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "config.fifo") &&
                   strstr(p.err.data, "not a regular file"),
           "$OCIO naming a FIFO: %s", p.err.data);
    proc_free(&p);
    unlink(fifo);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_filters_same_on_every_integrator, setup, teardown),
        cmocka_unit_test_setup_teardown(test_filter_in_checkpoint, setup, teardown),
        cmocka_unit_test_setup_teardown(test_background_and_gltf_default, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sky_options_checked, setup, teardown),
        cmocka_unit_test_setup_teardown(test_denoise, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ocio_fifo, setup, teardown),
        cmocka_unit_test_setup_teardown(test_corrupt_texture_one_line, setup, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
