/* tests/app_settings_test.c — one image-defining setting, one place (app/image_settings.h): a
 * dummy setting added as one more row of the table shows up, with nothing else changed, in
 *   - the checkpoint's settings block: a checkpoint written with dummy "on" is refused when
 *     resumed with "off", the one line naming --dummy and both values, and read when resumed
 *     with "on" (the film's sums and counts back bit for bit);
 *   - the EXR header: "raystream:dummy" = "on" (beside the rows every render has: seed,
 *     sampler, ...);
 *   - --stats-json's "settings" object: "dummy": "on".
 * And the table's own rules: a block with a setting this build does not know is refused, as is
 * one that lacks a row; a checkpoint of version 2 (before the settings block: fixed fields) is
 * still read, and refused with another --seed. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "app/checkpoint.h"
#include "app/report.h"
#include "app/signals.h"
#include "core/alloc.h"

/* report.c names an interrupting signal; none interrupts here */
const char *rs_signal_name(int sig)
{
    (void)sig;
    return "a signal";
}

static const char *g_dummy = "on";

static void text_dummy(const rs_image_settings *s, char *b, size_t n)
{
    (void)s;
    snprintf(b, n, "%s", g_dummy);
}

static rs_image_settings settings(void)
{
    rs_image_settings s;
    memset(&s, 0, sizeof s);
    s.width = 8;
    s.height = 4;
    s.spp = 2;
    s.max_depth = 5;
    s.rr_depth = 3;
    s.seed = 42;
    s.sampling = RS_SAMPLING_MIS;
    s.sampler = RS_SAMPLER_SOBOL;
    rs_filter_default(&s.filter);
    return s;
}

static int setup(void **state)
{
    static const rs_setting_desc dummy = {"dummy", "--dummy", text_dummy};
    static int added;
    (void)state;
    if (!added)
        added = rs_image_settings_add_row(&dummy);
    g_dummy = "on";
    return added ? 0 : -1;
}

/* The whole of a file, NUL-terminated (free it). */
static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    char *s;
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    return s;
}

static void test_block_and_match(void **state)
{
    rs_image_settings s = settings();
    char block[4096], option[64], a[128], b[128];
    size_t n;
    (void)state;
    n = rs_image_settings_block(&s, block, sizeof block);
    assert_true(n > 0);
    assert_non_null(strstr(block, "dummy=on\n"));
    assert_non_null(strstr(block, "seed=42\n"));
    assert_true(rs_image_settings_match(&s, block, n, option, sizeof option, a, b, sizeof a));
    g_dummy = "off";
    assert_false(rs_image_settings_match(&s, block, n, option, sizeof option, a, b, sizeof a));
    printf("  a block of dummy on, this render off: %s %s against %s\n", option, a, b);
    assert_string_equal(option, "--dummy");
    assert_string_equal(a, "on");
    assert_string_equal(b, "off");
    g_dummy = "on";
    /* a row this build does not know, and a row missing */
    {
        char more[4200];
        snprintf(more, sizeof more, "%swobble=3\n", block);
        assert_false(rs_image_settings_match(&s, more, strlen(more), option, sizeof option, a, b,
                                             sizeof a));
        assert_non_null(strstr(option, "wobble"));
    }
    {
        const char *cut = strstr(block, "dummy=on\n");
        assert_false(rs_image_settings_match(&s, block, (size_t)(cut - block), option,
                                             sizeof option, a, b, sizeof a));
        assert_string_equal(option, "--dummy");
        assert_string_equal(a, "(none)");
    }
}

/* A checkpoint written for the tests: a folder, a film of 8x4 pixels with one sample each, the
 * key it was written with. */
typedef struct ck {
    char dir[64], path[256], err[256];
    rs_checkpoint_key key;
    rs_film *film;
} ck;

static void ck_make(ck *c, uint64_t scene_hash)
{
    char staged[256];
    rs_path_ranges held = {NULL, 0, 0};
    uint32_t i;
    memset(c, 0, sizeof *c);
    snprintf(c->dir, sizeof c->dir, "/tmp/rs_settings_test_XXXXXX");
    assert_non_null(mkdtemp(c->dir));
    snprintf(c->path, sizeof c->path, "%s/c.ckpt", c->dir);
    snprintf(staged, sizeof staged, "%s/c.ckpt.tmp", c->dir);
    snprintf(c->err, sizeof c->err, "%s/err.txt", c->dir);
    c->key.scene_hash = scene_hash;
    c->key.img = settings();
    c->key.scene = "builtin:test";
    assert_int_equal(rs_film_create(8, 4, &c->film), RS_OK);
    for (i = 0; i < 32; ++i)
        rs_film_add(c->film, i, rs_v3(0.1f * (float)i, 0.5f, 2.0f));
    assert_true(rs_path_ranges_add(&held, 0, 32));
    assert_int_equal(rs_checkpoint_write(c->path, staged, 1, &c->key, c->film, &held), 1);
    rs_path_ranges_free(&held);
}

/* rs_checkpoint_read of `file` with c's key into a fresh film, stderr caught: the status, the
 * film's sums the checkpoint's (when read), *err what it printed (free it). */
