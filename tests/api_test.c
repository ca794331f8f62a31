/* tests/api_test.c — the C API (include/raystream.h) through the shared library, as an outside
 * program links it:
 *   - a render through the library is `raystream render`'s with the same options, bit for bit:
 *     the image (several scenes and option sets, the GPU fallback among the devices) and the
 *     --aov layers, compared with the command's files;
 *   - a scene built with the API (materials from JSON objects, a mesh from arrays with vertex
 *     normals and UVs that are not axis-aligned, a sphere, a quad light, camera, background)
 *     renders as the same scene written as a JSON file, loaded both from text and from the file;
 *   - the progress callback sees fractions in [0, 1] that never fall, and stops the render:
 *     RAYSTREAM_CANCELLED with the samples finished so far, fewer than asked;
 *   - hostile calls (NULL handles, unknown and command-only options, bad values, NaN vertices,
 *     indices out of range, a malformed material, missing files, an unwritable output) return
 *     the right status with one line naming the problem, print nothing on stderr, and leave
 *     the scene as it was;
 *   - the error message is the calling thread's own. */
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "raystream.h"

#define RS_HARNESS_NAME "api_test.c"
#include "cli_harness.h"

/* ---- helpers ------------------------------------------------------------------------------ */

/* Fails unless `got` is `want` with one line holding `needle` (below). */
static void expect_error(raystream_status got, raystream_status want, const char *needle);
static int try_while_busy(void *user, double fraction);

/* Options from "name=value" strings (NULL-terminated). */
static raystream_options *options(const char *const *kv)
{
    raystream_options *o = NULL;
    assert_int_equal(raystream_options_create(&o), RAYSTREAM_OK);
    for (; *kv; ++kv) {
        char name[64];
        const char *eq = strchr(*kv, '=');
        assert_non_null(eq);
        snprintf(name, sizeof name, "%.*s", (int)(eq - *kv), *kv);
        if (raystream_options_set(o, name, eq + 1) != RAYSTREAM_OK)
            fail_msg("option %s: %s", *kv, raystream_last_error());
    }
    return o;
}

/* The command's arguments for the same options: "--name", "value" (flags: "--name" alone). */
static int cli_args(const char *const *kv, const char **args, int n, char store[][128])
{
    int k = 0;
    for (; *kv; ++kv) {
        const char *eq = strchr(*kv, '=');
        char *c;
        snprintf(store[k], sizeof store[k], "--%.*s", (int)(eq - *kv), *kv);
        for (c = store[k]; *c; ++c) /* the library takes '_' for '-'; the command does not */
            *c = *c == '_' ? '-' : *c;
        args[n++] = store[k++];
        if (strcmp(eq + 1, "true") != 0)
            args[n++] = eq + 1;
    }
    args[n] = NULL;
    return n;
}

static raystream_image *render_name(const char *scene, const char *const *kv)
{
    raystream_options *o = options(kv);
    raystream_image *img = NULL;
    raystream_status st = raystream_render_scene(scene, o, &img);
    if (st != RAYSTREAM_OK)
        fail_msg("render %s: status %d: %s", scene, (int)st, raystream_last_error());
    raystream_options_release(o);
    return img;
}

static raystream_image *render_built(raystream_scene *s, const char *const *kv)
{
    raystream_options *o = options(kv);
    raystream_image *img = NULL;
    raystream_status st = raystream_render(s, o, &img);
    if (st != RAYSTREAM_OK)
        fail_msg("render: status %d: %s", (int)st, raystream_last_error());
    raystream_options_release(o);
    return img;
}

static int same_pixels(const raystream_image *a, const raystream_image *b)
{
    uint32_t w = raystream_image_width(a), h = raystream_image_height(a);
    return w == raystream_image_width(b) && h == raystream_image_height(b) &&
           memcmp(raystream_image_pixels(a), raystream_image_pixels(b),
                  (size_t)w * h * 3 * sizeof(float)) == 0;
}

/* ---- the command's images ----------------------------------------------------------------- */

/* `raystream render SCENE OPTIONS -o out.pfm` and the library's render: the same floats. */
static void expect_cli_image(const fixture *f, const char *scene, const char *const *kv)
{
    const char *args[48] = {"render", scene, "-q", "-o", "out.pfm"};
    char store[20][128], path[512];
    raystream_image *api = render_name(scene, kv), *cli = NULL;
    proc p;
    cli_args(kv, args, 5, store);
    run_expect(f, args, 0, &p);
    path_in(f, "out.pfm", path, sizeof path);
    assert_int_equal(raystream_image_read(path, &cli), RAYSTREAM_OK);
    EXPECT(&p, same_pixels(api, cli), "the library's image of %s differs from the command's",
           scene);
    proc_free(&p);
    raystream_image_release(api);
    raystream_image_release(cli);
}

