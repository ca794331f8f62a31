/* tests/scenes_gltf_test.c — glTF 2.0 files as scenes (scenes/gltf.h), on files this test
 * writes itself (no third-party assets):
 *   - the node hierarchy: a mesh placed by two nodes under a parent, each vertex where the
 *     composed translation / rotation / scale puts it;
 *   - the camera on a nested node (position, direction, yfov, aspect ratio -> image size), another
 *     picked by name, an error naming the file's cameras for a name it lacks, and a framing
 *     camera for a file without one;
 *   - KHR_lights_punctual: a point, a spot and a directional light on nested nodes (position,
 *     direction, colour times intensity, cone angles);
 *   - every texture slot: base colour (sRGB-decoded, times the factor), metallic-roughness and
 *     normal (data, as stored), emissive; the normal map's scale; a binary .glb with its texture
 *     embedded;
 *   - an emissive texture shows in the image (half of a quad red, half black: the bug that made a
 *     textured model glow uniformly white);
 *   - alpha cut-outs (MASK by the texture's alpha times the factor's, OPAQUE ignoring it) let
 *     an emitter behind show through, the same on every traversal;
 *   - the material extensions read from the JSON (emissive strength, ior, specular, unlit,
 *     volume), the census of used and unread extensions, bad values named; a slab of absorbing
 *     glass in the image (Beer-Lambert, exactly);
 *   - bad files: a missing texture, a missing buffer, cut JSON: one line naming the file, no
 *     scene. */
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

#include "accel/bvh8.h"
#include "core/image_io.h"
#include "core/srgb.h"
#include "render_util.h"
#include "scenes/gltf.h"
#include "scenes/gltf_check.h"

static char g_dir[64];

static void path_of(char *out, size_t n, const char *name)
{
    snprintf(out, n, "%s/%s", g_dir, name);
}

static void write_bytes(const char *name, const void *data, size_t n)
{
    char p[256];
    FILE *f;
    path_of(p, sizeof p, name);
    f = fopen(p, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(data, 1, n, f), n);
    fclose(f);
}

static void write_text(const char *name, const char *text) { write_bytes(name, text, strlen(text)); }

/* A w x h PNG of linear texels rgb (written sRGB-encoded, 8 bits). */
static void write_png(const char *name, uint32_t w, uint32_t h, const float *rgb)
{
    char p[256];
    path_of(p, sizeof p, name);
    assert_int_equal(rs_image_write(p, w, h, rgb), RS_OK);
}

/* The 8-bit code values / 255 of a PNG this test wrote (what a data texture holds). */
static float *read_raw(const char *name, uint32_t *w, uint32_t *h)
{
    char p[256];
    float *rgb;
    path_of(p, sizeof p, name);
    assert_int_equal(rs_image_read(p, w, h, &rgb), RS_OK);
    return rgb;
}

/* The quad's buffer: 4 positions, 4 normals, 4 UVs, 6 indices (16-bit): 140 bytes. */
#define QUAD_BYTES 140
static void quad_buffer(unsigned char *b)
{
    static const float pos[12] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0};
    static const float nrm[12] = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
    static const float uv[8] = {0, 1, 1, 1, 1, 0, 0, 0};
    static const uint16_t idx[6] = {0, 1, 2, 0, 2, 3};
    memcpy(b, pos, 48);
    memcpy(b + 48, nrm, 48);
    memcpy(b + 96, uv, 32);
    memcpy(b + 128, idx, 12);
}

