/* tests/render_layers_test.c — glTF's material layers (KHR_materials_specular, _clearcoat,
 * _sheen, _volume, _unlit as the loader makes them: scenes/mesh_materials.c) shade with RS_HD code, so
 * every integrator and device gives the same image bit for bit: the stream engine on the CPU, on
 * the CPU and the GPU's host fallback together, on the fallback alone, and the megakernel.  The
 * scene: a sheen floor, a coated sphere, a sphere with a coloured specular layer, a sphere of
 * absorbing rough glass, an emissive "unlit" quad, under a quad light and a grey sky; every
 * sampling mode. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_util.h"

#define SIZE 32u

static rs_scene *make_scene(void)
{
    rs_scene *s = NULL;
    rs_material m;
    uint32_t floor_id, coat_id, spec_id, glass_id, unlit_id, light_id;
    assert_int_equal(rs_scene_create("layers", &s), RS_OK);
    m = rs_mat_pbr(rs_v3(0.3f, 0.05f, 0.05f), 0.0f, 0.9f);
    m.sheen = rs_v3(1.0f, 0.8f, 0.6f);
    m.sheen_rough = 0.4f;
    assert_int_equal(rs_scene_add_material(s, &m, &floor_id), RS_OK);
    m = rs_mat_pbr(rs_v3(0.1f, 0.2f, 0.6f), 0.0f, 0.8f);
    m.coat = 1.0f;
    m.coat_alpha = 0.01f;
    assert_int_equal(rs_scene_add_material(s, &m, &coat_id), RS_OK);
    m = rs_mat_pbr(rs_v3(0.3f, 0.5f, 0.3f), 0.0f, 0.3f);
    m.specular = rs_v3(0.08f, 0.04f, 0.016f);
    m.spec_weight = 0.5f;
    assert_int_equal(rs_scene_add_material(s, &m, &spec_id), RS_OK);
    m = rs_mat_rough_dielectric(1.5f, 0.04f);
    m.sigma_a = rs_v3(0.2f, 0.9f, 1.6f);
    assert_int_equal(rs_scene_add_material(s, &m, &glass_id), RS_OK);
    m = rs_mat_pbr(rs_v3_splat(0.0f), 0.0f, 1.0f);
    m.emission = rs_v3(0.2f, 0.6f, 0.9f);
    m.spec_weight = 0.0f;
    assert_int_equal(rs_scene_add_material(s, &m, &unlit_id), RS_OK);
    m = rs_mat_light(rs_v3(8, 8, 8), 0);
    assert_int_equal(rs_scene_add_material(s, &m, &light_id), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, 0, -4), rs_v3(0, 0, 8), rs_v3(8, 0, 0),
                                       floor_id),
                     RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(-1.2f, 0.5f, 0), 0.5f, coat_id), RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0.5f, 0), 0.5f, spec_id), RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(1.2f, 0.5f, 0), 0.5f, glass_id), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-1, 1.2f, -1.5f), rs_v3(2, 0, 0),
                                       rs_v3(0, 0.6f, 0), unlit_id),
                     RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-1, 3, -1), rs_v3(2, 0, 0), rs_v3(0, 0, 2),
                                       light_id),
                     RS_OK);
    s->background = rs_v3(0.5f, 0.5f, 0.5f);
    s->camera.from = rs_v3(0, 1.5f, 5);
    s->camera.at = rs_v3(0, 0.5f, 0);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 40.0f;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

static void test_every_device_same_image(void **state)
{
    static const rs_sampling modes[] = {RS_SAMPLING_MIS, RS_SAMPLING_MIXTURE, RS_SAMPLING_BSDF};
    rs_scene *s = make_scene();
    size_t n = (size_t)SIZE * SIZE * 3, i, k;
    (void)state;
    for (k = 0; k < sizeof modes / sizeof *modes; ++k) {
        rt_args a = rt_defaults("layers", SIZE, 8);
        float *base, *other;
        double mean = 0;
        int v;
        a.sampling = modes[k];
        a.max_depth = 8;
        a.threads = 2;
        base = rt_render_scene(s, &a, NULL);
        assert_non_null(base);
        for (i = 0; i < n; ++i) {
            assert_true(isfinite(base[i]));
            mean += base[i];
        }
        assert_true(mean / (double)n > 0.05);
        for (v = 0; v < 3; ++v) {
            rt_args b = a;
            if (v == 0)
                b.with_fallback = 1;
            else if (v == 1)
                b.fallback_only = 1;
            else
                b.megakernel = 1;
            other = rt_render_scene(s, &b, NULL);
            assert_non_null(other);
            if (memcmp(base, other, n * sizeof(float)) != 0)
                fail_msg("sampling %d: variant %d differs from the stream engine on the CPU",
                         (int)modes[k], v);
            free(other);
        }
        print_message("sampling %d: mean %.4f, the same bits on 4 device sets\n", (int)modes[k],
                      mean / (double)n);
        free(base);
    }
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_device_same_image),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
