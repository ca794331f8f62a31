/* tests/app_cli_test.c — the `raystream` command as a user meets it: the real binary (RS_BINARY),
 * started with fork/execv (no shell) inside a fresh temporary folder, stdout and stderr captured,
 * killed and failed past a time limit.
 *
 * What is checked:
 *   - usage errors (unknown option or command, bad or out-of-range numbers, a missing value, an
 *     unknown built-in scene, sampling mode or device, an unsupported extension, a missing scene
 *     file) exit with 2, print exactly one line on stderr naming the problem, nothing on stdout,
 *     and write nothing;
 *   - an output that cannot be written (missing folder; read-only folder when not root; a
 *     folder, a read-only file or a missing folder for -o, --stats-json or --timeline; two
 *     outputs on one file) exits with 2 before any rendering, with one line naming the path, and
 *     writes nothing; a scene file that is a folder and a bad RS_FAULT are usage errors too;
 *   - --help, render --help, --version and scenes exit 0 and print to stdout;
 *   - a small render writes a PNG of the requested size that is not black and prints a summary
 *     with samples/s and rays/s; .exr and .hdr work and hold finite, non-negative linear values;
 *     without -o the image goes to cornell.png in the working folder; no temporary file is left;
 *   - a failing run leaves an existing output byte for byte as it was, also when it fails
 *     writing --stats-json after the render (the image is not replaced either);
 *   - SIGINT, SIGTERM and SIGHUP during a long render exit with 128 + the signal and write the
 *     partial image at full size; a second SIGINT while the image is being written kills the
 *     program and leaves no temporary file and every old output as it was;
 *   - a reader of stderr that goes away (`2>&1 | head -1`) does not stop the render;
 *   - --threads, --chunk-size and --wave-size change nothing in the pixels (bit-identical .exr).
 *
 * Every test gets its own folder from mkdtemp under /tmp, removed afterwards, so nothing is
 * written into the source or build tree.  The whole program runs in a few seconds on 2 cores. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifndef RS_SOURCE_DIR
#  define RS_SOURCE_DIR "."
#endif

#include "gpu/gpu_device.h"

#include "cli_harness.h"

/* ---- 1. usage errors ------------------------------------------------------------------------- */

typedef struct usage_case {
    const char *args[12];
    const char *words[4]; /* each must appear in the one stderr line */
} usage_case;

/* The names `raystream scenes` lists ("builtin:NAME  description" per line), space-separated. */
static void builtin_names(const fixture *f, char *names, size_t n)
{
    static const char *const args[] = {"scenes", NULL};
    proc p;
    const char *s;
    size_t used = 0;
    run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
    EXPECT(&p, exited_with(&p, 0), "'raystream scenes' failed");
    names[0] = '\0';
    for (s = strstr(p.out.data, "builtin:"); s; s = strstr(s, "builtin:")) {
        size_t k;
        s += 8;
        k = strcspn(s, " \t\n");
        if (used + k + 2 < n) {
            used += (size_t)snprintf(names + used, n - used, "%s%.*s", used ? " " : "", (int)k, s);
        }
        s += k;
    }
    EXPECT(&p, strstr(names, "cornell") != NULL, "'raystream scenes' does not list cornell");
    proc_free(&p);
}

static void test_usage_errors(void **state)
{
    const fixture *f = (const fixture *)*state;
    /* Each case but the unknown command starts from a small valid render into out.png, so a
     * parser that let the bad argument through would write out.png (and fail the check). */
    static const usage_case cases[] = {
        {{"render", "-o", "out.png", "--spp", "1", "--bogus", NULL}, {"--bogus"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive", "0", NULL}, {"--adaptive", "'0'"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive", "1.5", NULL}, {"--adaptive"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive", "nan", NULL}, {"--adaptive"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive-min-spp", "8", NULL},
         {"--adaptive-min-spp", "--adaptive"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive", "0.1", "--adaptive-min-spp", "1",
          NULL},
         {"--adaptive-min-spp"}},
        {{"render", "-o", "out.png", "--spp", "1", "--adaptive", "0.1", "--integrator",
          "megakernel", NULL},
         {"--adaptive", "megakernel"}},
        {{"rendr", "-o", "out.png", NULL}, {"rendr", "command"}},
        /* issue 39: a trailing comma rendered a grey 0.5; filter widths that rendered something
         * else (black, the default width) */
        {{"render", "-o", "out.png", "--spp", "1", "--background", "0.5,", NULL},
         {"--background", "'0.5,'"}},
        {{"render", "-o", "out.png", "--spp", "1", "--background", "0.5,0.5,0.5,", NULL},
         {"--background", "not a colour"}},
        {{"render", "-o", "out.png", "--spp", "1", "--filter", "mitchell:1e-38", NULL},
         {"--filter", "0.01"}},
        {{"render", "-o", "out.png", "--spp", "1", "--filter", "box:0.0004", NULL},
         {"--filter", "0.001"}},
        {{"render", "-o", "out.png", "--spp", "abc", NULL}, {"--spp", "abc"}},
        {{"render", "-o", "out.png", "--spp", "1", "--width", "12x", NULL}, {"--width", "12x"}},
        {{"render", "-o", "out.png", "--spp", "1", "--width", "0", NULL}, {"--width"}},
        {{"render", "-o", "out.png", "--spp", "1", "--height", "-3", NULL}, {"--height", "-3"}},
        {{"render", "-o", "out.png", "--width", "8", "--spp", "0", NULL}, {"--spp"}},
        {{"render", "-o", "out.png", "--width", "8", "--spp", NULL}, {"--spp"}},
        {{"render", "builtin:nope", "-o", "out.png", "--spp", "1", NULL}, {"nope"}},
        {{"render", "-o", "out.png", "--spp", "1", "--sampling", "sobol", NULL},
         {"--sampling", "sobol"}},
        {{"render", "-o", "out.png", "--spp", "1", "--devices", "cpu,tpu", NULL},
         {"--devices", "tpu"}},
        {{"render", "-o", "out.png", "--spp", "1", "--bvh-width", "16", NULL},
         {"--bvh-width", "16"}},
        {{"render", "-o", "out.png", "--spp", "1", "--waves", "5", NULL}, {"--waves", "5"}},
        {{"render", "-o", "out.png", "--spp", "1", "--integrator", "bdpt", NULL},
         {"--integrator", "bdpt"}},
        {{"render", "-o", "out.png", "--spp", "1", "--cpu-strategy", "guided", NULL},
         {"--cpu-strategy", "guided"}},
        {{"render", "-o", "out.png", "--spp", "1", "--cpu-walk", "pairs", NULL},
         {"--cpu-walk", "pairs"}},
        {{"render", "-o", "out.png", "--spp", "1", "--integrator", "megakernel", "--devices",
          "cpu,gpu", NULL},
         {"megakernel", "one device"}},
        {{"render", "-o", "out.png", "--spp", "1", "--devices", "cpu", "--require-gpu", NULL},
         {"--require-gpu", "--devices"}},
        {{"render", "-o", "out.png", "--spp", "1", "--chunk-size", "big", NULL},
         {"--chunk-size", "big"}},
        {{"render", "-o", "out.png", "--spp", "1", "--bvh-device", "tpu", NULL},
         {"--bvh-device", "tpu"}},
        {{"render", "-o", "out.png", "--spp", "1", "--bvh-device", "gpu", NULL},
         {"--bvh-device", "lbvh"}},
        {{"render", "--width", "8", "--spp", "1", "-o", "out.xyz", NULL}, {"out.xyz"}},
        {{"render", "no-such-scene.rss", "-o", "out.png", "--spp", "1", NULL},
         {"no-such-scene.rss"}},
        {{"render", RS_SOURCE_DIR "/scenes", "-o", "out.png", "--spp", "1", NULL},
         {"/scenes", "is a folder"}},
        {{"render", "-o", "out.png", "--spp", "1", "--stats-json", "/nonexistent-dir/s.json", NULL},
         {"--stats-json", "/nonexistent-dir"}},
        {{"render", "-o", "out.png", "--spp", "1", "--stats-json", "out.png", NULL},
         {"--stats-json", "out.png", "same file"}},
        {{"render", "-o", "out.png", "--spp", "1", "--timeline", "t.png", NULL},
         {"--timeline", "t.png", ".svg"}},
        {{"render", "-o", "out.png", "--spp", "1", "--timeline", "/nonexistent-dir/t.svg", NULL},
         {"--timeline", "/nonexistent-dir"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "0", NULL},
         {"--time-limit", "0"}},
        {{"render", "-o", "out.png", "--spp", "1", "--mpi-pass", "0", NULL},
         {"--mpi-pass", "0"}},
        {{"render", "-o", "out.png", "--spp", "1", "--mpi-timeout", "-2", NULL},
         {"--mpi-timeout", "-2"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "-1", NULL},
         {"--time-limit", "-1"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "abc", NULL},
         {"--time-limit", "abc"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "inf", NULL},
         {"--time-limit", "inf"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "nan", NULL},
         {"--time-limit", "nan"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "1e999", NULL},
         {"--time-limit", "1e999"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", "0x10", NULL},
         {"--time-limit", "0x10"}},
        {{"render", "-o", "out.png", "--spp", "1", "--time-limit", NULL}, {"--time-limit"}},
        {{"render", "-o", "out.png", "--spp", "1", "--checkpoint-interval", "5", NULL},
         {"--checkpoint-interval", "--checkpoint"}},
        {{"render", "-o", "out.png", "--spp", "1", "--checkpoint", "c.ckpt",
          "--checkpoint-interval", "0", NULL},
         {"--checkpoint-interval", "0"}},
        {{"render", "-o", "out.png", "--spp", "1", "--checkpoint", "/nonexistent-dir/c.ckpt", NULL},
         {"--checkpoint", "/nonexistent-dir"}},
        {{"render", "-o", "out.png", "--spp", "1", "--checkpoint", "out.png", NULL},
         {"--checkpoint", "out.png", "same file"}},
        {{"render", "-o", "out.png", "--spp", "1", "--resume", "no-such.ckpt", NULL},
         {"--resume", "no-such.ckpt"}},
        {{"render", "-o", "out.png", "--spp", "1", "--resume", RS_SOURCE_DIR "/scenes", NULL},
         {"--resume", "/scenes", "folder"}},
        /* found by tests/fuzz/fuzz_cli_options: an empty scene name was let through and
         * reported as ": no such scene file", naming nothing */
        {{"render", "", "-o", "out.png", "--spp", "1", NULL}, {"empty argument", "scene"}},
        {{"render", "--scene=", "-o", "out.png", "--spp", "1", NULL}, {"--scene", "empty"}},
        {{"render", "-o", "out.png", "--spp", "1", "--scene", "", NULL}, {"--scene", "empty"}},
    };
    char known[256], names[512];
    size_t c;
    int w;

    builtin_names(f, known, sizeof known);
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        proc p;
        int n;
        run(&p, f->dir, DEFAULT_TIMEOUT_S, cases[c].args);
        EXPECT(&p, exited_with(&p, 2), "a usage error must exit with status 2");
        EXPECT(&p, one_line(&p.err), "a usage error must print exactly one line on stderr");
        EXPECT(&p, p.out.len == 0, "a usage error must print nothing on stdout");
        for (w = 0; w < 4 && cases[c].words[w]; ++w)
            EXPECT(&p, strstr(p.err.data, cases[c].words[w]) != NULL,
                   "the error line should name '%s'", cases[c].words[w]);
        if (strcmp(cases[c].args[1], "builtin:nope") == 0) {
            /* the line lists every known scene */
            char list[256], *tok, *save = NULL;
            strcpy(list, known);
            for (tok = strtok_r(list, " ", &save); tok; tok = strtok_r(NULL, " ", &save))
                EXPECT(&p, strstr(p.err.data, tok) != NULL,
                       "the error line should list the known scene '%s'", tok);
        }
        n = list_dir(f->dir, names, sizeof names);
        EXPECT(&p, n == 0, "a usage error wrote into the working folder: %s", names);
        proc_free(&p);
    }
}

/* ---- 2. an output that cannot be written ----------------------------------------------------- */

/* Runs a render that would take an hour into `out`, which cannot be written, and checks that it
 * stops at once with status 2 and one line naming `out`, leaving `n_files` entries in the
 * working folder. */
static void expect_unwritable(const fixture *f, const char *out, int n_files)
{
    const char *const args[] = {"render", "--width", "256", "--height", "256",
                                "--spp",  "100000",  "-o",  out,        NULL};
    char names[512];
    proc p;
    run(&p, f->dir, 4 * EARLY_FAIL_LIMIT_S, args);
    EXPECT(&p, !p.timed_out && p.seconds < EARLY_FAIL_LIMIT_S,
           "an unwritable output must be reported before rendering (within %.0f s)",
           EARLY_FAIL_LIMIT_S);
    EXPECT(&p, exited_with(&p, 2), "an unwritable output is a usage error: status 2");
    EXPECT(&p, one_line(&p.err), "expected exactly one line on stderr");
    EXPECT(&p, strstr(p.err.data, out) != NULL, "the error line should name '%s'", out);
    EXPECT(&p, list_dir(f->dir, names, sizeof names) == n_files,
           "something was written into the working folder, which holds: %s", names);
    proc_free(&p);
}

