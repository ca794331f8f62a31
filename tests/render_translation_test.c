/* tests/render_translation_test.c — a scene moved away from the origin renders as it does at
 * the origin.
 *
 * Each scene is written as a scene file (the built-in ones by rs_scene_export_json), then read
 * again with one more transform step on every object (and on the camera's from and at): a
 * translation by 10^2, 10^3 or 10^4 units, and a rotation about y with the largest one.  The
 * renders use different seeds, so the two images' pixels are independent estimates of the same
 * values; the per-pixel differences d_i (their channel means) are then independent across pixels,
 * and z = mean(d) / (sd(d) / sqrt(N)) is a standard normal where the scenes agree.  Every pair must
 * have |z| < 4 (two-sided 6e-5 each; about 0.3% that one of the ~50 comparisons fails by
 * chance, and the seeds are fixed, so a pass is a pass every time), and so must each of the
 * image's 4 x 4 blocks, |z| < 4.5 (issue 41: the mean alone let through changes that move light
 * from one part of the image to another); a block that differs by less than 0.01% (the sky,
 * without noise: the camera's rounding at 10^4) is the same.
 *
 * What it catches: light leaking past occluders or surfaces shadowing themselves where rays
 * leave a surface (an offset that grows with the coordinates, as the 1e-4-of-the-coordinates
 * epsilon before shading/spawn.h did: +0.5% image mean at 10^2, +73% at 10^4 for the point-lit
 * scene), hit points or camera directions rounded at the scale of the coordinates, and shadow
 * rays that hit the light they aim at.
 *
 * World-space textures (checker) are not translation-invariant by definition: they are
 * replaced by their mean colour in both renders.  Built-in scenes that need the test models are
 * skipped without them (a line says so). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <unistd.h>
#include <cmocka.h>
#include <cjson/cJSON.h>

#include "render_util.h"
#include "scenes/scene_export.h"
#include "scenes/scene_json.h"

#define SIZE  48
#define Z_MAX 4.0
/* blocks per side, and the bound on each block's z (16 blocks x ~50 comparisons: two-sided
 * 6.8e-6 each, about 0.5% that one of them fails by chance; the seeds are fixed) */
#define BLOCKS  4
#define Z_BLOCK 4.5
/* a block whose mean differs by less than this (relative) is taken as the same: a part of the
 * image without noise (the sky) differs by the camera's rounding alone, a z of any size */
#define BLOCK_REL 1e-4

typedef struct placement {
    double deg;  /* rotation about y, first */
    double t[3]; /* then this translation */
    const char *name;
} placement;

static const placement places[] = {
    {0.0, {100.0, 40.0, -100.0}, "moved 1e2"},
    {0.0, {1000.0, 400.0, -1000.0}, "moved 1e3"},
    {0.0, {10000.0, 4000.0, -10000.0}, "moved 1e4"},
    {37.0, {-10000.0, 4000.0, 10000.0}, "turned 37 deg, moved 1e4"},
};
#define N_PLACES (sizeof places / sizeof places[0])

static void place_point(const placement *pl, const double in[3], double out[3])
{
    double c = cos(pl->deg * (3.14159265358979323846 / 180.0));
    double s = sin(pl->deg * (3.14159265358979323846 / 180.0));
    double x = c * in[0] + s * in[2], z = -s * in[0] + c * in[2];
    out[0] = x + pl->t[0];
    out[1] = in[1] + pl->t[1];
    out[2] = z + pl->t[2];
}

static void get3(const cJSON *a, double v[3])
{
    int i;
    assert_true(cJSON_IsArray(a) && cJSON_GetArraySize(a) == 3);
    for (i = 0; i < 3; ++i)
        v[i] = cJSON_GetArrayItem(a, i)->valuedouble;
}

static cJSON *make3(const double v[3]) { return cJSON_CreateDoubleArray(v, 3); }