#define VIEWS                                                                                      \
  "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":48},"                            \
  "{\"buffer\":0,\"byteOffset\":48,\"byteLength\":48},"                                            \
  "{\"buffer\":0,\"byteOffset\":96,\"byteLength\":32},"                                            \
  "{\"buffer\":0,\"byteOffset\":128,\"byteLength\":12}%s],"                                        \
  "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\","         \
  "\"min\":[-1,-1,0],\"max\":[1,1,0]},"                                                            \
  "{\"bufferView\":1,\"componentType\":5126,\"count\":4,\"type\":\"VEC3\"},"                       \
  "{\"bufferView\":2,\"componentType\":5126,\"count\":4,\"type\":\"VEC2\"},"                       \
  "{\"bufferView\":3,\"componentType\":5123,\"count\":6,\"type\":\"SCALAR\"}],"                    \
  "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},"  \
  "\"indices\":3,\"material\":0}]}]"

/* The full scene: root (translated) -> quadA (translated), quadB (rotated 90 degrees about z,
 * scaled by 2, translated), a camera node under root, three light nodes; one material with every
 * texture. */
static const char *k_full =
    "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
    "\"extensionsUsed\":[\"KHR_lights_punctual\"],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"lights\":["
    "{\"type\":\"point\",\"color\":[1,0.5,0.25],\"intensity\":20},"
    "{\"type\":\"spot\",\"color\":[1,1,1],\"intensity\":30,"
    "\"spot\":{\"innerConeAngle\":0.2,\"outerConeAngle\":0.6}},"
    "{\"type\":\"directional\",\"color\":[0.5,1,1],\"intensity\":2}]}},"
    "\"nodes\":[{\"name\":\"root\",\"translation\":[0,1,0],\"children\":[1,2,3,4,5,6,7]},"
    "{\"name\":\"quadA\",\"mesh\":0,\"translation\":[-2,0,0]},"
    "{\"name\":\"quadB\",\"mesh\":0,\"translation\":[2,0,0],"
    "\"rotation\":[0,0,0.70710678,0.70710678],\"scale\":[2,2,2]},"
    "{\"name\":\"cam\",\"camera\":0,\"translation\":[0,0,8]},"
    "{\"name\":\"side\",\"camera\":1,\"translation\":[8,0,0],"
    "\"rotation\":[0,0.70710678,0,0.70710678]},"
    "{\"name\":\"lp\",\"translation\":[0,2,3],\"extensions\":{\"KHR_lights_punctual\":{\"light\":0}}},"
    "{\"name\":\"ls\",\"translation\":[0,0,4],\"extensions\":{\"KHR_lights_punctual\":{\"light\":1}}},"
    "{\"name\":\"ld\",\"rotation\":[-0.70710678,0,0,0.70710678],"
    "\"extensions\":{\"KHR_lights_punctual\":{\"light\":2}}}],"
    "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.6,\"aspectRatio\":2.0,"
    "\"znear\":0.1}},{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.1}}],"
    "\"materials\":[{\"name\":\"all\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.5,1,1,1],"
    "\"baseColorTexture\":{\"index\":0},\"metallicFactor\":0.8,\"roughnessFactor\":0.6,"
    "\"metallicRoughnessTexture\":{\"index\":1}},\"normalTexture\":{\"index\":2,\"scale\":0.5},"
    "\"emissiveFactor\":[1,1,1],\"emissiveTexture\":{\"index\":3}}],"
    "\"textures\":[{\"source\":0},{\"source\":1},{\"source\":2},{\"source\":3}],"
    "\"images\":[{\"uri\":\"base.png\"},{\"uri\":\"mr.png\"},{\"uri\":\"normal.png\"},"
    "{\"uri\":\"emis.png\"}],"
    "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";

static void write_full_files(void)
{
    unsigned char b[QUAD_BYTES];
    static const float base[12] = {0.2f, 0.4f, 0.6f, 0.8f, 0.1f, 0.3f,
                                   0.5f, 0.7f, 0.9f, 0.25f, 0.5f, 0.75f};
    static const float mr[12] = {0, 0.5f, 1.0f, 0, 0.25f, 0.5f, 0, 1.0f, 0.0f, 0, 0.75f, 0.25f};
    static const float nm[12] = {0.5f, 0.5f, 1, 0.6f, 0.5f, 0.9f, 0.5f, 0.4f, 0.9f, 0.5f, 0.5f, 1};
    static const float emis[24] = {1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0,
                                   1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0};
    char buf[8192];
    quad_buffer(b);
    write_bytes("quad.bin", b, sizeof b);
    write_png("base.png", 2, 2, base);
    write_png("mr.png", 2, 2, mr);
    write_png("normal.png", 2, 2, nm);
    write_png("emis.png", 4, 2, emis);
    snprintf(buf, sizeof buf, k_full, "");
    write_text("full.gltf", buf);
}

static rs_scene *load(const char *name, const char *camera)
{
    char p[256];
    rs_gltf_opts o;
    rs_scene *s = NULL;
    path_of(p, sizeof p, name);
    memset(&o, 0, sizeof o);
    o.camera = camera;
    o.log = NULL;
    if (rs_scene_load_gltf(p, &o, &s) != RS_OK)
        fail_msg("%s: %s", p, rs_error_message());
    return s;
}

static void expect_v3(rs_vec3 a, float x, float y, float z, float tol)
{
    if (fabsf(a.x - x) > tol || fabsf(a.y - y) > tol || fabsf(a.z - z) > tol)
        fail_msg("(%g, %g, %g) != (%g, %g, %g)", a.x, a.y, a.z, x, y, z);
}

/* Whether the scene has a triangle vertex at p. */
static int has_vertex(const rs_scene *s, rs_vec3 p)
{
    uint32_t i;
    for (i = 0; i < s->n_tris; ++i) {
        const rs_vec3 *v = &s->tris[i].v0;
        int k;
        for (k = 0; k < 3; ++k)
            if (rs_v3_length(rs_v3_sub(v[k], p)) < 1e-5f)
                return 1;
    }
    return 0;
}

static void test_hierarchy_camera_lights(void **state)
{
    rs_scene *s;
    const rs_punctual *p;
    (void)state;
    write_full_files();
    s = load("full.gltf", NULL);
    /* two nodes place the quad: 2 x 2 triangles */
    assert_int_equal(s->n_tris, 4u);
    /* quadA: translated by root (0,1,0) and (-2,0,0): its corner (-1,-1,0) at (-3, 0, 0) */
    assert_true(has_vertex(s, rs_v3(-3, 0, 0)));
    assert_true(has_vertex(s, rs_v3(-1, 2, 0)));
    /* quadB: scale 2, 90 degrees about z, then (2,0,0), then root: (1,-1,0) -> (2,-2,0) ->
     * (2,2,0) -> (4,2,0) -> (4,3,0) */
    assert_true(has_vertex(s, rs_v3(4, 3, 0)));
    assert_true(has_vertex(s, rs_v3(0, -1, 0)));
    /* the first camera: at root + (0,0,8), looking down -z; yfov 0.6 rad; aspect 2 */
    expect_v3(s->camera.from, 0, 1, 8, 1e-5f);
    expect_v3(rs_v3_normalize(rs_v3_sub(s->camera.at, s->camera.from)), 0, 0, -1, 1e-5f);
    assert_true(fabsf(s->camera.vfov_deg - 0.6f * 57.29578f) < 1e-3f);
    assert_int_equal(s->width, 1024u);
    assert_int_equal(s->height, 512u);
    /* the three lights on their nodes */
    assert_int_equal(s->n_punctuals, 3u);
    p = &s->punctuals[0];
    assert_int_equal(p->type, RS_PUNCTUAL_POINT);
    expect_v3(p->pos, 0, 3, 3, 1e-5f);
    expect_v3(p->intensity, 20, 10, 5, 1e-4f);
    p = &s->punctuals[1];
    assert_int_equal(p->type, RS_PUNCTUAL_SPOT);
    expect_v3(p->pos, 0, 1, 4, 1e-5f);
    expect_v3(p->dir, 0, 0, -1, 1e-5f);
    assert_true(fabsf(p->cos_inner - cosf(0.2f)) < 1e-5f && fabsf(p->cos_outer - cosf(0.6f)) < 1e-5f);
    p = &s->punctuals[2];
    assert_int_equal(p->type, RS_PUNCTUAL_DIRECTIONAL);
    /* -90 degrees about x takes -z to -y: light straight down */
    expect_v3(p->dir, 0, -1, 0, 1e-5f);
    expect_v3(p->intensity, 1, 2, 2, 1e-5f);
    assert_true(s->n_lights == 3u && s->n_area_lights == 0u);
    rs_scene_destroy(s);

    /* the second camera by name: at (8,1,0), turned 90 degrees about y: looking down -x */
    s = load("full.gltf", "side");
    expect_v3(s->camera.from, 8, 1, 0, 1e-5f);
    expect_v3(rs_v3_normalize(rs_v3_sub(s->camera.at, s->camera.from)), -1, 0, 0, 1e-5f);
    assert_true(fabsf(s->camera.vfov_deg - 0.9f * 57.29578f) < 1e-3f);
    rs_scene_destroy(s);

    {
        /* a name the file lacks: the cameras it has */
        char p2[256];
        rs_gltf_opts o = {"front", NULL, NULL, 0};
        rs_scene *t = (rs_scene *)0x1;
        path_of(p2, sizeof p2, "full.gltf");
        rs_error_clear();
        assert_int_equal(rs_scene_load_gltf(p2, &o, &t), RS_ERR_ARG);
        assert_null(t);
        print_message("%s\n", rs_error_message());
        assert_non_null(strstr(rs_error_message(), "no camera named 'front'"));
        assert_non_null(strstr(rs_error_message(), "'cam', 'side'"));
        rs_error_clear();
    }
}

static void test_texture_slots(void **state)
{
    rs_scene *s;
    const rs_material *m;
    uint32_t w, h, i;
    float *raw;
    (void)state;
    write_full_files();
    s = load("full.gltf", NULL);
    assert_int_equal(s->n_materials, 1u);
    m = &s->materials[0];
    assert_int_equal(m->type, RS_MAT_PBR);
    assert_true(fabsf(m->metallic - 0.8f) < 1e-6f && fabsf(m->alpha - 0.36f) < 1e-6f);
    assert_int_not_equal(m->albedo_tex, RS_NO_TEXTURE);
    assert_int_not_equal(m->mr_tex, RS_NO_TEXTURE);
    assert_int_not_equal(m->normal_tex, RS_NO_TEXTURE);
    assert_int_not_equal(m->emission_tex, RS_NO_TEXTURE);
    assert_true(fabsf(m->normal_scale - 0.5f) < 1e-6f);
    expect_v3(m->emission, 1, 1, 1, 0);
    /* base colour: the stored codes sRGB-decoded, times the factor (0.5, 1, 1) */
    raw = read_raw("base.png", &w, &h);
    {
        const rs_image *im = &s->images[s->textures[m->albedo_tex].image];
        assert_int_equal(im->width, w);
        for (i = 0; i < w * h * 3; ++i)
            assert_true(fabsf(im->rgb[i] - rs_srgb_decode(raw[i]) * (i % 3 == 0 ? 0.5f : 1.0f)) <
                        1e-5f);
    }
    free(raw);
    /* metallic-roughness and normal: as stored */
    raw = read_raw("mr.png", &w, &h);
    {
        const rs_image *im = &s->images[s->textures[m->mr_tex].image];
        for (i = 0; i < w * h * 3; ++i)
            assert_true(fabsf(im->rgb[i] - raw[i]) < 1e-6f);
    }
    free(raw);
    raw = read_raw("normal.png", &w, &h);
    {
        const rs_image *im = &s->images[s->textures[m->normal_tex].image];
        for (i = 0; i < w * h * 3; ++i)
            assert_true(fabsf(im->rgb[i] - raw[i]) < 1e-6f);
    }
    free(raw);
    rs_scene_destroy(s);
}

/* One quad facing the camera, lit by nothing but its emissive texture (left half red, right half
 * black, as UV u runs across it): the image's left half is red, its right half dark. */
static void test_emissive_texture_renders(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1]}],"
        "\"nodes\":[{\"mesh\":0},{\"name\":\"cam\",\"camera\":0,\"translation\":[0,0,2.2]}],"
        "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.1}}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],"
        "\"metallicFactor\":0},\"emissiveFactor\":[2,2,2],\"emissiveTexture\":{\"index\":0}}],"
        "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"emis.png\"}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    char buf[4096];
    rs_scene *s;
    rt_args a = rt_defaults("", 32, 4);
    float *img;
    double left = 0, right = 0, left_g = 0;
    int x, y;
    (void)state;
    write_full_files();
    snprintf(buf, sizeof buf, k, "");
    write_text("emis.gltf", buf);
    s = load("emis.gltf", NULL);
    img = rt_render_scene(s, &a, NULL);
    assert_non_null(img);
    for (y = 8; y < 24; ++y)
        for (x = 0; x < 32; ++x) {
            const float *p = &img[3 * (y * 32 + x)];
            if (x >= 9 && x < 14) {
                left += p[0];
                left_g += p[1];
            } else if (x >= 18 && x < 23) {
                right += p[0];
            }
        }
    print_message("emissive quad: left red %.3f (green %.3f), right red %.3f\n", left, left_g,
                  right);
    assert_true(left > 100.0);         /* 80 pixels of radiance ~2 */
    assert_true(right < 0.05 * left);  /* the texture's black half */
    assert_true(left_g < 0.05 * left); /* red, not white */
    free(img);
    rs_scene_destroy(s);
}