static void test_render_matches_cli(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const plain[] = {"width=96", "spp=4", NULL};
    static const char *const settings[] = {
        "width=80",       "height=60",         "spp=3",
        "seed=7",         "max-depth=6",       "sampler=independent",
        "filter=box:0.5", "light_sampler=bvh", NULL};
    static const char *const fallback[] = {"width=64", "spp=2", "devices=cpu:1,gpu", NULL};
    static const char *const adaptive[] = {"width=64", "spp=32", "adaptive=0.1",
                                           "adaptive-min-spp=8", NULL};
    static const char *const mk[] = {"width=64", "spp=2", "integrator=megakernel", "threads=1",
                                     NULL};
    expect_cli_image(f, "builtin:cornell", plain);
    expect_cli_image(f, "builtin:materials", settings);
    expect_cli_image(f, "builtin:rtiow-final", fallback);
    expect_cli_image(f, "builtin:cornell-glass", adaptive);
    expect_cli_image(f, "builtin:bouncing-spheres", mk);
}

/* The --aov layers: the library's equal the command's EXR channels. */
static void test_aov_matches_cli(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const kv[] = {"width=48", "spp=4", "aov=albedo,normal,depth,samples", NULL};
    static const struct {
        const char *layer, *channel;
        int c, n;
    } chans[] = {{"albedo", "albedo.G", 1, 3},
                 {"normal", "normal.X", 0, 3},
                 {"depth", "depth.Z", 0, 1},
                 {"samples", "samples.Y", 0, 1}};
    const char *args[48] = {"render", "builtin:cornell", "-q", "-o", "out.exr"};
    char store[20][128], path[512];
    raystream_image *api = render_name("builtin:cornell", kv);
    proc p;
    size_t k, i;
    cli_args(kv, args, 5, store);
    run_expect(f, args, 0, &p);
    path_in(f, "out.exr", path, sizeof path);
    assert_int_equal(raystream_image_layer_count(api), 4);
    for (k = 0; k < 4; ++k) {
        uint32_t w, h;
        float *data = NULL;
        int ch = 0;
        const float *mine = raystream_image_layer(api, chans[k].layer, &ch);
        assert_non_null(mine);
        assert_int_equal(ch, chans[k].n);
        assert_int_equal(rs_image_read_channel(path, chans[k].channel, &w, &h, &data), RS_OK);
        assert_int_equal(w * h, 48u * 48u);
        for (i = 0; i < (size_t)w * h; ++i)
            if (memcmp(&data[i], &mine[i * ch + chans[k].c], sizeof(float)) != 0)
                fail_msg("%s pixel %zu: library %g, command %g", chans[k].channel, i,
                         (double)mine[i * ch + chans[k].c], (double)data[i]);
        rs_free(data);
    }
    /* the header: every attribute of the command's (raystream:*) with the same value */
    {
        static const char *const keys[] = {"raystream:scene",     "raystream:spp",
                                           "raystream:devices",   "raystream:integrator",
                                           "raystream:version",   "raystream:seed",
                                           "raystream:filter",    "raystream:sampler",
                                           "raystream:max_depth", NULL};
        char mine[512], theirs[512], api_path[512];
        path_in(f, "api.exr", api_path, sizeof api_path);
        assert_int_equal(raystream_image_write(api, api_path), RAYSTREAM_OK);
        for (k = 0; keys[k]; ++k) {
            assert_int_equal(rs_image_read_meta(api_path, keys[k], mine, sizeof mine), RS_OK);
            assert_int_equal(rs_image_read_meta(path, keys[k], theirs, sizeof theirs), RS_OK);
            if (strcmp(mine, theirs) != 0)
                fail_msg("%s: library '%s', command '%s'", keys[k], mine, theirs);
        }
    }
    proc_free(&p);
    raystream_image_release(api);
}

/* ---- a scene built with the API against its JSON file ------------------------------------- */