/* The steps of placement pl, appended to an object's transform (none, one step or steps). */
static void add_steps(cJSON *obj, const placement *pl)
{
    cJSON *tf = cJSON_DetachItemFromObject(obj, "transform"), *steps = cJSON_CreateArray();
    cJSON *rot = cJSON_CreateObject(), *r = cJSON_CreateObject(), *tr = cJSON_CreateObject();
    double axis[3] = {0.0, 1.0, 0.0};
    if (cJSON_IsArray(tf)) {
        while (cJSON_GetArraySize(tf) > 0)
            cJSON_AddItemToArray(steps, cJSON_DetachItemFromArray(tf, 0));
        cJSON_Delete(tf);
    } else if (tf) {
        cJSON_AddItemToArray(steps, tf);
    }
    if (pl->deg != 0.0) {
        cJSON_AddItemToObject(r, "axis", make3(axis));
        cJSON_AddNumberToObject(r, "degrees", pl->deg);
        cJSON_AddItemToObject(rot, "rotate", r);
        cJSON_AddItemToArray(steps, rot);
    } else {
        cJSON_Delete(rot);
        cJSON_Delete(r);
    }
    cJSON_AddItemToObject(tr, "translate", make3(pl->t));
    cJSON_AddItemToArray(steps, tr);
    cJSON_AddItemToObject(obj, "transform", steps);
}

/* Scene file text `text` with every object placed by pl (NULL: as it is), its checker textures
 * made solid, at SIZE x SIZE; parsed and finalized (base_dir: its image files). */
static rs_scene *load_placed(const char *text, const char *base_dir, const placement *pl)
{
    cJSON *root = cJSON_Parse(text), *o, *cam, *img, *tex;
    rs_scene *s = NULL;
    char *out;
    assert_non_null(root);
    img = cJSON_CreateObject();
    cJSON_AddNumberToObject(img, "width", SIZE);
    cJSON_AddNumberToObject(img, "height", SIZE);
    cJSON_DeleteItemFromObject(root, "image");
    cJSON_AddItemToObject(root, "image", img);
    cJSON_ArrayForEach(tex, cJSON_GetObjectItem(root, "textures"))
    {
        cJSON *type = cJSON_GetObjectItem(tex, "type");
        if (cJSON_IsString(type) && strcmp(type->valuestring, "checker") == 0) {
            double a[3], b[3], m[3];
            int i;
            get3(cJSON_GetObjectItem(tex, "a"), a);
            get3(cJSON_GetObjectItem(tex, "b"), b);
            for (i = 0; i < 3; ++i)
                m[i] = 0.5 * (a[i] + b[i]);
            while (tex->child)
                cJSON_Delete(cJSON_DetachItemViaPointer(tex, tex->child));
            cJSON_AddStringToObject(tex, "type", "solid");
            cJSON_AddItemToObject(tex, "color", make3(m));
        }
    }
    if (pl) {
        cam = cJSON_GetObjectItem(root, "camera");
        assert_non_null(cam);
        {
            const char *keys[2] = {"from", "at"};
            int k;
            for (k = 0; k < 2; ++k) {
                double p[3], q[3];
                get3(cJSON_GetObjectItem(cam, keys[k]), p);
                place_point(pl, p, q);
                cJSON_ReplaceItemInObject(cam, keys[k], make3(q));
            }
        }
        cJSON_ArrayForEach(o, cJSON_GetObjectItem(root, "objects")) add_steps(o, pl);
    }
    out = cJSON_PrintUnformatted(root);
    assert_non_null(out);
    if (rs_scene_parse_json(out, strlen(out), "placed scene", base_dir, &s) != RS_OK)
        fail_msg("placed scene: %s", rs_error_message());
    cJSON_free(out);
    cJSON_Delete(root);
    return s;
}

static float *render(const rs_scene *s, uint32_t spp, uint64_t seed)
{
    rt_args a = rt_defaults("", SIZE, spp);
    float *img;
    a.seed = seed;
    a.sampler = RS_SAMPLER_SOBOL; /* scrambled per pixel and seed: pixels stay independent */
    a.threads = 2;
    a.bvh = RS_BVH_SAH;
    img = rt_render_scene(s, &a, NULL);
    assert_non_null(img);
    return img;
}