static void test_output_in_missing_folder(void **state)
{
    const fixture *f = (const fixture *)*state;
    char names[512];
    assert_false(file_exists("/nonexistent-dir"));
    expect_unwritable(f, "/nonexistent-dir/x.png", 0);
    assert_false(file_exists("/nonexistent-dir"));
    assert_int_equal(list_dir(f->dir, names, sizeof names), 0);
}

static void test_output_in_read_only_folder(void **state)
{
    const fixture *f = (const fixture *)*state;
    char ro[128], names[512];
    if (geteuid() == 0) {
        print_message("running as root, which ignores folder permissions: skipped\n");
        skip();
    }
    path_in(f, "ro", ro, sizeof ro);
    assert_int_equal(mkdir(ro, 0755), 0);
    assert_int_equal(chmod(ro, 0555), 0);
    expect_unwritable(f, "ro/x.png", 1);
    if (list_dir(ro, names, sizeof names) != 0)
        fail_msg("the read-only folder got files: %s", names);
    if (list_dir(f->dir, names, sizeof names) != 1)
        fail_msg("the working folder should hold only ro/, it holds: %s", names);
}

/* ---- 3. help and version --------------------------------------------------------------------- */

static void expect_stdout(const fixture *f, const char *const *args, const char *const *words)
{
    proc p;
    char names[512];
    int i;
    run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
    EXPECT(&p, exited_with(&p, 0), "expected exit status 0");
    EXPECT(&p, p.out.len > 0, "expected text on stdout");
    EXPECT(&p, p.err.len == 0, "expected nothing on stderr");
    for (i = 0; words[i]; ++i)
        EXPECT(&p, strstr(p.out.data, words[i]) != NULL, "stdout should mention '%s'", words[i]);
    EXPECT(&p, list_dir(f->dir, names, sizeof names) == 0, "files were written: %s", names);
    proc_free(&p);
}

static void test_help_and_version(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const help[] = {"--help", NULL};
    static const char *const help_words[] = {"usage: raystream", "render", "scenes", NULL};
    static const char *const render_help[] = {"render", "--help", NULL};
    static const char *const render_help_words[] = {"usage: raystream render", "--spp", "--output",
                                                    "130", NULL};
    static const char *const render_help2[] = {"render", "--spp", "4", "-h", NULL};
    static const char *const scenes[] = {"scenes", NULL};
    static const char *const scenes_words[] = {"builtin:cornell", NULL};
    static const char *const version[] = {"--version", NULL};
    static const char *const version_words[] = {"CUDA", "OpenMP", "OpenImageIO", NULL};
    proc p;

    expect_stdout(f, help, help_words);
    expect_stdout(f, render_help, render_help_words);
    expect_stdout(f, render_help2, render_help_words);
    expect_stdout(f, scenes, scenes_words);
    expect_stdout(f, version, version_words);

    run(&p, f->dir, DEFAULT_TIMEOUT_S, version);
    EXPECT(&p, strncmp(p.out.data, "raystream ", 10) == 0,
           "the version line should start with 'raystream '");
    EXPECT(&p, isdigit((unsigned char)p.out.data[10]), "a version number should follow");
    proc_free(&p);
}

/* ---- 4. rendering ---------------------------------------------------------------------------- */

/* Runs a render that must succeed and leave exactly the file `name` in the folder. */
static void render_ok(proc *p, const fixture *f, const char *const *args, const char *name)
{
    char names[512], path[256];
    int n;
    run(p, f->dir, DEFAULT_TIMEOUT_S, args);
    EXPECT(p, exited_with(p, 0), "the render should succeed");
    path_in(f, name, path, sizeof path);
    EXPECT(p, file_exists(path), "%s was not written", name);
    n = list_dir(f->dir, names, sizeof names);
    EXPECT(p, n == 1, "only %s should be in the folder (no temporary files), found: %s", name,
           names);
}

/* render_ok, then the bytes of the image it wrote (the "good output" a later run must keep). */
static char *render_good(const fixture *f, const char *const *args, const char *name, size_t *n)
{
    char path[256];
    char *bytes;
    proc p;
    render_ok(&p, f, args, name);
    proc_free(&p);
    path_in(f, name, path, sizeof path);
    bytes = read_bytes(path, n);
    assert_non_null(bytes);
    return bytes;
}

static void test_render_png(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "--width", "64", "--height", "48",
                                       "--spp",  "4",       "-o", "out.png",  NULL};
    proc p;
    image im;
    double mean;

    render_ok(&p, f, args, "out.png");
    EXPECT(&p, strstr(p.err.data, "samples/s") != NULL, "the summary should give samples/s");
    EXPECT(&p, strstr(p.err.data, "rays/s") != NULL, "the summary should give rays/s");
    EXPECT(&p, strstr(p.err.data, "out.png") != NULL, "the summary should name out.png");
    im = read_image(&p, f, "out.png");
    EXPECT(&p, im.w == 64 && im.h == 48, "out.png is %ux%u, not 64x48", im.w, im.h);
    mean = image_mean(&im);
    EXPECT(&p, mean > 0.01, "out.png is black: mean %g", mean);
    EXPECT(&p, first_bad_value(&im) < 0, "out.png has a value outside [0, 1]");
    rs_free(im.rgb);
    proc_free(&p);
}

static void test_render_float_formats(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const exr[] = {"render", "--width", "64", "--height", "48",
                                      "--spp",  "4",       "-o", "out.exr",  NULL};
    static const char *const hdr[] = {"render", "--width", "64", "--height", "48", "--spp",
                                      "4",      "-q",      "-o", "out.hdr",  NULL};
    char path[256];
    proc p;
    image im;
    double mean;
    long bad;

    render_ok(&p, f, exr, "out.exr");
    im = read_image(&p, f, "out.exr");
    EXPECT(&p, im.w == 64 && im.h == 48, "out.exr is %ux%u, not 64x48", im.w, im.h);
    bad = first_bad_value(&im);
    EXPECT(&p, bad < 0, "out.exr value %ld is %g", bad, bad < 0 ? 0.0 : (double)im.rgb[bad]);
    mean = image_mean(&im);
    EXPECT(&p, mean > 0.0 && isfinite(mean), "out.exr mean linear value is %g", mean);
    rs_free(im.rgb);
    proc_free(&p);
    path_in(f, "out.exr", path, sizeof path);
    assert_int_equal(unlink(path), 0);

    render_ok(&p, f, hdr, "out.hdr");
    EXPECT(&p, p.err.len == 0, "-q should silence the progress and the summary");
    im = read_image(&p, f, "out.hdr");
    EXPECT(&p, im.w == 64 && im.h == 48, "out.hdr is %ux%u, not 64x48", im.w, im.h);
    mean = image_mean(&im);
    EXPECT(&p, first_bad_value(&im) < 0 && mean > 0.0, "out.hdr mean linear value is %g", mean);
    rs_free(im.rgb);
    proc_free(&p);
}

static void test_render_default_output(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "--width", "32", "--spp", "1", NULL};
    proc p;
    image im;

    render_ok(&p, f, args, "cornell.png");
    im = read_image(&p, f, "cornell.png");
    /* the Cornell box is square: one size given keeps the aspect ratio */
    EXPECT(&p, im.w == 32 && im.h == 32, "cornell.png is %ux%u, not 32x32", im.w, im.h);
    rs_free(im.rgb);
    proc_free(&p);
}

/* ---- 5. a failing run keeps the old output --------------------------------------------------- */

static void test_failed_run_keeps_output(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const good[] = {"render", "--width", "24", "--height", "16", "--spp",
                                       "2",      "-q",      "-o", "good.png", NULL};
    static const char *const bad[][12] = {
        {"render", "-o", "good.png", "--width", "24", "--bogus", NULL},
        {"render", "-o", "good.png", "--width", "24", "--spp", "0", NULL},
        {"render", "builtin:nope", "-o", "good.png", "--width", "24", NULL},
        {"render", "-o", "good.png", "--width", "24", "--devices", "tpu", NULL},
    };
    char path[256], names[512];
    char *before, *after;
    size_t n_before = 0, n_after = 0, c;
    proc p;

    render_ok(&p, f, good, "good.png");
    proc_free(&p);
    path_in(f, "good.png", path, sizeof path);
    before = read_bytes(path, &n_before);
    assert_non_null(before);
    for (c = 0; c < sizeof bad / sizeof bad[0]; ++c) {
        run(&p, f->dir, DEFAULT_TIMEOUT_S, bad[c]);
        EXPECT(&p, exited_with(&p, 2), "expected a usage error");
        after = read_bytes(path, &n_after);
        EXPECT(&p, after != NULL, "good.png is gone");
        EXPECT(&p, n_after == n_before && memcmp(before, after, n_before) == 0,
               "good.png changed (%zu bytes before, %zu after)", n_before, n_after);
        free(after);
        EXPECT(&p, list_dir(f->dir, names, sizeof names) == 1,
               "only good.png should be in the folder, found: %s", names);
        proc_free(&p);
    }
    free(before);
}

/* ---- 6. Ctrl-C ------------------------------------------------------------------------------- */

/* Lets run `p` (just started) set up and install its handlers for ~1.5 s (setup takes
 * milliseconds; a progress line cannot be awaited, as the first one comes after 10% of the
 * work); fails if it ended meanwhile. */
static void let_it_render(proc *p)
{
    int i;
    for (i = 0; i < 15; ++i) {
        proc_pump(p, 100);
        if (waitpid(p->pid, &p->status, WNOHANG) == p->pid) {
            p->reaped = 1;
            p->seconds = rs_now_s() - p->start;
            EXPECT(p, 0, "the long render ended before the signal was sent");
        }
    }
}

/* One long render (args, into partial.png) stopped by `sig` after ~1.5 s must exit within
 * limit_s with 128 + sig and leave the partial image, full size, and nothing else. */
static void signal_case(const fixture *f, const char *const *args, int sig, double limit_s)
{
    char names[512];
    double sent;
    proc p;
    image im;

    proc_start(&p, f->dir, args);
    let_it_render(&p);
    sent = rs_now_s();
    assert_int_equal(kill(p.pid, sig), 0);
    proc_finish(&p, (sent - p.start) + limit_s);
    EXPECT(&p, !p.timed_out, "signal %d should end the render within %.0f s", sig, limit_s);
    EXPECT(&p, exited_with(&p, 128 + sig), "signal %d should end the render with status %d", sig,
           128 + sig);
    EXPECT(&p, contains_ci(p.err.data, "partial") || contains_ci(p.err.data, "interrupted"),
           "stderr should say the image is partial");
    EXPECT(&p, list_dir(f->dir, names, sizeof names) == 1 && strcmp(names, "partial.png") == 0,
           "the folder should hold partial.png and nothing else, it holds: %s", names);
    im = read_image(&p, f, "partial.png");
    EXPECT(&p, im.w == 256 && im.h == 256, "partial.png is %ux%u, not 256x256", im.w, im.h);
    rs_free(im.rgb);
    proc_free(&p);
    snprintf(names, sizeof names, "%s/partial.png", f->dir); /* the next case starts clean */
    unlink(names);
}

static void sigint_case(const fixture *f, const char *const *args, double limit_s)
{
    signal_case(f, args, SIGINT, limit_s);
}

static void test_sigint_writes_partial_image(void **state)
{
    /* about an hour on 2 cores: it can only end through SIGINT */
    static const char *const args[] = {"render", "--width", "256", "--height",    "256",
                                       "--spp",  "100000",  "-o",  "partial.png", NULL};
    sigint_case((const fixture *)*state, args, SIGINT_EXIT_LIMIT_S);
}

/* The megakernel too: on the CPU, split by columns, each thread starts on a column of 256
 * pixels at 100000 spp (~18 s), so it must stop within a pixel (~0.05 s), not a line: 5 s
 * allowed (the check per line alone took 17.7 s).  As the GPU megakernel's passes (here on host
 * threads) it stops between passes. */
static void test_sigint_megakernel(void **state)
{
    static const char *const cpu[] = {"render",     "--width",   "256",         "--height",
                                      "256",        "--spp",     "100000",      "--integrator",
                                      "megakernel", "--devices", "cpu",         "--cpu-strategy",
                                      "columns",    "-o",        "partial.png", NULL};
    static const char *const gpu[] = {
        "render",       "--width",    "256",       "--height", "256", "--spp",       "100000",
        "--integrator", "megakernel", "--devices", "gpu",      "-o",  "partial.png", NULL};
    const fixture *f = (const fixture *)*state;
    const char *why = "";
    sigint_case(f, cpu, 5.0);
    if (rs_gpu_count(&why) == 0) /* with a GPU its passes are milliseconds: nothing to see */
        sigint_case(f, gpu, 5.0);
}