/* A w x h TGA with alpha (uncompressed, 32-bit BGRA, top row first): grey, alpha[i] / 255. */
static void write_tga_alpha(const char *name, uint32_t w, uint32_t h, const unsigned char *alpha)
{
    unsigned char buf[18 + 4 * 64];
    uint32_t i;
    assert_true(w * h <= 64);
    memset(buf, 0, 18);
    buf[2] = 2; /* uncompressed true colour */
    buf[12] = (unsigned char)w, buf[14] = (unsigned char)h;
    buf[16] = 32;
    buf[17] = 0x28; /* 8 alpha bits, top-left origin */
    for (i = 0; i < w * h; ++i) {
        buf[18 + 4 * i] = buf[19 + 4 * i] = buf[20 + 4 * i] = 128;
        buf[21 + 4 * i] = alpha[i];
    }
    write_bytes(name, buf, 18 + 4 * (size_t)w * h);
}

/* glTF's alpha cut-out: a black quad in front of an emitting one, cut out where its base colour
 * texture's alpha (times the factor's) is under alphaCutoff: the emitter shows through the left
 * half (alpha 0) and not the right (alpha 1); a factor alpha under the cutoff cuts the whole
 * quad; OPAQUE ignores alpha.  The cut-out triangles take the scalar leaf test (never packed), so
 * the binary, 4- and 8-wide traversals agree. */