/* z of the mean per-pixel difference between images a and b over the w x h pixels at (x0, y0)
 * (see the top of the file); *rel: the relative difference of their means there. */
static double region_z(const float *a, const float *b, uint32_t x0, uint32_t y0, uint32_t w,
                       uint32_t h, double *rel)
{
    const size_t n = (size_t)w * h;
    double sum = 0.0, sum2 = 0.0, ma = 0.0, mb = 0.0, mean, var;
    uint32_t x, y;
    for (y = y0; y < y0 + h; ++y)
        for (x = x0; x < x0 + w; ++x) {
            size_t i = (size_t)y * SIZE + x;
            double pa = ((double)a[3 * i] + a[3 * i + 1] + a[3 * i + 2]) / 3.0;
            double pb = ((double)b[3 * i] + b[3 * i + 1] + b[3 * i + 2]) / 3.0;
            double d = pb - pa;
            sum += d;
            sum2 += d * d;
            ma += pa;
            mb += pb;
        }
    mean = sum / (double)n;
    var = (sum2 - sum * mean) / (double)(n - 1);
    *rel = ma > 0.0 ? mb / ma - 1.0 : 0.0;
    if (!(var > 0.0))
        return mean == 0.0 ? 0.0 : INFINITY;
    return mean / sqrt(var / (double)n);
}

/* Renders scene-file text at the origin and at every placement: the whole image's |z| < Z_MAX,
 * and each of its BLOCKS x BLOCKS blocks' |z| < Z_BLOCK, so that a change that moves light from
 * one part of the image to another (a shadow displaced, a leak in a corner) shows even where
 * the image's mean stays put. */
static void check_text(const char *label, const char *text, const char *base_dir, uint32_t spp)
{
    rs_scene *s0 = load_placed(text, base_dir, NULL);
    float *ref = render(s0, spp, 1);
    size_t k;
    int bad = 0;
    rs_scene_destroy(s0);
    for (k = 0; k < N_PLACES; ++k) {
        rs_scene *s = load_placed(text, base_dir, &places[k]);
        float *img = render(s, spp, 2 + k);
        double rel, z = region_z(ref, img, 0, 0, SIZE, SIZE, &rel), worst = 0.0, brel;
        uint32_t bx, by, side = SIZE / BLOCKS;
        for (by = 0; by < BLOCKS; ++by)
            for (bx = 0; bx < BLOCKS; ++bx) {
                double bz = region_z(ref, img, bx * side, by * side, side, side, &brel);
                /* a block without noise (the sky alone) differs by rounding only */
                if (fabs(brel) >= BLOCK_REL && !(fabs(bz) <= fabs(worst)))
                    worst = bz;
            }
        print_message("%-22s %-26s mean %+8.4f%%  z %+6.2f, worst block z %+6.2f%s\n", label,
                      places[k].name, 100.0 * rel, z, worst,
                      (fabs(z) < Z_MAX || fabs(rel) < 1e-6) && fabs(worst) < Z_BLOCK
                          ? ""
                          : "  <- beyond noise");
        /* a scene without noise (the furnace: every sample is 0.5) differs by rounding only */
        bad += !(fabs(z) < Z_MAX || fabs(rel) < 1e-6) || !(fabs(worst) < Z_BLOCK);
        rs_scene_destroy(s);
        free(img);
    }
    free(ref);
    assert_int_equal(bad, 0);
}