/* SIGTERM (a supervisor, `kill`) and SIGHUP (the terminal went away) stop like Ctrl-C: the
 * samples so far are written, and the status is 128 + the signal. */
static void test_sigterm_sighup_write_partial_image(void **state)
{
    static const char *const args[] = {"render", "--width", "256", "--height",    "256",
                                       "--spp",  "100000",  "-o",  "partial.png", NULL};
    const fixture *f = (const fixture *)*state;
    signal_case(f, args, SIGTERM, SIGINT_EXIT_LIMIT_S);
    signal_case(f, args, SIGHUP, SIGINT_EXIT_LIMIT_S);
}

/* Writes `text` to the file `name` in the test folder. */
static void put_file(const fixture *f, const char *name, const char *text)
{
    char path[256];
    FILE *fp;
    path_in(f, name, path, sizeof path);
    fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    assert_int_equal(fclose(fp), 0);
}

/* 1 if the file `name` in the test folder holds exactly `len` bytes `want`. */
static int file_is(const fixture *f, const char *name, const char *want, size_t len)
{
    char path[256];
    size_t n = 0;
    char *got;
    int same;
    path_in(f, name, path, sizeof path);
    got = read_bytes(path, &n);
    same = got && n == len && memcmp(got, want, len) == 0;
    free(got);
    return same;
}

/* A second SIGINT while the image is being written: the program dies of it at once, the
 * temporary file the image was going into (OUT.tmp-PID, core/image_io's name) is removed, and
 * the old image, stats and timeline are as they were.  The image is 2048x2048 EXR, so writing it
 * takes a good fraction of a second; the test watches for the temporary file and then signals.
 * Should the write end before the signal lands (the program then exits 130), it tries again. */
#define OLD_JSON "{\"old\": true}\n"
#define OLD_SVG  "<svg>old</svg>\n"
static void test_second_signal_removes_temp_file(void **state)
{
    static const char *const good_args[] = {"render", "--width", "16",          "--spp", "1",
                                            "-q",     "-o",      "partial.exr", NULL};
    static const char *const args[] = {"render",  "--width",     "2048",   "--height",
                                       "2048",    "--spp",       "100000", "--stats-json",
                                       "st.json", "--timeline",  "t.svg",  "-q",
                                       "-o",      "partial.exr", NULL};
    const fixture *f = (const fixture *)*state;
    char path[256], tmp[300], names[512];
    char *good;
    size_t n_good = 0;
    int attempt, caught = 0;
    proc p;

    good = render_good(f, good_args, "partial.exr", &n_good);
    path_in(f, "partial.exr", path, sizeof path);
    put_file(f, "st.json", OLD_JSON);
    put_file(f, "t.svg", OLD_SVG);
    for (attempt = 0; attempt < 3 && !caught; ++attempt) {
        double deadline;
        int seen = 0;
        proc_start(&p, f->dir, args);
        snprintf(tmp, sizeof tmp, "%s.tmp-%ld", path, (long)p.pid);
        let_it_render(&p);
        assert_int_equal(kill(p.pid, SIGINT), 0);
        deadline = rs_now_s() + SIGINT_EXIT_LIMIT_S;
        while (!seen && rs_now_s() < deadline) {
            if (file_exists(tmp)) {
                seen = 1;
                kill(p.pid, SIGINT);
            } else if (waitpid(p.pid, &p.status, WNOHANG) == p.pid) {
                p.reaped = 1;
                break;
            } else {
                sleep_s(0.0005);
            }
        }
        proc_finish(&p, (rs_now_s() - p.start) + SIGINT_EXIT_LIMIT_S);
        EXPECT(&p, seen || !exited_with(&p, 130),
               "the image was written without %s ever existing: is core/image_io's temporary "
               "name still OUT.tmp-PID?",
               tmp);
        EXPECT(&p, seen, "the render did not stop and write within %.0f s", SIGINT_EXIT_LIMIT_S);
        caught = WIFSIGNALED(p.status) && WTERMSIG(p.status) == SIGINT;
        EXPECT(&p, caught || exited_with(&p, 130),
               "a second SIGINT while writing should kill the program (or come too late)");
        EXPECT(&p, list_dir(f->dir, names, sizeof names) == 3,
               "the folder should hold partial.exr, st.json and t.svg only, it holds: %s", names);
        EXPECT(&p, caught || file_exists(path), "partial.exr is gone");
        if (caught) {
            EXPECT(&p, file_is(f, "partial.exr", good, n_good),
                   "the old partial.exr was replaced by a killed run");
            EXPECT(&p, file_is(f, "st.json", OLD_JSON, strlen(OLD_JSON)),
                   "the old st.json was replaced by a killed run");
            EXPECT(&p, file_is(f, "t.svg", OLD_SVG, strlen(OLD_SVG)),
                   "the old t.svg was replaced by a killed run");
        } else { /* the write won the race: put the old files back and try again */
            FILE *fp = fopen(path, "wb");
            assert_non_null(fp);
            assert_int_equal(fwrite(good, 1, n_good, fp), n_good);
            assert_int_equal(fclose(fp), 0);
            put_file(f, "st.json", OLD_JSON);
            put_file(f, "t.svg", OLD_SVG);
        }
        proc_free(&p);
    }
    free(good);
    if (!caught)
        fail_msg("three times the image was written before the second SIGINT landed");
}

/* `raystream render ... 2>&1 | head -1`: the reader takes one line and goes away.  The render
 * must go on (SIGPIPE ignored, EPIPE on stderr harmless) and write its image. */
static void test_reader_gone_keeps_rendering(void **state)
{
    static const char *const args[] = {"render", "--width", "160",      "--spp",
                                       "64",     "-o",      "pipe.png", NULL};
    const fixture *f = (const fixture *)*state;
    proc p;
    image im;
    double deadline;
    proc_start(&p, f->dir, args);
    deadline = rs_now_s() + DEFAULT_TIMEOUT_S;
    while (!strchr(p.err.data, '\n') && p.err_fd >= 0 && rs_now_s() < deadline)
        proc_pump(&p, 20);
    EXPECT(&p, strchr(p.err.data, '\n') != NULL, "expected a progress line on stderr");
    if (p.out_fd >= 0)
        close(p.out_fd);
    if (p.err_fd >= 0)
        close(p.err_fd);
    p.out_fd = p.err_fd = -1;
    proc_finish(&p, DEFAULT_TIMEOUT_S);
    EXPECT(&p, exited_with(&p, 0), "the render should go on after its reader went away");
    im = read_image(&p, f, "pipe.png");
    EXPECT(&p, im.w == 160 && im.h == 160 && image_mean(&im) > 0.01,
           "pipe.png is %ux%u with mean %g", im.w, im.h, image_mean(&im));
    rs_free(im.rgb);
    proc_free(&p);
}

/* Every output is checked before the render: a folder, a missing folder, a read-only file or
 * folder, for -o, --stats-json and --timeline, is refused at once (status 2, one line naming it),
 * and the good image already at -o stays byte for byte. */
static void test_outputs_checked_first(void **state)
{
    static const char *const good_args[] = {"render", "--width", "16",       "--spp", "1",
                                            "-q",     "-o",      "good.png", NULL};
    typedef struct out_case {
        const char *opt, *path, *word;
        int needs_non_root;
    } out_case;
    static const out_case cases[] = {
        {"-o", "dir.png", "folder", 0},
        {"--stats-json", "dir.png", "folder", 0},
        {"--timeline", "dir.svg", "folder", 0},
        {"--stats-json", "missing/st.json", "missing", 0},
        {"--timeline", "missing/t.svg", "missing", 0},
        {"--stats-json", "good.png/st.json", "not a folder", 0},
        {"--stats-json", "ro.json", "not writable", 1},
        {"-o", "ro.png", "not writable", 1},
        {"--timeline", "rodir/t.svg", "not writable", 1},
    };
    const fixture *f = (const fixture *)*state;
    char path[256], before[512], after[512];
    char *good;
    size_t n_good = 0, c;
    int n_before;
    proc p;

    good = render_good(f, good_args, "good.png", &n_good);
    path_in(f, "dir.png", path, sizeof path);
    assert_int_equal(mkdir(path, 0755), 0);
    path_in(f, "dir.svg", path, sizeof path);
    assert_int_equal(mkdir(path, 0755), 0);
    put_file(f, "ro.json", "{}\n");
    put_file(f, "ro.png", "not really a png\n");
    path_in(f, "ro.json", path, sizeof path);
    assert_int_equal(chmod(path, 0444), 0);
    path_in(f, "ro.png", path, sizeof path);
    assert_int_equal(chmod(path, 0444), 0);
    path_in(f, "rodir", path, sizeof path);
    assert_int_equal(mkdir(path, 0555), 0);
    n_before = list_dir(f->dir, before, sizeof before);
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const char *args[] = {"render", "--width", "256",      "--height", "256", "--spp",
                              "100000", "-o",      "good.png", NULL,       NULL,  NULL};
        if (cases[c].needs_non_root && geteuid() == 0)
            continue; /* root writes whatever it likes */
        if (strcmp(cases[c].opt, "-o") == 0) {
            args[8] = cases[c].path;
        } else {
            args[9] = cases[c].opt;
            args[10] = cases[c].path;
        }
        run(&p, f->dir, 4 * EARLY_FAIL_LIMIT_S, args);
        EXPECT(&p, !p.timed_out && p.seconds < EARLY_FAIL_LIMIT_S,
               "a bad output must be refused before rendering (within %.0f s)", EARLY_FAIL_LIMIT_S);
        EXPECT(&p, exited_with(&p, 2), "a bad output is a usage error: status 2");
        EXPECT(&p, one_line(&p.err), "expected exactly one line on stderr");
        EXPECT(&p, strstr(p.err.data, cases[c].path) && strstr(p.err.data, cases[c].word),
               "the line should name %s and say '%s'", cases[c].path, cases[c].word);
        EXPECT(&p, file_is(f, "good.png", good, n_good), "good.png changed");
        EXPECT(&p, list_dir(f->dir, after, sizeof after) == n_before && strcmp(before, after) == 0,
               "the folder changed: %s, was %s", after, before);
        proc_free(&p);
    }
    free(good);
}

/* A run that fails after the render replaces nothing: here --stats-json's folder disappears
 * while it renders, so the stats cannot be written at the end; the good image at -o must stay
 * (it used to be replaced first) and no temporary file is left. */
static void test_failed_stats_keeps_image(void **state)
{
    static const char *const good_args[] = {"render", "--width", "16",       "--spp", "1",
                                            "-q",     "-o",      "good.png", NULL};
    static const char *const args[] = {"render", "--width",  "256", "--height",     "256",
                                       "--spp",  "100000",   "-q",  "--stats-json", "sub/st.json",
                                       "-o",     "good.png", NULL};
    const fixture *f = (const fixture *)*state;
    char path[256], names[512];
    char *good;
    size_t n_good = 0;
    proc p;

    good = render_good(f, good_args, "good.png", &n_good);
    path_in(f, "sub", path, sizeof path);
    assert_int_equal(mkdir(path, 0755), 0);
    proc_start(&p, f->dir, args);
    let_it_render(&p);
    EXPECT(&p, rmdir(path) == 0, "cannot remove %s: %s", path, strerror(errno));
    assert_int_equal(kill(p.pid, SIGINT), 0);
    proc_finish(&p, (rs_now_s() - p.start) + SIGINT_EXIT_LIMIT_S);
    EXPECT(&p, file_is(f, "good.png", good, n_good), "good.png was replaced by a failed run");
    EXPECT(&p, exited_with(&p, 1), "failing to write the stats is a runtime error: status 1");
    EXPECT(&p, strstr(p.err.data, "st.json") && strstr(p.err.data, "no output was replaced"),
           "stderr should name st.json and say that nothing was replaced");
    EXPECT(&p, list_dir(f->dir, names, sizeof names) == 1,
           "only good.png should be in the folder, found: %s", names);
    free(good);
    proc_free(&p);
}

/* A malformed RS_FAULT is a usage error (status 2, one line naming it), whatever the devices. */
static void test_bad_fault_env(void **state)
{
    static const char *const args[] = {"render", "--width", "8",       "--spp",
                                       "1",      "-o",      "bad.png", NULL};
    const fixture *f = (const fixture *)*state;
    char names[512];
    proc p;
    setenv("RS_FAULT", "gpu:sometimes", 1);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
    unsetenv("RS_FAULT");
    EXPECT(&p, exited_with(&p, 2), "a malformed RS_FAULT is a usage error: status 2");
    EXPECT(&p,
           one_line(&p.err) && strstr(p.err.data, "RS_FAULT") &&
               strstr(p.err.data, "gpu:sometimes"),
           "expected one line naming RS_FAULT and its bad part");
    EXPECT(&p, list_dir(f->dir, names, sizeof names) == 0, "files were written: %s", names);
    proc_free(&p);
}