static const char k_scene_json[] =
    "{\"camera\": {\"from\": [0.3, 1.2, 3.5], \"at\": [0, 0.4, 0], \"up\": [0.1, 1, 0], "
    "\"vfov\": 35},\n"
    " \"image\": {\"width\": 72, \"height\": 54},\n"
    " \"background\": [0.05, 0.07, 0.1],\n"
    " \"materials\": {\"red\": {\"type\": \"lambertian\", \"albedo\": [0.7, 0.2, 0.15]},\n"
    "               \"gold\": {\"type\": \"metal\", \"albedo\": [0.9, 0.7, 0.3], \"fuzz\": 0.2},\n"
    "               \"lamp\": {\"type\": \"light\", \"emission\": [6, 5, 4]}},\n"
    " \"objects\": [\n"
    "  {\"type\": \"triangle\", \"vertices\": [[-2, 0, -2], [2, 0.2, 2], [2, 0, -2]],\n"
    "   \"normals\": [0, 1, 0, 0.28734789, 0.95782629, 0, 0, 1, 0],\n"
    "   \"uv\": [0, 0, 1, 1, 1, 0], \"material\": \"red\"},\n"
    "  {\"type\": \"triangle\", \"vertices\": [[-2, 0, -2], [-2, 0.1, 2], [2, 0.2, 2]],\n"
    "   \"normals\": [0, 1, 0, 0, 0.99503719, 0.09950372, 0.28734789, 0.95782629, 0],\n"
    "   \"uv\": [0, 0, 0, 1, 1, 1], \"material\": \"red\"},\n"
    "  {\"type\": \"sphere\", \"center\": [0.2, 0.5, 0.1], \"radius\": 0.5, \"material\": "
    "\"gold\"},\n"
    "  {\"type\": \"quad\", \"q\": [-0.5, 2, -0.5], \"u\": [1, 0, 0], \"v\": [0, 0, 1], "
    "\"material\": \"lamp\"}]}\n";

static raystream_scene *build_scene(void)
{
    static const float pos[] = {-2, 0, -2, 2, 0.2f, 2, 2, 0, -2, -2, 0.1f, 2};
    static const float nrm[] = {0, 1, 0, 0.28734789f, 0.95782629f, 0,
                                0, 1, 0, 0,           0.99503719f, 0.09950372f};
    static const float uv[] = {0, 0, 1, 1, 1, 0, 0, 1};
    static const uint32_t idx[] = {0, 1, 2, 0, 3, 1};
    const float center[3] = {0.2f, 0.5f, 0.1f}, q[3] = {-0.5f, 2, -0.5f}, u[3] = {1, 0, 0},
                v[3] = {0, 0, 1};
    const float from[3] = {0.3f, 1.2f, 3.5f}, at[3] = {0, 0.4f, 0}, up[3] = {0.1f, 1, 0},
                bg[3] = {0.05f, 0.07f, 0.1f};
    raystream_scene *s = NULL;
    uint32_t red, gold, lamp, n_tris;
    assert_int_equal(raystream_scene_create(&s), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_material(
                         s, "{\"type\": \"lambertian\", \"albedo\": [0.7, 0.2, 0.15]}", &red),
                     RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_material(s,
                                                  "{\"type\": \"metal\", \"albedo\": [0.9, 0.7, "
                                                  "0.3], \"fuzz\": 0.2}",
                                                  &gold),
                     RAYSTREAM_OK);
    assert_int_equal(
        raystream_scene_add_material(s, "{\"type\": \"light\", \"emission\": [6, 5, 4]}", &lamp),
        RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_mesh(s, pos, 4, idx, 2, nrm, uv, red), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_sphere(s, center, 0.5f, gold), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_quad(s, q, u, v, lamp), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_set_camera(s, from, at, up, 35.0f, 0, 0), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_set_background(s, bg), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_set_image_size(s, 72, 54), RAYSTREAM_OK);
    raystream_scene_counts(s, NULL, NULL, &n_tris, NULL);
    assert_int_equal(n_tris, 2);
    return s;
}

