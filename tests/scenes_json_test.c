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
#include <dirent.h>
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <sys/resource.h>
#include <sys/un.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "render_util.h"
#include "scenes/builtin.h"
#include "scenes/scene_json.h"
#include "test_rand.h"
#include "test_files.h"

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

/* scenes/examples/NAME.json renders builtin:NAME bit for bit (32x32, 4 spp). */
static void expect_example_is_builtin(const char *name, uint32_t quads, uint32_t spheres)
{
    char path[512];
    rs_scene *js, *bi;
    rt_args a = rt_defaults(name, 32, 4);
    float *from_file, *builtin;
    snprintf(path, sizeof path, RS_SOURCE_DIR "/scenes/examples/%s.json", name);
    if (rs_scene_load_json(path, &js) != RS_OK)
        fail_msg("%s: %s", path, rs_error_message());
    assert_int_equal(js->n_quads, quads);
    assert_int_equal(js->n_spheres, spheres);
    assert_int_equal(rs_builtin_create(name, &bi), RS_OK);
    assert_int_equal(js->n_tris, bi->n_tris);
    assert_int_equal(js->n_lights, bi->n_lights);
    assert_int_equal(js->n_materials, bi->n_materials);
    assert_int_equal(js->width, bi->width);
    assert_int_equal(js->height, bi->height);
    rs_scene_destroy(bi);
    from_file = rt_render_scene(js, &a, NULL);
    builtin = rt_render(&a, NULL);
    assert_non_null(from_file);
    assert_non_null(builtin);
    if (memcmp(from_file, builtin, 32 * 32 * 3 * sizeof(float)) != 0)
        fail_msg("%s does not render builtin:%s bit for bit", path, name);
    free(from_file);
    free(builtin);
    rs_scene_destroy(js);
}

static int have_models(void)
{
    struct stat sb;
    return stat(RS_SOURCE_DIR "/../shared/models/teapot/teapot.obj", &sb) == 0 &&
           stat(RS_SOURCE_DIR "/../shared/models/bunny/bun_zipper.ply", &sb) == 0;
}

/* Every thesis scene as a file (scenes/examples/), each the built-in scene bit for bit: the
 * random spheres and the materials scene were written by `raystream export`, the rest by hand
 * (the mesh scenes with mesh objects, their rotation and fit the built-ins' own). */
static void test_example_equals_builtin(void **state)
{
    (void)state;
    expect_example_is_builtin("cornell", 18u, 0u);
    expect_example_is_builtin("cornell-glass", 12u, 1u);
    expect_example_is_builtin("rtiow-final", 0u, 486u);
    expect_example_is_builtin("bouncing-spheres", 0u, 485u);
    expect_example_is_builtin("materials", 2u, 15u);
    expect_example_is_builtin("furnace", 0u, 1u);
    if (!have_models()) {
        print_message("skipping cornell-teapot and cornell-bunny-teapot: no %s\n",
                      RS_SOURCE_DIR "/../shared/models");
        return;
    }
    expect_example_is_builtin("cornell-teapot", 6u, 0u);
    expect_example_is_builtin("cornell-bunny-teapot", 6u, 0u);
}

/* Every file in scenes/examples/ loads and renders (48 x 32, 2 spp) to a finite image that is not
 * black: the examples docs/scene-format.md shows for each key. */