/* ---- 7. scheduling does not show in the pixels ----------------------------------------------- */

static void test_threads_and_chunks_change_nothing(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const runs[][24] = {
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "1", "-o",
         "t1.exr", NULL},
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2", "-o",
         "t2.exr", NULL},
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--chunk-size", "7", "-o", "c7.exr", NULL},
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--wave-size", "1000", "-o", "w1000.exr", NULL},
        /* the binary BVH kernel instead of the 4-wide one: the same hits, the same image */
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--bvh-width", "2", "-o", "b2.exr", NULL},
        /* waves in flight and fixed vs adaptive chunks, on the CPU and its GPU stand-in */
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--waves", "3", "--chunk-size", "auto", "--devices", "cpu:1,gpu", "-o", "v3.exr", NULL},
        /* the thesis's per-pixel megakernel, its three OpenMP strategies, and no BVH at all */
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--integrator", "megakernel", "--cpu-strategy", "columns", "-o", "mk.exr", NULL},
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--cpu-strategy", "tasks", "--no-bvh", "-o", "nb.exr", NULL},
        /* the CPU's waves walking the 8-wide tree eight rays at a time, or one (the same hits;
         * the 4-wide tree where the CPU has no AVX2) */
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2",
         "--cpu-walk", "packets", "-o", "pk.exr", NULL},
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "1",
         "--cpu-walk", "single", "-o", "sg.exr", NULL},
        /* the LBVH with its sort on the GPU (here: a warning, then the host's): the same tree */
        {"render", "--width", "40", "--height", "40", "--spp", "8", "-q", "--threads", "2", "--bvh",
         "lbvh", "--bvh-device", "gpu", "-o", "lg.exr", NULL},
    };
    image ref = {0, 0, NULL};
    size_t r;

    for (r = 0; r < sizeof runs / sizeof runs[0]; ++r) {
        const char *name = NULL;
        proc p;
        image im;
        int k;
        for (k = 0; runs[r][k]; ++k)
            if (strcmp(runs[r][k], "-o") == 0)
                name = runs[r][k + 1];
        run(&p, f->dir, DEFAULT_TIMEOUT_S, runs[r]);
        EXPECT(&p, exited_with(&p, 0), "the render should succeed");
        im = read_image(&p, f, name);
        EXPECT(&p, im.w == 40 && im.h == 40, "%s is %ux%u, not 40x40", name, im.w, im.h);
        EXPECT(&p, image_mean(&im) > 0.0, "%s is black", name);
        if (!ref.rgb) {
            ref = im;
        } else {
            size_t i, n = (size_t)40 * 40 * 3;
            for (i = 0; i < n; ++i)
                if (memcmp(&ref.rgb[i], &im.rgb[i], sizeof(float)) != 0)
                    break;
            if (i < n) {
                float a = ref.rgb[i], b = im.rgb[i];
                rs_free(ref.rgb);
                rs_free(im.rgb);
                EXPECT(&p, 0,
                       "%s differs from t1.exr at pixel (%zu, %zu) channel %zu: %.9g, not %.9g",
                       name, (i / 3) % 40, (i / 3) / 40, i % 3, (double)b, (double)a);
            }
            rs_free(im.rgb);
        }
        proc_free(&p);
    }
    rs_free(ref.rgb);
}
/* Where no CUDA device can be used (CI: the toolkit but no driver), `--devices cpu:1,gpu` still
 * renders: the gpu becomes the CPU fallback device after one warning line, and the image is the
 * CPU-only image bit for bit (the fallback runs the very same traversal).  The same for
 * `--integrator megakernel --devices gpu`: the CUDA megakernel's passes run on host threads. */
static void test_gpu_fallback(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const cpu_args[] = {"render", "--width",   "24",  "--spp",        "4",
                                           "-q",     "--devices", "cpu", "--chunk-size", "100",
                                           "-o",     "cpu.exr",   NULL};
    static const char *const mix_args[] = {
        "render",    "--width",      "24",  "--spp", "4",         "-q", "--devices",
        "cpu:1,gpu", "--chunk-size", "100", "-o",    "mixed.exr", NULL};
    static const char *const mk_args[] = {
        "render",     "--width",   "24",  "--spp", "4",      "-q", "--integrator",
        "megakernel", "--devices", "gpu", "-o",    "mk.exr", NULL};
    const char *why = "";
    proc p, q, r;
    image a, b, c;
    if (rs_gpu_count(&why) > 0) {
        print_message("a CUDA device is present: the fallback path is not exercised here\n");
        skip();
    }
    run(&p, f->dir, DEFAULT_TIMEOUT_S, cpu_args);
    EXPECT(&p, exited_with(&p, 0), "the cpu render should succeed");
    run(&q, f->dir, DEFAULT_TIMEOUT_S, mix_args);
    EXPECT(&q, exited_with(&q, 0), "the cpu+gpu render should fall back and succeed");
    EXPECT(&q, one_line(&q.err) && contains_ci(q.err.data, "fallback"),
           "expected one warning line naming the fallback");
    /* the GPU megakernel's fallback: its passes on host threads, the wavefront's image */
    run(&r, f->dir, DEFAULT_TIMEOUT_S, mk_args);
    EXPECT(&r, exited_with(&r, 0), "the gpu megakernel should fall back and succeed");
    EXPECT(&r,
           one_line(&r.err) && contains_ci(r.err.data, "megakernel") &&
               contains_ci(r.err.data, "fallback"),
           "expected one warning line naming the megakernel's fallback");
    a = read_image(&p, f, "cpu.exr");
    b = read_image(&q, f, "mixed.exr");
    c = read_image(&r, f, "mk.exr");
    EXPECT(&q, same_image(&a, &b), "the fallback changed the image");
    EXPECT(&r, same_image(&a, &c), "the megakernel's fallback changed the image");
    rs_free(a.rgb);
    rs_free(b.rgb);
    rs_free(c.rgb);
    proc_free(&p);
    proc_free(&q);
    proc_free(&r);
}
/* --require-gpu ("GPU or fail"): a gpu that cannot be used is one line naming it and the flag,
 * exit 1, before the render and with no file written, for the stream engine and the megakernel
 * (gpu:63 is no device on any machine here); where no CUDA device can be used, --devices auto
 * with it fails the same way.  Without the flag the fallback stays (test_gpu_fallback). */
static void test_require_gpu(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const cases[][16] = {
        {"render", "--width", "24", "--spp", "1", "-q", "--devices", "cpu:1,gpu:63",
         "--require-gpu", "-o", "x.png", NULL},
        {"render", "--width", "24", "--spp", "1", "-q", "--integrator", "megakernel", "--devices",
         "gpu:63", "--require-gpu", "-o", "x.png", NULL},
        {"render", "--width", "24", "--spp", "1", "-q", "--require-gpu", "-o", "x.png", NULL},
        {"render", "--width", "24", "--spp", "1", "-q", "--integrator", "megakernel",
         "--require-gpu", "-o", "x.png", NULL}};
    static const char *const words[][2] = {
        {"gpu:63", "cannot be used"}, {"megakernel", "gpu:63"}, {"auto", "no CUDA device"},
        {"auto", "no CUDA device"}};
    const char *why = "";
    char names[512];
    size_t c, n = sizeof cases / sizeof cases[0];
    proc p;
    if (rs_gpu_count(&why) > 0)
        n = 2; /* auto finds a device: only the missing gpu:63 can fail */
    for (c = 0; c < n; ++c) {
        run(&p, f->dir, DEFAULT_TIMEOUT_S, cases[c]);
        EXPECT(&p, exited_with(&p, 1), "--require-gpu with no usable gpu should exit 1");
        EXPECT(&p,
               one_line(&p.err) && strstr(p.err.data, "--require-gpu") &&
                   strstr(p.err.data, words[c][0]) && strstr(p.err.data, words[c][1]),
               "expected one line naming --require-gpu, '%s' and '%s'", words[c][0],
               words[c][1]);
        EXPECT(&p, !contains_ci(p.err.data, "warning"), "no fallback warning with --require-gpu");
        EXPECT(&p, list_dir(f->dir, names, sizeof names) == 0, "files were written: %s", names);
        proc_free(&p);
    }
}

/* Scene files and meshes from the command line: a good JSON scene and a mesh render; a bad
 * JSON scene and an unreadable mesh give one line naming the file and exit 1; a mesh with bad
 * faces renders with one warning line counting them. */
/* RS_FAULT=gpu:after=2 makes the gpu (here its fallback) fail on its third chunk: the render
 * still finishes on the cpu with every sample (the image is the cpu-only image bit for bit),
 * and --stats / --stats-json say which device failed.  A malformed RS_FAULT is an error. */
static void test_device_fault_and_stats(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const cpu_args[] = {"render",    "--width", "24", "--spp",   "4", "-q",
                                           "--devices", "cpu",     "-o", "ref.exr", NULL};
    static const char *const fault_args[] = {
        "render",       "--width",    "24",           "--spp",     "4",
        "--devices",    "cpu:1,gpu",  "--chunk-size", "50",        "--stats",
        "--stats-json", "stats.json", "-o",           "fault.exr", NULL};
    static const char *const bad_args[] = {"render", "--width", "8",       "--spp",
                                           "1",      "-o",      "bad.png", NULL};
    const char *why = "";
    char path[4200], json[4096];
    proc p, q, r;
    image a, b;
    FILE *js;
    size_t n;
    if (rs_gpu_count(&why) > 0) {
        print_message("a CUDA device is present: the fallback's fault is not exercised here\n");
        skip();
    }
    run(&p, f->dir, DEFAULT_TIMEOUT_S, cpu_args);
    EXPECT(&p, exited_with(&p, 0), "the cpu render should succeed");
    setenv("RS_FAULT", "gpu:after=2", 1);
    run(&q, f->dir, DEFAULT_TIMEOUT_S, fault_args);
    setenv("RS_FAULT", "gpu:sometimes", 1);
    run(&r, f->dir, DEFAULT_TIMEOUT_S, bad_args);
    unsetenv("RS_FAULT");
    EXPECT(&q, exited_with(&q, 0), "the render should survive the gpu's failure");
    EXPECT(&q, strstr(q.err.data, "failed") != NULL, "the summary should say the gpu failed");
    a = read_image(&p, f, "ref.exr");
    b = read_image(&q, f, "fault.exr");
    EXPECT(&q, same_image(&a, &b), "samples were lost or changed when the gpu failed");
    rs_free(a.rgb);
    rs_free(b.rgb);
    snprintf(path, sizeof path, "%s/stats.json", f->dir);
    js = fopen(path, "r");
    EXPECT(&q, js != NULL, "--stats-json should write %s", path);
    n = fread(json, 1, sizeof json - 1, js);
    json[n] = '\0';
    fclose(js);
    EXPECT(&q,
           strstr(json, "\"name\": \"gpu-fallback:0\"") && strstr(json, "\"failed\": true") &&
               strstr(json, "\"name\": \"cpu\"") && strstr(json, "\"failed\": false"),
           "stats.json should list both devices and the failure: %s", json);
    EXPECT(&r, exited_with(&r, 2) && one_line(&r.err) && strstr(r.err.data, "RS_FAULT") != NULL,
           "a malformed RS_FAULT should be a usage error naming it");
    proc_free(&p);
    proc_free(&q);
    proc_free(&r);
}

/* Reads a whole small file into buf (NUL-terminated); 0 if it cannot be read. */
static int slurp(const char *path, char *buf, size_t cap)
{
    FILE *fp = fopen(path, "r");
    size_t n;
    if (!fp)
        return 0;
    n = fread(buf, 1, cap - 1, fp);
    buf[n] = '\0';
    fclose(fp);
    return 1;
}

/* --stats and --stats-json time every stage under its name (--shade-on host: the stage table);
 * --timeline draws a lane per device and one for the render thread, for both integrators, and
 * by default (every device running its paths whole) a lane per device with its calls. */