static void test_built_scene_equals_json(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const kv[] = {"spp=8", NULL};
    raystream_scene *built = build_scene(), *text = NULL, *file = NULL;
    raystream_image *a, *b, *c;
    char path[512];
    double mean = 0.0;
    size_t i;
    write_in(f, "scene.json", k_scene_json);
    path_in(f, "scene.json", path, sizeof path);
    assert_int_equal(raystream_scene_from_json(k_scene_json, NULL, &text), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_load(path, &file), RAYSTREAM_OK);
    a = render_built(built, kv);
    b = render_built(text, kv);
    c = render_built(file, kv);
    assert_int_equal(raystream_image_width(a), 72);
    assert_int_equal(raystream_image_height(a), 54);
    for (i = 0; i < 72 * 54 * 3; ++i)
        mean += raystream_image_pixels(a)[i];
    assert_true(mean / (72 * 54 * 3) > 0.01); /* lit: the comparison means something */
    assert_true(same_pixels(a, b));
    assert_true(same_pixels(a, c));
    /* a scene renders again the same (finalized again with this render's extras) */
    raystream_image_release(b);
    b = render_built(built, kv);
    assert_true(same_pixels(a, b));
    raystream_image_release(a);
    raystream_image_release(b);
    raystream_image_release(c);
    { /* one render at a time */
        raystream_options *o = options(kv);
        raystream_options_set_progress(o, try_while_busy, built);
        assert_int_equal(raystream_render(built, o, &b), RAYSTREAM_OK);
        raystream_image_release(b);
        raystream_options_release(o);
    }
    raystream_scene_release(built);
    raystream_scene_release(text);
    raystream_scene_release(file);
}

/* Instances of a prototype and punctual lights, against the file's groups, instances and lights:
 * two placements that turn, scale unevenly and move it, a point and a spot light. */
static const char k_inst_json[] =
    "{\"camera\": {\"from\": [0.5, 2.5, 5], \"at\": [0, 0.5, 0], \"vfov\": 40},\n"
    " \"image\": {\"width\": 64, \"height\": 48},\n"
    " \"materials\": {\"grey\": {\"type\": \"lambertian\", \"albedo\": [0.6, 0.6, 0.6]},\n"
    "               \"green\": {\"type\": \"lambertian\", \"albedo\": [0.2, 0.7, 0.3]}},\n"
    " \"groups\": {\"tet\": [\n"
    "  {\"type\": \"triangle\", \"vertices\": [[0, 0, 0], [1, 0, 0], [0, 1, 0]], \"material\": "
    "\"green\"},\n"
    "  {\"type\": \"triangle\", \"vertices\": [[0, 0, 0], [0, 1, 0], [0, 0, 1]], \"material\": "
    "\"green\"},\n"
    "  {\"type\": \"triangle\", \"vertices\": [[0, 0, 0], [0, 0, 1], [1, 0, 0]], \"material\": "
    "\"green\"},\n"
    "  {\"type\": \"triangle\", \"vertices\": [[1, 0, 0], [0, 0, 1], [0, 1, 0]], \"material\": "
    "\"green\"}]},\n"
    " \"objects\": [\n"
    "  {\"type\": \"triangle\", \"vertices\": [[-3, 0, -3], [3, 0, 3], [3, 0, -3]], \"material\": "
    "\"grey\"},\n"
    "  {\"type\": \"triangle\", \"vertices\": [[-3, 0, -3], [-3, 0, 3], [3, 0, 3]], \"material\": "
    "\"grey\"},\n"
    "  {\"type\": \"instance\", \"group\": \"tet\", \"transform\": [{\"matrix\": [0.8, -0.3, 0.1, "
    "-1, 0.3, 0.9, 0, 0.2, -0.1, 0.05, 1.2, 0.3, 0, 0, 0, 1]}]},\n"
    "  {\"type\": \"instance\", \"group\": \"tet\", \"transform\": [{\"matrix\": [0.5, 0, 0.6, "
    "1.1, 0, 1.4, 0, 0, -0.6, 0, 0.5, -0.4, 0, 0, 0, 1]}]},\n"
    "  {\"type\": \"point_light\", \"position\": [0.5, 3, 1], \"intensity\": [9, 8, 7]},\n"
    "  {\"type\": \"spot_light\", \"position\": [-2, 3, 2], \"direction\": [0.5, -1, -0.4], "
    "\"intensity\": [20, 20, 25], \"outer\": 30}]}\n";