static void test_alpha_cutout(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
        "\"nodes\":[{\"mesh\":0},{\"mesh\":1,\"translation\":[0,0,0.5]},"
        "{\"name\":\"cam\",\"camera\":0,\"translation\":[0,0,2.7]}],"
        "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9,\"znear\":0.1}}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,1],"
        "\"metallicFactor\":0},\"emissiveFactor\":[2,2,2]},"
        "{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0,0,0,%s],\"metallicFactor\":0,"
        "\"baseColorTexture\":{\"index\":0}},\"alphaMode\":\"%s\",\"alphaCutoff\":0.5}],"
        "\"textures\":[{\"source\":0}],\"images\":[{\"uri\":\"alpha.tga\"}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    static const unsigned char alpha[8] = {0, 0, 255, 255, 0, 0, 255, 255};
    static const struct {
        const char *factor, *mode;
        int left, right; /* whether the emitter shows */
        int untextured;  /* the factor alone (issue 39: alpha 0 without a texture still hid) */
    } cases[] = {{"1", "MASK", 1, 0, 0},      {"0.3", "MASK", 1, 1, 0}, {"1", "OPAQUE", 0, 0, 0},
                 {"0.3", "OPAQUE", 0, 0, 0}, {"0", "MASK", 1, 1, 1},   {"0.3", "MASK", 1, 1, 1},
                 {"0.7", "MASK", 0, 0, 1},   {"0", "OPAQUE", 0, 0, 1}};
    size_t c;
    (void)state;
    write_full_files();
    write_tga_alpha("alpha.tga", 4, 2, alpha);
    for (c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        char buf[8192], json[8192], *m;
        rs_scene *s;
        float *ref = NULL;
        uint32_t width;
        snprintf(json, sizeof json, k, cases[c].factor, cases[c].mode, "");
        if (cases[c].untextured) {
            static const char tex[] = ",\"baseColorTexture\":{\"index\":0}";
            m = strstr(json, tex);
            assert_non_null(m);
            memmove(m, m + strlen(tex), strlen(m + strlen(tex)) + 1);
        }
        /* a second mesh, the same quad with material 1 */
        m = strstr(json, "\"material\":0}]}]");
        assert_non_null(m);
        snprintf(buf, sizeof buf, "%.*s\"material\":0}]},{\"primitives\":[{\"attributes\":"
                 "{\"POSITION\":0,\"NORMAL\":1%s},\"indices\":3,\"material\":1}]}]%s",
                 (int)(m - json), json, cases[c].untextured ? "" : ",\"TEXCOORD_0\":2",
                 m + strlen("\"material\":0}]}]"));
        write_text("alpha.gltf", buf);
        s = load("alpha.gltf", NULL);
        assert_int_equal(s->n_masks != 0, strcmp(cases[c].mode, "MASK") == 0 &&
                                              (!cases[c].untextured || cases[c].left));
        for (width = 2; width <= 8; width *= 2) {
            rt_args a = rt_defaults("", 32, 2);
            float *img;
            double left = 0, right = 0;
            int x, y;
            if (width == 8 && !rs_bvh8_supported())
                continue;
            a.bvh_width = width;
            img = rt_render_scene(s, &a, NULL);
            assert_non_null(img);
            for (y = 10; y < 22; ++y)
                for (x = 0; x < 32; ++x) {
                    const float *p = &img[3 * (y * 32 + x)];
                    if (x >= 9 && x < 14)
                        left += p[0];
                    else if (x >= 18 && x < 23)
                        right += p[0];
                }
            if (width == 2)
                print_message("alpha %s %s%s: left %.2f, right %.2f\n", cases[c].factor,
                              cases[c].mode, cases[c].untextured ? " untextured" : "", left,
                              right);
            if ((left > 60.0) != cases[c].left || (right > 60.0) != cases[c].right)
                fail_msg("alpha %s %s, %u-wide: left %.2f, right %.2f (60 pixels of ~2 when the "
                         "emitter shows)",
                         cases[c].factor, cases[c].mode, width, left, right);
            if (!ref)
                ref = img;
            else {
                assert_memory_equal(ref, img, sizeof(float) * 32 * 32 * 3);
                free(img);
            }
        }
        free(ref);
        rs_scene_destroy(s);
    }
}

/* KHR_materials_transmission (with KHR_materials_ior) makes rough glass of the base colour's
 * tint and the material's roughness. */
static void test_transmission(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"extensionsUsed\":[\"KHR_materials_transmission\",\"KHR_materials_ior\"],"
        "\"nodes\":[{\"mesh\":0}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorFactor\":[0.9,0.95,1,1],"
        "\"metallicFactor\":0,\"roughnessFactor\":0.3},\"extensions\":{"
        "\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
        "\"KHR_materials_ior\":{\"ior\":1.33}}}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    char buf[4096];
    rs_scene *s;
    const rs_material *m;
    (void)state;
    write_full_files();
    snprintf(buf, sizeof buf, k, "");
    write_text("glass.gltf", buf);
    s = load("glass.gltf", NULL);
    m = &s->materials[s->tri_mat[0]];
    assert_int_equal(m->type, RS_MAT_ROUGH_DIELECTRIC);
    assert_true(fabsf(m->ior - 1.33f) < 1e-6f);
    assert_true(fabsf(m->alpha - 0.09f) < 1e-6f);
    expect_v3(m->albedo, 0.9f, 0.95f, 1.0f, 1e-6f);
    rs_scene_destroy(s);
}

/* One quad with one material whose "extensions" object is `ext`, the file listing `used`. */
static rs_scene *load_ext(const char *name, const char *used, const char *pbr, const char *ext)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"extensionsUsed\":[%s],\"nodes\":[{\"mesh\":0}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{%s},\"emissiveFactor\":[0.5,0.25,1],"
        "\"extensions\":{%s}}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    char buf[8192], views[4] = "";
    snprintf(buf, sizeof buf, k, used, pbr, ext, views);
    write_text(name, buf);
    return load(name, NULL);
}

/* The material extensions read from the file's JSON (scenes/gltf_check.h): emissive strength,
 * ior and specular into the dielectric layer's F0 and weight, unlit, volume; the defaults give
 * exactly rs_mat_pbr's 0.04 and 1; the census of what the file uses; bad values named. */