static void test_stage_stats_and_timeline(void **state)
{
    const fixture *f = (const fixture *)*state;
    /* large enough that every stage takes a measurable time (at 24x24 and 4 spp the shadow
     * rays' wait once printed 0.000000 s) */
    static const char *const stream_args[] = {
        "render",  "--width", "48",         "--spp",   "8",          "--devices", "cpu:1,gpu",
        "--shade-on", "host", "--stats",    "--stats-json", "st.json", "--timeline", "s.svg",
        "-o",      "s.exr",   NULL};
    /* by default each device runs its paths whole: one lane each, spans of whole calls */
    static const char *const paths_args[] = {
        "render",  "--width", "48", "--spp", "8", "--devices", "cpu:1,gpu", "--stats",
        "--timeline", "p.svg", "-o", "p.exr", NULL};
    static const char *const mk_args[] = {
        "render", "--width",    "24",    "--spp", "4",  "--integrator", "megakernel", "--devices",
        "cpu",    "--timeline", "m.svg", "-q",    "-o", "m.exr",        NULL};
    static const char *const stages[] = {
        "raygen", "trace-closest", "shade", "trace-shadow", "resolve-shadows", "compact", "film"};
    static char svg[1 << 20];
    char path[4200], json[8192];
    proc p, q;
    size_t k;
    run(&p, f->dir, DEFAULT_TIMEOUT_S, stream_args);
    EXPECT(&p, exited_with(&p, 0), "the render with --stats and --timeline should succeed");
    EXPECT(&p, strstr(p.err.data, "stage (render thread)") != NULL,
           "--stats should print the stage table");
    snprintf(path, sizeof path, "%s/st.json", f->dir);
    EXPECT(&p, slurp(path, json, sizeof json), "--stats-json should write %s", path);
    for (k = 0; k < sizeof stages / sizeof stages[0]; ++k) {
        char key[64];
        const char *at;
        snprintf(key, sizeof key, "\"%s\": ", stages[k]);
        at = strstr(json, key);
        EXPECT(&p, at != NULL, "stats.json should time the stage %s: %s", stages[k], json);
        EXPECT(&p, at && strtod(at + strlen(key), NULL) > 0.0,
               "the stage %s should have taken some time", stages[k]);
        EXPECT(&p, strstr(p.err.data, stages[k]) != NULL, "--stats should list %s", stages[k]);
    }
    snprintf(path, sizeof path, "%s/s.svg", f->dir);
    EXPECT(&p, slurp(path, svg, sizeof svg), "--timeline should write %s", path);
    EXPECT(&p, strncmp(svg, "<svg", 4) == 0 && strstr(svg, "</svg>") != NULL,
           "the timeline should be an SVG picture");
    EXPECT(&p,
           strstr(svg, "gpu-fallback:0") && strstr(svg, "cpu (1 thread)") &&
               strstr(svg, "shading (render thread)"),
           "the timeline should have a lane per device and one for shading");
    EXPECT(&p, strstr(svg, "trace-closest") && strstr(svg, "shade"),
           "the timeline should name the stages it shows");
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, paths_args);
    EXPECT(&p, exited_with(&p, 0), "the render of whole paths with --timeline should succeed");
    EXPECT(&p,
           strstr(p.err.data, "cpu (wavefront)") && strstr(p.err.data, "gpu-fallback:0 (wavefront)"),
           "--stats should show both devices running their paths whole");
    snprintf(path, sizeof path, "%s/p.svg", f->dir);
    EXPECT(&p,
           slurp(path, svg, sizeof svg) && strstr(svg, "pass") && strstr(svg, "cpu (wavefront)") &&
               strstr(svg, "gpu-fallback:0"),
           "the timeline should show each device's calls on its lane");
    run(&q, f->dir, DEFAULT_TIMEOUT_S, mk_args);
    EXPECT(&q, exited_with(&q, 0), "the megakernel render with --timeline should succeed");
    snprintf(path, sizeof path, "%s/m.svg", f->dir);
    EXPECT(&q, slurp(path, svg, sizeof svg) && strstr(svg, "pass") && strstr(svg, "cpu"),
           "the megakernel's timeline should show its passes on the cpu's lane");
    proc_free(&p);
    proc_free(&q);
}

static void test_scene_files_and_meshes(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const json_ok[] = {"render",  RS_SOURCE_DIR "/scenes/examples/cornell.json",
                                          "--width", "16",
                                          "--spp",   "1",
                                          "-q",      "-o",
                                          "j.png",   NULL};
    static const char *const mesh_ok[] = {"render",  "--mesh", RS_SOURCE_DIR "/tests/data/cube.ply",
                                          "--width", "16",     "--spp",
                                          "1",       "-q",     NULL};
    static const char *const mesh_bad[] = {
        "render",  "--mesh", RS_SOURCE_DIR "/tests/data/garbage.obj",
        "--width", "16",     "--spp",
        "1",       "-q",     "-o",
        "x.png",   NULL};
    static const char *const mesh_nan[] = {"render",  "--mesh", RS_SOURCE_DIR "/tests/data/nan.obj",
                                           "--width", "16",     "--spp",
                                           "1",       "-q",     "-o",
                                           "n.png",   NULL};
    static const char *const json_bad[] = {"render", "bad.json", "-q", "-o", "y.png", NULL};
    char path[512];
    FILE *fp;
    proc p;
    run(&p, f->dir, DEFAULT_TIMEOUT_S, json_ok);
    EXPECT(&p, exited_with(&p, 0), "the example scene file should render");
    path_in(f, "j.png", path, sizeof path);
    EXPECT(&p, file_exists(path), "j.png was not written");
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, mesh_ok);
    EXPECT(&p, exited_with(&p, 0), "--mesh cube.ply should render");
    path_in(f, "cube.png", path, sizeof path);
    EXPECT(&p, file_exists(path), "--mesh cube.ply should write cube.png by default");
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, mesh_bad);
    EXPECT(&p, exited_with(&p, 1) && one_line(&p.err) && strstr(p.err.data, "garbage.obj"),
           "an unreadable mesh: exit 1, one line naming it");
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, mesh_nan);
    EXPECT(&p, exited_with(&p, 0) && one_line(&p.err) && strstr(p.err.data, "1 faces dropped"),
           "a mesh with a NaN face: rendered, one warning counting the dropped face");
    proc_free(&p);
    path_in(f, "bad.json", path, sizeof path);
    fp = fopen(path, "w");
    assert_non_null(fp);
    fputs("{\"camera\": {\"from\": [0,0,1], \"at\": [0,0,0]},\n \"objects\": [{\"type\": "
          "\"sphere\", \"center\": [0,0,0], \"radius\": 1, \"material\": \"nope\"}]}\n",
          fp);
    fclose(fp);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, json_bad);
    EXPECT(&p,
           exited_with(&p, 1) && one_line(&p.err) && strstr(p.err.data, "bad.json") &&
               strstr(p.err.data, "objects[0].material"),
           "a bad scene file: exit 1, one line naming the file and the field");
    path_in(f, "y.png", path, sizeof path);
    EXPECT(&p, !file_exists(path), "no image for a bad scene");
    proc_free(&p);
    {
        /* a scene file that is a FIFO (whose open would block) and a PLY whose header is cut
         * (Assimp's reader spins on it): at once, exit 1, one line naming the file */
        static const char *const fifo_scene[] = {"render", "f.json", "-q", "-o", "z.png", NULL};
        static const char *const cut_ply[] = {"render", "--mesh", "cut.ply", "--width", "16",
                                              "--spp",  "1",      "-q",      "-o",      "z.png",
                                              NULL};
        path_in(f, "f.json", path, sizeof path);
        assert_int_equal(mkfifo(path, 0600), 0);
        run(&p, f->dir, 30.0, fifo_scene);
        EXPECT(&p,
               exited_with(&p, 1) && one_line(&p.err) && strstr(p.err.data, "f.json") &&
                   strstr(p.err.data, "not a regular file"),
               "a FIFO as the scene: exit 1, one line naming it");
        proc_free(&p);
        path_in(f, "cut.ply", path, sizeof path);
        fp = fopen(path, "w");
        assert_non_null(fp);
        fputs("ply\nformat ascii 1.0\n", fp);
        fclose(fp);
        run(&p, f->dir, 30.0, cut_ply);
        EXPECT(&p,
               exited_with(&p, 1) && one_line(&p.err) && strstr(p.err.data, "cut.ply") &&
                   strstr(p.err.data, "no end_header"),
               "a PLY whose header is cut: exit 1, one line naming it");
        proc_free(&p);
        path_in(f, "z.png", path, sizeof path);
        if (file_exists(path))
            fail_msg("z.png was written for a refused input");
    }
}

/* ---- 9. bounded and resumable renders -------------------------------------------------------- */

/* The unsigned number after "KEY": in the file `name` of the test folder, or -1. */
static long long json_number(const fixture *f, const char *name, const char *key)
{
    char path[256], text[8192], pat[64];
    const char *at;
    path_in(f, name, path, sizeof path);
    if (!slurp(path, text, sizeof text))
        return -1;
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    at = strstr(text, pat);
    return at ? strtoll(at + strlen(pat), NULL, 10) : -1;
}

/* The images `a` and `b` of the test folder are the same bit for bit (`p`: the run to show). */
static void expect_same_image(const proc *p, const fixture *f, const char *a, const char *b)
{
    image x = read_image(p, f, a), y = read_image(p, f, b);
    size_t i = 0, n = (size_t)x.w * x.h * 3;
    if (x.w == y.w && x.h == y.h)
        for (i = 0; i < n && memcmp(&x.rgb[i], &y.rgb[i], sizeof(float)) == 0; ++i)
            ;
    if (!(x.w == y.w && x.h == y.h && i == n)) {
        float va = i < n ? x.rgb[i] : 0.0f, vb = i < n && y.w == x.w ? y.rgb[i] : 0.0f;
        rs_free(x.rgb);
        rs_free(y.rgb);
        EXPECT(p, 0, "%s (%ux%u) and %s (%ux%u) differ at value %zu: %.9g against %.9g", a, x.w,
               x.h, b, y.w, y.h, i, (double)va, (double)vb);
    }
    rs_free(x.rgb);
    rs_free(y.rgb);
}

/* Scenes as users make them: bad glTF, instance cycles, absurd transforms, a camera the file
 * lacks, a missing environment map: exit 1 (2 for a misused option), one line naming the file,
 * no image.  `raystream export` of builtin:cornell renders builtin:cornell bit for bit. */
static void test_user_scenes(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const struct {
        const char *file, *text, *words[2];
        const char *extra;
        int code;
    } cases[] = {
        {"cut.gltf", "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\"nod",
         {"cut.gltf", NULL}, NULL, 1},
        {"cycle.json",
         "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"groups\":{\"a\":[{\"type\":"
         "\"instance\",\"group\":\"b\"}],\"b\":[{\"type\":\"instance\",\"group\":\"a\"}]},"
         "\"objects\":[{\"type\":\"instance\",\"group\":\"a\"}]}",
         {"cycle.json", "cycle: a -> b -> a"}, NULL, 1},
        {"flat.json",
         "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"materials\":{\"m\":{\"type\":"
         "\"lambertian\"}},\"objects\":[{\"type\":\"quad\",\"q\":[0,0,0],\"u\":[1,0,0],"
         "\"v\":[0,1,0],\"material\":\"m\",\"transform\":{\"scale\":[1,1,0]}}]}",
         {"flat.json", "objects[0].transform.scale"}, NULL, 1},
        {"cam.json", "{}", {"--camera", NULL}, "--camera", 2},
        {"env.json", NULL, {"nosuch.exr", NULL}, "--envmap", 1},
    };
    size_t k;
    char path[512];
    proc p;
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        const char *args[12];
        int n = 0;
        if (cases[k].text)
            write_in(f, cases[k].file, cases[k].text);
        args[n++] = "render";
        args[n++] = cases[k].text ? cases[k].file
                                  : RS_SOURCE_DIR "/scenes/examples/cornell.json";
        if (cases[k].extra) {
            args[n++] = cases[k].extra;
            args[n++] = strcmp(cases[k].extra, "--camera") == 0 ? "front" : "nosuch.exr";
        }
        args[n++] = "--width";
        args[n++] = "16";
        args[n++] = "-o";
        args[n++] = "user.png";
        args[n] = NULL;
        run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
        EXPECT(&p,
               exited_with(&p, cases[k].code) && one_line(&p.err) &&
                   strstr(p.err.data, cases[k].words[0]) &&
                   (!cases[k].words[1] || strstr(p.err.data, cases[k].words[1])),
               "%s: exit %d, one line naming it", cases[k].file, cases[k].code);
        path_in(f, "user.png", path, sizeof path);
        EXPECT(&p, !file_exists(path), "%s: an image was written for a refused scene",
               cases[k].file);
        proc_free(&p);
    }
    {
        /* export, then render the file: the built-in scene's image bit for bit */
        static const char *const exp[] = {"export", "builtin:cornell", "-q", "-o", "e.json",
                                          NULL};
        static const char *const from_file[] = {"render", "e.json", "--width", "24", "--spp",
                                                "2", "-q", "-o", "e.exr", NULL};
        static const char *const builtin[] = {"render", "builtin:cornell", "--width", "24",
                                              "--spp", "2", "-q", "-o", "b.exr", NULL};
        static const char *const bad_out[] = {"export", "builtin:cornell", "-q", "-o", "e.png",
                                              NULL};
        run_expect(f, exp, 0, &p);
        proc_free(&p);
        run_expect(f, from_file, 0, &p);
        proc_free(&p);
        run_expect(f, builtin, 0, &p);
        expect_same_image(&p, f, "e.exr", "b.exr");
        proc_free(&p);
        run(&p, f->dir, DEFAULT_TIMEOUT_S, bad_out);
        EXPECT(&p, exited_with(&p, 2) && one_line(&p.err) && strstr(p.err.data, "-o FILE.json"),
               "export to a .png: a usage error");
        proc_free(&p);
    }
    {
        /* a group of triangles placed three times: one shared copy, said so on loading; the
         * same image with --flatten-instances (copies), and export writes the copies */
        static const char *const inst[] = {"render", "inst.json", "--width", "24", "--spp", "4",
                                           "-o", "i.exr", NULL};
        static const char *const flat[] = {"render", "inst.json", "--width", "24", "--spp", "4",
                                           "-q", "--flatten-instances", "-o", "f.exr", NULL};
        static const char *const exp[] = {"export", "inst.json", "-o", "ie.json", NULL};
        static const char *const from_export[] = {"render", "ie.json", "--width", "24", "--spp",
                                                  "4", "-q", "-o", "ie.exr", NULL};
        write_in(f, "inst.json",
                 "{\"camera\":{\"from\":[0,1,5],\"at\":[0,0.5,0]},\"materials\":{\"m\":"
                 "{\"type\":\"lambertian\",\"albedo\":[0.6,0.5,0.4]}},\"groups\":{\"fin\":["
                 "{\"type\":\"triangle\",\"vertices\":[[0,0,0],[0.8,0,0],[0,1,0.2]],"
                 "\"material\":\"m\"},{\"type\":\"triangle\",\"vertices\":[[0,0,0],[0,1,0.2],"
                 "[-0.5,0,0.4]],\"material\":\"m\"}]},\"objects\":["
                 "{\"type\":\"instance\",\"group\":\"fin\"},"
                 "{\"type\":\"instance\",\"group\":\"fin\",\"transform\":[{\"rotate\":[0,120,0]},"
                 "{\"translate\":[-1,0,0]}]},"
                 "{\"type\":\"instance\",\"group\":\"fin\",\"transform\":{\"scale\":[-1,1,1]}}]}");
        run_expect(f, inst, 0, &p);
        EXPECT(&p, strstr(p.err.data, "group 'fin': 2 triangles placed 3 times (instanced") &&
                       strstr(p.err.data, "3 of them instances placing 6 triangles"),
               "the load and the summary should say what was instanced");
        proc_free(&p);
        run_expect(f, flat, 0, &p);
        expect_same_image(&p, f, "i.exr", "f.exr");
        proc_free(&p);
        run_expect(f, exp, 0, &p);
        EXPECT(&p, strstr(p.err.data, "6 triangles"), "export writes the six copies");
        proc_free(&p);
        run_expect(f, from_export, 0, &p);
        expect_same_image(&p, f, "i.exr", "ie.exr");
        proc_free(&p);
    }
}