static void test_instances_and_lights_equal_json(void **state)
{
    static const float ground[] = {-3, 0, -3, 3, 0, 3, 3, 0, -3, -3, 0, 3};
    static const uint32_t ground_idx[] = {0, 1, 2, 0, 3, 1};
    static const float tet[] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
    static const uint32_t tet_idx[] = {0, 1, 2, 0, 2, 3, 0, 3, 1, 1, 3, 2};
    static const double m1[12] = {0.8, -0.3, 0.1, -1, 0.3, 0.9, 0, 0.2, -0.1, 0.05, 1.2, 0.3};
    static const double m2[12] = {0.5, 0, 0.6, 1.1, 0, 1.4, 0, 0, -0.6, 0, 0.5, -0.4};
    static const double singular[12] = {1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0};
    static const char *const kv[] = {"spp=8", NULL};
    const float from[3] = {0.5f, 2.5f, 5}, at[3] = {0, 0.5f, 0}, up[3] = {0, 1, 0};
    raystream_scene *s = NULL, *file = NULL;
    raystream_image *a, *b;
    uint32_t grey, green, lamp, proto, tris;
    (void)state;
    assert_int_equal(raystream_scene_create(&s), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_material(
                         s, "{\"type\": \"lambertian\", \"albedo\": [0.6, 0.6, 0.6]}", &grey),
                     RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_material(
                         s, "{\"type\": \"lambertian\", \"albedo\": [0.2, 0.7, 0.3]}", &green),
                     RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_mesh(s, ground, 4, ground_idx, 2, NULL, NULL, grey),
                     RAYSTREAM_OK);
    assert_int_equal(
        raystream_scene_add_prototype(s, tet, 4, tet_idx, 4, NULL, NULL, green, &proto),
        RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_instance(s, proto, m1), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_instance(s, proto, m2), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_add_light(s, "{\"type\": \"point_light\", \"position\": "
                                                  "[0.5, 3, 1], \"intensity\": [9, 8, 7]}"),
                     RAYSTREAM_OK);
    assert_int_equal(
        raystream_scene_add_light(s, "{\"type\": \"spot_light\", \"position\": [-2, 3, 2], "
                                     "\"direction\": [0.5, -1, -0.4], \"intensity\": [20, 20, 25], "
                                     "\"outer\": 30}"),
        RAYSTREAM_OK);
    assert_int_equal(raystream_scene_set_camera(s, from, at, up, 40.0f, 0, 0), RAYSTREAM_OK);
    assert_int_equal(raystream_scene_set_image_size(s, 64, 48), RAYSTREAM_OK);
    /* refused: an unknown prototype, a singular matrix, an emitting prototype, a light that is
     * not a punctual one; the scene as it was */
    expect_error(raystream_scene_add_instance(s, 7, m1), RAYSTREAM_ERROR_ARGUMENT, "prototype 7");
    expect_error(raystream_scene_add_instance(s, proto, singular), RAYSTREAM_ERROR_ARGUMENT,
                 "instance");
    assert_int_equal(
        raystream_scene_add_material(s, "{\"type\": \"light\", \"emission\": [1, 1, 1]}", &lamp),
        RAYSTREAM_OK);
    expect_error(raystream_scene_add_prototype(s, tet, 4, tet_idx, 4, NULL, NULL, lamp, &proto),
                 RAYSTREAM_ERROR_ARGUMENT, "emits light");
    expect_error(raystream_scene_add_light(s, "{\"type\": \"sphere\"}"), RAYSTREAM_ERROR_ARGUMENT,
                 "point_light");
    expect_error(raystream_scene_add_light(s, "{\"type\": \"point_light\", \"intensity\": -1}"),
                 RAYSTREAM_ERROR_ARGUMENT, "light");
    raystream_scene_counts(s, NULL, NULL, &tris, NULL);
    assert_int_equal(tris, 2 + 2 * 4);
    assert_int_equal(raystream_scene_from_json(k_inst_json, NULL, &file), RAYSTREAM_OK);
    a = render_built(s, kv);
    b = render_built(file, kv);
    assert_true(same_pixels(a, b));
    {
        double mean = 0.0;
        size_t i;
        for (i = 0; i < 64 * 48 * 3; ++i)
            mean += raystream_image_pixels(a)[i];
        assert_true(mean / (64 * 48 * 3) > 0.01); /* the lights light it */
    }
    raystream_image_release(a);
    raystream_image_release(b);
    raystream_scene_release(s);
    raystream_scene_release(file);
}

/* ---- progress and cancelling -------------------------------------------------------------- */

typedef struct progress_log {
    int calls;
    double last;
    int fell;
    int stop_after;
} progress_log;

/* While a scene renders, a second render of it and a change to it are refused. */
static int try_while_busy(void *user, double fraction)
{
    raystream_scene *s = (raystream_scene *)user;
    raystream_image *img = NULL;
    const float c[3] = {0, 0, 0};
    (void)fraction;
    expect_error(raystream_render(s, NULL, &img), RAYSTREAM_ERROR_ARGUMENT, "being rendered");
    assert_null(img);
    expect_error(raystream_scene_add_sphere(s, c, 1.0f, 0), RAYSTREAM_ERROR_ARGUMENT,
                 "being rendered");
    return 0;
}