static void test_material_extensions(void **state)
{
    rs_scene *s;
    const rs_material *m;
    rs_gltf_ext e;
    char p[256];
    double f0;
    (void)state;
    write_full_files();
    /* none: the defaults, bit for bit */
    s = load_ext("plain.gltf", "", "\"baseColorFactor\":[0.2,0.4,0.6,1]", "");
    m = &s->materials[s->tri_mat[0]];
    assert_true(m->specular.x == 0.04f && m->specular.y == 0.04f && m->specular.z == 0.04f);
    assert_true(m->spec_weight == 1.0f && m->coat == 0.0f && rs_v3_is_zero(m->sheen));
    expect_v3(m->emission, 0.5f, 0.25f, 1.0f, 0.0f);
    rs_scene_destroy(s);
    /* emissive strength (Assimp 5.2 drops it), ior 2 and a coloured specular at weight .6 */
    s = load_ext("spec.gltf",
                 "\"KHR_materials_emissive_strength\",\"KHR_materials_ior\","
                 "\"KHR_materials_specular\"",
                 "\"baseColorFactor\":[0.2,0.4,0.6,1],\"metallicFactor\":0",
                 "\"KHR_materials_emissive_strength\":{\"emissiveStrength\":4},"
                 "\"KHR_materials_ior\":{\"ior\":2},"
                 "\"KHR_materials_specular\":{\"specularFactor\":0.6,"
                 "\"specularColorFactor\":[1,0.5,0.2]}");
    m = &s->materials[s->tri_mat[0]];
    assert_int_equal(m->type, RS_MAT_PBR);
    expect_v3(m->emission, 2.0f, 1.0f, 4.0f, 0.0f);
    f0 = (1.0 / 3.0) * (1.0 / 3.0);
    expect_v3(m->specular, (float)f0, (float)(f0 * 0.5), (float)(f0 * 0.2), 1e-7f);
    assert_true(m->spec_weight == 0.6f);
    rs_scene_destroy(s);
    /* specularColorFactor above 1, as the schema allows (issue 39: refused): F0 held to 1 */
    s = load_ext("spec4.gltf", "\"KHR_materials_ior\",\"KHR_materials_specular\"",
                 "\"baseColorFactor\":[0.2,0.4,0.6,1],\"metallicFactor\":0",
                 "\"KHR_materials_ior\":{\"ior\":2},"
                 "\"KHR_materials_specular\":{\"specularColorFactor\":[4,20,0.5]}");
    m = &s->materials[s->tri_mat[0]];
    expect_v3(m->specular, (float)(f0 * 4), 1.0f, (float)(f0 * 0.5), 1e-7f);
    rs_scene_destroy(s);
    /* unlit: the base colour emitted, nothing reflected */
    s = load_ext("unlit.gltf", "\"KHR_materials_unlit\"", "\"baseColorFactor\":[0.2,0.4,0.6,1]",
                 "\"KHR_materials_unlit\":{}");
    m = &s->materials[s->tri_mat[0]];
    expect_v3(m->emission, 0.2f, 0.4f, 0.6f, 1e-7f);
    expect_v3(m->albedo, 0.0f, 0.0f, 0.0f, 0.0f);
    assert_true(m->spec_weight == 0.0f && m->metallic == 0.0f);
    rs_scene_destroy(s);
    /* volume on a transmitting material: sigma_a = -ln(colour) / distance */
    s = load_ext("volume.gltf",
                 "\"KHR_materials_transmission\",\"KHR_materials_volume\",\"KHR_materials_ior\"",
                 "\"metallicFactor\":0,\"roughnessFactor\":0",
                 "\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
                 "\"KHR_materials_ior\":{\"ior\":1.25},"
                 "\"KHR_materials_volume\":{\"thicknessFactor\":1,\"attenuationDistance\":2,"
                 "\"attenuationColor\":[0.5,0.25,1]}");
    m = &s->materials[s->tri_mat[0]];
    assert_int_equal(m->type, RS_MAT_ROUGH_DIELECTRIC);
    assert_true(m->ior == 1.25f);
    expect_v3(m->sigma_a, (float)(log(2.0) / 2), (float)(log(4.0) / 2), 0.0f, 1e-7f);
    rs_scene_destroy(s);
    /* the census: what raystream reads, what it does not */
    s = load_ext("census.gltf", "\"KHR_materials_iridescence\",\"KHR_materials_clearcoat\","
                 "\"KHR_materials_sheen\",\"EXT_texture_webp\"", "",
                 "\"KHR_materials_sheen\":{\"sheenColorFactor\":[1,0.5,0.25],"
                 "\"sheenRoughnessFactor\":0.3},"
                 "\"KHR_materials_clearcoat\":{\"clearcoatFactor\":0.8,"
                 "\"clearcoatRoughnessFactor\":0.5}");
    m = &s->materials[s->tri_mat[0]];
    assert_true(m->coat == 0.8f && m->coat_alpha == 0.25f);
    expect_v3(m->sheen, 1.0f, 0.5f, 0.25f, 0.0f);
    assert_true(m->sheen_rough == 0.3f);
    rs_scene_destroy(s);
    path_of(p, sizeof p, "census.gltf");
    assert_int_equal(rs_gltf_read_ext(p, 0, &e), RS_OK);
    assert_string_equal(e.used, "KHR_materials_clearcoat, KHR_materials_sheen");
    assert_string_equal(e.unread, "KHR_materials_iridescence, EXT_texture_webp");
    assert_int_equal(e.n_materials, 1);
    rs_gltf_ext_free(&e);
}

static void expect_bad(const char *name, const char *text, const char *a, const char *b);

