/* tests/scenes_json_test.c — the JSON scene reader: the example Cornell box file is the built-in
 * scene exactly (the same image bit for bit); every kind of bad input is an RS_ERR_ARG whose
 * one-line message names the file and the field (or the line of a syntax error); image textures
 * load relative to the scene file; and 20000 random mutations of a valid file never crash the
 * reader (run it under ASan: scripts/check-sanitizers.sh). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/image_io.h"
#include "render_util.h"
#include "scenes/scene_json.h"
#include "test_rand.h"

#ifndef RS_SOURCE_DIR
#  define RS_SOURCE_DIR "."
#endif

static char *read_text(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf;
    long n;
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    buf = (char *)malloc((size_t)n + 1);
    assert_int_equal(fread(buf, 1, (size_t)n, f), (size_t)n);
    buf[n] = '\0';
    fclose(f);
    *len = (size_t)n;
    return buf;
}

static void test_example_equals_builtin(void **state)
{
    rs_scene *js;
    rt_args a = rt_defaults("cornell", 32, 4);
    float *from_file, *builtin;
    (void)state;
    assert_int_equal(rs_scene_load_json(RS_SOURCE_DIR "/scenes/examples/cornell.json", &js), RS_OK);
    assert_int_equal(js->n_quads, 18u);
    assert_int_equal(js->n_lights, 1u);
    assert_int_equal(js->width, 600u);
    from_file = rt_render_scene(js, &a, NULL);
    builtin = rt_render(&a, NULL);
    assert_non_null(from_file);
    assert_non_null(builtin);
    assert_memory_equal(from_file, builtin, 32 * 32 * 3 * sizeof(float));
    free(from_file);
    free(builtin);
    rs_scene_destroy(js);
}

typedef struct bad_case {
    const char *json;
    const char *words[3]; /* each must appear in the message */
} bad_case;

#define CAM "\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]}"
#define MAT "\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5]}}"