static int on_progress(void *user, double fraction)
{
    progress_log *l = (progress_log *)user;
    if (fraction < l->last || fraction < 0.0 || fraction > 1.0)
        l->fell = 1;
    l->last = fraction;
    return ++l->calls >= l->stop_after;
}

static void test_progress_and_cancel(void **state)
{
    static const char *const kv[] = {"width=96", "spp=256", "threads=1", NULL};
    raystream_options *o = options(kv);
    raystream_image *img = NULL;
    progress_log log = {0, 0.0, 0, 1000000};
    (void)state;
    /* all the way: the fractions rise to 1 */
    raystream_options_set(o, "spp", "4");
    raystream_options_set_progress(o, on_progress, &log);
    assert_int_equal(raystream_render_scene("builtin:cornell", o, &img), RAYSTREAM_OK);
    assert_true(log.calls >= 1);
    assert_false(log.fell);
    assert_true(log.last == 1.0);
    raystream_image_release(img);
    /* stopped at the first call: cancelled, with what was finished */
    memset(&log, 0, sizeof log);
    log.stop_after = 1;
    raystream_options_set(o, "spp", "256");
    assert_int_equal(raystream_render_scene("builtin:cornell", o, &img), RAYSTREAM_CANCELLED);
    assert_non_null(img);
    assert_true(raystream_image_spp(img) < 256.0);
    assert_int_equal(log.calls, 1);
    assert_non_null(strstr(raystream_last_error(), "cancelled"));
    raystream_image_release(img);
    raystream_options_release(o);
}

/* ---- hostile calls ------------------------------------------------------------------------ */

/* Runs fn with stderr going to a file; returns what was printed there. */
static void stderr_of(void (*fn)(void *), void *arg, char *out, size_t n)
{
    char path[] = "/tmp/raystream-api-stderr-XXXXXX";
    int fd = mkstemp(path), saved = dup(2);
    ssize_t k;
    assert_true(fd >= 0 && saved >= 0);
    fflush(stderr);
    dup2(fd, 2);
    fn(arg);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    lseek(fd, 0, SEEK_SET);
    k = read(fd, out, n - 1);
    out[k > 0 ? k : 0] = '\0';
    close(fd);
    unlink(path);
}

static void expect_error(raystream_status got, raystream_status want, const char *needle)
{
    if (got != want || !strstr(raystream_last_error(), needle) ||
        strchr(raystream_last_error(), '\n'))
        fail_msg("status %d (want %d), message '%s' (want one line with '%s')", (int)got, (int)want,
                 raystream_last_error(), needle);
}

