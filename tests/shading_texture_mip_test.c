/* tests/shading_texture_mip_test.c — filtered image textures (docs/textures.md): the mip
 * pyramids rs_scene_finalize builds, the trilinear lookup and its level of detail, a
 * checkerboard ground plane toward the horizon against its analytic value, the three
 * integrators' bit-identical images with it, and glTF's KHR_texture_transform read from a
 * hand-written file (tests/data/texture_transform.gltf). */
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
#include "scenes/builtin.h"
#include "scenes/gltf.h"
#include "shading/path.h"

/* A w x h image of uniform random values in [0, 1) (a fixed LCG). */
static float *random_image(uint32_t w, uint32_t h, uint32_t seed)
{
    float *rgb = (float *)malloc(3 * (size_t)w * h * sizeof *rgb);
    size_t i;
    assert_non_null(rgb);
    for (i = 0; i < 3 * (size_t)w * h; ++i) {
        seed = seed * 1664525u + 1013904223u;
        rgb[i] = (float)(seed >> 8) * (1.0f / 16777216.0f);
    }
    return rgb;
}

static double level_mean(const rs_image *l, int c)
{
    double s = 0.0;
    size_t i, n = (size_t)l->width * l->height;
    for (i = 0; i < n; ++i)
        s += l->rgb[3 * i + c];
    return s / (double)n;
}

/* A scene holding image `img` (w x h) behind an image texture, finalized: its pyramid built. */
static rs_scene *textured_scene(uint32_t w, uint32_t h, const float *rgb, uint32_t *image)
{
    rs_scene *s = NULL;
    rs_texture t;
    rs_material m;
    uint32_t tex, mat;
    assert_int_equal(rs_scene_create("mip", &s), RS_OK);
    assert_int_equal(rs_scene_add_image(s, w, h, rgb, image), RS_OK);
    memset(&t, 0, sizeof t);
    t.type = RS_TEX_IMAGE;
    t.image = *image;
    assert_int_equal(rs_scene_add_texture(s, &t, &tex), RS_OK);
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = tex;
    assert_int_equal(rs_scene_add_material(s, &m, &mat), RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, -3), 1.0f, mat), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

/* Levels down to 1x1 of max(1, floor(w/2)) x max(1, floor(h/2)) each, one block; every level's
 * mean is level 0's (to rounding for 2:1 box reductions; within the filter's tolerance where
 * odd sides are split); an image used only as the environment map keeps one level. */
static void test_pyramid_sizes_and_means(void **state)
{
    static const uint32_t sizes[][3] = {{64, 32, 7}, {37, 20, 6}, {1, 5, 3}, {1, 1, 1}};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof sizes / sizeof *sizes; ++k) {
        uint32_t w = sizes[k][0], h = sizes[k][1], img, j, c;
        float *rgb = random_image(w, h, 7 + (uint32_t)k);
        rs_scene *s = textured_scene(w, h, rgb, &img);
        const rs_image *im = &s->images[img];
        int pot = (w & (w - 1)) == 0 && (h & (h - 1)) == 0;
        /* OpenImageIO weighs each source texel by the box at its centre: exact for 2:1, uneven
         * where an odd side is split (37x20 keeps the mean to 3%; 1x5 -> 1x2, one of five
         * texels shared, moves it by up to a fifth) */
        double tol = pot ? 1e-5 : w >= 16 && h >= 16 ? 0.03 : 0.25;
        assert_int_equal(im->levels, sizes[k][2]);
        assert_memory_equal(im->rgb, rgb, 3 * (size_t)w * h * sizeof *rgb); /* level 0 kept */
        for (j = 0; j < im->levels; ++j) {
            rs_image l = rs_image_level(im, j);
            assert_int_equal(l.width, w);
            assert_int_equal(l.height, h);
            for (c = 0; c < 3; ++c) {
                double m0 = level_mean(im, c), mj = level_mean(&l, c);
                assert_true(fabs(mj - m0) <= tol * (m0 > 0.1 ? m0 : 0.1));
            }
            w = w > 1 ? w / 2 : 1;
            h = h > 1 ? h / 2 : 1;
        }
        assert_int_equal(w, 1);
        assert_int_equal(h, 1);
        rs_scene_destroy(s);
        free(rgb);
    }
    {
        /* an image used only as the environment map keeps one level */
        rs_scene *s = NULL;
        float *rgb = random_image(16, 8, 3);
        uint32_t img;
        rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
        uint32_t mat;
        assert_int_equal(rs_scene_create("env", &s), RS_OK);
        assert_int_equal(rs_scene_add_image(s, 16, 8, rgb, &img), RS_OK);
        assert_int_equal(rs_scene_set_environment(s, img, rs_v3_splat(1.0f), NULL), RS_OK);
        assert_int_equal(rs_scene_add_material(s, &m, &mat), RS_OK);
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, -3), 1.0f, mat), RS_OK);
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        assert_true(s->images[img].levels <= 1);
        rs_scene_destroy(s);
        free(rgb);
    }
}