static const bad_case g_bad[] = {
    {"", {"t.json:1", "syntax"}},
    {"{\n\"camera\": {\n\"from\": [0,0,1],,\n}", {"t.json:3", "syntax"}},
    {"[1, 2]", {"JSON object"}},
    {"{" MAT ",\"objects\":[]}", {"missing 'camera'"}},
    {"{" CAM "," MAT "}", {"missing 'objects'"}},
    {"{" CAM "," MAT ",\"objects\":[],\"bogus\":1}", {"unknown key 'bogus'"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
     "\"material\":\"nope\"}]}",
     {"objects[0].material", "nope"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0],\"radius\":1,"
     "\"material\":\"m\"}]}",
     {"objects[0].center", "3 numbers"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":-1,"
     "\"material\":\"m\"}]}",
     {"objects[0].radius", "out of range"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"cone\",\"material\":\"m\"}]}",
     {"objects[0]", "unknown object type 'cone'"}},
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[1.5,0,0]}},"
     "\"objects\":[]}",
     {"materials.m.albedo", "[0, 1]"}},
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"plastic\"}},\"objects\":[]}",
     {"materials.m", "unknown material type 'plastic'"}},
    {"{" CAM ",\"materials\":{\"g\":{\"type\":\"dielectric\",\"ior\":\"1.5\"}},\"objects\":[]}",
     {"materials.g.ior", "number"}},
    {"{" CAM ",\"materials\":{\"p\":{\"type\":\"phong\",\"exponent\":-2}},\"objects\":[]}",
     {"materials.p.exponent"}},
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"lambertian\",\"texture\":\"t\"}},"
     "\"objects\":[]}",
     {"materials.m.texture", "no texture named 't'"}},
    {"{" CAM ",\"textures\":{\"t\":{\"type\":\"image\",\"file\":\"missing.png\"}},"
     "\"objects\":[]}",
     {"textures.t", "missing.png"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"quad\",\"q\":[0,0,0],\"u\":[1,0,0],"
     "\"v\":[2,0,0],\"material\":\"m\"}]}",
     {"objects[0]", "parallelogram"}},
    {"{\"camera\":{\"from\":[0,0,0],\"at\":[0,0,0]}," MAT ",\"objects\":[]}", {"camera", "differ"}},
    {"{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0],\"vfov\":0}," MAT ",\"objects\":[]}",
     {"camera.vfov"}},
    {"{" CAM "," MAT ",\"image\":{\"width\":10.5},\"objects\":[]}", {"image", "whole"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"box\",\"min\":[1,1,1],\"max\":[0,2,2],"
     "\"material\":\"m\"}]}",
     {"objects[0]", "'max' must exceed 'min'"}},
};

static void test_bad_inputs(void **state)
{
    size_t k;
    (void)state;
    for (k = 0; k < sizeof g_bad / sizeof g_bad[0]; ++k) {
        rs_scene *s = (rs_scene *)0x1;
        const char *msg;
        int w;
        rs_error_clear();
        assert_int_equal(
            rs_scene_parse_json(g_bad[k].json, strlen(g_bad[k].json), "t.json", NULL, &s),
            RS_ERR_ARG);
        assert_null(s);
        msg = rs_error_message();
        assert_non_null(strstr(msg, "t.json"));
        assert_null(strchr(msg, '\n'));
        for (w = 0; w < 3 && g_bad[k].words[w]; ++w)
            if (!strstr(msg, g_bad[k].words[w]))
                fail_msg("case %zu: message '%s' lacks '%s'", k, msg, g_bad[k].words[w]);
    }
    rs_error_clear();
}

/* An image texture next to the scene file, named relatively: loaded and sRGB-decoded. */
static void test_image_texture_relative(void **state)
{
    char dir[] = "/tmp/rs_json_XXXXXX", png[256], scene_path[256];
    static const float px[2 * 2 * 3] = {0.0f, 0.2f, 1.0f, 0.5f,  0.5f, 0.5f,
                                        1.0f, 0.0f, 0.0f, 0.05f, 0.6f, 0.9f};
    const char *json = "{" CAM ",\"textures\":{\"t\":{\"type\":\"image\",\"file\":\"tex.png\"}},"
                       "\"materials\":{\"m\":{\"type\":\"lambertian\",\"texture\":\"t\"}},"
                       "\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
                       "\"material\":\"m\"}]}";
    FILE *f;
    rs_scene *s;
    int i;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(png, sizeof png, "%s/tex.png", dir);
    snprintf(scene_path, sizeof scene_path, "%s/scene.json", dir);
    assert_int_equal(rs_image_write(png, 2, 2, px), RS_OK);
    f = fopen(scene_path, "w");
    assert_non_null(f);
    fputs(json, f);
    fclose(f);
    assert_int_equal(rs_scene_load_json(scene_path, &s), RS_OK);
    assert_int_equal(s->n_images, 1u);
    assert_int_equal(s->images[0].width, 2u);
    /* written as 8-bit sRGB, read back linear: equal within one 8-bit step */
    for (i = 0; i < 12; ++i)
        assert_true(fabsf(s->images[0].rgb[i] - px[i]) < 0.01f);
    rs_scene_destroy(s);
    remove(png);
    remove(scene_path);
    rmdir(dir);
}

/* Random byte edits of the example file: every outcome is RS_OK or RS_ERR_ARG (never a crash,
 * a hang or another code), and on error no scene comes back. */
static void test_mutations_never_crash(void **state)
{
    size_t len, k;
    char *orig = read_text(RS_SOURCE_DIR "/scenes/examples/cornell.json", &len);
    char *buf = (char *)malloc(len + 1);
    uint64_t st = 2024;
    static const char alphabet[] = "{}[],:\"0123456789.-eE \nabcxyz";
    int ok = 0, bad = 0;
    (void)state;
    for (k = 0; k < 20000; ++k) {
        rs_scene *s = NULL;
        rs_status r;
        int edits = 1 + (int)(splitmix64(&st) % 4), e;
        size_t n = len;
        memcpy(buf, orig, len + 1);
        for (e = 0; e < edits; ++e) {
            size_t pos = (size_t)(splitmix64(&st) % n);
            switch (splitmix64(&st) % 3) {
            case 0: buf[pos] = alphabet[splitmix64(&st) % (sizeof alphabet - 1)]; break;
            case 1: /* delete a byte */
                memmove(buf + pos, buf + pos + 1, n - pos);
                n--;
                break;
            default: n = pos; /* truncate */
            }
            if (n == 0)
                break;
        }
        r = rs_scene_parse_json(buf, n, "m.json", NULL, &s);
        if (r == RS_OK) {
            assert_non_null(s);
            rs_scene_destroy(s);
            ok++;
        } else {
            assert_int_equal(r, RS_ERR_ARG);
            assert_null(s);
            bad++;
        }
        rs_error_clear();
    }
    print_message("mutations: %d still valid, %d rejected\n", ok, bad);
    assert_true(bad > 1000);
    free(buf);
    free(orig);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_example_equals_builtin),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_image_texture_relative),
        cmocka_unit_test(test_mutations_never_crash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
