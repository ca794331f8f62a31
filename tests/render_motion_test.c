/* tests/render_motion_test.c — motion blur: per-ray time, moving spheres, and the BVH bounds
 * that must cover a sphere's whole sweep.
 *
 * Coverage test: a black sphere (radius r = 0.5) moves along x from -2 to +2 during the shutter
 * [0, 1] in front of a white sky (radiance 1).  The ray through the image centre runs along the
 * z axis and is blocked while |x(t)| < r, i.e. for a fraction 2r / 4 = 1/4 of the shutter, so
 * the centre pixel's expected value is 3/4.  With a frozen shutter the same pixel is 0 (sphere
 * centred) or 1 (sphere away).
 *
 * A moving sphere light is sampled where it is at each path's time (the stream integrator and
 * the megakernel); see test_moving_light_sampled_at_ray_time. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "render_util.h"
#include "test_rand.h"

#define SIZE 21 /* odd: one pixel is centred on the axis */

static rs_scene *moving_scene(float open, float close)
{
    rs_scene *s;
    rs_material black = rs_mat_lambertian(rs_v3(0, 0, 0));
    uint32_t id;
    assert_int_equal(rs_scene_create("motion", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &black, &id), RS_OK);
    assert_int_equal(
        rs_scene_add_moving_sphere(s, rs_v3(-2, 0, 0), 0.0f, rs_v3(2, 0, 0), 1.0f, 0.5f, id),
        RS_OK);
    s->camera.from = rs_v3(0, 0, 10);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.up = rs_v3(0, 1, 0);
    /* a narrow view: the centre pixel spans about 0.01 units at the sphere, 2% of r */
    s->camera.vfov_deg = 1.2f;
    s->camera.shutter_open = open;
    s->camera.shutter_close = close;
    s->background = rs_v3(1, 1, 1);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

static double centre_pixel(float open, float close, uint32_t spp)
{
    rs_scene *s = moving_scene(open, close);
    rt_args a = rt_defaults("motion", SIZE, spp);
    float *img;
    double v;
    a.threads = 2;
    img = rt_render_scene(s, &a, NULL);
    assert_non_null(img);
    v = img[3 * ((SIZE / 2) * SIZE + SIZE / 2)];
    free(img);
    rs_scene_destroy(s);
    return v;
}

/* 40000 samples of a Bernoulli(3/4): standard error 0.0022; the bound 0.015 is ~7 sigma, while
 * a renderer that ignores time (sphere frozen at t = 0 or 0.5) gives 1 or 0. */
static void test_blurred_coverage(void **state)
{
    double v;
    (void)state;
    v = centre_pixel(0.0f, 1.0f, 40000);
    print_message("centre pixel over the shutter: %.4f (expected 0.75)\n", v);
    assert_true(fabs(v - 0.75) < 0.015);
}

static void test_frozen_shutter(void **state)
{
    (void)state;
    assert_true(centre_pixel(0.5f, 0.5f, 16) < 1e-6);             /* sphere centred at t = 0.5 */
    assert_true(fabs(centre_pixel(0.0f, 0.0f, 16) - 1.0) < 1e-6); /* sphere at x = -2 */
}

/* A moving sphere light: each path samples the light where it is at the path's time.  A sphere
 * of radiance 4 moves from (-2, 1, 0) at t = 0 to (2, 1, 0) at t = 1 over a grey floor seen from
 * above (image right is +x).  With the shutter frozen at t, the image must match the same sphere
 * standing still where it is at t (same seed: the same random numbers, the same geometry).
 * Next-event estimation from the sphere's t = 0 place would light the floor under (-2, 1, 0)
 * (the shadow ray, at the path's time, no longer meets the sphere there), which the static
 * render at (2, 1, 0) leaves dark: the halves below differ several times over. */
static rs_scene *lit_floor(int moving, float x_at_rest, float shutter)
{
    rs_scene *s;
    rs_material grey = rs_mat_lambertian(rs_v3(0.5f, 0.5f, 0.5f));
    rs_material light = rs_mat_light(rs_v3(4, 4, 4), 0);
    uint32_t g, l;
    assert_int_equal(rs_scene_create("moving-light", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &grey, &g), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &light, &l), RS_OK);
    /* u x v = (8, 0, 0) x (0, 0, -8) = (0, 64, 0): the floor faces up */
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, 0, 4), rs_v3(8, 0, 0), rs_v3(0, 0, -8), g),
                     RS_OK);
    if (moving)
        assert_int_equal(rs_scene_add_moving_sphere(s, rs_v3(-2, 1, 0), 0.0f, rs_v3(2, 1, 0), 1.0f,
                                                    0.5f, l),
                         RS_OK);
    else
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(x_at_rest, 1, 0), 0.5f, l), RS_OK);
    s->camera.from = rs_v3(0, 8, 0);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.up = rs_v3(0, 0, -1);
    s->camera.vfov_deg = 60.0f;
    s->camera.shutter_open = s->camera.shutter_close = shutter;
    s->background = rs_v3(0, 0, 0);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