static void hostile_calls(void *arg)
{
    const fixture *f = (const fixture *)arg;
    static const float nan_pos[] = {0, 0, 0, 1, 0, 0, 0, NAN, 0};
    static const float pos[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    static const uint32_t idx[] = {0, 1, 2}, bad_idx[] = {0, 1, 3};
    const float c[3] = {0, 0, 0}, zero[3] = {0, 0, 0}, x[3] = {1, 0, 0};
    raystream_options *o = NULL;
    raystream_scene *s = NULL, *none = NULL;
    raystream_image *img = (raystream_image *)1;
    uint32_t mat, tris;
    char path[512];
    assert_int_equal(raystream_options_create(&o), RAYSTREAM_OK);
    expect_error(raystream_options_set(o, "bogus", "1"), RAYSTREAM_ERROR_ARGUMENT, "bogus");
    expect_error(raystream_options_set(o, "output", "x.png"), RAYSTREAM_ERROR_ARGUMENT, "--output");
    expect_error(raystream_options_set(o, "resume", "x.ckpt"), RAYSTREAM_ERROR_ARGUMENT,
                 "--resume");
    expect_error(raystream_options_set(o, "denoise", "maybe"), RAYSTREAM_ERROR_ARGUMENT, "flag");
    expect_error(raystream_options_set(NULL, "spp", "1"), RAYSTREAM_ERROR_ARGUMENT, "NULL");
    /* values are checked by the render, with the command's message; nothing is returned */
    assert_int_equal(raystream_options_set(o, "spp", "-3"), RAYSTREAM_OK);
    expect_error(raystream_render_scene("builtin:cornell", o, &img), RAYSTREAM_ERROR_ARGUMENT,
                 "--spp -3");
    assert_null(img);
    assert_int_equal(raystream_options_set(o, "spp", NULL), RAYSTREAM_OK);
    assert_int_equal(raystream_options_set(o, "width", "40000"), RAYSTREAM_OK);
    expect_error(raystream_render_scene("builtin:cornell", o, &img), RAYSTREAM_ERROR_ARGUMENT,
                 "--width");
    assert_int_equal(raystream_options_set(o, "width", "8"), RAYSTREAM_OK);
    assert_int_equal(raystream_options_set(o, "sampler", "magic"), RAYSTREAM_OK);
    expect_error(raystream_render_scene("builtin:cornell", o, &img), RAYSTREAM_ERROR_ARGUMENT,
                 "magic");
    assert_int_equal(raystream_options_set(o, "sampler", NULL), RAYSTREAM_OK);
    expect_error(raystream_render_scene("builtin:nope", o, &img), RAYSTREAM_ERROR_ARGUMENT, "nope");
    expect_error(raystream_render_scene("/no/such/scene.json", o, &img), RAYSTREAM_ERROR_IO,
                 "/no/such/scene.json");
    expect_error(raystream_scene_load(NULL, &none), RAYSTREAM_ERROR_ARGUMENT, "no scene");
    assert_null(none);
    write_in(f, "broken.json", "{\"camera\": {\"from\": [0, 0, 1], \"at\": [0, 0, 1]}}");
    path_in(f, "broken.json", path, sizeof path);
    expect_error(raystream_scene_load(path, &none), RAYSTREAM_ERROR_RUNTIME, "must differ");
    expect_error(raystream_scene_from_json("{\"objects\": [", NULL, &none),
                 RAYSTREAM_ERROR_ARGUMENT, "syntax");
    expect_error(raystream_render(NULL, o, &img), RAYSTREAM_ERROR_ARGUMENT, "NULL");
    /* a scene keeps what it had when an add is refused */
    assert_int_equal(raystream_scene_create(&s), RAYSTREAM_OK);
    expect_error(raystream_scene_add_material(s, "{\"type\": \"glitter\"}", &mat),
                 RAYSTREAM_ERROR_ARGUMENT, "glitter");
    expect_error(raystream_scene_add_material(s, "{\"type\": ", &mat), RAYSTREAM_ERROR_ARGUMENT,
                 "syntax");
    expect_error(raystream_scene_add_mesh(s, pos, 3, idx, 1, NULL, NULL, 0),
                 RAYSTREAM_ERROR_ARGUMENT, "material 0");
    assert_int_equal(raystream_scene_add_material(s, "{\"type\": \"lambertian\"}", &mat),
                     RAYSTREAM_OK);
    expect_error(raystream_scene_add_mesh(s, nan_pos, 3, idx, 1, NULL, NULL, mat),
                 RAYSTREAM_ERROR_ARGUMENT, "vertex 2");
    expect_error(raystream_scene_add_mesh(s, pos, 3, bad_idx, 1, NULL, NULL, mat),
                 RAYSTREAM_ERROR_ARGUMENT, "vertex 3");
    expect_error(raystream_scene_add_mesh(s, NULL, 3, idx, 1, NULL, NULL, mat),
                 RAYSTREAM_ERROR_ARGUMENT, "positions");
    expect_error(raystream_scene_add_sphere(s, c, -1.0f, mat), RAYSTREAM_ERROR_ARGUMENT, "radius");
    expect_error(raystream_scene_add_quad(s, c, x, x, mat), RAYSTREAM_ERROR_ARGUMENT,
                 "parallelogram");
    expect_error(raystream_scene_set_camera(s, c, zero, x, 40, 0, 0), RAYSTREAM_ERROR_ARGUMENT,
                 "differ");
    expect_error(raystream_scene_set_image_size(s, 0, 10), RAYSTREAM_ERROR_ARGUMENT, "0x10");
    raystream_scene_counts(s, NULL, NULL, &tris, NULL);
    assert_int_equal(tris, 0);
    /* a scene that is loaded already takes no loading options */
    assert_int_equal(raystream_options_set(o, "background", "sky"), RAYSTREAM_OK);
    expect_error(raystream_render(s, o, &img), RAYSTREAM_ERROR_ARGUMENT, "background");
    raystream_scene_release(s);
    raystream_options_release(o);
    /* writing where nothing can be written */
    assert_int_equal(raystream_image_read("/no/such/image.exr", &img), RAYSTREAM_ERROR_IO);
    assert_null(img);
}

static void test_hostile_calls(void **state)
{
    char printed[4096];
    stderr_of(hostile_calls, *state, printed, sizeof printed);
    if (printed[0])
        fail_msg("the library printed on stderr:\n%s", printed);
}

static void test_write_errors(void **state)
{
    static const char *const kv[] = {"width=8", "spp=1", NULL};
    raystream_image *img = render_name("builtin:cornell", kv);
    char path[512];
    const fixture *f = (const fixture *)*state;
    expect_error(raystream_image_write(img, "/no/such/folder/out.exr"), RAYSTREAM_ERROR_IO,
                 "/no/such/folder");
    expect_error(raystream_image_write(img, ""), RAYSTREAM_ERROR_ARGUMENT, "no file name");
    path_in(f, "small.png", path, sizeof path);
    assert_int_equal(raystream_image_write(img, path), RAYSTREAM_OK);
    raystream_image_release(img);
}

/* ---- renders on several threads at once --------------------------------------------------- */

typedef struct job {
    const char *scene;
    const char *const *kv;
    raystream_image *img;
} job;

static void *render_job(void *arg)
{
    job *j = (job *)arg;
    raystream_options *o = NULL;
    const char *const *kv;
    raystream_options_create(&o);
    for (kv = j->kv; *kv; ++kv) {
        char name[64];
        const char *eq = strchr(*kv, '=');
        snprintf(name, sizeof name, "%.*s", (int)(eq - *kv), *kv);
        raystream_options_set(o, name, eq + 1);
    }
    if (raystream_render_scene(j->scene, o, &j->img) != RAYSTREAM_OK)
        j->img = NULL;
    raystream_options_release(o);
    return NULL;
}

/* Two scenes with different options (the light BVH on one, not the other) rendered at once on
 * two threads: each the image it has alone. */
static void test_threads_at_once(void **state)
{
    static const char *const kv_a[] = {"width=48", "spp=4", "light-sampler=bvh", "threads=1", NULL};
    static const char *const kv_b[] = {"width=40", "spp=3", "texture-filter=bilinear", "threads=1",
                                       NULL};
    job jobs[2] = {{"builtin:many-lights", kv_a, NULL}, {"builtin:materials", kv_b, NULL}};
    raystream_image *alone[2];
    pthread_t t[2];
    int k;
    (void)state;
    for (k = 0; k < 2; ++k)
        alone[k] = render_name(jobs[k].scene, jobs[k].kv);
    for (k = 0; k < 2; ++k)
        assert_int_equal(pthread_create(&t[k], NULL, render_job, &jobs[k]), 0);
    for (k = 0; k < 2; ++k) {
        pthread_join(t[k], NULL);
        assert_non_null(jobs[k].img);
        assert_true(same_pixels(jobs[k].img, alone[k]));
        raystream_image_release(jobs[k].img);
        raystream_image_release(alone[k]);
    }
}

/* ---- the version and the thread's own error ----------------------------------------------- */

static void *fail_in_thread(void *arg)
{
    raystream_scene *s = NULL;
    (void)arg;
    raystream_scene_load("builtin:no-such-thing", &s);
    return strstr(raystream_last_error(), "no-such-thing") ? (void *)1 : NULL;
}

static void test_version_and_thread_errors(void **state)
{
    pthread_t t;
    void *ok = NULL;
    char want[16];
    raystream_options *o = NULL;
    (void)state;
    assert_int_equal(raystream_version(), RAYSTREAM_VERSION);
    snprintf(want, sizeof want, "%d.%d.%d ", RAYSTREAM_VERSION_MAJOR, RAYSTREAM_VERSION_MINOR,
             RAYSTREAM_VERSION_PATCH);
    assert_memory_equal(raystream_version_string(), want, strlen(want));
    raystream_options_create(&o);
    expect_error(raystream_options_set(o, "nothing-like-it", "1"), RAYSTREAM_ERROR_ARGUMENT,
                 "nothing-like-it");
    assert_int_equal(pthread_create(&t, NULL, fail_in_thread, NULL), 0);
    pthread_join(t, &ok);
    assert_non_null(ok);
    assert_non_null(strstr(raystream_last_error(), "nothing-like-it")); /* still this thread's */
    raystream_options_release(o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_render_matches_cli, setup, teardown),
        cmocka_unit_test_setup_teardown(test_aov_matches_cli, setup, teardown),
        cmocka_unit_test_setup_teardown(test_built_scene_equals_json, setup, teardown),
        cmocka_unit_test(test_instances_and_lights_equal_json),
        cmocka_unit_test(test_progress_and_cancel),
        cmocka_unit_test_setup_teardown(test_hostile_calls, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_errors, setup, teardown),
        cmocka_unit_test(test_threads_at_once),
        cmocka_unit_test(test_version_and_thread_errors),
    };
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