/* Built-in scene `name` through its scene file. */
static void check_builtin(const char *name, uint32_t spp)
{
    char dir[] = "/tmp/rs_translate_XXXXXX", path[512];
    rs_scene *s = NULL;
    FILE *f;
    long len;
    char *text;
    rs_status st = rs_builtin_create(name, &s);
    if (st == RS_ERR_IO) {
        print_message("%s: skipped (%s)\n", name, rs_error_message());
        return;
    }
    assert_int_equal(st, RS_OK);
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/%s.json", dir, name);
    assert_int_equal(rs_scene_export_json(s, path), RS_OK);
    rs_scene_destroy(s);
    f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    text = (char *)malloc((size_t)len + 1);
    assert_non_null(text);
    assert_int_equal(fread(text, 1, (size_t)len, f), (size_t)len);
    text[len] = '\0';
    fclose(f);
    check_text(name, text, dir, spp);
    free(text);
    {
        /* the export's files: the scene and any images beside it */
        char cmd[600];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
        assert_int_equal(system(cmd), 0);
    }
}

/* A built-in scene and the spp its comparisons need (the noisier, the more). */
typedef struct builtin_case {
    const char *name;
    uint32_t spp;
} builtin_case;

static builtin_case builtins[] = {
    {"cornell", 256},         {"cornell-glass", 256}, {"materials", 64},       {"rtiow-final", 32},
    {"bouncing-spheres", 32}, {"furnace", 16},        {"cornell-teapot", 128},
};

static void test_builtin(void **state)
{
    const builtin_case *c = (const builtin_case *)*state;
    check_builtin(c->name, c->spp);
}

/* The scene of the report: a diffuse floor, a diffuse sphere resting on it (the contact shadow
 * is where a leaking offset shows first) and one light, the camera 4.5 units away. */
#define SMALL_SCENE_HEAD                                                                           \
  "{\"camera\": {\"from\": [0, 2, 4.5], \"at\": [0, 0.5, 0], \"vfov\": 40},"                       \
  " \"background\": {\"horizon\": [0, 0, 0], \"zenith\": [0, 0, 0]},"                              \
  " \"materials\": {\"floor\": {\"type\": \"lambertian\", \"albedo\": [0.7, 0.7, 0.7]},"           \
  "   \"ball\": {\"type\": \"lambertian\", \"albedo\": [0.6, 0.5, 0.4]},"                          \
  "   \"lamp\": {\"type\": \"light\", \"emission\": [8, 8, 8]}},"                                  \
  " \"objects\": ["                                                                                \
  "   {\"type\": \"quad\", \"q\": [-3, 0, 3], \"u\": [6, 0, 0], \"v\": [0, 0, -6],"                \
  "    \"material\": \"floor\"},"                                                                  \
  "   {\"type\": \"sphere\", \"center\": [0, 0.7, 0], \"radius\": 0.7, \"material\": \"ball\"},"

static void test_point_light(void **state)
{
    (void)state;
    check_text("point light",
               SMALL_SCENE_HEAD "{\"type\": \"point_light\", \"position\": [1.2, 2.5, 1],"
                                " \"intensity\": [10, 10, 10]}]}",
               ".", 64);
}

static void test_spot_light(void **state)
{
    (void)state;
    check_text("spot light",
               SMALL_SCENE_HEAD "{\"type\": \"spot_light\", \"position\": [1.2, 2.5, 1],"
                                " \"direction\": [-0.4, -1, -0.3], \"intensity\": [10, 10, 10],"
                                " \"inner\": 15, \"outer\": 35}]}",
               ".", 64);
}

static void test_area_light(void **state)
{
    (void)state;
    check_text("area light",
               SMALL_SCENE_HEAD "{\"type\": \"quad\", \"q\": [0.7, 2.5, 0.5], \"u\": [1, 0, 0],"
                                " \"v\": [0, 0, 1], \"material\": \"lamp\"}]}",
               ".", 64);
}