/* --time-limit: a render that would take minutes stops on a whole pass, says how many spp it
 * did (summary, --stats-json), and its image is the one `--spp THAT` gives, bit for bit: every
 * pixel has that many samples and the image is divided by them.  Stream and megakernel. */
static void test_time_limit(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const integrators[][4] = {
        {"--devices", "cpu", NULL}, {"--integrator", "megakernel", "--devices", "cpu"}};
    size_t k;
    for (k = 0; k < 2; ++k) {
        const char *args[MAX_ARGS] = {
            "render",       "--width", "32",           "--height", "24", "--spp", "1000000",
            "--time-limit", "0.3",     "--stats-json", "s.json",   "-o", "t.exr"};
        char spp_text[32], path[256];
        const char *ref[] = {"render", "--width", "32", "--height", "24", "--spp",
                             spp_text, "-q",      "-o", "ref.exr",  NULL};
        int n = 13, i;
        long long spp;
        proc p, q;
        for (i = 0; i < 4 && integrators[k][i]; ++i)
            args[n++] = integrators[k][i];
        args[n] = NULL;
        run(&p, f->dir, 60.0, args);
        EXPECT(&p, !p.timed_out && exited_with(&p, 0),
               "a time-limited render should end by itself with status 0");
        spp = json_number(f, "s.json", "spp");
        EXPECT(&p, spp >= 1 && spp < 1000000, "s.json should give the spp done, not %lld", spp);
        EXPECT(&p, json_number(f, "s.json", "spp_requested") == 1000000,
               "s.json should give the spp asked for");
        EXPECT(&p, json_number(f, "s.json", "samples") == spp * 32 * 24,
               "s.json: every pixel should have %lld samples", spp);
        snprintf(spp_text, sizeof spp_text, "%lld", spp);
        EXPECT(&p, strstr(p.err.data, spp_text) && strstr(p.err.data, "of 1000000 spp"),
               "the summary should say %s of 1000000 spp", spp_text);
        {
            char meta[64];
            path_in(f, "t.exr", path, sizeof path);
            EXPECT(&p,
                   rs_image_read_meta(path, "raystream:spp", meta, sizeof meta) == RS_OK &&
                       strcmp(meta, spp_text) == 0,
                   "t.exr's header should give raystream:spp %s", spp_text);
            rs_error_clear();
        }
        run_expect(f, ref, 0, &q);
        expect_same_image(&q, f, "t.exr", "ref.exr");
        proc_free(&p);
        proc_free(&q);
        for (i = 0; i < 3; ++i) {
            static const char *const names[] = {"t.exr", "ref.exr", "s.json"};
            path_in(f, names[i], path, sizeof path);
            unlink(path);
        }
    }
}

/* --checkpoint then --resume to more samples: the image of the uninterrupted render bit for
 * bit, on the CPU, CPU + GPU (the fallback here), the megakernel, and checkpointing on into the
 * file it continues; the resumed run traces only the samples it adds. */
static void test_checkpoint_resume(void **state)
{
    const fixture *f = (const fixture *)*state;
#define SMALL "--width", "40", "--height", "30", "-q", "--stats-json"
    static const char *const full[] = {"render",    SMALL, "full.json", "--spp",    "8",
                                       "--devices", "cpu", "-o",        "full.exr", NULL};
    static const char *const part[] = {"render", SMALL,       "part.json", "--spp",
                                       "3",      "--devices", "cpu",       "--checkpoint",
                                       "c.ckpt", "-o",        "part.exr",  NULL};
    static const char *const resumes[][24] = {
        {"render", SMALL, "r1.json", "--resume", "c.ckpt", "--spp", "8", "--devices", "cpu", "-o",
         "r1.exr", NULL},
        {"render", SMALL, "r2.json", "--resume", "c.ckpt", "--spp", "8", "--devices", "cpu,gpu",
         "-o", "r2.exr", NULL},
        {"render", SMALL, "r3.json", "--resume", "c.ckpt", "--spp", "8", "--integrator",
         "megakernel", "--devices", "cpu", "-o", "r3.exr", NULL},
        {"render", SMALL, "r4.json", "--resume", "c.ckpt", "--spp", "8", "--integrator",
         "megakernel", "--devices", "gpu", "-o", "r4.exr", NULL},
    };
    /* on into the same file: 3 -> 5 spp, then (no --spp: the file's 5) nothing to add, then 8 */
    static const char *const chain[][24] = {
        {"render", SMALL, "c1.json", "--resume", "c.ckpt", "--checkpoint", "c.ckpt", "--spp", "5",
         "--devices", "cpu:1,gpu", "--wave-size", "777", "-o", "c5.exr", NULL},
        {"render", SMALL, "c2.json", "--resume", "c.ckpt", "-o", "c5b.exr", NULL},
        {"render", SMALL, "c3.json", "--resume", "c.ckpt", "--spp", "8", "-o", "c8.exr", NULL},
    };
    static const char *const five[] = {"render", SMALL, "five.json", "--spp",
                                       "5",      "-o",  "five.exr",  NULL};
#undef SMALL
    long long rays_full, rays;
    size_t k;
    proc p;

    run_expect(f, full, 0, &p);
    proc_free(&p);
    rays_full = json_number(f, "full.json", "rays");
    run_expect(f, part, 0, &p);
    proc_free(&p);
    for (k = 0; k < sizeof resumes / sizeof resumes[0]; ++k) {
        char name[16];
        run_expect(f, resumes[k], 0, &p);
        snprintf(name, sizeof name, "r%zu.exr", k + 1);
        expect_same_image(&p, f, name, "full.exr");
        snprintf(name, sizeof name, "r%zu.json", k + 1);
        EXPECT(&p,
               json_number(f, name, "resumed_samples") == 3 * 1200 &&
                   json_number(f, name, "samples") == 8 * 1200,
               "%s should say 3 spp resumed, 8 in all", name);
        rays = json_number(f, name, "rays");
        /* 5 of 8 spp traced: about 5/8 of the rays */
        EXPECT(&p, rays > 0 && rays < rays_full * 3 / 4,
               "the resumed render traced %lld rays, the whole one %lld: it should add only the "
               "missing samples",
               rays, rays_full);
        proc_free(&p);
    }
    run_expect(f, five, 0, &p);
    proc_free(&p);
    for (k = 0; k < sizeof chain / sizeof chain[0]; ++k) {
        run_expect(f, chain[k], 0, &p);
        if (k == 0)
            expect_same_image(&p, f, "c5.exr", "five.exr");
        if (k == 1) {
            expect_same_image(&p, f, "c5b.exr", "five.exr");
            EXPECT(&p, json_number(f, "c2.json", "rays") == 0,
                   "a checkpoint that holds every sample asked for needs no rays");
        }
        if (k == 2)
            expect_same_image(&p, f, "c8.exr", "full.exr");
        proc_free(&p);
    }
}

/* A stop in the middle of a pass (SIGINT: the checkpoint written on the way out), and a render
 * killed outright (SIGKILL: the last periodic checkpoint), each resumed on another device set:
 * the uninterrupted render's image bit for bit. */
static void test_resume_after_signal(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const sig_run[] = {
        "render",       "--width", "40",        "--height", "30", "--spp",        "1000000",
        "--wave-size",  "1000",    "--devices", "cpu",      "-q", "--checkpoint", "s.ckpt",
        "--stats-json", "s.json",  "-o",        "p.exr",    NULL};
    static const char *const kill_run[] = {"render",
                                           "--width",
                                           "40",
                                           "--height",
                                           "30",
                                           "--spp",
                                           "1000000",
                                           "--devices",
                                           "cpu:1,gpu",
                                           "-q",
                                           "--checkpoint",
                                           "k.ckpt",
                                           "--checkpoint-interval",
                                           "0.1",
                                           "-o",
                                           "k.exr",
                                           NULL};
    char spp_text[32];
    const char *resume[] = {"render",   "--width", "40",    "--height", "30",
                            "--resume", "s.ckpt",  "--spp", spp_text,   "--devices",
                            "cpu,gpu",  "-q",      "-o",    "rs.exr",   NULL};
    const char *ref[] = {"render", "--width",   "40",  "--height", "30",      "--spp", spp_text,
                         "-q",     "--devices", "cpu", "-o",       "ref.exr", NULL};
    static const char *const resume_k[] = {
        "render",       "--width", "40",           "--height", "30",        "--resume", "k.ckpt",
        "--spp",        "1000000", "--time-limit", "0.2",      "--devices", "cpu",      "-q",
        "--stats-json", "k.json",  "-o",           "rk.exr",   NULL};
    char path[256];
    long long samples, spp;
    proc p, q;

    proc_start(&p, f->dir, sig_run);
    let_it_render(&p);
    assert_int_equal(kill(p.pid, SIGINT), 0);
    proc_finish(&p, (rs_now_s() - p.start) + SIGINT_EXIT_LIMIT_S);
    EXPECT(&p, exited_with(&p, 130), "SIGINT should stop it with status 130");
    samples = json_number(f, "s.json", "samples");
    EXPECT(&p, samples > 0, "s.json should count the samples done: %lld", samples);
    fprintf(stderr, "  SIGINT after %lld samples: %lld whole passes + %lld paths\n", samples,
            samples / 1200, samples % 1200);
    snprintf(spp_text, sizeof spp_text, "%lld", samples / 1200 + 2);
    run_expect(f, resume, 0, &q);
    proc_free(&q);
    run_expect(f, ref, 0, &q);
    expect_same_image(&q, f, "rs.exr", "ref.exr");
    proc_free(&p);
    proc_free(&q);
    path_in(f, "ref.exr", path, sizeof path);
    unlink(path);

    proc_start(&p, f->dir, kill_run);
    let_it_render(&p);
    /* the first periodic checkpoint comes after the first whole wave (2^20 paths with two
     * devices): on a loaded machine that can take longer than let_it_render waits */
    path_in(f, "k.ckpt", path, sizeof path);
    {
        int i;
        for (i = 0; i < 600 && !file_exists(path); ++i)
            proc_pump(&p, 50);
    }
    assert_int_equal(kill(p.pid, SIGKILL), 0);
    proc_finish(&p, 10.0);
    EXPECT(&p, file_exists(path), "a periodic checkpoint should have been written within 30 s");
    run_expect(f, resume_k, 0, &q);
    spp = json_number(f, "k.json", "spp");
    EXPECT(&q, spp > 0 && json_number(f, "k.json", "resumed_samples") > 0,
           "k.json: %lld spp after resuming", spp);
    snprintf(spp_text, sizeof spp_text, "%lld", spp);
    proc_free(&q);
    run_expect(f, ref, 0, &q);
    expect_same_image(&q, f, "rk.exr", "ref.exr");
    proc_free(&p);
    proc_free(&q);
}