static void test_every_example_renders(void **state)
{
    DIR *d = opendir(RS_SOURCE_DIR "/scenes/examples");
    struct dirent *e;
    int n = 0;
    (void)state;
    assert_non_null(d);
    while ((e = readdir(d)) != NULL) {
        char path[1024];
        size_t len = strlen(e->d_name);
        rs_scene *s;
        rt_args a = rt_defaults("", 48, 2);
        float *img;
        double mean;
        int i;
        if (len < 6 || strcmp(e->d_name + len - 5, ".json") != 0)
            continue;
        snprintf(path, sizeof path, RS_SOURCE_DIR "/scenes/examples/%s", e->d_name);
        if (rs_scene_load_json(path, &s) != RS_OK) {
            if (!have_models() && strstr(rs_error_message(), "shared/models")) {
                print_message("skipping %s: it needs the shared models\n", e->d_name);
                rs_error_clear();
                continue;
            }
            fail_msg("%s: %s", path, rs_error_message());
        }
        a.height = 32;
        a.threads = 2;
        img = rt_render_scene(s, &a, NULL);
        assert_non_null(img);
        for (i = 0; i < 48 * 32 * 3; ++i)
            assert_true(isfinite(img[i]) && img[i] >= 0.0f);
        mean = rt_mean(img, 48 * 32 * 3);
        print_message("%-26s %u spheres, %u quads, %u triangles, %u materials: mean %.4f\n",
                      e->d_name, s->n_spheres, s->n_quads, s->n_tris, s->n_materials, mean);
        assert_true(mean > 0.01);
        free(img);
        rs_scene_destroy(s);
        ++n;
    }
    closedir(d);
    assert_true(n >= 8);
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
    /* a misspelt key: its JSON path and the closest known key (a swap of neighbours is one
     * edit) */
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
     "\"materail\":\"m\"}]}",
     {"objects[0]", "unknown key 'materail'", "did you mean 'material'?"}},
    {"{\"camera\":{\"form\":[0,0,5],\"at\":[0,0,0]}," MAT ",\"objects\":[]}",
     {"camera", "did you mean 'from'?"}},
    {"{" CAM "," MAT ",\"objectz\":[]}", {"did you mean 'objects'?"}},
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
    /* non-finite numbers anywhere (cJSON reads 1e999 as inf) */
    {"{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0],\"shutter\":[-1e999,1e999]}," MAT
     ",\"objects\":[]}",
     {"camera.shutter[0]", "not finite"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1e999,"
     "\"material\":\"m\"}]}",
     {"objects[0].radius", "not finite"}},
    {"{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0],\"shutter\":[0,1e300]}," MAT
     ",\"objects\":[]}",
     {"camera.shutter", "finite"}},
    /* trailing content after the one JSON value */
    {"{" CAM "," MAT ",\"objects\":[]} x", {"t.json:1", "after the JSON value"}},
    {"{" CAM "," MAT ",\"objects\":[]}\n\n{}", {"t.json:3", "after the JSON value"}},
    /* duplicate keys, named with their object's path */
    {"{" CAM "," CAM "," MAT ",\"objects\":[]}", {"(top level)", "'camera' appears twice"}},
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5],"
     "\"albedo\":[1,1,1]}},\"objects\":[]}",
     {"materials.m", "'albedo' appears twice"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
     "\"radius\":2,\"material\":\"m\"}]}",
     {"objects[0]", "'radius' appears twice"}},
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"lambertian\"},\"m\":{\"type\":\"metal\"}},"
     "\"objects\":[]}",
     {"materials", "'m' appears twice"}},
    /* every reflectance in [0, 1] */
    {"{" CAM ",\"materials\":{\"m\":{\"type\":\"metal\",\"albedo\":[5,5,5]}},\"objects\":[]}",
     {"materials.m.albedo", "[0, 1]"}},
    {"{" CAM ",\"materials\":{\"p\":{\"type\":\"phong\",\"ks\":[5,5,5]}},\"objects\":[]}",
     {"materials.p.ks", "[0, 1]"}},
    {"{" CAM ",\"materials\":{\"g\":{\"type\":\"dielectric\",\"tint\":[1,2,1]}},"
     "\"objects\":[]}",
     {"materials.g.tint", "[0, 1]"}},
    {"{" CAM ",\"textures\":{\"t\":{\"type\":\"solid\",\"color\":[3,0,0]}},\"objects\":[]}",
     {"textures.t.color", "[0, 1]"}},
    {"{" CAM ",\"textures\":{\"t\":{\"type\":\"checker\",\"a\":[0,0,0],\"b\":[0,1.5,0]}},"
     "\"objects\":[]}",
     {"textures.t.b", "[0, 1]"}},
    /* transforms: every kind of absurd one, named by its path */