/* Bad extension values: one line naming the file, the material and the field. */
static void test_material_extensions_bad(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],\"materials\":[{\"extensions\":{%s}}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    static const char *const cases[][3] = {
        {"\"KHR_materials_ior\":{\"ior\":0.5}", "KHR_materials_ior.ior", "below 1"},
        {"\"KHR_materials_specular\":{\"specularColorFactor\":[-1,0,0]}",
         "specularColorFactor[0]", "number >= 0"},
        {"\"KHR_materials_sheen\":{\"sheenColorFactor\":[2,0,0]}", "sheenColorFactor[0]",
         "[0, 1]"},
        /* an extension that is not an object was skipped without a word */
        {"\"KHR_materials_sheen\":\"x\"", "extensions.KHR_materials_sheen", "not an object"},
        {"\"KHR_materials_ior\":[1.5]", "extensions.KHR_materials_ior", "not an object"},
        {"\"KHR_materials_volume\":{\"attenuationDistance\":0}", "attenuationDistance",
         "above 0"},
        {"\"KHR_materials_emissive_strength\":{\"emissiveStrength\":\"x\"}", "emissiveStrength",
         "not a number"},
    };
    char buf[8192];
    size_t i;
    (void)state;
    write_full_files();
    for (i = 0; i < sizeof cases / sizeof *cases; ++i) {
        char views[4] = "", ext[256];
        snprintf(ext, sizeof ext, "%s", cases[i][0]);
        snprintf(buf, sizeof buf, k, ext, views);
        expect_bad("badext.gltf", buf, cases[i][1], cases[i][2]);
    }
    /* a required extension raystream does not read: not loaded (glTF 2.0, 3.12; issue 39: it
     * rendered with a warning); a required one it reads loads */
    {
        char req[8400];
        snprintf(buf, sizeof buf, k, "", "");
        snprintf(req, sizeof req, "{\"extensionsRequired\":[\"KHR_materials_iridescence\"],"
                                  "\"extensionsUsed\":[\"KHR_materials_iridescence\"],%s",
                 buf + 1);
        expect_bad("required.gltf", req, "requires the extension KHR_materials_iridescence",
                   "must not load");
    }
}

/* KHR_texture_transform values that are not what the extension's schema says: Assimp's reader
 * asserted on offset and scale that are not two numbers (SIGABRT, no line of ours: issue 39);
 * now one line naming the file, the material and the field, before Assimp reads it.  The file
 * is tests/data/texture_transform.gltf with material 1's offset [0.5, 0] replaced. */
static void test_texture_transform_bad(void **state)
{
    static const char *const cases[][2] = {
        {"\"offset\": [2]", "offset: want two numbers"},
        {"\"offset\": []", "offset: want two numbers"},
        {"\"offset\": [\"a\", \"b\"]", "offset: want two numbers"},
        {"\"offset\": [null, null]", "offset: want two numbers"},
        {"\"offset\": [[1], [2]]", "offset: want two numbers"},
        {"\"offset\": [0, 0], \"scale\": [1, 2, 3]", "scale: want two numbers"},
        {"\"offset\": [0, 0], \"scale\": 2", "scale: want two numbers"},
        {"\"rotation\": \"x\"", "rotation: want a number"},
        {"\"texCoord\": -1", "texCoord: want a whole number"},
        {"\"texCoord\": 0.5", "texCoord: want a whole number"},
    };
    static const char *const key = "{\"offset\": [0.5, 0]}";
    char *text, *at, buf[16384];
    size_t i, n;
    FILE *f = fopen(RS_SOURCE_DIR "/tests/data/texture_transform.gltf", "rb");
    (void)state;
    assert_non_null(f);
    text = (char *)calloc(1, 16384);
    assert_non_null(text);
    n = fread(text, 1, 16383, f);
    fclose(f);
    assert_true(n > 0 && n < 16000);
    at = strstr(text, key);
    assert_non_null(at);
    for (i = 0; i < sizeof cases / sizeof *cases; ++i) {
        snprintf(buf, sizeof buf, "%.*s{%s}%s", (int)(at - text), text, cases[i][0],
                 at + strlen(key));
        expect_bad("badxf.gltf", buf, "materials[1].pbrMetallicRoughness.baseColorTexture."
                                      "extensions.KHR_texture_transform.",
                   cases[i][1]);
    }
    /* not an object at all */
    snprintf(buf, sizeof buf, "%.*s[1, 2]%s", (int)(at - text), text, at + strlen(key));
    expect_bad("badxf.gltf", buf, "KHR_texture_transform: not an object", NULL);
    free(text);
}

/* KHR_materials_volume in the image: a slab of clear glass (ior 1: no refraction, no
 * reflection) 2 units thick, two quads facing out, in front of the white sky a glTF file
 * without lights gets.  Each camera ray crosses it straight: the pixel is exp(-sigma_a 2) =
 * the attenuation colour, exactly (no noise). */
static void test_volume_renders(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0,1,2]}],"
        "\"extensionsUsed\":[\"KHR_materials_transmission\",\"KHR_materials_volume\","
        "\"KHR_materials_ior\"],"
        "\"nodes\":[{\"mesh\":0,\"scale\":[3,3,1],\"translation\":[0,0,1]},"
        "{\"mesh\":0,\"scale\":[3,3,1],\"translation\":[0,0,-1],\"rotation\":[0,1,0,0]},"
        "{\"camera\":0,\"translation\":[0,0,6]}],"
        "\"cameras\":[{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.3,\"aspectRatio\":1,"
        "\"znear\":0.1}}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},"
        "\"extensions\":{\"KHR_materials_transmission\":{\"transmissionFactor\":1},"
        "\"KHR_materials_ior\":{\"ior\":1},\"KHR_materials_volume\":{\"attenuationDistance\":2,"
        "\"attenuationColor\":[0.5,0.25,0.8]}}}],"
        "\"buffers\":[{\"uri\":\"quad.bin\",\"byteLength\":140}]," VIEWS "}";
    char buf[8192], views[4] = "";
    rs_scene *s;
    rt_args a = rt_defaults("slab", 16, 4);
    float *rgb;
    size_t i;
    (void)state;
    write_full_files();
    snprintf(buf, sizeof buf, k, views);
    write_text("slab.gltf", buf);
    s = load("slab.gltf", NULL);
    a.width = a.height = 16;
    rgb = rt_render_scene(s, &a, NULL);
    assert_non_null(rgb);
    for (i = 0; i < 16 * 16; ++i) {
        uint32_t x = (uint32_t)i % 16, y = (uint32_t)i / 16;
        int c;
        for (c = 0; c < 3; ++c) {
            /* a ray at angle t to the axis crosses 2 / cos t: at most 1.03x (yfov 0.3) */
            double want = c == 0 ? 0.5 : c == 1 ? 0.25 : 0.8, v = rgb[3 * i + c];
            assert_true(v <= want + 1e-5 && v >= pow(want, 1.03) - 1e-5);
            if ((x == 7 || x == 8) && (y == 7 || y == 8))
                assert_true(fabs(v - want) < 2e-3 * want); /* the axis: 2 units exactly */
        }
    }
    printf("slab of glass, attenuation colour (.5, .25, .8) over 2: centre (%.4f, %.4f, %.4f), "
           "corner (%.4f, %.4f, %.4f)\n",
           rgb[3 * (7 * 16 + 7)], rgb[3 * (7 * 16 + 7) + 1], rgb[3 * (7 * 16 + 7) + 2], rgb[0],
           rgb[1], rgb[2]);
    free(rgb);
    rs_scene_destroy(s);
}

