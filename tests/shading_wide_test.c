/* tests/shading_wide_test.c — the eight-lane shading (shading/shade_wide.c) against the scalar
 * shading it restates (shading/path.h: rs_path_shade_at): every image rendered with it on is the
 * image rendered with it off, bit for bit, and the counter of entries it shaded shows that it ran
 * (or, where the scene has lights it does not handle, that it stayed out).
 *
 * Scenes chosen to reach each branch: the Cornell box (parallelograms, one light, roulette),
 * its glass twin (a sphere and a glass material between the walls: lanes of a batch shaded by
 * either code, their rays written to the streams in either order), and a scene built here: tilted vertex normals on a
 * curved triangle mesh (shading normals not along any axis, some facing away from the ray), a
 * one-sided triangle light and a two-sided parallelogram light (picked by power: the CDF), with
 * and without a uniform sky (light sampling's sky branch, the sky's pdf kept for MIS).  Each in
 * the three samplers, on the render thread's stream engine and on the CPU device's own waves, one
 * and two threads.  builtin:many-lights has sphere lights, which the wide code leaves to the
 * scalar shading. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "gpucheck_util.h"
#include "shading/shade_wide.h"

/* A curved sheet of triangles with vertex normals tilted off the face normals, a Lambertian
 * floor and back wall, a sphere, a metal panel, a one-sided triangle light, a two-sided
 * parallelogram light; `sky`: a uniform sky as well. */
static rs_scene *made_scene(int sky)
{
    rs_scene *s = NULL;
    rs_material floor_m = rs_mat_lambertian(rs_v3(0.6f, 0.55f, 0.5f));
    rs_material sheet_m = rs_mat_lambertian(rs_v3(0.3f, 0.7f, 0.4f));
    rs_material metal_m = rs_mat_metal(rs_v3(0.8f, 0.8f, 0.9f), 0.1f);
    rs_material tri_l = rs_mat_light(rs_v3(12.0f, 10.0f, 8.0f), 0);
    rs_material quad_l = rs_mat_light(rs_v3(3.0f, 4.0f, 6.0f), 1);
    uint32_t fl, sh, me, tl, ql, i, j;
    assert_int_equal(rs_scene_create("wide", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &floor_m, &fl), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &sheet_m, &sh), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &metal_m, &me), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &tri_l, &tl), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &quad_l, &ql), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, 0, -4), rs_v3(0, 0, 8), rs_v3(8, 0, 0), fl),
                     RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, 0, -3), rs_v3(8, 0, 0), rs_v3(0, 4, 0), fl),
                     RS_OK);
    /* the sheet: z = 0.3 sin(x) cos(y) over a grid, normals of a steeper surface */
    for (j = 0; j < 6; ++j)
        for (i = 0; i < 8; ++i) {
            rs_vec3 p[4], v[3];
            float nrm[4][3], tri_n[9];
            int c, k;
            for (c = 0; c < 4; ++c) {
                float x = -1.6f + 0.4f * (float)(i + (uint32_t)(c & 1));
                float y = 0.3f + 0.35f * (float)(j + (uint32_t)(c >> 1));
                float z = 0.3f * sinf(2.0f * x) * cosf(1.5f * y) - 1.0f;
                float gx = -0.9f * cosf(2.0f * x), gy = 0.7f * sinf(1.5f * y);
                float len = sqrtf(gx * gx + gy * gy + 1.0f);
                p[c] = rs_v3(x, y, z);
                nrm[c][0] = gx / len;
                nrm[c][1] = gy / len;
                nrm[c][2] = 1.0f / len;
            }
            for (k = 0; k < 2; ++k) {
                static const int corner[2][3] = {{0, 1, 3}, {0, 3, 2}};
                for (c = 0; c < 3; ++c) {
                    v[c] = p[corner[k][c]];
                    memcpy(&tri_n[3 * c], nrm[corner[k][c]], sizeof nrm[0]);
                }
                assert_int_equal(rs_scene_add_triangle_full(s, v, NULL, tri_n, sh), RS_OK);
            }
        }
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(1.8f, 0.6f, -0.5f), 0.6f, fl), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-3.5f, 0.2f, -2.5f), rs_v3(1.0f, 0, 0.6f),
                                       rs_v3(0, 1.5f, 0), me),
                     RS_OK);
    /* a triangle light facing down and a small two-sided panel */
    assert_int_equal(rs_scene_add_triangle(s, rs_v3(-1.0f, 3.5f, 0.0f), rs_v3(1.0f, 3.5f, 0.5f),
                                           rs_v3(0.0f, 3.5f, -1.0f), tl),
                     RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(2.5f, 1.0f, 0.5f), rs_v3(0, 0.6f, 0.3f),
                                       rs_v3(0.3f, 0, -0.5f), ql),
                     RS_OK);
    s->camera.from = rs_v3(0.5f, 1.8f, 4.5f);
    s->camera.at = rs_v3(0.0f, 1.0f, -1.0f);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 50.0f;
    if (sky)
        s->background = rs_v3(0.4f, 0.5f, 0.7f);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