#define SPH "{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,\"material\":\"m\""
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"scale\":0}}]}",
     {"objects[0].transform.scale", "must not be 0"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"scale\":[1,2,1]}}]}",
     {"objects[0].transform", "ellipsoid"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"matrix\":[1,0,0,0,0,1,0,0,0,0,1,0,"
     "0,0,1,1]}}]}",
     {"objects[0].transform.matrix", "last row"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"matrix\":[1,0,0,0,0,1,0,0,1,1,0,0,"
     "0,0,0,1]}}]}",
     {"objects[0].transform", "singular"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":[{\"translate\":[1,0,0]},"
     "{\"scale\":1e20},{\"scale\":1e20}]}]}",
     {"objects[0].transform", "beyond 1e30"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"rotate\":{\"axis\":[0,0,0],"
     "\"degrees\":5}}}]}",
     {"objects[0].transform.rotate.axis", "zero"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"translate\":[1,0,0],\"scale\":2}}]}",
     {"objects[0].transform", "one key"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":{\"rotat\":[0,0,0]}}]}",
     {"objects[0].transform", "did you mean 'rotate'?"}},
    {"{" CAM "," MAT ",\"objects\":[" SPH ",\"transform\":\"up\"}]}",
     {"objects[0].transform", "array of steps"}},
    /* groups and instances */
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"instance\",\"group\":\"g\"}]}",
     {"objects[0].group", "no group named 'g'"}},
    {"{" CAM "," MAT ",\"groups\":{\"a\":[{\"type\":\"instance\",\"group\":\"b\"}],"
     "\"b\":[" SPH "},{\"type\":\"instance\",\"group\":\"a\"}]},"
     "\"objects\":[{\"type\":\"instance\",\"group\":\"a\"}]}",
     {"groups.b[1].group", "cycle: a -> b -> a"}},
    {"{" CAM "," MAT ",\"groups\":{\"a\":[{\"type\":\"instance\",\"group\":\"a\"}]},"
     "\"objects\":[{\"type\":\"instance\",\"group\":\"a\"}]}",
     {"groups.a[0].group", "cycle: a -> a"}},
    {"{" CAM "," MAT ",\"groups\":{\"a\":[" SPH "}]},\"objects\":[{\"type\":\"instance\","
     "\"group\":\"a\",\"transform\":{\"scale\":[1,1,3]}}]}",
     {"groups.a[0]", "ellipsoid", "placed by the instance at objects[0]"}},
    {"{" CAM "," MAT ",\"groups\":{\"a\":{}},\"objects\":[]}", {"groups.a", "array of objects"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"instance\",\"group\":\"g\",\"material\":\"m\"}]}",
     {"objects[0]", "unknown key 'material'"}},
    /* lights */
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"spot_light\",\"position\":[0,0,0],"
     "\"direction\":[0,-1,0],\"intensity\":[1,1,1],\"inner\":40,\"outer\":20}]}",
     {"objects[0].outer", "narrower"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"spot_light\",\"position\":[0,0,0],"
     "\"direction\":[0,-1,0],\"intensity\":[1,1,1],\"outer\":91}]}",
     {"objects[0].outer", "90"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"directional_light\",\"direction\":[0,0,0],"
     "\"irradiance\":[1,1,1]}]}",
     {"objects[0].direction", "zero"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"point_light\",\"position\":[0,0,0],"
     "\"intensity\":[-1,1,1]}]}",
     {"objects[0].intensity", ">= 0"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"triangle\",\"vertices\":[[0,0,0],[1,0,0],"
     "[0,1,0]],\"normals\":[0,0,1],\"material\":\"m\"}]}",
     {"objects[0].normals", "9 numbers"}},
    /* meshes */
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"mesh\",\"file\":\"/nonexistent/x.obj\"}]}",
     {"objects[0]", "/nonexistent/x.obj"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"mesh\",\"file\":\"x.obj\",\"material\":\"m\","
     "\"materials\":{}}]}",
     {"objects[0]", "either 'material' or 'materials'"}},
    {"{" CAM "," MAT ",\"objects\":[{\"type\":\"mesh\",\"file\":\"x.obj\","
     "\"materials\":{\"a\":\"nope\"}}]}",
     {"objects[0].materials.a", "no material named 'nope'"}},
    /* a key with a newline in it still gives one line */
    {"{" CAM "," MAT ",\"objects\":[],\"a\\nb\":1}", {"unknown key 'a?b'"}},
};

/* An RGBA PNG's colour is read as stored, not multiplied by its alpha (issue 39: OpenImageIO
 * associates alpha by default, and a white texel of alpha 128 read as 0.5, 0.215 once decoded
 * from sRGB; glTF's and PNG's colours are not premultiplied).  tests/data/white_alpha128.png:
 * 2x1, (255, 255, 255, 128) twice. */
static void test_rgba_not_premultiplied(void **state)
{
    uint32_t w = 0, h = 0;
    float *rgb = NULL, *alpha = NULL;
    (void)state;
    if (rs_image_read_linear(RS_SOURCE_DIR "/tests/data/white_alpha128.png", &w, &h, &rgb) != RS_OK)
        fail_msg("%s", rs_error_message());
    assert_true(w == 2 && h == 1);
    print_message("white, alpha 128: read as %g %g %g\n", rgb[0], rgb[1], rgb[2]);
    assert_true(rgb[0] == 1.0f && rgb[1] == 1.0f && rgb[2] == 1.0f && rgb[3] == 1.0f);
    rs_free(rgb);
    assert_int_equal(rs_image_read_alpha(RS_SOURCE_DIR "/tests/data/white_alpha128.png", &w, &h,
                                         &alpha),
                     RS_OK);
    assert_non_null(alpha);
    assert_true(fabsf(alpha[0] - 128.0f / 255.0f) < 1e-6f);
    rs_free(alpha);
}

/* An image whose decoded floats exceed what the process may allocate is refused from its
 * header, by one line naming it and the sizes, before anything is allocated (issue 39: a 0.8 MB
 * PNG of 16384^2 took 3.3 GB under a 4 GB limit: a whole copy of its channels beside the
 * result, now read a strip of rows at a time).  A child process under an address-space limit
 * 30 MB above what it has mapped reads a 2048^2 PNG (48 MB of floats); the same image reads in
 * the parent, unlimited, bit for bit as written. */
static void test_image_memory_bound(void **state)
{
    char dir[] = "/tmp/rs_mem_XXXXXX", png[256];
    const uint32_t n = 2048;
    float *rgb = (float *)malloc((size_t)n * n * 3 * sizeof(float)), *back = NULL;
    uint32_t w, h;
    size_t i;
    pid_t pid;
    int status = 0;
    (void)state;
    assert_non_null(rgb);
    for (i = 0; i < (size_t)n * n * 3; ++i)
        rgb[i] = (float)((i * 2654435761u) >> 24) / 255.0f;
    assert_non_null(mkdtemp(dir));
    snprintf(png, sizeof png, "%s/big.png", dir);
    assert_int_equal(rs_image_write(png, n, n, rgb), RS_OK);
    free(rgb);
    fflush(NULL);
    pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        struct rlimit rl;
        unsigned long long pages = 0;
        FILE *f = fopen("/proc/self/statm", "r");
        float *got = NULL;
        rs_status st;
        if (!f || fscanf(f, "%llu", &pages) != 1)
            _exit(3);
        fclose(f);
        rl.rlim_cur = rl.rlim_max = pages * (unsigned long long)sysconf(_SC_PAGESIZE) + (30u << 20);
        if (setrlimit(RLIMIT_AS, &rl) != 0)
            _exit(4);
        st = rs_image_read(png, &w, &h, &got);
        fprintf(stderr, "under the limit: %s\n", rs_error_message());
        _exit(st == RS_ERR_NOMEM && strstr(rs_error_message(), "big.png") &&
                      strstr(rs_error_message(), "2048x2048") &&
                      strstr(rs_error_message(), "as floats, more than")
                  ? 0
                  : 1);
    }
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    assert_int_equal(rs_image_read(png, &w, &h, &back), RS_OK);
    assert_true(w == n && h == n);
    rs_free(back);
    remove(png);
    rmdir(dir);
}

/* A scene's light tables are checked against what the process may allocate before they are
 * made (issue 39: 10^7 emitters copied from a 1 MB file passed 2.2 GB first): a million emitting
 * quads (20 MB of tables) finalized in a child whose address-space limit leaves 8 MB. */
static void test_light_tables_bounded(void **state)
{
    pid_t pid;
    int status = 0;
    (void)state;
    fflush(NULL);
    pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        rs_scene *sc = NULL;
        rs_material lamp = rs_mat_light(rs_v3(1, 1, 1), 0);
        struct rlimit rl;
        unsigned long long pages = 0;
        uint32_t mat, i;
        FILE *f;
        rs_status st;
        rs_scene_set_extras(0, 1); /* the tables alone (the light BVH is checked the same way) */
        if (rs_scene_create("lamps", &sc) != RS_OK || rs_scene_add_material(sc, &lamp, &mat))
            _exit(3);
        for (i = 0; i < 1000000; ++i)
            if (rs_scene_add_quad(sc, rs_v3((float)(i % 1000), (float)(i / 1000), 0),
                                  rs_v3(0.5f, 0, 0), rs_v3(0, 0.5f, 0), mat) != RS_OK)
                _exit(4);
        f = fopen("/proc/self/statm", "r");
        if (!f || fscanf(f, "%llu", &pages) != 1)
            _exit(5);
        fclose(f);
        rl.rlim_cur = rl.rlim_max = pages * (unsigned long long)sysconf(_SC_PAGESIZE) + (8u << 20);
        if (setrlimit(RLIMIT_AS, &rl) != 0)
            _exit(6);
        st = rs_scene_finalize(sc);
        fprintf(stderr, "a million lights under the limit: %s\n", rs_error_message());
        _exit(st == RS_ERR_NOMEM && strstr(rs_error_message(), "1000000 lights take") &&
                      strstr(rs_error_message(), "of light tables")
                  ? 0
                  : 1);
    }
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
}

/* A spot light's documented widest cone, outer 90 degrees, loads (issue 39: cosf of 90 degrees
 * in float radians is -4.4e-8, and the light was refused by a line naming neither file nor
 * object): its cosines are held at 0. */
static void test_spot_cone_90(void **state)
{
    static const char json[] =
        "{" CAM "," MAT ",\"objects\":[{\"type\":\"spot_light\",\"position\":[0,0,0],"
        "\"direction\":[0,-1,0],\"intensity\":[1,1,1],\"inner\":90,\"outer\":90}]}";
    rs_scene *s = NULL;
    (void)state;
    rs_error_clear();
    if (rs_scene_parse_json(json, strlen(json), "t.json", NULL, &s) != RS_OK)
        fail_msg("%s", rs_error_message());
    assert_int_equal(s->n_punctuals, 1);
    assert_true(s->punctuals[0].cos_outer == 0.0f && s->punctuals[0].cos_inner == 0.0f);
    rs_scene_destroy(s);
}

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
    {
        /* a NUL byte after the value is content too */
        static const char nul[] = "{" CAM "," MAT ",\"objects\":[]}\n\0";
        rs_scene *s = (rs_scene *)0x1;
        assert_int_equal(rs_scene_parse_json(nul, sizeof nul - 1, "t.json", NULL, &s), RS_ERR_ARG);
        assert_null(s);
        assert_non_null(strstr(rs_error_message(), "t.json:2: a control byte (0x00)"));
        rs_error_clear();
    }
    {
        /* bytes cJSON took quietly (issue 27): NUL and other control bytes as white space, a
         * string cut at an escaped NUL ("w\u0000junk" picked material w), text not UTF-8 */
        static const struct {
            const char *text;
            size_t len;
            const char *want;
        } k[] = {
            {"{\0" CAM "," MAT ",\"objects\":[]}", 0, "t.json:1: a control byte (0x00)"},
            {"{\n\x01" CAM "," MAT ",\"objects\":[]}", 0, "t.json:2: a control byte (0x01)"},
            {"{" CAM "," MAT ",\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
             "\"material\":\"w\\u0000junk\"}]}",
             0, "a NUL character"},
            {"{" CAM "," MAT ",\"objects\":[],\"name\":\"caf\xe9\"}", 0, "not UTF-8 (byte 0xe9)"},
            {"{" CAM "," MAT ",\"objects\":[],\"name\":\"\xc0\xaf\"}", 0, "not UTF-8 (byte 0xc0)"},
        };
        size_t i;
        for (i = 0; i < sizeof k / sizeof k[0]; ++i) {
            rs_scene *s = (rs_scene *)0x1;
            size_t n = i == 0 ? 1 + strlen(k[i].text + 2) + 1 : strlen(k[i].text);
            assert_int_equal(rs_scene_parse_json(k[i].text, n, "t.json", NULL, &s), RS_ERR_ARG);
            assert_null(s);
            if (!strstr(rs_error_message(), k[i].want))
                fail_msg("case %zu: '%s' lacks '%s'", i, rs_error_message(), k[i].want);
            rs_error_clear();
        }
        {
            /* and UTF-8 itself is fine, in names and strings */
            static const char ok[] =
                "{" CAM ",\"materials\":{\"caf\xc3\xa9 \xe2\x9c\x93\":{\"type\":\"lambertian\","
                "\"albedo\":[0.5,0.5,0.5]}},\"objects\":[{\"type\":\"sphere\",\"center\":[0,0,0],\"radius\":1,"
                "\"material\":\"caf\xc3\xa9 \xe2\x9c\x93\"}]}";
            rs_scene *s = NULL;
            if (rs_scene_parse_json(ok, strlen(ok), "t.json", NULL, &s) != RS_OK)
                fail_msg("UTF-8 names refused: %s", rs_error_message());
            rs_scene_destroy(s);
        }
    }
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

/* Loads `scene` (a file) and expects a failure whose one-line message has `a` and `b`. */
static void expect_load_error(const char *scene, const char *a, const char *b)
{
    rs_scene *s = (rs_scene *)0x1;
    rs_status st;
    rs_error_clear();
    st = rs_scene_load_json(scene, &s);
    if (st == RS_OK)
        fail_msg("%s loaded without an error", scene);
    assert_true(st == RS_ERR_ARG || st == RS_ERR_IO);
    assert_null(s);
    print_message("%s -> %s\n", scene, rs_error_message());
    assert_null(strchr(rs_error_message(), '\n'));
    if (!strstr(rs_error_message(), a) || (b && !strstr(rs_error_message(), b)))
        fail_msg("message '%s' lacks '%s' or '%s'", rs_error_message(), a, b ? b : "");
    rs_error_clear();
}

/* Values the reader's syntax takes but the renderer cannot render right (issue 27): refused
 * at load, naming the object as the file does.  A light of 1e20 rendered black (its samples
 * beyond what the film holds were dropped), a sphere 3e19 away or a quad 2e10 wide vanished
 * (a float square overflowed), and errors named "quad 0" where the file said objects[1]. */
static void test_ranges_named(void **state)
{
    char dir[] = "/tmp/rs_json_XXXXXX", path[256], json[2048], map[256];
    static const char *const head =
        "{\"camera\": {\"from\": [0,0,5], \"at\": [0,0,0], \"vfov\": 40},"
        "\"materials\": {\"w\": {\"type\": \"lambertian\", \"albedo\": [0.5,0.5,0.5]},"
        "\"lamp\": {\"type\": \"light\", \"emission\": [%s]}},%s"
        "\"objects\": [{\"type\": \"sphere\", \"center\": [%s], \"radius\": 1, "
        "\"material\": \"w\"},"
        "{\"type\": \"quad\", \"q\": [-1,3,-1], \"u\": [%s], \"v\": [0,0,2], "
        "\"material\": \"lamp\"}]}";
    static const float px[12] = {1, 1, 1, 2, 2, 2, 3, 3, 3, 1e9f, 1, 1};
    rs_scene *s;
    FILE *f;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/s.json", dir);
    snprintf(map, sizeof map, "%s/sky.exr", dir);
    assert_int_equal(rs_image_write(map, 2, 2, px), RS_OK);
#define SCENE(emit, bg, centre, u)                                                              \
    do {                                                                                       \
        snprintf(json, sizeof json, head, emit, bg, centre, u);                                \
        f = fopen(path, "w");                                                                  \
        assert_non_null(f);                                                                    \
        fputs(json, f);                                                                        \
        fclose(f);                                                                             \
    } while (0)
    /* the limits themselves load */
    SCENE("1e12, 1e12, 1e12", "", "0, 0, -999999999", "2, 0, 0");
    assert_int_equal(rs_scene_load_json(path, &s), RS_OK);
    rs_scene_destroy(s);
    SCENE("1e20, 1e20, 1e20", "", "0, 0, 0", "2, 0, 0");
    expect_load_error(path, "materials.lamp: emission 1e+20", "film");
    SCENE("5, 5, 5", "", "0, 0, -3e19", "2, 0, 0");
    expect_load_error(path, "objects[0]: a point beyond", NULL);
    SCENE("5, 5, 5", "", "0, 0, 0", "2e10, 0, 0");
    expect_load_error(path, "objects[1]: a point beyond", NULL);
    /* the camera is the rays' origin: a sphere near the origin seen from 3e19 vanished too */
    {
        char far[2048];
        SCENE("5, 5, 5", "", "0, 0, 0", "2, 0, 0");
        snprintf(far, sizeof far, "%s", json);
        {
            char *at = strstr(far, "[0,0,5]");
            assert_non_null(at);
            memmove(at + 12, at + 7, strlen(at + 7) + 1);
            memcpy(at, "[0,0,3e19]", 10);
            at[10] = ' ', at[11] = ' ';
        }
        f = fopen(path, "w");
        fputs(far, f);
        fclose(f);
        expect_load_error(path, "camera.from: a point beyond", NULL);
    }
    /* a map of texels up to 1e9 is fine; scaled by 1e4 it is not */
    {
        char bg[512];
        snprintf(bg, sizeof bg, "\"background\": {\"map\": \"%s\", \"scale\": 1e4},", map);
        SCENE("5, 5, 5", bg, "0, 0, 0", "2, 0, 0");
    }
    expect_load_error(path, "background.map", "brightest texel");
#undef SCENE
    remove(path);
    remove(map);
    rmdir(dir);
}

/* Images that fail to read say why in our one line, and nothing else reaches stderr (issue
 * 27): a corrupt PNG printed libpng's own line first, a truncated map said "read failed:" and
 * nothing more, a 10^6 x 1 map "too large (at most 268435456 pixels)". */
static void test_image_messages(void **state)
{
    static const unsigned char bad_png[] = {
        0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n', 0, 0, 0, 13, 'I', 'H', 'D', 'R', 0, 0, 0, 16,
        0,    0,   0,   16,  8,     2,     0,    0,    0, 0x90, 0x91, 0x68, 0x36, 0, 0, 0, 5,
        'I',  'D', 'A', 'T', 'x',   'x',   'x',  'x',  'x'};
    char dir[] = "/tmp/rs_img_XXXXXX", png[256], pfm[256], wide[256], err[256], said[512];
    uint32_t w, h;
    float *rgb = NULL;
    FILE *f;
    int saved;
    size_t n;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(png, sizeof png, "%s/bad.png", dir);
    snprintf(pfm, sizeof pfm, "%s/cut.pfm", dir);
    snprintf(wide, sizeof wide, "%s/wide.pfm", dir);
    snprintf(err, sizeof err, "%s/stderr.txt", dir);
    f = fopen(png, "wb");
    fwrite(bad_png, 1, sizeof bad_png, f);
    fclose(f);
    f = fopen(pfm, "wb");
    fputs("PF\n4 4\n-1.0\n", f);
    fwrite("0123456789", 1, 10, f); /* 192 bytes of pixels are due */
    fclose(f);
    f = fopen(wide, "wb");
    fputs("PF\n1000000 1\n-1.0\n", f);
    {
        static float row[3000];
        int k;
        for (k = 0; k < 1000; ++k)
            fwrite(row, sizeof row[0], 3000, f);
    }
    fclose(f);
    /* stderr into a file while the images are read: it must stay empty */
    fflush(stderr);
    saved = dup(2);
    f = fopen(err, "w");
    dup2(fileno(f), 2);
    assert_int_not_equal(rs_image_read_linear(png, &w, &h, &rgb), RS_OK);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    fclose(f);
    f = fopen(err, "r");
    n = fread(said, 1, sizeof said - 1, f);
    fclose(f);
    said[n] = 0;
    print_message("%s\n", rs_error_message());
    assert_int_equal(n, 0);
    assert_non_null(strstr(rs_error_message(), "bad.png"));
    assert_non_null(strstr(rs_error_message(), "IDAT"));
    assert_null(strchr(rs_error_message(), '\n'));
    rs_error_clear();
    assert_int_not_equal(rs_image_read(pfm, &w, &h, &rgb), RS_OK);
    print_message("%s\n", rs_error_message());
    assert_non_null(strstr(rs_error_message(), "cut short or corrupt"));
    rs_error_clear();
    assert_int_not_equal(rs_image_read(wide, &w, &h, &rgb), RS_OK);
    print_message("%s\n", rs_error_message());
    assert_non_null(strstr(rs_error_message(), "has a side over 65536"));
    rs_error_clear();
    assert_null(rgb);
    remove(png);
    remove(pfm);
    remove(wide);
    remove(err);
    rmdir(dir);
}

/* A .pfm is written by core/pfm.c in every build (OpenImageIO 2.4 cannot write one: `-o x.pfm`
 * was refused) and reads back bit for bit, through OpenImageIO where the build has it: a 3x2
 * image whose rows differ (the format stores the bottom row first), a negative value and a
 * denormal.  Layers still need an .exr, and a folder that is not there is named. */
static void test_pfm_round_trip(void **state)
{
    char dir[] = "/tmp/rs_pfm_XXXXXX", p[256], q[256];
    float img[18], *back = NULL;
    uint32_t w = 0, h = 0, i;
    rs_image_layer layer = {"albedo", "RGB", img};
    (void)state;
    for (i = 0; i < 18; ++i)
        img[i] = (float)i * 0.37f - 1.0f;
    img[5] = 1e-40f;
    assert_non_null(mkdtemp(dir));
    snprintf(p, sizeof p, "%s/a.pfm", dir);
    assert_int_equal(rs_image_check_output(p), RS_OK);
    assert_int_equal(rs_image_write(p, 3, 2, img), RS_OK);
    assert_int_equal(rs_image_read_linear(p, &w, &h, &back), RS_OK);
    assert_true(w == 3 && h == 2);
    assert_memory_equal(back, img, sizeof img);
    rs_free(back);
    snprintf(q, sizeof q, "%s/B.PFM", dir);
    assert_int_equal(rs_image_write_view(q, 3, 2, img, NULL, 0, NULL, 0, NULL), RS_OK);
    assert_int_not_equal(rs_image_write_layers(q, 3, 2, img, &layer, 1, NULL, 0), RS_OK);
    assert_non_null(strstr(rs_error_message(), "B.PFM"));
    rs_error_clear();
    snprintf(q, sizeof q, "%s/none/c.pfm", dir);
    assert_int_not_equal(rs_image_check_output(q), RS_OK);
    assert_non_null(strstr(rs_error_message(), "none"));
    rs_error_clear();
    snprintf(q, sizeof q, "%s/B.PFM", dir);
    remove(q);
    remove(p);
    rmdir(dir);
}

/* Scene files and textures that are not regular files of a sane size are refused by name,
 * without being read: a FIFO (opening one for reading blocks until a writer comes), /dev/zero
 * (never ends), a folder, a socket, a sparse file of 300 MiB.  alarm() turns a regression (a
 * hang) into a failed test instead of a stuck one. */
static void test_file_kinds(void **state)
{
    char dir[] = "/tmp/rs_json_XXXXXX", fifo[256], sub[256], sock[256], big[256], scene[256];
    char json[1024];
    static const char *const tex_files[] = {"fifo.png", "/dev/zero", "sub"};
    static const char *const tex_words[] = {"not a regular file", "not a regular file",
                                            "is a folder"};
    struct sockaddr_un addr;
    int fd, k;
    (void)state;
    alarm(60);
    assert_non_null(mkdtemp(dir));
    snprintf(fifo, sizeof fifo, "%s/fifo.json", dir);
    snprintf(sub, sizeof sub, "%s/sub", dir);
    snprintf(sock, sizeof sock, "%s/sock.json", dir);
    snprintf(big, sizeof big, "%s/big.json", dir);
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    assert_int_equal(mkdir(sub, 0700), 0);
    fd = socket(AF_UNIX, SOCK_STREAM, 0);
    assert_true(fd >= 0);
    memset(&addr, 0, sizeof addr);
    addr.sun_family = AF_UNIX;
    assert_true(strlen(sock) < sizeof addr.sun_path);
    memcpy(addr.sun_path, sock, strlen(sock) + 1);
    assert_int_equal(bind(fd, (const struct sockaddr *)&addr, sizeof addr), 0);
    close(fd);
    fd = open(big, O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    assert_int_equal(ftruncate(fd, (off_t)300 << 20), 0); /* sparse: no disk used */
    close(fd);

    expect_load_error(fifo, fifo, "not a regular file");
    expect_load_error("/dev/zero", "/dev/zero", "not a regular file");
    expect_load_error(sub, sub, "is a folder");
    expect_load_error(sock, sock, "not a regular file");
    expect_load_error(big, big, "larger than 256 MiB");

    /* the same for an image texture the scene names */
    snprintf(fifo, sizeof fifo, "%s/fifo.png", dir);
    assert_int_equal(mkfifo(fifo, 0600), 0);
    for (k = 0; k < 3; ++k) {
        snprintf(json, sizeof json,
                 "{" CAM ",\"textures\":{\"t\":{\"type\":\"image\",\"file\":\"%s\"}},"
                 "\"objects\":[]}",
                 tex_files[k]);
        write_file(scene, json);
        expect_load_error(scene, tex_files[k], tex_words[k]);
    }
    alarm(0);
    remove(fifo);
    snprintf(fifo, sizeof fifo, "%s/fifo.json", dir);
    remove(fifo);
    remove(sock);
    remove(big);
    remove(scene);
    rmdir(sub);
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
        cmocka_unit_test(test_every_example_renders),
        cmocka_unit_test(test_bad_inputs),
        cmocka_unit_test(test_image_texture_relative),
        cmocka_unit_test(test_file_kinds),
        cmocka_unit_test(test_ranges_named),
        cmocka_unit_test(test_image_messages),
        cmocka_unit_test(test_pfm_round_trip),
        cmocka_unit_test(test_spot_cone_90),
        cmocka_unit_test(test_rgba_not_premultiplied),
        cmocka_unit_test(test_image_memory_bound),
        cmocka_unit_test(test_light_tables_bounded),
        cmocka_unit_test(test_mutations_never_crash),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