/* The EXR header records the render: scene, spp done and asked for, seed, sampling, sampler,
 * max depth, devices, integrator, version. */
/* One channel of an EXR this test wrote. */
static float *read_channel(const proc *p, const fixture *f, const char *name, const char *ch,
                           uint32_t *w, uint32_t *h)
{
    char path[256];
    float *d = NULL;
    path_in(f, name, path, sizeof path);
    EXPECT(p, rs_image_read_channel(path, ch, w, h, &d) == RS_OK, "%s has no channel %s: %s",
           name, ch, rs_error_message());
    return d;
}

/* --aov: albedo, normal, depth and sample-count layers in the EXR beside an unchanged beauty
 * image, the same on any device set; the Cornell box's tall block (the image's centre) is white
 * (0.73), faces the camera and is 500..1500 away; pixels that see out of the box are black,
 * without a normal and infinitely far; every pixel has the spp.  A PNG output or an unknown layer is a usage error
 * before any work. */
static void test_aov_layers(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const plain[] = {"render", "--width", "32", "--height", "32", "--spp", "4",
                                        "-q", "-o", "plain.exr", NULL};
    static const char *const aov[] = {"render", "--width", "32", "--height", "32", "--spp", "4",
                                      "-q", "--aov", "all", "-o", "aov.exr", NULL};
    static const char *const aov2[] = {"render", "--width", "32", "--height", "32", "--spp", "4",
                                       "-q", "--aov", "albedo,normal,depth,samples",
                                       "--devices", "cpu:1,gpu", "-o", "aov2.exr", NULL};
    static const char *const png[] = {"render", "--aov", "all", "-o", "aov.png", NULL};
    static const char *const bad[] = {"render", "--aov", "albedo,shadows", "-o", "x.exr", NULL};
    static const char *const chans[] = {"albedo.R", "albedo.G", "albedo.B", "normal.X",
                                        "normal.Y", "normal.Z", "depth.Z",  "samples.Y"};
    float *c[8];
    uint32_t w = 0, h = 0, i;
    size_t k;
    proc p;
    run_expect(f, plain, 0, &p);
    proc_free(&p);
    run_expect(f, aov, 0, &p);
    expect_same_image(&p, f, "plain.exr", "aov.exr"); /* R, G, B untouched */
    for (k = 0; k < 8; ++k) {
        c[k] = read_channel(&p, f, "aov.exr", chans[k], &w, &h);
        EXPECT(&p, w == 32 && h == 32, "%s is %ux%u", chans[k], w, h);
    }
    {
        uint32_t mid = 16 * 32 + 16, corner = 0;
        float nz = c[5][mid], len = sqrtf(c[3][mid] * c[3][mid] + c[4][mid] * c[4][mid] +
                                          nz * nz);
        print_message("centre: albedo %.3f %.3f %.3f normal %.3f %.3f %.3f depth %.1f\n",
                      c[0][mid], c[1][mid], c[2][mid], c[3][mid], c[4][mid], nz, c[6][mid]);
        EXPECT(&p, fabsf(c[0][mid] - 0.73f) < 1e-3f && fabsf(c[2][mid] - 0.73f) < 1e-3f,
               "the block's albedo is %.4f, not 0.73", c[0][mid]);
        EXPECT(&p, fabsf(len - 1.0f) < 1e-3f && nz < -0.9f, "the block's normal (%g %g %g)",
               c[3][mid], c[4][mid], nz);
        EXPECT(&p, c[6][mid] > 500.0f && c[6][mid] < 1500.0f, "the block is %g away", c[6][mid]);
        /* where every sample left the box's open front: black, no normal, infinitely far */
        for (i = 0, corner = 0; i < 32 * 32; ++i) {
            EXPECT(&p, c[7][i] == 4.0f, "pixel %u has %g samples, not 4", i, c[7][i]);
            if (isinf(c[6][i])) {
                EXPECT(&p, c[0][i] == 0.0f && c[3][i] == 0.0f && c[4][i] == 0.0f,
                       "pixel %u sees nothing but has albedo %g, normal x %g", i, c[0][i],
                       c[3][i]);
                ++corner;
            }
        }
        EXPECT(&p, corner > 0 && corner < 200, "%u pixels see nothing", corner);
    }
    proc_free(&p);
    run_expect(f, aov2, 0, &p);
    expect_same_image(&p, f, "aov.exr", "aov2.exr");
    for (k = 0; k < 8; ++k) {
        float *d = read_channel(&p, f, "aov2.exr", chans[k], &w, &h);
        EXPECT(&p, memcmp(d, c[k], 32 * 32 * sizeof(float)) == 0,
               "%s differs on cpu:1,gpu", chans[k]);
        rs_free(d);
        rs_free(c[k]);
    }
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, png);
    EXPECT(&p, exited_with(&p, 2) && one_line(&p.err) && strstr(p.err.data, "not a .exr"),
           "--aov with a PNG: a usage error");
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, bad);
    EXPECT(&p, exited_with(&p, 2) && one_line(&p.err) && strstr(p.err.data, "'shadows'"),
           "--aov with an unknown layer: a usage error naming it");
    proc_free(&p);
    {
        /* a list past 127 characters is read whole (the layers after the cut were missing) */
        char list[400] = "";
        const char *argv[] = {"render", "--width", "8", "--height", "8", "--spp", "1", "-q",
                              "--aov", list, "-o", "long.exr", NULL};
        float *d;
        for (k = 0; k < 30; ++k)
            strcat(list, "albedo,");
        strcat(list, "depth");
        run_expect(f, argv, 0, &p);
        d = read_channel(&p, f, "long.exr", "depth.Z", &w, &h);
        EXPECT(&p, d && w == 8 && h == 8, "the layer after 210 characters of --aov is missing");
        rs_free(d);
        proc_free(&p);
    }
}

/* The --aov layers with --checkpoint and --resume: the film's passes travel in the checkpoint, so
 * a 3-spp render resumed to 8 (on the CPU, and on CPU + GPU, the fallback here) has every layer
 * of the uninterrupted 8-spp render bit for bit; a checkpoint made without --aov cannot give
 * them (one line, a usage error, no image), and one made with them resumes without --aov to the
 * plain image. */
static void test_aov_resume(void **state)
{
    const fixture *f = (const fixture *)*state;
#define AOV "--width", "40", "--height", "30", "-q", "--aov", "all"
    static const char *const full[] = {"render", AOV, "--spp", "8", "-o", "full.exr", NULL};
    static const char *const part[] = {"render", AOV, "--spp", "3", "--checkpoint", "a.ckpt",
                                       "-o", "part.exr", NULL};
    static const char *const cpu[] = {"render", AOV, "--resume", "a.ckpt", "--spp", "8",
                                      "--devices", "cpu", "-o", "r1.exr", NULL};
    static const char *const mixed[] = {"render", AOV, "--resume", "a.ckpt", "--spp", "8",
                                        "--devices", "cpu:1,gpu", "-o", "r2.exr", NULL};
    static const char *const plain_part[] = {"render", "--width", "40", "--height", "30", "-q",
                                             "--spp", "3", "--checkpoint", "p.ckpt", "-o",
                                             "pp.exr", NULL};
    static const char *const want_aov[] = {"render", AOV, "--resume", "p.ckpt", "--spp", "8",
                                           "-o", "no.exr", NULL};
    static const char *const plain_full[] = {"render", "--width", "40", "--height", "30", "-q",
                                             "--spp", "8", "-o", "pf.exr", NULL};
    static const char *const no_aov[] = {"render", "--width", "40", "--height", "30", "-q",
                                         "--resume", "a.ckpt", "--spp", "8", "-o", "r3.exr", NULL};
#undef AOV
    static const char *const chans[] = {"R",        "G",        "B",        "albedo.R",
                                        "albedo.G", "albedo.B", "normal.X", "normal.Y",
                                        "normal.Z", "depth.Z",  "samples.Y"};
    static const char *const outs[] = {"r1.exr", "r2.exr"};
    char path[256];
    uint32_t w, h;
    size_t k, o;
    proc p;
    run_expect(f, full, 0, &p);
    proc_free(&p);
    run_expect(f, part, 0, &p);
    proc_free(&p);
    run_expect(f, cpu, 0, &p);
    proc_free(&p);
    run_expect(f, mixed, 0, &p);
    for (o = 0; o < 2; ++o)
        for (k = 0; k < sizeof chans / sizeof chans[0]; ++k) {
            float *a = read_channel(&p, f, "full.exr", chans[k], &w, &h);
            float *b = read_channel(&p, f, outs[o], chans[k], &w, &h);
            EXPECT(&p, memcmp(a, b, 40 * 30 * sizeof(float)) == 0,
                   "%s of the render resumed to %s is not the uninterrupted render's", chans[k],
                   outs[o]);
            rs_free(a);
            rs_free(b);
        }
    proc_free(&p);
    run_expect(f, plain_part, 0, &p);
    proc_free(&p);
    run(&p, f->dir, DEFAULT_TIMEOUT_S, want_aov);
    path_in(f, "no.exr", path, sizeof path);
    EXPECT(&p, exited_with(&p, 2) && one_line(&p.err) && strstr(p.err.data, "without the passes"),
           "--aov resumed from a checkpoint without passes: one usage line");
    EXPECT(&p, !file_exists(path), "the refused resume wrote an image");
    proc_free(&p);
    run_expect(f, plain_full, 0, &p);
    proc_free(&p);
    run_expect(f, no_aov, 0, &p);
    expect_same_image(&p, f, "pf.exr", "r3.exr");
    proc_free(&p);
}

/* --adaptive: pixels stop at different sample counts (the samples layer shows them, from 16 to
 * the --spp), the summary says so, and the image is the same on cpu:1,gpu. */
static void test_adaptive(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const one[] = {"render", "--width", "24", "--height", "24", "--spp", "48",
                                      "--adaptive", "0.15", "--aov", "samples", "-o", "ad.exr",
                                      NULL};
    static const char *const two[] = {"render",   "--width",    "24",   "--height", "24",
                                      "--spp",    "48",         "-q",   "--adaptive", "0.15",
                                      "--devices", "cpu:1,gpu", "-o", "ad2.exr", NULL};
    uint32_t w = 0, h = 0, i, lo = UINT32_MAX, hi = 0;
    float *n;
    proc p;
    run_expect(f, one, 0, &p);
    EXPECT(&p, strstr(p.err.data, "adaptive to 0.15 in ") && strstr(p.err.data, "spp on average"),
           "the summary should say how adaptive sampling went");
    n = read_channel(&p, f, "ad.exr", "samples.Y", &w, &h);
    for (i = 0; i < w * h; ++i) {
        lo = (uint32_t)n[i] < lo ? (uint32_t)n[i] : lo;
        hi = (uint32_t)n[i] > hi ? (uint32_t)n[i] : hi;
    }
    rs_free(n);
    EXPECT(&p, lo == 16 && hi == 48, "samples per pixel from %u to %u, not 16 to 48", lo, hi);
    proc_free(&p);
    run_expect(f, two, 0, &p);
    expect_same_image(&p, f, "ad.exr", "ad2.exr");
    proc_free(&p);
}

/* --adaptive with --checkpoint and --resume: stopped by the time limit (twice, the second time
 * from the first checkpoint into a new one) and resumed on another device set, the image is
 * the uninterrupted adaptive render's bit for bit; a checkpoint of the other kind, or with
 * another threshold, is refused with the flag named. */
/* --flatten-instances renders the instanced scene's image bit for bit, so a checkpoint of one
 * resumes with the other (it was refused as "made for another scene"). */