/* `a` (over `scene`, or a's built-in where NULL) with the wide shading off, then on: the same
 * image; returns the entries it shaded. */
static uint64_t same_image(const char *what, const rs_scene *scene, const rt_args *a)
{
    float *ref, *img;
    uint64_t before;
    char label[200];
    rs_shade_wide_use(0);
    ref = scene ? rt_render_scene(scene, a, NULL) : rt_render(a, NULL);
    rs_shade_wide_use(1);
    before = rs_shade_wide_count();
    img = scene ? rt_render_scene(scene, a, NULL) : rt_render(a, NULL);
    assert_non_null(ref);
    assert_non_null(img);
    assert_true(gc_image_sane(ref, a->width, a->height));
    snprintf(label, sizeof label, "%s: scalar vs wide shading (sampler %d, %s, %d threads)", what,
             (int)a->sampler, a->wavefront ? "CPU waves" : "render thread", a->threads);
    assert_int_equal(gc_diff_pixels(label, ref, img, a->width, a->height), 0);
    free(ref);
    free(img);
    return rs_shade_wide_count() - before;
}

/* Every sampler, both engines, one and two threads: `scene` (or a built-in) the same image. */
static void every_way(const char *what, const rs_scene *scene, const char *builtin, int expect)
{
    static const rs_sampler samplers[] = {RS_SAMPLER_SOBOL, RS_SAMPLER_INDEPENDENT,
                                          RS_SAMPLER_ZSOBOL};
    size_t k;
    int wf, t;
    for (k = 0; k < sizeof samplers / sizeof samplers[0]; ++k)
        for (wf = 0; wf < 2; ++wf)
            for (t = 1; t <= 2; ++t) {
                rt_args a = rt_defaults(builtin ? builtin : "cornell", 40, 6);
                uint64_t shaded;
                a.sampler = samplers[k];
                a.wavefront = wf;
                a.threads = t;
                shaded = same_image(what, scene, &a);
                if (!rs_shade_wide_use(1)) {
                    print_message("%s: this CPU has no AVX2; only the scalar shading ran\n", what);
                    assert_true(shaded == 0);
                } else if (expect) {
                    assert_true(shaded > 0);
                } else {
                    assert_true(shaded == 0);
                }
            }
}

static void test_cornell(void **state)
{
    (void)state;
    every_way("cornell", NULL, "cornell", 1);
}

static void test_cornell_glass(void **state)
{
    (void)state;
    every_way("cornell-glass", NULL, "cornell-glass", 1);
}

static void test_made_scene(void **state)
{
    rs_scene *s = made_scene(0);
    (void)state;
    every_way("tilted normals, triangle and two-sided lights", s, NULL, 1);
    rs_scene_destroy(s);
}

static void test_made_scene_sky(void **state)
{
    rs_scene *s = made_scene(1);
    (void)state;
    assert_true(s->env_pick > 0.0f && s->env_uniform);
    every_way("tilted normals, lights and a uniform sky", s, NULL, 1);
    rs_scene_destroy(s);
}

static void test_sphere_lights_stay_scalar(void **state)
{
    (void)state;
    every_way("many-lights (sphere lights)", NULL, "many-lights", 0);
}

/* The settings the wide code does not restate keep it out: other estimators, the light BVH, the
 * last segment. */
static void test_ready(void **state)
{
    rs_scene *s = made_scene(1);
    rs_render_consts it;
    (void)state;
    if (!rs_shade_wide_use(1)) {
        rs_scene_destroy(s);
        skip();
    }
    memset(&it, 0, sizeof it);
    it.scene = s;
    it.max_depth = 5;
    it.rr_depth = 3;
    it.sampling = RS_SAMPLING_MIS;
    assert_true(rs_shade_wide_ready(&it, 0));
    assert_true(rs_shade_wide_ready(&it, 3));
    assert_false(rs_shade_wide_ready(&it, 4)); /* its vertices draw no next ray */
    it.sampling = RS_SAMPLING_MIXTURE;
    assert_false(rs_shade_wide_ready(&it, 0));
    it.sampling = RS_SAMPLING_MIS;
    it.light_sampler = RS_LIGHT_SAMPLER_BVH;
    assert_false(rs_shade_wide_ready(&it, 0));
    it.light_sampler = RS_LIGHT_SAMPLER_POWER;
    rs_shade_wide_use(0);
    assert_false(rs_shade_wide_ready(&it, 0));
    rs_shade_wide_use(1);
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cornell),
        cmocka_unit_test(test_cornell_glass),
        cmocka_unit_test(test_made_scene),
        cmocka_unit_test(test_made_scene_sky),
        cmocka_unit_test(test_sphere_lights_stay_scalar),
        cmocka_unit_test(test_ready),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