/* A .glb: the JSON chunk and a binary chunk holding the buffer and a PNG texture. */
static void test_glb_embedded(void **state)
{
    static const char *k =
        "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
        "\"nodes\":[{\"mesh\":0}],"
        "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
        "\"textures\":[{\"source\":0}],"
        "\"images\":[{\"bufferView\":4,\"mimeType\":\"image/png\"}],"
        "\"buffers\":[{\"byteLength\":%u}]," VIEWS "}";
    char json[4096], views[128], p[256];
    unsigned char *png, *glb;
    size_t png_n, jn, bn, n;
    uint32_t u, w, h, i;
    FILE *f;
    rs_scene *s;
    float *raw;
    (void)state;
    write_full_files();
    path_of(p, sizeof p, "base.png");
    f = fopen(p, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    png_n = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    png = (unsigned char *)malloc(png_n);
    assert_int_equal(fread(png, 1, png_n, f), png_n);
    fclose(f);
    snprintf(views, sizeof views, ",{\"buffer\":0,\"byteOffset\":140,\"byteLength\":%u}",
             (unsigned)png_n);
    snprintf(json, sizeof json, k, (unsigned)(QUAD_BYTES + png_n), views);
    jn = (strlen(json) + 3) & ~(size_t)3;
    bn = (QUAD_BYTES + png_n + 3) & ~(size_t)3;
    n = 12 + 8 + jn + 8 + bn;
    glb = (unsigned char *)calloc(1, n);
    memcpy(glb, "glTF", 4);
    u = 2, memcpy(glb + 4, &u, 4);
    u = (uint32_t)n, memcpy(glb + 8, &u, 4);
    u = (uint32_t)jn, memcpy(glb + 12, &u, 4);
    memcpy(glb + 16, "JSON", 4);
    memset(glb + 20, ' ', jn);
    memcpy(glb + 20, json, strlen(json));
    u = (uint32_t)bn, memcpy(glb + 20 + jn, &u, 4);
    memcpy(glb + 24 + jn, "BIN\0", 4);
    quad_buffer(glb + 28 + jn);
    memcpy(glb + 28 + jn + QUAD_BYTES, png, png_n);
    write_bytes("embedded.glb", glb, n);
    free(glb);
    free(png);
    s = load("embedded.glb", NULL);
    assert_int_equal(s->n_tris, 2u);
    assert_int_not_equal(s->materials[0].albedo_tex, RS_NO_TEXTURE);
    raw = read_raw("base.png", &w, &h);
    {
        const rs_image *im = &s->images[s->textures[s->materials[0].albedo_tex].image];
        assert_int_equal(im->width, w);
        assert_int_equal(im->height, h);
        for (i = 0; i < w * h * 3; ++i)
            assert_true(fabsf(im->rgb[i] - rs_srgb_decode(raw[i])) < 1e-5f);
    }
    free(raw);
    /* no camera: one that frames the quad (its centre ahead, all of it in view); no light: the
     * white sky */
    {
        rs_vec3 d = rs_v3_normalize(rs_v3_sub(s->camera.at, s->camera.from));
        float dist = rs_v3_length(s->camera.from);
        assert_true(rs_v3_length(s->camera.at) < 1e-5f);
        assert_true(dist * tanf(0.5f * s->camera.vfov_deg * 0.01745329f) > 1.4142f);
        assert_true(d.z < -0.5f);
        expect_v3(s->background, 1, 1, 1, 0);
    }
    rs_scene_destroy(s);
}

static void expect_bad(const char *name, const char *text, const char *a, const char *b)
{
    char p[256];
    rs_scene *s = (rs_scene *)0x1;
    write_text(name, text);
    path_of(p, sizeof p, name);
    rs_error_clear();
    if (rs_scene_load_gltf(p, NULL, &s) == RS_OK)
        fail_msg("%s loaded", name);
    assert_null(s);
    print_message("%s\n", rs_error_message());
    assert_null(strchr(rs_error_message(), '\n'));
    assert_non_null(strstr(rs_error_message(), name));
    if (!strstr(rs_error_message(), a) || (b && !strstr(rs_error_message(), b)))
        fail_msg("'%s' lacks '%s' or '%s'", rs_error_message(), a, b ? b : "");
    rs_error_clear();
}

static void test_bad_files(void **state)
{
    char buf[8192];
    (void)state;
    write_full_files();
    /* a texture that is not there */
    snprintf(buf, sizeof buf, k_full, "");
    {
        char *at = strstr(buf, "emis.png");
        memcpy(at, "gone.png", 8);
    }
    expect_bad("notex.gltf", buf, "gone.png", NULL);
    /* a buffer that is not there */
    snprintf(buf, sizeof buf, k_full, "");
    {
        char *at = strstr(buf, "quad.bin");
        memcpy(at, "lost.bin", 8);
    }
    expect_bad("nobuf.gltf", buf, "nobuf.gltf", NULL);
    /* cut JSON */
    snprintf(buf, sizeof buf, k_full, "");
    buf[strlen(buf) / 2] = '\0';
    expect_bad("cut.gltf", buf, "cut.gltf", NULL);
    /* not JSON at all */
    expect_bad("junk.gltf", "\x01\x02 this is not glTF", "junk.gltf", "not a glTF file");
    /* the start of a PLY header: Assimp offered it to its PLY reader, which spun for ever
     * (tests/fuzz/fuzz_mesh found it); refused before any reader sees it */
    expect_bad("plyish.gltf", "ply\xed\xed\nformat ascii 2.0\nelement vertex 8\nproperty float x\n",
               "plyish.gltf", "not a glTF file");
    expect_bad("plyish.glb", "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\n",
               "plyish.glb", "not a glTF binary");
}

/* Files made to hurt (issue 27): refused before Assimp sees them, one line naming the field. */
static void test_hostile_files(void **state)
{
    char buf[8192], p[256];
    char *deep;
    size_t k, n;
    int i;
    rs_scene *s = (rs_scene *)0x1;
    unsigned char glb[900];
    uint32_t u;
    (void)state;
    write_full_files();
    /* a buffer in a folder that is not there: Assimp read quad.bin beside the scene instead */
    snprintf(buf, sizeof buf, k_full, "");
    {
        char *at = strstr(buf, "\"quad.bin\"");
        memmove(at + 5, at + 1, strlen(at + 1) + 1);
        memcpy(at + 1, "sub/", 4);
    }
    expect_bad("subdir.gltf", buf, "buffers[0].uri 'sub/quad.bin'", "no such file");
    /* a URL: never fetched, and not a same-named file either */
    snprintf(buf, sizeof buf, k_full, "");
    {
        char *at = strstr(buf, "\"quad.bin\"");
        char tail[8192];
        snprintf(tail, sizeof tail, "\"http://example.com/quad.bin\"%s", at + 10);
        strcpy(at, tail);
    }
    expect_bad("url.gltf", buf, "buffers[0].uri 'http://example.com/quad.bin'", "relative");
    /* nodes nested 30,000 deep: Assimp's recursive reader overflowed the stack */
    n = 30000;
    deep = (char *)malloc(n * 40 + 256);
    k = (size_t)sprintf(deep, "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],"
                              "\"nodes\":[");
    for (i = 0; i < (int)n; ++i)
        k += (size_t)sprintf(deep + k, i + 1 < (int)n ? "{\"children\":[%d]}," : "{}", i + 1);
    sprintf(deep + k, "]}");
    expect_bad("deep.gltf", deep, "nest deeper than 256 levels", NULL);
    free(deep);
    /* a cycle, and a node with two parents */
    expect_bad("cycle.gltf",
               "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[1]},"
               "{\"children\":[0]}]}",
               "cycle", NULL);
    expect_bad("twice.gltf",
               "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[2]},"
               "{\"children\":[2]},{}]}",
               "nodes[2] is a child twice", NULL);
    expect_bad("badchild.gltf",
               "{\"asset\":{\"version\":\"2.0\"},\"nodes\":[{\"children\":[7]}]}",
               "nodes[0].children names no node", NULL);
    /* --camera naming a camera that is there but cannot be looked through: said so (it was
     * "no camera named 'side' (the file has: 'cam', 'side')") */
    {
        static const char *const kinds[][2] = {
            {"{\"type\":\"orthographic\",\"orthographic\":{\"xmag\":1,\"ymag\":1,"
             "\"znear\":0.1,\"zfar\":100}}",
             "camera 'side' is orthographic"},
            {"{\"type\":\"perspective\",\"perspective\":{\"yfov\":0,\"znear\":0.1}}",
             "camera 'side' has a field of view of 0"}};
        int c;
        for (c = 0; c < 2; ++c) {
            rs_gltf_opts go;
            char *at, tail[8192];
            snprintf(buf, sizeof buf, k_full, "");
            at = strstr(buf, "{\"type\":\"perspective\",\"perspective\":{\"yfov\":0.9");
            assert_non_null(at);
            snprintf(tail, sizeof tail, "%s%s", kinds[c][0], strstr(at, "}}") + 2);
            strcpy(at, tail);
            write_text("cams.gltf", buf);
            path_of(p, sizeof p, "cams.gltf");
            memset(&go, 0, sizeof go);
            go.camera = "side";
            s = (rs_scene *)0x1;
            rs_error_clear();
            assert_int_not_equal(rs_scene_load_gltf(p, &go, &s), RS_OK);
            print_message("%s\n", rs_error_message());
            if (!strstr(rs_error_message(), kinds[c][1]))
                fail_msg("'%s' lacks '%s'", rs_error_message(), kinds[c][1]);
            rs_error_clear();
        }
    }
    /* a 900-byte .glb whose chunk claims 3.75 GiB: refused before anything is allocated */
    memset(glb, ' ', sizeof glb);
    memcpy(glb, "glTF", 4);
    u = 2, memcpy(glb + 4, &u, 4);
    u = sizeof glb, memcpy(glb + 8, &u, 4);
    u = 0xF0000000u, memcpy(glb + 12, &u, 4);
    memcpy(glb + 16, "JSON", 4);
    write_bytes("huge.glb", glb, sizeof glb);
    path_of(p, sizeof p, "huge.glb");
    assert_int_not_equal(rs_scene_load_gltf(p, NULL, &s), RS_OK);
    assert_non_null(strstr(rs_error_message(), "claims 4026531840 bytes"));
    rs_error_clear();
    /* and one whose header claims more bytes than the file has */
    u = 1u << 31, memcpy(glb + 8, &u, 4);
    write_bytes("long.glb", glb, sizeof glb);
    path_of(p, sizeof p, "long.glb");
    assert_int_not_equal(rs_scene_load_gltf(p, NULL, &s), RS_OK);
    assert_non_null(strstr(rs_error_message(), "truncated or corrupt"));
    rs_error_clear();
}

static int setup(void **state)
{
    (void)state;
    snprintf(g_dir, sizeof g_dir, "/tmp/rs_gltf_XXXXXX");
    return mkdtemp(g_dir) ? 0 : -1;
}

static int teardown(void **state)
{
    static const char *files[] = {"quad.bin",  "base.png",     "mr.png",     "normal.png",
                                  "emis.png",  "full.gltf",    "emis.gltf",  "embedded.glb",
                                  "notex.gltf", "nobuf.gltf",  "cut.gltf",   "junk.gltf",
                                  "plyish.gltf", "plyish.glb",  "glass.gltf", "alpha.gltf", "alpha.tga"};
    size_t i;
    char p[256];
    (void)state;
    for (i = 0; i < sizeof files / sizeof files[0]; ++i) {
        path_of(p, sizeof p, files[i]);
        remove(p);
    }
    rmdir(g_dir);
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hierarchy_camera_lights),
        cmocka_unit_test(test_texture_slots),
        cmocka_unit_test(test_emissive_texture_renders),
        cmocka_unit_test(test_glb_embedded),
        cmocka_unit_test(test_transmission),
        cmocka_unit_test(test_material_extensions),
        cmocka_unit_test(test_material_extensions_bad),
        cmocka_unit_test(test_texture_transform_bad),
        cmocka_unit_test(test_volume_renders),
        cmocka_unit_test(test_alpha_cutout),
        cmocka_unit_test(test_bad_files),
        cmocka_unit_test(test_hostile_files),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