/* The means of the image's left and right halves (the middle column left out). */
static void halves(int moving, float x_at_rest, float shutter, int megakernel, double *left,
                   double *right)
{
    rs_scene *s = lit_floor(moving, x_at_rest, shutter);
    rt_args a = rt_defaults("moving-light", SIZE, 256);
    float *img;
    uint32_t x, y;
    a.threads = 2;
    a.megakernel = megakernel;
    img = rt_render_scene(s, &a, NULL);
    assert_non_null(img);
    *left = *right = 0.0;
    for (y = 0; y < SIZE; ++y)
        for (x = 0; x < SIZE; ++x) {
            double v = img[3 * (y * SIZE + x)];
            if (x < SIZE / 2)
                *left += v;
            else if (x > SIZE / 2)
                *right += v;
        }
    *left /= (SIZE / 2) * SIZE;
    *right /= (SIZE / 2) * SIZE;
    free(img);
    rs_scene_destroy(s);
}

static void test_moving_light_sampled_at_ray_time(void **state)
{
    int mk;
    (void)state;
    for (mk = 0; mk < 2; ++mk) {
        double ml, mr, sl, sr, s0l, s0r;
        halves(1, 0.0f, 1.0f, mk, &ml, &mr);   /* moving, frozen at t = 1 */
        halves(0, 2.0f, 1.0f, mk, &sl, &sr);   /* standing at (2, 1, 0) */
        halves(0, -2.0f, 1.0f, mk, &s0l, &s0r); /* standing at (-2, 1, 0): what t = 0 would be */
        print_message("%s: moving at t = 1: halves %.5f | %.5f; at rest there %.5f | %.5f; at "
                      "rest at its t = 0 place %.5f | %.5f\n",
                      mk ? "megakernel" : "stream", ml, mr, sl, sr, s0l, s0r);
        /* the test tells the two places apart */
        assert_true(s0l > 3.0 * sl && sr > 3.0 * s0r);
        assert_true(fabs(ml - sl) <= 0.02 * sl && fabs(mr - sr) <= 0.02 * sr);
        /* and at t = 0 the moving sphere is where it started */
        halves(1, 0.0f, 0.0f, mk, &ml, &mr);
        assert_true(fabs(ml - s0l) <= 0.02 * s0l && fabs(mr - s0r) <= 0.02 * s0r);
    }
}

/* Moving spheres in the BVH: closest hits at random times equal brute force, which only works
 * if every node's bounds cover the whole sweep of the spheres below it. */
static void test_bvh_moving_vs_brute_force(void **state)
{
    const uint32_t ns = 400, nrays = 20000;
    rs_sphere *sph = (rs_sphere *)calloc(ns, sizeof *sph);
    rs_vec3 *motion = (rs_vec3 *)calloc(ns, sizeof *motion);
    rs_geom g;
    rs_bvh *bvh;
    rs_bvh_view bv;
    uint64_t st = 99;
    uint32_t i, k, hits = 0;
    (void)state;
    for (i = 0; i < ns; ++i) {
        sph[i].center = rnd_box(&st, 20.0f);
        sph[i].radius = rnd_range(&st, 0.2, 1.5);
        motion[i] = (i % 3) ? rnd_box(&st, 6.0f) : rs_v3(0, 0, 0);
    }
    memset(&g, 0, sizeof g);
    g.spheres = sph;
    g.sphere_motion = motion;
    g.n_spheres = ns;
    g.time0 = 0.0f;
    g.time1 = 1.0f;
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    bv = rs_bvh_view_of(bvh);
    for (k = 0; k < nrays; ++k) {
        rs_ray r = mk_ray(rnd_box(&st, 25.0f), rnd_unit(&st), 0.0f, 1e30f);
        rs_hit h;
        float best = 1e30f;
        uint32_t best_prim = RS_NO_HIT;
        r.time = (float)rnd01(&st);
        for (i = 0; i < ns; ++i) {
            float t, u, v;
            if (rs_geom_intersect(&g, i, &r, &t, &u, &v) && t < best) {
                best = t;
                best_prim = i;
            }
        }
        rs_bvh_closest(&bv, &g, r, &h);
        assert_int_equal(h.prim, best_prim);
        if (best_prim != RS_NO_HIT) {
            assert_true(h.t == best);
            hits++;
        }
        assert_int_equal(rs_bvh_occluded(&bv, &g, r), best_prim != RS_NO_HIT);
    }
    print_message("%u of %u rays hit a moving sphere field\n", hits, nrays);
    assert_true(hits > nrays / 10);
    rs_bvh_destroy(bvh);
    free(sph);
    free(motion);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_blurred_coverage),
        cmocka_unit_test(test_frozen_shutter),
        cmocka_unit_test(test_moving_light_sampled_at_ray_time),
        cmocka_unit_test(test_bvh_moving_vs_brute_force),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