static void test_resume_flattened(void **state)
{
    const fixture *f = (const fixture *)*state;
#define SC RS_SOURCE_DIR "/scenes/examples/instances.json", "--width", "64", "--height", "48", "-q"
    static const char *const ref[] = {"render", SC, "--spp", "8", "-o", "ref.exr", NULL};
    static const char *const cut[] = {"render", SC, "--spp", "4", "--checkpoint", "i.ckpt",
                                      "-o", "a.exr", NULL};
    static const char *const flat[] = {"render", SC, "--spp", "8", "--flatten-instances",
                                       "--resume", "i.ckpt", "--checkpoint", "f.ckpt", "-o",
                                       "f.exr", NULL};
    static const char *const back[] = {"render", SC, "--spp", "8", "--resume", "f.ckpt", "-o",
                                       "b.exr", NULL};
#undef SC
    proc p;
    run_expect(f, ref, 0, &p);
    proc_free(&p);
    run_expect(f, cut, 0, &p);
    proc_free(&p);
    run_expect(f, flat, 0, &p);
    expect_same_image(&p, f, "f.exr", "ref.exr");
    proc_free(&p);
    run_expect(f, back, 0, &p); /* a flattened render's checkpoint, resumed instanced */
    expect_same_image(&p, f, "b.exr", "ref.exr");
    proc_free(&p);
}

static void test_adaptive_resume(void **state)
{
    const fixture *f = (const fixture *)*state;
#define AD "--width", "64", "--height", "48", "--spp", "64", "--adaptive", "0.1", "-q"
    static const char *const ref[] = {"render", AD, "--devices", "cpu", "-o", "ref.exr", NULL};
    static const char *const cut1[] = {"render",       AD,     "--devices",    "cpu",
                                       "--wave-size",  "300",  "--time-limit", "0.1",
                                       "--checkpoint", "a.ckpt", "-o",         "a.exr",
                                       NULL};
    static const char *const cut2[] = {"render",       AD,       "--devices",    "cpu:1,gpu",
                                       "--resume",     "a.ckpt", "--time-limit", "0.1",
                                       "--checkpoint", "b.ckpt", "-o",           "b.exr",
                                       NULL};
    static const char *const last[] = {"render", AD, "--devices", "cpu,gpu", "--resume",
                                       "b.ckpt", "--stats-json", "b.json", "-o", "r.exr", NULL};
    static const char *const no_ad[] = {"render", "--width", "64", "--height", "48",
                                        "--spp", "64", "-q", "--resume", "a.ckpt",
                                        "-o", "x.exr", NULL};
    static const char *const other_t[] = {"render", "--width", "64", "--height", "48",
                                          "--spp", "64", "-q", "--adaptive", "0.2",
                                          "--resume", "a.ckpt", "-o", "x.exr", NULL};
    static const char *const plain[] = {"render", "--width", "64", "--height", "48", "--spp",
                                        "4", "-q", "--checkpoint", "p.ckpt", "-o", "p.exr", NULL};
    static const char *const plain_ad[] = {"render", AD, "--resume", "p.ckpt", "-o", "x.exr",
                                           NULL};
#undef AD
    proc p;
    run_expect(f, ref, 0, &p);
    proc_free(&p);
    run_expect(f, cut1, 0, &p);
    proc_free(&p);
    run_expect(f, cut2, 0, &p);
    proc_free(&p);
    run_expect(f, last, 0, &p);
    expect_same_image(&p, f, "r.exr", "ref.exr");
    fprintf(stderr, "  adaptive: %lld of the samples came from the checkpoints\n",
            json_number(f, "b.json", "resumed_samples"));
    EXPECT(&p, json_number(f, "b.json", "resumed_samples") > 0,
           "the last render should continue what the checkpoints hold");
    proc_free(&p);
    run_expect(f, no_ad, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "--adaptive"),
           "an adaptive checkpoint resumed without --adaptive: one line naming it");
    proc_free(&p);
    run_expect(f, other_t, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "--adaptive") && strstr(p.err.data, "0.2"),
           "another threshold: one line naming --adaptive and both values");
    proc_free(&p);
    run_expect(f, plain, 0, &p);
    proc_free(&p);
    run_expect(f, plain_ad, 2, &p);
    EXPECT(&p, one_line(&p.err) && strstr(p.err.data, "without --adaptive"),
           "a plain checkpoint resumed with --adaptive: refused");
    proc_free(&p);
}

static void test_exr_metadata(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render",      "builtin:materials",
                                       "--width",     "24",
                                       "--spp",       "3",
                                       "--seed",      "42",
                                       "--sampler",   "independent",
                                       "--max-depth", "7",
                                       "--devices",   "cpu:1,gpu",
                                       "-q",          "-o",
                                       "m.exr",       NULL};
    static const struct {
        const char *key, *want;
    } fields[] = {
        {"raystream:scene", "builtin:materials"},
        {"raystream:spp", "3"},
        {"raystream:spp_requested", "3"},
        {"raystream:seed", "42"},
        {"raystream:sampling", "mis"},
        {"raystream:sampler", "independent"},
        {"raystream:max_depth", "7"},
        {"raystream:devices", "cpu,gpu-fallback:0"},
        {"raystream:integrator", "stream"},
    };
    char path[256], value[256];
    size_t k;
    proc p;
    run_expect(f, args, 0, &p);
    path_in(f, "m.exr", path, sizeof path);
    for (k = 0; k < sizeof fields / sizeof fields[0]; ++k) {
        value[0] = '\0';
        EXPECT(&p, rs_image_read_meta(path, fields[k].key, value, sizeof value) == RS_OK,
               "m.exr has no %s", fields[k].key);
        EXPECT(&p, strcmp(value, fields[k].want) == 0, "m.exr's %s is '%s', not '%s'",
               fields[k].key, value, fields[k].want);
    }
    EXPECT(&p,
           rs_image_read_meta(path, "raystream:version", value, sizeof value) == RS_OK &&
               strspn(value, "0123456789.") > 0,
           "m.exr's raystream:version is '%s'", value);
    rs_error_clear();
    proc_free(&p);
}

/* Copies the first `len` bytes of file `from` to `to` (the test folder's), byte `flip` (if >= 0)
 * inverted. */
static void copy_cut(const fixture *f, const char *from, const char *to, size_t len, long flip)
{
    char a[256], b[256];
    size_t n = 0;
    char *data;
    FILE *fp;
    path_in(f, from, a, sizeof a);
    path_in(f, to, b, sizeof b);
    data = read_bytes(a, &n);
    assert_non_null(data);
    if (len > n)
        len = n;
    if (flip >= 0 && (size_t)flip < len)
        data[flip] = (char)~data[flip];
    fp = fopen(b, "wb");
    assert_non_null(fp);
    assert_int_equal(fwrite(data, 1, len, fp), len);
    fclose(fp);
    free(data);
}

/* --resume refuses, with one line naming the file (and the field), a checkpoint of other
 * settings (status 2) and a truncated or corrupt one (status 1), and replaces no file. */
static void test_checkpoint_refused(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const make[] = {"render", "--width",  "40", "--height",     "30",
                                       "--spp",  "2",        "-q", "--checkpoint", "c.ckpt",
                                       "-o",     "good.exr", NULL};
    static const char *const make_z[] = {"render",       "--width", "40", "--height",  "30",
                                         "--spp",        "2",       "-q", "--sampler", "zsobol",
                                         "--checkpoint", "z.ckpt",  "-o", "z.exr",     NULL};
    static const struct {
        const char *args[8];
        const char *file, *word;
        int code;
    } cases[] = {
        {{"--seed", "7"}, "c.ckpt", "--seed", 2},
        {{"--width", "20"}, "c.ckpt", "size", 2},
        {{"--sampling", "bsdf"}, "c.ckpt", "--sampling", 2},
        {{"--sampler", "independent"}, "c.ckpt", "--sampler", 2},
        {{"--max-depth", "5"}, "c.ckpt", "--max-depth", 2},
        {{"--isect-tri", "watertight"}, "c.ckpt", "--isect-tri", 2},
        {{"builtin:materials"}, "c.ckpt", "scene", 2},
        {{"--spp", "1"}, "c.ckpt", "--spp", 2},
        {{"--sampler", "zsobol", "--spp", "4"}, "z.ckpt", "zsobol", 2},
        {{NULL}, "half.ckpt", "truncated", 1},
        {{NULL}, "flip.ckpt", "corrupt", 1},
        {{NULL}, "head.ckpt", "corrupt", 1},
        {{NULL}, "text.ckpt", "not a raystream checkpoint", 1},
        {{NULL}, "empty.ckpt", "truncated", 1},
    };
    char good_path[256], ck_path[256], names[512];
    char *good, *ck, *after;
    size_t n_good = 0, n_ck = 0, n_after = 0, c, k;
    int before;
    proc p;

    run_expect(f, make, 0, &p);
    proc_free(&p);
    run_expect(f, make_z, 0, &p);
    proc_free(&p);
    path_in(f, "good.exr", good_path, sizeof good_path);
    path_in(f, "c.ckpt", ck_path, sizeof ck_path);
    good = read_bytes(good_path, &n_good);
    ck = read_bytes(ck_path, &n_ck);
    assert_non_null(good);
    assert_non_null(ck);
    copy_cut(f, "c.ckpt", "half.ckpt", n_ck / 2, -1);
    copy_cut(f, "c.ckpt", "flip.ckpt", n_ck, (long)(n_ck / 2));
    copy_cut(f, "c.ckpt", "head.ckpt", n_ck, 32); /* the sample count in the header */
    put_file(f, "text.ckpt",
             "{\"not\": \"a checkpoint, but long enough to hold a header\"}\n"
             "................................................................");
    put_file(f, "empty.ckpt", "");
    before = list_dir(f->dir, names, sizeof names);
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const char *args[MAX_ARGS] = {
            "render",   "--width",     "40",           "--height", "30", "--spp",   "2",
            "--resume", cases[c].file, "--checkpoint", "c.ckpt",   "-o", "good.exr"};
        int n = 13;
        for (k = 0; k < 8 && cases[c].args[k]; ++k)
            args[n++] = cases[c].args[k];
        args[n] = NULL;
        if (strcmp(cases[c].file, "z.ckpt") == 0)
            args[10] = "z2.ckpt";
        run(&p, f->dir, DEFAULT_TIMEOUT_S, args);
        EXPECT(&p, exited_with(&p, cases[c].code), "expected status %d", cases[c].code);
        EXPECT(&p, one_line(&p.err), "expected exactly one line on stderr");
        EXPECT(&p, strstr(p.err.data, cases[c].file) && strstr(p.err.data, cases[c].word),
               "the line should name %s and '%s'", cases[c].file, cases[c].word);
        after = read_bytes(good_path, &n_after);
        EXPECT(&p, after && n_after == n_good && memcmp(after, good, n_good) == 0,
               "good.exr changed");
        free(after);
        after = read_bytes(ck_path, &n_after);
        EXPECT(&p, after && n_after == n_ck && memcmp(after, ck, n_ck) == 0, "c.ckpt changed");
        free(after);
        EXPECT(&p, list_dir(f->dir, names, sizeof names) == before,
               "a refused resume left a file behind: %s", names);
        proc_free(&p);
    }
    free(good);
    free(ck);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_usage_errors, setup, teardown),
        cmocka_unit_test_setup_teardown(test_output_in_missing_folder, setup, teardown),
        cmocka_unit_test_setup_teardown(test_output_in_read_only_folder, setup, teardown),
        cmocka_unit_test_setup_teardown(test_help_and_version, setup, teardown),
        cmocka_unit_test_setup_teardown(test_render_png, setup, teardown),
        cmocka_unit_test_setup_teardown(test_render_float_formats, setup, teardown),
        cmocka_unit_test_setup_teardown(test_render_default_output, setup, teardown),
        cmocka_unit_test_setup_teardown(test_failed_run_keeps_output, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sigint_writes_partial_image, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sigint_megakernel, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sigterm_sighup_write_partial_image, setup, teardown),
        cmocka_unit_test_setup_teardown(test_second_signal_removes_temp_file, setup, teardown),
        cmocka_unit_test_setup_teardown(test_reader_gone_keeps_rendering, setup, teardown),
        cmocka_unit_test_setup_teardown(test_outputs_checked_first, setup, teardown),
        cmocka_unit_test_setup_teardown(test_failed_stats_keeps_image, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_fault_env, setup, teardown),
        cmocka_unit_test_setup_teardown(test_threads_and_chunks_change_nothing, setup, teardown),
        cmocka_unit_test_setup_teardown(test_device_fault_and_stats, setup, teardown),
        cmocka_unit_test_setup_teardown(test_gpu_fallback, setup, teardown),
        cmocka_unit_test_setup_teardown(test_require_gpu, setup, teardown),
        cmocka_unit_test_setup_teardown(test_user_scenes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_scene_files_and_meshes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_stage_stats_and_timeline, setup, teardown),
        cmocka_unit_test_setup_teardown(test_time_limit, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_resume, setup, teardown),
        cmocka_unit_test_setup_teardown(test_resume_after_signal, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_refused, setup, teardown),
        cmocka_unit_test_setup_teardown(test_exr_metadata, setup, teardown),
        cmocka_unit_test_setup_teardown(test_aov_layers, setup, teardown),
        cmocka_unit_test_setup_teardown(test_aov_resume, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive_resume, setup, teardown),
        cmocka_unit_test_setup_teardown(test_resume_flattened, setup, teardown),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
