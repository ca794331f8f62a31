/* tests/scenes_mirror_test.c — rs_scene_mirror_create, the deep copy the CUDA megakernel makes of
 * a scene in device memory, checked here with host memory (the same code; only the copy
 * callbacks differ):
 *   - every array is copied (no pointer shared with the original), the byte count adds up;
 *   - the original's arrays are then scribbled over and freed, and the mirror still renders the
 *     original's image bit for bit (a shallow or missing copy changes the image, and under
 *     AddressSanitizer is a use after free);
 *   - a copy failing at any step releases every block made before it and reports the error. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "render_util.h"

typedef struct host_ops {
    int live;    /* blocks allocated and not yet released */
    int calls;   /* copy calls so far */
    int fail_at; /* the copy call that fails (1-based); 0: none */
} host_ops;

static rs_status host_copy(void *user, void **dst, const void *src, size_t bytes)
{
    host_ops *h = (host_ops *)user;
    *dst = NULL;
    if (++h->calls == h->fail_at)
        return rs_error_set(RS_ERR_NOMEM, "copy %d refused by the test", h->calls);
    *dst = malloc(bytes);
    if (!*dst)
        return rs_error_set(RS_ERR_NOMEM, "out of memory");
    memcpy(*dst, src, bytes);
    ++h->live;
    return RS_OK;
}

static void host_release(void *user, void *p)
{
    host_ops *h = (host_ops *)user;
    --h->live;
    free(p);
}

/* The materials scene (every material, checker/stripes/image textures, a sphere light, a quad
 * light) plus what it lacks: a moving sphere under an open shutter, and a triangle with UVs and
 * vertex normals under the image texture. */
static rs_scene *make_scene(void)
{
    rs_scene *s;
    rs_material m;
    uint32_t id;
    rs_vec3 v[3];
    static const float uv[6] = {0.1f, 0.2f, 0.9f, 0.1f, 0.5f, 0.95f};
    static const float nrm[9] = {0, 0.6f, 0.8f, 0.6f, 0, 0.8f, 0, 0, 1};
    uint32_t k;
    if (rs_builtin_create("materials", &s) != RS_OK)
        return NULL;
    m = rs_mat_lambertian(rs_v3(.7f, .3f, .2f));
    for (k = 0; k < s->n_textures; ++k)
        if (s->textures[k].type == RS_TEX_IMAGE)
            m.albedo_tex = k;
    assert_int_not_equal(m.albedo_tex, RS_NO_TEXTURE);
    assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
    assert_int_equal(
        rs_scene_add_moving_sphere(s, rs_v3(-1, 2.5f, 1), 0.0f, rs_v3(1, 2.5f, 1), 1.0f, 0.5f, id),
        RS_OK);
    v[0] = rs_v3(-2, 0.1f, 2);
    v[1] = rs_v3(2, 0.1f, 2);
    v[2] = rs_v3(0, 2.5f, 2.5f);
    assert_int_equal(rs_scene_add_triangle_full(s, v, uv, nrm, id), RS_OK);
    s->camera.shutter_open = 0.0f;
    s->camera.shutter_close = 1.0f;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

#define SHARED(field) (m.scene.field && m.scene.field == s->field)

static void test_mirror_renders_alone(void **state)
{
    rs_scene *s = make_scene();
    host_ops h = {0, 0, 0};
    rs_mirror_ops ops = {host_copy, host_release, &h};
    rs_scene_mirror m;
    rt_args a = rt_defaults("", 48, 4);
    float *ref, *img;
    uint64_t want;
    uint32_t i;
    (void)state;
    assert_non_null(s);
    assert_non_null(s->sphere_motion);
    assert_non_null(s->tri_uv);
    assert_non_null(s->tri_normal);
    assert_true(s->n_images > 0 && s->n_lights >= 2);
    a.threads = 2;
    ref = rt_render_scene(s, &a, NULL);
    assert_non_null(ref);

    assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_OK);
    assert_false(SHARED(spheres) || SHARED(sphere_mat) || SHARED(sphere_motion) || SHARED(quads) ||
                 SHARED(quad_mat) || SHARED(tris) || SHARED(tri_mat) || SHARED(tri_uv) ||
                 SHARED(tri_normal) || SHARED(materials) || SHARED(textures) || SHARED(images) ||
                 SHARED(lights) || SHARED(light_cdf) || SHARED(prim_light));
    want = s->n_spheres * (sizeof(rs_sphere) + sizeof(uint32_t) + sizeof(rs_vec3)) +
           s->n_quads * (sizeof(rs_quad) + sizeof(uint32_t)) +
           s->n_tris * (sizeof(rs_tri) + sizeof(uint32_t) + 15 * sizeof(float)) +
           s->n_materials * sizeof(rs_material) + s->n_textures * sizeof(rs_texture) +
           s->n_images * sizeof(rs_image) + s->n_lights * sizeof(rs_light) +
           (s->n_lights + 1) * sizeof(float) +
           (s->n_spheres + s->n_quads + s->n_tris) * sizeof(int32_t);
    for (i = 0; i < s->n_images; ++i) {
        want += 3ull * s->images[i].width * s->images[i].height * sizeof(float);
        assert_ptr_not_equal(m.scene.images[i].rgb, s->images[i].rgb);
    }
    assert_int_equal(m.bytes, want);
    assert_int_equal(h.live, (int)m.n_blocks);

    /* the original's data scribbled over, then freed: only the mirror is left */
    memset(s->spheres, 0x7f, s->n_spheres * sizeof *s->spheres);
    memset(s->materials, 0x7f, s->n_materials * sizeof *s->materials);
    memset(s->tri_uv, 0x7f, 6 * s->n_tris * sizeof(float));
    for (i = 0; i < s->n_images; ++i)
        memset(s->images[i].rgb, 0,
               3ull * s->images[i].width * s->images[i].height * sizeof(float));
    rs_scene_destroy(s);

    img = rt_render_scene(&m.scene, &a, NULL);
    assert_non_null(img);
    assert_memory_equal(img, ref, (size_t)48 * 48 * 3 * sizeof(float));
    rs_scene_mirror_release(&m, &ops);
    assert_int_equal(h.live, 0);
    free(img);
    free(ref);
}

static void test_mirror_failure_releases(void **state)
{
    rs_scene *s = make_scene();
    host_ops h = {0, 0, 0};
    rs_mirror_ops ops = {host_copy, host_release, &h};
    rs_scene_mirror m;
    int total, k;
    (void)state;
    assert_non_null(s);
    assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_OK);
    total = h.calls;
    rs_scene_mirror_release(&m, &ops);
    assert_true(total >= 16);
    for (k = 1; k <= total; ++k) {
        h.calls = h.live = 0;
        h.fail_at = k;
        assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_ERR_NOMEM);
        assert_int_equal(h.live, 0);
        assert_null(m.blocks);
        rs_error_clear();
    }
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_mirror_renders_alone),
                                       cmocka_unit_test(test_mirror_failure_releases)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