/* At a whole level of detail the trilinear lookup is the bilinear one on that level, bit for
 * bit; between two it is their linear mix; lod 0 and a zero footprint are today's lookup. */
static void test_trilinear_whole_levels(void **state)
{
    uint32_t img, k, i;
    float *rgb = random_image(32, 16, 11);
    rs_scene *s = textured_scene(32, 16, rgb, &img);
    const rs_image *im = &s->images[img];
    const rs_texture *t = &s->textures[0];
    (void)state;
    for (i = 0; i < 200; ++i) {
        float u = -1.5f + 0.0371f * (float)i, v = 2.25f - 0.0213f * (float)i;
        rs_vec3 a, b, c;
        rs_image l;
        for (k = 0; k < im->levels; ++k) {
            l = rs_image_level(im, k);
            a = rs_image_trilinear(im, u, v, (float)k);
            b = rs_image_bilinear(&l, u, v);
            assert_memory_equal(&a, &b, sizeof a);
        }
        l = rs_image_level(im, 1);
        a = rs_image_bilinear(&l, u, v);
        l = rs_image_level(im, 2);
        b = rs_image_bilinear(&l, u, v);
        c = rs_image_trilinear(im, u, v, 1.25f);
        assert_true(fabsf(c.x - (0.75f * a.x + 0.25f * b.x)) < 1e-6f);
        a = rs_texture_eval_lod(t, s->images, u, v, rs_v3(0, 0, 0), 0.0f);
        b = rs_image_bilinear(im, u, v);
        assert_memory_equal(&a, &b, sizeof a);
        a = rs_texture_eval(t, s->images, u, v, rs_v3(0, 0, 0));
        assert_memory_equal(&a, &b, sizeof a);
        /* past the last level: the 1x1 level, the mean */
        a = rs_texture_eval_lod(t, s->images, u, v, rs_v3(0, 0, 0), 1e6f);
        l = rs_image_level(im, im->levels - 1);
        assert_true(fabsf(a.y - l.rgb[1]) < 1e-6f);
    }
    /* the level of detail: log2 of the footprint in texels, held to [0, levels - 1] */
    assert_true(rs_image_lod(im, 0.0f) == 0.0f);
    assert_true(rs_image_lod(im, NAN) == 0.0f);
    assert_true(rs_image_lod(im, INFINITY) == (float)(im->levels - 1));
    /* a footprint of 4 texels of this 32x16 image (sqrt(512) texels per UV unit): lod 2 */
    assert_true(fabsf(rs_image_lod(im, 4.0f / sqrtf(512.0f)) - 2.0f) < 0.02f);
    for (i = 1; i < 4000; ++i) {
        float x = 1.0f + 0.013f * (float)i * (float)i,
              y = 1.0f + 0.013f * (float)(i + 1) * (float)(i + 1);
        assert_true(fabsf(rs_log2_approx(x) - log2f(x)) < 0.01f);
        assert_true(rs_log2_approx(y) >= rs_log2_approx(x));
    }
    rs_scene_destroy(s);
    free(rgb);
}

/* The checkerboard ground: a plane 2L wide at y = 0 whose UVs repeat once per world unit, an
 * image of 8x8 black and white checks of 8x8 texels each (mean 0.5), a white Lambertian under a
 * uniform white sky; the camera 1 above it looking at the horizon. */
#define GROUND_L 500.0f
#define GROUND_W 96u
#define GROUND_H 64u