/* The 12 triangles of box [lo, hi], outward, as scene-file objects (appended to buf). */
static void box_tris(char *buf, size_t cap, const double lo[3], const double hi[3])
{
    /* corners by bits (x, y, z); each face as two triangles, counter-clockwise from outside */
    static const int faces[6][4] = {{0, 2, 6, 4}, {1, 5, 7, 3}, {0, 4, 5, 1},
                                    {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 6, 7, 5}};
    int f, k;
    for (f = 0; f < 6; ++f)
        for (k = 0; k < 2; ++k) {
            int c[3] = {faces[f][0], faces[f][k + 1], faces[f][k + 2]}, j;
            size_t n = strlen(buf);
            snprintf(buf + n, cap - n,
                     "%s{\"type\": \"triangle\", \"material\": \"wood\", "
                     "\"vertices\": [",
                     buf[n - 1] == '[' ? "" : ", ");
            for (j = 0; j < 3; ++j) {
                n = strlen(buf);
                snprintf(buf + n, cap - n, "%s[%g, %g, %g]", j ? ", " : "",
                         c[j] & 4 ? hi[0] : lo[0], c[j] & 2 ? hi[1] : lo[1],
                         c[j] & 1 ? hi[2] : lo[2]);
            }
            n = strlen(buf);
            snprintf(buf + n, cap - n, "]}");
        }
}

/* Instances (the two-level BVH): a group of two boxes' triangles placed three times, then the
 * instances' transforms moved far with everything else. */
static void test_instances(void **state)
{
    static char text[16384];
    const double lo1[3] = {-0.5, 0.0, -0.5}, hi1[3] = {0.5, 0.6, 0.5};
    const double lo2[3] = {-0.3, 0.6, -0.2}, hi2[3] = {0.2, 1.0, 0.3};
    (void)state;
    snprintf(text, sizeof text, "%s",
             "{\"camera\": {\"from\": [0, 3, 6], \"at\": [0, 0.5, 0], \"vfov\": 40},"
             " \"background\": {\"horizon\": [0.3, 0.3, 0.3], \"zenith\": [0.1, 0.2, 0.4]},"
             " \"materials\": {\"floor\": {\"type\": \"lambertian\", \"albedo\": [0.7, 0.7, 0.7]},"
             "   \"wood\": {\"type\": \"lambertian\", \"albedo\": [0.6, 0.4, 0.2]},"
             "   \"lamp\": {\"type\": \"light\", \"emission\": [6, 6, 6]}},"
             " \"groups\": {\"stack\": [");
    box_tris(text, sizeof text, lo1, hi1);
    box_tris(text, sizeof text, lo2, hi2);
    snprintf(text + strlen(text), sizeof text - strlen(text), "%s",
             "]}, \"objects\": ["
             "   {\"type\": \"quad\", \"q\": [-4, 0, 4], \"u\": [8, 0, 0], \"v\": [0, 0, -8],"
             "    \"material\": \"floor\"},"
             "   {\"type\": \"instance\", \"group\": \"stack\","
             "    \"transform\": {\"translate\": [-1.5, 0, 0]}},"
             "   {\"type\": \"instance\", \"group\": \"stack\"},"
             "   {\"type\": \"instance\", \"group\": \"stack\", \"transform\": [{\"rotate\":"
             "    {\"axis\": [0, 1, 0], \"degrees\": 45}}, {\"translate\": [1.5, 0, -0.5]}]},"
             "   {\"type\": \"point_light\", \"position\": [2, 3, 2], \"intensity\": [8, 8, 8]},"
             "   {\"type\": \"quad\", \"q\": [-2, 2.5, -1], \"u\": [1, 0, 0], \"v\": [0, 0, 1],"
             "    \"material\": \"lamp\"}]}");
    assert_true(strlen(text) + 1 < sizeof text);
    check_text("instances", text, ".", 64);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_point_light),
        cmocka_unit_test(test_spot_light),
        cmocka_unit_test(test_area_light),
        cmocka_unit_test(test_instances),
        cmocka_unit_test_prestate(test_builtin, &builtins[0]),
        cmocka_unit_test_prestate(test_builtin, &builtins[1]),
        cmocka_unit_test_prestate(test_builtin, &builtins[2]),
        cmocka_unit_test_prestate(test_builtin, &builtins[3]),
        cmocka_unit_test_prestate(test_builtin, &builtins[4]),
        cmocka_unit_test_prestate(test_builtin, &builtins[5]),
        cmocka_unit_test_prestate(test_builtin, &builtins[6]),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