static int ck_read(ck *c, const char *file, char **err)
{
    rs_path_ranges back = {NULL, 0, 0};
    rs_film *read = NULL;
    int rc, saved;
    assert_int_equal(rs_film_create(8, 4, &read), RS_OK);
    fflush(stderr);
    saved = dup(2);
    assert_non_null(freopen(c->err, "w", stderr));
    rc = rs_checkpoint_read(file, &c->key, read, &back);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    *err = slurp(c->err);
    if (rc == 0) {
        assert_int_equal(rs_path_ranges_total(&back), 32);
        assert_memory_equal(read->sum, c->film->sum, 32 * 3 * sizeof *read->sum);
        assert_memory_equal(read->count, c->film->count, 32 * sizeof *read->count);
    }
    rs_path_ranges_free(&back);
    rs_film_destroy(read);
    return rc;
}

static void ck_free(ck *c, const char *other)
{
    rs_film_destroy(c->film);
    unlink(c->path);
    unlink(c->err);
    if (other)
        unlink(other);
    rmdir(c->dir);
}

static void test_checkpoint_follows(void **state)
{
    ck c;
    char *err;
    (void)state;
    ck_make(&c, 0x1234);
    /* resumed with dummy off: refused, the line naming it */
    g_dummy = "off";
    assert_int_equal(ck_read(&c, c.path, &err), 2);
    printf("  resumed with --dummy off: \"%.*s\"\n", (int)strcspn(err, "\n"), err);
    assert_non_null(strstr(err, "--dummy on"));
    assert_non_null(strstr(err, "--dummy off"));
    free(err);
    /* with dummy on: read back */
    g_dummy = "on";
    assert_int_equal(ck_read(&c, c.path, &err), 0);
    free(err);
    ck_free(&c, NULL);
}

static uint32_t get32(const unsigned char *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}

/* Checkpoint `from` (version 7) rewritten as version 2 at `to`: the flags and the settings block
 * cut from the header, the checksum (FNV-1a 64 of every byte before it) made anew. */
static void to_version2(const char *from, const char *to)
{
    FILE *f = fopen(from, "rb"), *g;
    long n;
    unsigned char *d;
    uint32_t name_len, ranges, v2 = 2, hdr2, hdr7;
    uint64_t h = 14695981039346656037ull;
    size_t body, i, out;
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    d = malloc((size_t)n);
    assert_non_null(d);
    assert_int_equal(fread(d, 1, (size_t)n, f), (size_t)n);
    fclose(f);
    assert_int_equal(get32(d + 8), 7);
    name_len = get32(d + 88);
    ranges = get32(d + 92 + name_len);
    hdr7 = get32(d + 12);
    hdr2 = 92 + name_len + 8 + 16 * ranges;
    body = (size_t)n - 8 - hdr7;
    memmove(d + hdr2, d + hdr7, body);
    memcpy(d + 8, &v2, 4);
    memcpy(d + 12, &hdr2, 4);
    out = hdr2 + body;
    for (i = 0; i < out; ++i)
        h = (h ^ d[i]) * 1099511628211ull;
    memcpy(d + out, &h, 8);
    g = fopen(to, "wb");
    assert_non_null(g);
    assert_int_equal(fwrite(d, 1, out + 8, g), out + 8);
    fclose(g);
    free(d);
}

static void test_version2_read(void **state)
{
    ck c;
    char old[256], *err;
    (void)state;
    ck_make(&c, 0x77);
    snprintf(old, sizeof old, "%s/v2.ckpt", c.dir);
    to_version2(c.path, old);
    assert_int_equal(ck_read(&c, old, &err), 0);
    free(err);
    c.key.img.seed = 43;
    assert_int_equal(ck_read(&c, old, &err), 2);
    printf("  a version-2 file read back; with --seed 43: \"%.*s\"\n", (int)strcspn(err, "\n"),
           err);
    assert_non_null(strstr(err, "--seed 42"));
    free(err);
    ck_free(&c, old);
}

static void test_header_and_json_follow(void **state)
{
    char dir[] = "/tmp/rs_settings_test_XXXXXX", path[256];
    rs_image_settings s = settings();
    rs_report rep;
    rs_report_meta m;
    size_t i;
    int found = 0, seed = 0;
    char *json;
    (void)state;
    memset(&rep, 0, sizeof rep);
    rep.scene = "builtin:test";
    rep.width = 8;
    rep.height = 4;
    rep.spp = rep.spp_min = 2;
    rep.img = &s;
    rs_report_image_meta(&rep, &m);
    for (i = 0; i < m.n; ++i) {
        if (strcmp(m.meta[i].key, "raystream:dummy") == 0) {
            assert_string_equal(m.meta[i].value, "on");
            found = 1;
        }
        if (strcmp(m.meta[i].key, "raystream:seed") == 0) {
            assert_string_equal(m.meta[i].value, "42");
            seed = 1;
        }
    }
    assert_true(found && seed);
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/s.json", dir);
    assert_int_equal(rs_report_write_json(&rep, path, "s.json"), 1);
    json = slurp(path);
    assert_non_null(strstr(json, "\"settings\": {"));
    assert_non_null(strstr(json, "\"dummy\": \"on\""));
    assert_non_null(strstr(json, "\"sampler\": \"sobol\""));
    printf("  the EXR header has raystream:dummy = on (%zu attributes); the JSON's settings "
           "have \"dummy\": \"on\"\n",
           m.n);
    free(json);
    unlink(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup(test_block_and_match, setup),
        cmocka_unit_test_setup(test_checkpoint_follows, setup),
        cmocka_unit_test_setup(test_version2_read, setup),
        cmocka_unit_test_setup(test_header_and_json_follow, setup),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