static rs_scene *ground_scene(void)
{
    rs_scene *s = NULL;
    float rgb[64 * 64 * 3], uv[6];
    rs_texture t;
    rs_material m;
    rs_vec3 a = rs_v3(-GROUND_L, 0, -GROUND_L), b = rs_v3(GROUND_L, 0, -GROUND_L),
            c = rs_v3(GROUND_L, 0, GROUND_L), d = rs_v3(-GROUND_L, 0, GROUND_L);
    uint32_t img, tex, mat, x, y;
    for (y = 0; y < 64; ++y)
        for (x = 0; x < 64; ++x) {
            float g = ((x / 8 + y / 8) & 1) ? 1.0f : 0.0f;
            rgb[3 * (y * 64 + x)] = rgb[3 * (y * 64 + x) + 1] = rgb[3 * (y * 64 + x) + 2] = g;
        }
    assert_int_equal(rs_scene_create("mip-ground", &s), RS_OK);
    assert_int_equal(rs_scene_add_image(s, 64, 64, rgb, &img), RS_OK);
    memset(&t, 0, sizeof t);
    t.type = RS_TEX_IMAGE;
    t.image = img;
    assert_int_equal(rs_scene_add_texture(s, &t, &tex), RS_OK);
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = tex;
    assert_int_equal(rs_scene_add_material(s, &m, &mat), RS_OK);
    /* UVs = world x, z shifted to start at 0 */
    uv[0] = 0, uv[1] = 0, uv[2] = 2 * GROUND_L, uv[3] = 0, uv[4] = 2 * GROUND_L,
    uv[5] = 2 * GROUND_L;
    assert_int_equal(rs_scene_add_triangle_uv(s, a, b, c, uv, mat), RS_OK);
    uv[2] = 2 * GROUND_L, uv[3] = 2 * GROUND_L, uv[4] = 0, uv[5] = 2 * GROUND_L;
    assert_int_equal(rs_scene_add_triangle_uv(s, a, c, d, uv, mat), RS_OK);
    s->background = rs_v3_splat(1.0f);
    s->background_sky = 0;
    s->camera.from = rs_v3(0, 1, 0);
    s->camera.at = rs_v3(0, 1, -1);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 30.0f;
    s->width = GROUND_W;
    s->height = GROUND_H;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

/* The ground rendered: 0 stream engine, 1 CPU megakernel, 2 the GPU fallback's megakernel.
 * Paths of two segments sampled by the BSDF alone: every bounce ray reaches the sky, so a
 * sample's radiance is exactly the albedo its lookup gives. */
static float *render_ground(const rs_scene *s, uint32_t spp, uint32_t filter, int mode)
{
    rs_geom g = rs_scene_geom(s);
    rs_bvh *bvh = NULL;
    rs_device *dev = NULL;
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    float *rgb = (float *)malloc((size_t)GROUND_W * GROUND_H * 3 * sizeof *rgb);
    assert_non_null(rgb);
    assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
    assert_int_equal(mode == 2 ? rs_gpu_fallback_create(1, 0, NULL, &dev)
                               : rs_cpu_device_create(1, "cpu", &dev),
                     RS_OK);
    assert_int_equal(rs_device_upload(dev, &g, bvh), RS_OK);
    assert_int_equal(rs_film_create(GROUND_W, GROUND_H, &film), RS_OK);
    memset(&st, 0, sizeof st);
    st.width = GROUND_W;
    st.height = GROUND_H;
    st.spp = spp;
    st.max_depth = 2;
    st.seed = 5;
    st.sampling = RS_SAMPLING_BSDF;
    st.sampler = RS_SAMPLER_SOBOL;
    st.threads = 1;
    st.texture_filter = filter;
    if (mode == 0) {
        assert_int_equal(rs_sched_create(&dev, 1, NULL, &sched), RS_OK);
        assert_int_equal(rs_render(s, sched, &st, NULL, film, &stats), RS_OK);
    } else {
        assert_int_equal(rs_render_passes(s, dev, &st, NULL, film, &stats), RS_OK);
    }
    rs_film_resolve(film, rgb);
    rs_sched_destroy(sched);
    rs_device_destroy(dev);
    rs_film_destroy(film);
    rs_bvh_destroy(bvh);
    return rgb;
}

/* Mean |pixel - 0.5| over the far region: the rows 1 to 8 below the horizon (hits 14 to 120
 * units away, each pixel covering from about 1.7 to 15 checks along the view), every column. */
static double far_error(const float *rgb)
{
    double e = 0.0;
    uint32_t x, y, n = 0;
    for (y = GROUND_H / 2 + 1; y <= GROUND_H / 2 + 8; ++y)
        for (x = 0; x < GROUND_W; ++x, ++n)
            e += fabs(rgb[3 * (y * GROUND_W + x) + 1] - 0.5);
    return e / n;
}

/* The analytic test: far from the camera the checkerboard's pixels converge to its mean, 0.5
 * (albedo times the sky's 1).  At 4 spp the bilinear lookups still alias (each sample sees a
 * black or a white check); trilinear's are within a small fraction of that.  The stream engine,
 * the CPU megakernel and the fallback give the same image, bit for bit. */
static void test_ground_plane_converges(void **state)
{
    rs_scene *s = ground_scene();
    float *bi4 = render_ground(s, 4, RS_TEXTURE_BILINEAR, 1);
    float *tri4 = render_ground(s, 4, RS_TEXTURE_TRILINEAR, 1);
    float *bi64 = render_ground(s, 64, RS_TEXTURE_BILINEAR, 1);
    float *tri64 = render_ground(s, 64, RS_TEXTURE_TRILINEAR, 1);
    float *stream = render_ground(s, 4, RS_TEXTURE_TRILINEAR, 0);
    float *fallback = render_ground(s, 4, RS_TEXTURE_TRILINEAR, 2);
    double eb4 = far_error(bi4), et4 = far_error(tri4), eb64 = far_error(bi64),
           et64 = far_error(tri64);
    size_t bytes = (size_t)GROUND_W * GROUND_H * 3 * sizeof(float);
    (void)state;
    printf("far-region mean |pixel - 0.5|: bilinear 4 spp %.4f, 64 spp %.4f; trilinear 4 spp "
           "%.4f, 64 spp %.4f\n",
           eb4, eb64, et4, et64);
    assert_true(eb4 > 0.05);      /* the aliasing is there to remove */
    assert_true(et4 < eb4 / 3.0); /* the bar */
    assert_true(et4 < eb64);      /* 4 filtered samples beat 64 unfiltered */
    assert_memory_equal(stream, tri4, bytes);
    assert_memory_equal(fallback, tri4, bytes);
    {
        /* filtering moves no energy: over the bottom rows, where the checks are a pixel or
         * more, the two images' means agree */
        double d = 0.0;
        uint32_t x, y, n = 0;
        for (y = GROUND_H - 8; y < GROUND_H; ++y)
            for (x = 0; x < GROUND_W; ++x, ++n)
                d += tri64[3 * (y * GROUND_W + x)] - bi64[3 * (y * GROUND_W + x)];
        assert_true(fabs(d / n) < 0.02);
    }
    free(bi4);
    free(tri4);
    free(bi64);
    free(tri64);
    free(stream);
    free(fallback);
    rs_scene_destroy(s);
}

/* The level of detail grows with the distance along the ground, and is 0 with bilinear
 * filtering (tex_spread 0). */
static void test_lod_monotone_in_distance(void **state)
{
    rs_scene *s = ground_scene();
    rs_render_settings st;
    rs_render_consts it;
    const rs_material *m = &s->materials[0];
    const rs_image *im = &s->images[s->textures[0].image];
    float last = -1.0f, z;
    uint32_t prim = s->n_spheres + s->n_quads; /* the first triangle (z < 0 side is either) */
    (void)state;
    memset(&st, 0, sizeof st);
    st.width = GROUND_W;
    st.height = GROUND_H;
    st.spp = 1;
    st.max_depth = 2;
    assert_int_equal(rs_render_constants(s, &st, &it), RS_OK);
    assert_true(it.tex_spread > 0.0f);
    for (z = -0.5f; z > -400.0f; z *= 1.1f) {
        rs_vec3 x = rs_v3(0.1f, 0.0f, z), ng = rs_v3(0, 1, 0);
        float fw = rs_texture_footprint(&it, m, x, ng);
        float lod = rs_image_lod(im, rs_surface_uv_footprint(s, prim, ng, fw));
        assert_true(lod >= last);
        last = lod;
    }
    assert_true(last == (float)(im->levels - 1));
    st.texture_filter = RS_TEXTURE_BILINEAR;
    assert_int_equal(rs_render_constants(s, &st, &it), RS_OK);
    assert_true(it.tex_spread == 0.0f);
    assert_true(rs_texture_footprint(&it, m, rs_v3(0, 0, -50), rs_v3(0, 1, 0)) == 0.0f);
    rs_scene_destroy(s);
}

/* The material of glTF texture_transform.gltf named `name`: its base colour texture. */
static const rs_texture *gltf_texture(const rs_scene *s, uint32_t k)
{
    uint32_t i, seen = 0;
    for (i = 0; i < s->n_materials; ++i)
        if (s->materials[i].albedo_tex != RS_NO_TEXTURE && seen++ == k)
            return &s->textures[s->materials[i].albedo_tex];
    fail_msg("material %u with a texture not found", k);
    return NULL;
}

/* The file's four quads (2 x 2, side by side at x = -3.3, -1.1, 1.1, 3.3 in the plane z = 0,
 * glTF UVs (0, 1) at the lower-left corner: the renderer's (0, 0)) rendered head-on as white
 * Lambertians carrying each material's texture, under a white sky with BSDF sampling: each pixel
 * is the texture's colour at its UVs, averaged over the pixel. */
#define TT_W 200u
#define TT_H 50u

static float *render_quads(rs_scene *s, float *corner_x, float *corner_y, float *du, float *dv)
{
    rs_render_settings st;
    rs_render_consts it;
    uint32_t i;
    for (i = 0; i < s->n_materials; ++i) {
        uint32_t tex = s->materials[i].albedo_tex;
        s->materials[i] = rs_mat_lambertian(rs_v3_splat(1.0f));
        s->materials[i].albedo_tex = tex;
    }
    s->background = rs_v3_splat(1.0f);
    s->background_sky = 0;
    s->camera.from = rs_v3(0, 0, 6);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 60.0f;
    s->camera.aperture = 0.0f;
    s->camera.focus_dist = 0.0f;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    /* the focus plane is z = 0: pixel (a, b) (continuous) looks at corner + a du + b dv */
    memset(&st, 0, sizeof st);
    st.width = TT_W;
    st.height = TT_H;
    st.spp = 1;
    st.max_depth = 2;
    assert_int_equal(rs_render_constants(s, &st, &it), RS_OK);
    *corner_x = it.camera.origin.x + it.camera.corner.x;
    *corner_y = it.camera.origin.y + it.camera.corner.y;
    *du = it.camera.du.x;
    *dv = it.camera.dv.y;
    {
        rs_geom g = rs_scene_geom(s);
        rs_bvh *bvh = NULL;
        rs_device *dev = NULL;
        rs_film *film = NULL;
        rs_render_stats stats;
        float *rgb = (float *)malloc((size_t)TT_W * TT_H * 3 * sizeof *rgb);
        assert_non_null(rgb);
        assert_int_equal(rs_bvh_build(&g, NULL, &bvh), RS_OK);
        assert_int_equal(rs_cpu_device_create(1, "cpu", &dev), RS_OK);
        assert_int_equal(rs_device_upload(dev, &g, bvh), RS_OK);
        assert_int_equal(rs_film_create(TT_W, TT_H, &film), RS_OK);
        st.spp = 16;
        st.seed = 9;
        st.sampling = RS_SAMPLING_BSDF;
        st.sampler = RS_SAMPLER_SOBOL;
        st.threads = 1;
        assert_int_equal(rs_render_passes(s, dev, &st, NULL, film, &stats), RS_OK);
        rs_film_resolve(film, rgb);
        rs_device_destroy(dev);
        rs_film_destroy(film);
        rs_bvh_destroy(bvh);
        return rgb;
    }
}

/* The rendered pixel over point (x, y) of the plane z = 0. */
static rs_vec3 pixel_at(const float *rgb, float cx, float cy, float du, float dv, float x, float y)
{
    uint32_t i = (uint32_t)((x - cx) / du), j = (uint32_t)((y - cy) / dv);
    const float *p = &rgb[3 * ((size_t)j * TT_W + i)];
    assert_true(i < TT_W && j < TT_H);
    return rs_v3(p[0], p[1], p[2]);
}

static int is_red(rs_vec3 c) { return c.x > 0.99f && c.z < 0.01f; }
static int is_blue(rs_vec3 c) { return c.z > 0.99f && c.x < 0.01f; }

/* KHR_texture_transform as the spec defines it (offset, rotation, scale: T R S on glTF's UVs,
 * v down), through Assimp 5.2: the file's four materials on a 2x1 red|blue texture. */
static void test_khr_texture_transform(void **state)
{
    char path[4096];
    const char *src = __FILE__, *slash = strrchr(src, '/');
    rs_scene *s = NULL;
    const rs_texture *t;
    rs_vec3 p = rs_v3(0, 0, 0);
    (void)state;
    snprintf(path, sizeof path, "%.*s/data/texture_transform.gltf", slash ? (int)(slash - src) : 1,
             slash ? src : ".");
    assert_int_equal(rs_scene_load_gltf(path, NULL, &s), RS_OK);
    /* 0: none: the UVs as they are (u < 1/2 red, u > 1/2 blue at texel centres) */
    t = gltf_texture(s, 0);
    assert_int_equal(t->uv_xform, 0);
    assert_true(is_red(rs_texture_eval(t, s->images, 0.25f, 0.5f, p)));
    assert_true(is_blue(rs_texture_eval(t, s->images, 0.75f, 0.5f, p)));
    /* 1: offset [0.5, 0]: the colours trade places */
    t = gltf_texture(s, 1);
    assert_int_equal(t->uv_xform, 1);
    assert_true(is_blue(rs_texture_eval(t, s->images, 0.25f, 0.5f, p)));
    assert_true(is_red(rs_texture_eval(t, s->images, 0.75f, 0.5f, p)));
    {
        /* 2: offset [0.5, 0.25], rotation 0.3, scale [2, 3], against the spec's matrix applied
         * to glTF's UVs (v_gltf = 1 - v) */
        double c = cos(0.3), sn = sin(0.3), sx = 2, sy = 3, ox = 0.5, oy = 0.25;
        int i;
        t = gltf_texture(s, 2);
        assert_int_equal(t->uv_xform, 1);
        for (i = 0; i < 9; ++i) {
            double u = 0.1 * i, v = 1.0 - 0.07 * i, vg = 1.0 - v;
            double ug2 = c * sx * u + sn * sy * vg + ox, vg2 = -sn * sx * u + c * sy * vg + oy;
            double u2 = t->uv_m[0] * u + t->uv_m[1] * v + t->uv_m[2];
            double v2 = t->uv_m[3] * u + t->uv_m[4] * v + t->uv_m[5];
            assert_true(fabs(u2 - ug2) < 1e-5);
            assert_true(fabs(v2 - (1.0 - vg2)) < 1e-5);
        }
    }
    {
        /* 3: the spec's example (offset [0, 1], rotation pi/2, scale 0.5): the lower-left
         * quadrant of the image, turned: every UV of [0, 1]^2 lands in [0, 1/2]^2 (v up) */
        int i, j;
        t = gltf_texture(s, 3);
        for (i = 0; i <= 4; ++i)
            for (j = 0; j <= 4; ++j) {
                float u = 0.25f * i, v = 0.25f * j;
                float u2 = t->uv_m[0] * u + t->uv_m[1] * v + t->uv_m[2];
                float v2 = t->uv_m[3] * u + t->uv_m[4] * v + t->uv_m[5];
                assert_true(u2 > -1e-5f && u2 < 0.5f + 1e-5f);
                assert_true(v2 > -1e-5f && v2 < 0.5f + 1e-5f);
            }
        /* v = 1/2 maps to u' = 1/4, the red texel's centre; v = 0 to u' = 1/2, the seam */
        assert_true(is_red(rs_texture_eval(t, s->images, 0.5f, 0.5f, p)));
    }
    {
        /* rendered: the plain quad is red on its left half's centre and blue on its right's,
         * the half-offset one the other way round; and every pixel well inside a quad is its
         * texture at the pixel's centre (the transform applied by the renderer's lookups) */
        static const float qx[4] = {-3.3f, -1.1f, 1.1f, 3.3f};
        float cx, cy, du, dv, *rgb = render_quads(s, &cx, &cy, &du, &dv);
        uint32_t k, i, j, checked = 0;
        rs_vec3 c;
        c = pixel_at(rgb, cx, cy, du, dv, qx[0] - 0.5f, 0.0f);
        assert_true(c.x > 0.9f && c.z < 0.1f);
        c = pixel_at(rgb, cx, cy, du, dv, qx[0] + 0.5f, 0.0f);
        assert_true(c.z > 0.9f && c.x < 0.1f);
        c = pixel_at(rgb, cx, cy, du, dv, qx[1] - 0.5f, 0.0f);
        assert_true(c.z > 0.9f && c.x < 0.1f);
        c = pixel_at(rgb, cx, cy, du, dv, qx[1] + 0.5f, 0.0f);
        assert_true(c.x > 0.9f && c.z < 0.1f);
        for (j = 0; j < TT_H; ++j)
            for (i = 0; i < TT_W; ++i) {
                float x = cx + (i + 0.5f) * du, y = cy + (j + 0.5f) * dv;
                for (k = 0; k < 4; ++k) {
                    float lx = x - qx[k], ly = y;
                    rs_vec3 want;
                    const float *px = &rgb[3 * ((size_t)j * TT_W + i)];
                    if (!(fabsf(lx) < 0.9f && fabsf(ly) < 0.9f))
                        continue;
                    want = rs_texture_eval(gltf_texture(s, k), s->images, 0.5f * (lx + 1.0f),
                                           0.5f * (ly + 1.0f), p);
                    /* a pixel spans 1/20 of a quad: a ramp's value at its centre is its mean,
                     * to the kinks of the wrap */
                    assert_true(fabsf(px[0] - want.x) < 0.08f && fabsf(px[2] - want.z) < 0.08f);
                    ++checked;
                }
            }
        printf("%u pixels inside the quads as the transforms say\n", checked);
        assert_true(checked > 400);
        free(rgb);
    }
    rs_scene_destroy(s);
}

/* rs_scene_set_extras: without pyramids (the CLI under --texture-filter bilinear) a texture's
 * image keeps its one level, with them (the default) it has its pyramid; without the light BVH
 * (--light-sampler power) none is built, and a render asking for it is refused (issue 39: both
 * were built for every render, gigabytes for a large texture or 10^7 emitters). */
static void test_extras_only_where_read(void **state)
{
    char path[4096];
    const char *src = __FILE__, *slash = strrchr(src, '/');
    rs_scene *s = NULL, *lit = NULL;
    rs_render_settings st;
    rs_render_consts it;
    (void)state;
    snprintf(path, sizeof path, "%.*s/data/texture_transform.gltf", slash ? (int)(slash - src) : 1,
             slash ? src : ".");
    rs_scene_set_extras(0, 0);
    assert_int_equal(rs_scene_load_gltf(path, NULL, &s), RS_OK);
    assert_int_equal(rs_builtin_create("many-lights", &lit), RS_OK);
    rs_scene_set_extras(1, 1);
    assert_true(s->images[gltf_texture(s, 0)->image].levels == 1);
    assert_true(lit->n_lights > 100 && !lit->light_bvh_built && lit->light_nodes == NULL);
    memset(&st, 0, sizeof st);
    st.width = st.height = 8;
    st.spp = 1;
    st.max_depth = 4;
    st.light_sampler = RS_LIGHT_SAMPLER_BVH;
    rs_error_clear();
    assert_int_not_equal(rs_render_constants(lit, &st, &it), RS_OK);
    assert_non_null(strstr(rs_error_message(), "without its light BVH"));
    rs_error_clear();
    st.light_sampler = RS_LIGHT_SAMPLER_POWER;
    assert_int_equal(rs_render_constants(lit, &st, &it), RS_OK);
    rs_scene_destroy(s);
    rs_scene_destroy(lit);
    /* the defaults: both */
    assert_int_equal(rs_scene_load_gltf(path, NULL, &s), RS_OK);
    assert_int_equal(rs_builtin_create("many-lights", &lit), RS_OK);
    assert_true(s->images[gltf_texture(s, 0)->image].levels > 1);
    assert_true(lit->light_bvh_built && lit->light_nodes != NULL);
    rs_scene_destroy(s);
    rs_scene_destroy(lit);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pyramid_sizes_and_means),
        cmocka_unit_test(test_trilinear_whole_levels),
        cmocka_unit_test(test_lod_monotone_in_distance),
        cmocka_unit_test(test_ground_plane_converges),
        cmocka_unit_test(test_khr_texture_transform),
        cmocka_unit_test(test_extras_only_where_read),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
