/* scenes/builtin_gpucheck.c — builtin:gpucheck, a small scene made to reach every device function
 * of the megakernel (rs_gpu_path_radiance and everything it calls) and every branch of the
 * traversal, so that one render of it compares the CUDA device, its host fallback and the CPU
 * device over all of them (tests/render_gpucheck_test.c on any machine, tests/gpu_trace_test.c on a
 * GPU).
 *
 * Everything is made here, without files: the textures, the normal map, the metallic-roughness
 * map, the alpha mask and the environment map are computed in code.  What it holds:
 *   geometry   spheres (one moving during the shutter), quads (the floor, an area light),
 *              triangles with UVs and vertex normals (a curved patch), a triangle with UVs and no
 *              normals beside ones with, triangles with an alpha cut-out, and a prototype of
 *              triangles placed twice by the two-level BVH: once under an oblique rotation with a
 *              non-uniform scale, once mirrored (det < 0) and sheared;
 *   materials  every rs_material_type: Lambertian (plain, textured, uniformly sampled), uniform
 *              diffuse, Disney diffuse, Phong, fuzzy metal, glass (Schlick and exact Fresnel),
 *              area lights (one- and two-sided), GGX conductors (complex index, Schlick colour,
 *              and a mirror-smooth one), rough glass (rough and smooth), pbr with a normal map, a
 *              metallic-roughness map, a base-colour image, a textured emission (found by paths)
 *              and a constant one (a light);
 *   textures   solid, checker, stripes, image (bilinear), on spheres (longitude/latitude UVs),
 *              quads and triangles (interpolated UVs);
 *   lights     quad, triangle and sphere emitters (a pbr one too), point, spot and directional
 *              lights, and an importance-sampled, rotated environment map (not uniform: it has a
 *              sun);
 *   camera     a thin lens (defocus) and a shutter (motion blur).
 * The preferred size is 96x64; the tests render 64x40.  Not reached here, as no one scene can:
 * the constant and sky backgrounds and the uniform sky (the map replaces them: builtin:furnace,
 * builtin:materials), and the --isect-* alternatives to the default intersection tests. */
#include "scenes/builtin_gpucheck.h"

#include <math.h>
#include <string.h>

#include "core/try.h"
#include "scenes/transform.h"

#define GC_PI 3.14159265358979323846

/* ---- images made in code ------------------------------------------------------------------ */

/* A base colour: a warm-to-cool gradient with a grid of dark lines (orientation visible). */
static rs_status add_base_image(rs_scene *s, uint32_t *id)
{
    enum { W = 32, H = 32 };
    float rgb[W * H * 3];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            float *p = &rgb[3 * (y * W + x)];
            int line = x % 8 == 0 || y % 8 == 0;
            p[0] = line ? 0.05f : 0.2f + 0.7f * (float)x / (W - 1);
            p[1] = line ? 0.05f : 0.3f + 0.4f * (float)y / (H - 1);
            p[2] = line ? 0.05f : 0.8f - 0.6f * (float)x / (W - 1);
        }
    return rs_scene_add_image(s, W, H, rgb, id);
}

/* A tangent-space normal map of round bumps, (n + 1) / 2 per channel (linear data). */
static rs_status add_normal_image(rs_scene *s, uint32_t *id)
{
    enum { W = 32, H = 32 };
    float rgb[W * H * 3];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            /* h(u, v) = sin(2 pi 4u) sin(2 pi 4v) / 8: the slopes give the normal */
            double u = (x + 0.5) / W, v = (y + 0.5) / H, k = 2.0 * GC_PI * 4.0;
            double dx = -k / 8.0 * cos(k * u) * sin(k * v), dy = -k / 8.0 * sin(k * u) * cos(k * v);
            double l = sqrt(dx * dx + dy * dy + 1.0);
            float *p = &rgb[3 * (y * W + x)];
            p[0] = (float)(0.5 * (dx / l + 1.0));
            p[1] = (float)(0.5 * (dy / l + 1.0));
            p[2] = (float)(0.5 * (1.0 / l + 1.0));
        }
    return rs_scene_add_image(s, W, H, rgb, id);
}

/* glTF's metallic-roughness: roughness in G (0.1 to 1 across), metallic in B (0 to 1 down). */
static rs_status add_mr_image(rs_scene *s, uint32_t *id)
{
    enum { W = 16, H = 16 };
    float rgb[W * H * 3];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            float *p = &rgb[3 * (y * W + x)];
            p[0] = 0.0f;
            p[1] = 0.1f + 0.9f * (float)x / (W - 1);
            p[2] = (float)y / (H - 1);
        }
    return rs_scene_add_image(s, W, H, rgb, id);
}

/* An equirectangular sky (rows from the zenith down): blue above, a warm horizon, a dark ground,
 * and a small bright sun 35 degrees from the zenith, so that importance sampling has something
 * to find. */
static rs_status add_sky_image(rs_scene *s, uint32_t *id)
{
    enum { W = 64, H = 32 };
    float rgb[W * H * 3];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            double theta = (y + 0.5) / H * GC_PI, phi = (x + 0.5) / W * 2.0 * GC_PI;
            double up = cos(theta), sun_t = 35.0 * GC_PI / 180.0, sun_p = 0.3 * 2.0 * GC_PI;
            /* angle to the sun's direction */
            double c = sin(theta) * sin(sun_t) * cos(phi - sun_p) + cos(theta) * cos(sun_t);
            float *p = &rgb[3 * (y * W + x)];
            if (up > 0) {
                p[0] = (float)(0.35 + 0.4 * (1 - up));
                p[1] = (float)(0.5 + 0.25 * (1 - up));
                p[2] = (float)(0.9 - 0.2 * (1 - up));
            } else {
                p[0] = p[1] = p[2] = (float)(0.08 + 0.05 * (1 + up));
            }
            if (c > 0.995) {
                p[0] += 60.0f;
                p[1] += 50.0f;
                p[2] += 35.0f;
            }
        }
    return rs_scene_add_image(s, W, H, rgb, id);
}

/* An alpha mask of 16x16 texels: a disc of holes in a frame (0 = a hole). */
static rs_status add_holes_mask(rs_scene *s, uint32_t *id)
{
    enum { W = 16, H = 16 };
    float a[W * H];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            int cx = x % 8, cy = y % 8;
            a[y * W + x] =
                (cx - 3.5f) * (cx - 3.5f) + (cy - 3.5f) * (cy - 3.5f) < 7.0f ? 0.0f : 1.0f;
        }
    return rs_scene_add_mask(s, W, H, a, 1.0f, 0.5f, id);
}

static rs_status add_texture(rs_scene *s, uint32_t type, rs_vec3 a, rs_vec3 b, float scale,
                             uint32_t image, uint32_t *id)
{
    rs_texture t;
    memset(&t, 0, sizeof t);
    t.type = type;
    t.a = a;
    t.b = b;
    t.scale = scale;
    t.image = image;
    return rs_scene_add_texture(s, &t, id);
}

/* ---- geometry ------------------------------------------------------------------------------- */

/* The curved patch: a 4x3 grid of cells over x in [x0, x0 + 2], z in [z0, z0 + 1.2], raised by a
 * smooth bump, with UVs over [0, 2] x [0, 1] (wrapping textures) and the surface's exact unit
 * normals at the vertices. */
static rs_status add_patch(rs_scene *s, float x0, float y0, float z0, uint32_t mat)
{
    enum { NX = 4, NZ = 3 };
    int i, j, k;
    for (j = 0; j < NZ; ++j)
        for (i = 0; i < NX; ++i) {
            /* the cell's corners (i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1) */
            static const int ci[4] = {0, 1, 1, 0}, cj[4] = {0, 0, 1, 1};
            rs_vec3 p[4];
            float uv[4][2], n[4][3];
            for (k = 0; k < 4; ++k) {
                double fx = (double)(i + ci[k]) / NX, fz = (double)(j + cj[k]) / NZ;
                double x = 2.0 * fx, z = 1.2 * fz;
                /* height h = 0.35 sin(pi fx) sin(pi fz); its gradient gives the normal */
                double h = 0.35 * sin(GC_PI * fx) * sin(GC_PI * fz);
                double hx = 0.35 * GC_PI / 2.0 * cos(GC_PI * fx) * sin(GC_PI * fz);
                double hz = 0.35 * GC_PI / 1.2 * sin(GC_PI * fx) * cos(GC_PI * fz);
                double l = sqrt(hx * hx + hz * hz + 1.0);
                p[k] = rs_v3(x0 + (float)x, y0 + (float)h, z0 + (float)z);
                uv[k][0] = (float)(2.0 * fx);
                uv[k][1] = (float)(1.0 - fz);
                n[k][0] = (float)(-hx / l);
                n[k][1] = (float)(1.0 / l);
                n[k][2] = (float)(-hz / l);
            }
            {
                /* two triangles facing up: (0, 2, 1) and (0, 3, 2) */
                static const int tri[2][3] = {{0, 2, 1}, {0, 3, 2}};
                int t, c;
                for (t = 0; t < 2; ++t) {
                    rs_vec3 v[3];
                    float tuv[6], tn[9];
                    for (c = 0; c < 3; ++c) {
                        int q = tri[t][c];
                        v[c] = p[q];
                        tuv[2 * c] = uv[q][0];
                        tuv[2 * c + 1] = uv[q][1];
                        tn[3 * c] = n[q][0];
                        tn[3 * c + 1] = n[q][1];
                        tn[3 * c + 2] = n[q][2];
                    }
                    RS_TRY(rs_scene_add_triangle_full(s, v, tuv, tn, mat));
                }
            }
        }
    return RS_OK;
}

/* A square of two triangles with UVs [0, 2]^2 (so the mask repeats), upright, facing +z. */
static rs_status add_upright_square(rs_scene *s, rs_vec3 lo, float size, uint32_t mat)
{
    rs_vec3 a = lo, b = rs_v3(lo.x + size, lo.y, lo.z), c = rs_v3(lo.x + size, lo.y + size, lo.z),
            d = rs_v3(lo.x, lo.y + size, lo.z), v[3];
    float uv1[6] = {0, 0, 2, 0, 2, 2}, uv2[6] = {0, 0, 2, 2, 0, 2};
    v[0] = a, v[1] = b, v[2] = c;
    RS_TRY(rs_scene_add_triangle_full(s, v, uv1, NULL, mat));
    v[0] = a, v[1] = c, v[2] = d;
    return rs_scene_add_triangle_full(s, v, uv2, NULL, mat);
}

/* The prototype: a square pyramid (base 1 x 1 at y = 0, apex at y = 0.9) of six triangles, its
 * sides alternating two materials, with UVs, rounded vertex normals on the sides and none on the
 * base (its rows are zeros: "use the face's").  Added as the scene's own triangles, then made a
 * prototype; *first, *count name it. */
static rs_status add_pyramid_prototype(rs_scene *s, uint32_t mat_a, uint32_t mat_b, uint32_t *first,
                                       uint32_t *count)
{
    const rs_vec3 base[4] = {rs_v3(-0.5f, 0, -0.5f), rs_v3(0.5f, 0, -0.5f), rs_v3(0.5f, 0, 0.5f),
                             rs_v3(-0.5f, 0, 0.5f)};
    const rs_vec3 apex = rs_v3(0, 0.9f, 0), centre = rs_v3(0, 0.3f, 0);
    uint32_t from = s->n_tris;
    int k, c;
    for (k = 0; k < 4; ++k) {
        /* side k: base k+1, base k, apex, outward (counter-clockwise seen from outside) */
        rs_vec3 v[3];
        float uv[6] = {0, 0, 1, 0, 0.5f, 1}, n[9];
        v[0] = base[(k + 1) % 4];
        v[1] = base[k];
        v[2] = apex;
        for (c = 0; c < 3; ++c) {
            rs_vec3 d = rs_v3_normalize(rs_v3_sub(v[c], centre));
            n[3 * c] = d.x, n[3 * c + 1] = d.y, n[3 * c + 2] = d.z;
        }
        RS_TRY(rs_scene_add_triangle_full(s, v, uv, n, k % 2 ? mat_b : mat_a));
    }
    {
        /* the base, facing down */
        rs_vec3 v[3];
        float uv[6] = {0, 0, 1, 0, 1, 1};
        v[0] = base[0], v[1] = base[1], v[2] = base[2];
        RS_TRY(rs_scene_add_triangle_full(s, v, uv, NULL, mat_a));
        v[0] = base[0], v[1] = base[2], v[2] = base[3];
        RS_TRY(rs_scene_add_triangle_full(s, v, uv, NULL, mat_a));
    }
    return rs_scene_make_prototype(s, from, first, count);
}

/* Places the prototype by x (rs_xform, double) as an instance. */
static rs_status place(rs_scene *s, uint32_t first, uint32_t count, const rs_xform *x)
{
    double m[12];
    int i;
    for (i = 0; i < 3; ++i) {
        m[4 * i] = x->m[i][0];
        m[4 * i + 1] = x->m[i][1];
        m[4 * i + 2] = x->m[i][2];
        m[4 * i + 3] = x->t[i];
    }
    return rs_scene_add_instance(s, first, count, m);
}

static rs_status add_mat(rs_scene *s, rs_material m, uint32_t *id)
{
    return rs_scene_add_material(s, &m, id);
}

static rs_status add_punctual(rs_scene *s, uint32_t type, rs_vec3 pos, rs_vec3 dir, rs_vec3 power,
                              float inner_deg, float outer_deg)
{
    rs_punctual p;
    memset(&p, 0, sizeof p);
    p.type = type;
    p.pos = pos;
    p.dir = dir;
    p.intensity = power;
    p.cos_inner = (float)cos(inner_deg * GC_PI / 180.0);
    p.cos_outer = (float)cos(outer_deg * GC_PI / 180.0);
    return rs_scene_add_punctual(s, &p);
}

/* The scene's textures and the images they read. */
typedef struct gc_tex {
    uint32_t floor, stripes, solid, base, normal, mr, emit, sky_image;
} gc_tex;

static rs_status gc_textures(rs_scene *s, gc_tex *t)
{
    uint32_t i_base, i_normal, i_mr;
    RS_TRY(add_base_image(s, &i_base));
    RS_TRY(add_normal_image(s, &i_normal));
    RS_TRY(add_mr_image(s, &i_mr));
    RS_TRY(add_sky_image(s, &t->sky_image));
    RS_TRY(add_texture(s, RS_TEX_CHECKER, rs_v3(.7f, .7f, .7f), rs_v3(.25f, .25f, .3f), 0.5f, 0,
                       &t->floor));
    RS_TRY(add_texture(s, RS_TEX_STRIPES, rs_v3(.9f, .85f, .2f), rs_v3(.2f, .3f, .8f), 6.0f, 0,
                       &t->stripes));
    RS_TRY(add_texture(s, RS_TEX_SOLID, rs_v3(.3f, .7f, .4f), rs_v3(0, 0, 0), 1.0f, 0, &t->solid));
    RS_TRY(add_texture(s, RS_TEX_IMAGE, rs_v3(0, 0, 0), rs_v3(0, 0, 0), 1.0f, i_base, &t->base));
    RS_TRY(
        add_texture(s, RS_TEX_IMAGE, rs_v3(0, 0, 0), rs_v3(0, 0, 0), 1.0f, i_normal, &t->normal));
    RS_TRY(add_texture(s, RS_TEX_IMAGE, rs_v3(0, 0, 0), rs_v3(0, 0, 0), 1.0f, i_mr, &t->mr));
    RS_TRY(add_texture(s, RS_TEX_STRIPES, rs_v3(1, .6f, .2f), rs_v3(.1f, .1f, .1f), 4.0f, 0,
                       &t->emit));
    return RS_OK;
}

/* The floor, and the back row of spheres: the GGX conductors, rough glass, pbr. */
static rs_status gc_floor_and_back_row(rs_scene *s, const gc_tex *t)
{
    rs_material m;
    uint32_t id;
    rs_vec3 gold_eta = rs_v3(0.143f, 0.375f, 1.442f), gold_k = rs_v3(3.983f, 2.386f, 1.603f);
    /* the floor: a textured quad */
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = t->floor;
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-7, 0, 5), rs_v3(14, 0, 0), rs_v3(0, 0, -12), id));

    /* back row of spheres (z = -2): the GGX conductors, rough glass, pbr */
    RS_TRY(add_mat(s, rs_mat_conductor(gold_eta, gold_k, 0.25f), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-3.6f, 0.6f, -2), 0.6f, id));
    RS_TRY(add_mat(s, rs_mat_conductor_f0(rs_v3(.95f, .64f, .54f), 0.08f), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-2.2f, 0.6f, -2), 0.6f, id));
    RS_TRY(add_mat(s, rs_mat_conductor(gold_eta, gold_k, 0.0f), &id)); /* smooth: a delta */
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-0.8f, 0.6f, -2.2f), 0.6f, id));
    RS_TRY(add_mat(s, rs_mat_rough_dielectric(1.5f, 0.2f), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(0.6f, 0.6f, -2), 0.6f, id));
    m = rs_mat_rough_dielectric(1.33f, 0.0f); /* smooth: a delta, exact Fresnel */
    m.albedo = rs_v3(.8f, .95f, 1.0f);
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(2.0f, 0.6f, -2.2f), 0.6f, id));
    m = rs_mat_pbr(rs_v3(.8f, .3f, .2f), 0.5f, 0.4f);
    m.emission = rs_v3(.6f, .15f, .05f); /* constant: a light, sampled */
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(3.4f, 0.6f, -2), 0.6f, id));
    return RS_OK;
}

/* The middle row: the thesis's materials on small spheres, and the moving sphere. */
static rs_status gc_middle_row(rs_scene *s, const gc_tex *t)
{
    rs_material m;
    uint32_t id, glass, lambert;
    /* middle row (z = -0.6): the thesis's materials on small spheres */
    m = rs_mat_disney_diffuse(rs_v3_splat(1.0f), 0.6f);
    m.albedo_tex = t->base; /* an image on a sphere: longitude/latitude UVs */
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-4.2f, 0.4f, -0.6f), 0.4f, id));
    RS_TRY(add_mat(s, rs_mat_phong(rs_v3(.1f, .3f, .6f), rs_v3(.4f, .4f, .4f), 40.0f), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-1.2f, 0.4f, -0.2f), 0.4f, id));
    RS_TRY(add_mat(s, rs_mat_metal(rs_v3(.8f, .8f, .85f), 0.25f), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-0.2f, 0.4f, -0.4f), 0.4f, id));
    RS_TRY(add_mat(s, rs_mat_dielectric(1.5f), &glass));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(4.3f, 0.4f, -0.6f), 0.4f, glass));
    m = rs_mat_dielectric(1.7f);
    m.flags |= RS_MAT_EXACT_FRESNEL;
    m.albedo = rs_v3(1.0f, .9f, .8f);
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-2.6f, 0.35f, 2.3f), 0.35f, id));
    m = rs_mat_diffuse_uniform(rs_v3_splat(1.0f));
    m.albedo_tex = t->stripes;
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(1.2f, 0.35f, 2.2f), 0.35f, id));
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = t->solid;
    m.flags |= RS_MAT_UNIFORM_SAMPLING;
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(2.3f, 0.35f, 2.3f), 0.35f, id));

    /* the moving sphere: up by 0.5 over the shutter */
    RS_TRY(add_mat(s, rs_mat_lambertian(rs_v3(.8f, .2f, .6f)), &lambert));
    RS_TRY(rs_scene_add_moving_sphere(s, rs_v3(3.3f, 0.45f, 1.0f), 0.0f, rs_v3(3.3f, 0.95f, 1.0f),
                                      1.0f, 0.45f, lambert));
    return RS_OK;
}

/* The area lights, the pbr patch and tile, a two-sided emitter and the alpha cut-out. */
static rs_status gc_lights_and_patches(rs_scene *s, const gc_tex *t)
{
    rs_material m;
    uint32_t id, mask;
    /* lights: a sphere, a one-sided quad facing down, a two-sided triangle (after the patch) */
    RS_TRY(add_mat(s, rs_mat_light(rs_v3(8, 6, 3), 0), &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-2.8f, 1.6f, 0.6f), 0.15f, id));
    RS_TRY(add_mat(s, rs_mat_light(rs_v3(6, 6, 7), 0), &id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-1, 4, -1.5f), rs_v3(2, 0, 0), rs_v3(0, 0, 1.5f), id));

    /* the pbr patch: base colour image, normal map, metallic-roughness map; triangles with UVs
     * and vertex normals */
    m = rs_mat_pbr(rs_v3_splat(1.0f), 1.0f, 0.7f);
    m.albedo_tex = t->base;
    m.normal_tex = t->normal;
    m.normal_scale = 0.8f;
    m.mr_tex = t->mr;
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(add_patch(s, -2.0f, 0.0f, 0.4f, id));

    /* a pbr tile with a textured emission (found by paths only), two triangles with UVs */
    m = rs_mat_pbr(rs_v3(.2f, .2f, .2f), 0.0f, 0.5f);
    m.emission = rs_v3(3, 3, 3);
    m.emission_tex = t->emit;
    RS_TRY(add_mat(s, m, &id));
    {
        rs_vec3 v[3];
        float uv1[6] = {0, 0, 1, 0, 1, 1}, uv2[6] = {0, 0, 1, 1, 0, 1};
        v[0] = rs_v3(-1.2f, 0.01f, 2.9f), v[1] = rs_v3(-0.2f, 0.01f, 2.9f);
        v[2] = rs_v3(-0.2f, 0.01f, 2.1f);
        RS_TRY(rs_scene_add_triangle_full(s, v, uv1, NULL, id));
        v[1] = rs_v3(-0.2f, 0.01f, 2.1f), v[2] = rs_v3(-1.2f, 0.01f, 2.1f);
        RS_TRY(rs_scene_add_triangle_full(s, v, uv2, NULL, id));
    }

    /* a two-sided emitting triangle (with the default UVs, no normals) */
    RS_TRY(add_mat(s, rs_mat_light(rs_v3(2, 4, 8), 1), &id));
    RS_TRY(rs_scene_add_triangle(s, rs_v3(4.6f, 0.2f, -1.4f), rs_v3(5.4f, 0.2f, -1.0f),
                                 rs_v3(5.0f, 1.6f, -1.2f), id));

    /* the alpha cut-out: an upright square of striped triangles with holes, in front of glass */
    RS_TRY(add_holes_mask(s, &mask));
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = t->stripes;
    m.alpha_mask = mask;
    RS_TRY(add_mat(s, m, &id));
    RS_TRY(add_upright_square(s, rs_v3(0.6f, 0.0f, 0.9f), 1.1f, id));
    return RS_OK;
}

/* Two instances of a pyramid prototype whose sides alternate a rough Schlick conductor and a
 * normal-mapped pbr with UVs and vertex normals: one placed obliquely, one mirrored and
 * sheared. */
static rs_status gc_pyramids(rs_scene *s, const gc_tex *tex)
{
    static const double axis[3] = {1, 1, 0.3};
    rs_material m;
    uint32_t proto_first, proto_count, a, b;
    rs_xform r, sc, t, x, sh;
    RS_TRY(add_mat(s, rs_mat_conductor_f0(rs_v3(.9f, .9f, .95f), 0.3f), &a));
    m = rs_mat_pbr(rs_v3(.3f, .6f, .9f), 0.2f, 0.35f);
    m.albedo_tex = tex->base;
    m.normal_tex = tex->normal;
    m.normal_scale = 1.0f;
    RS_TRY(add_mat(s, m, &b));
    RS_TRY(add_pyramid_prototype(s, a, b, &proto_first, &proto_count));
    /* oblique rotation after a non-uniform scale */
    sc = rs_xform_scale(0.9, 1.4, 0.7);
    r = rs_xform_rotate_axis(axis, 35.0);
    t = rs_xform_translate(2.9, 0.35, -0.4);
    x = rs_xform_compose(&r, &sc);
    x = rs_xform_compose(&t, &x);
    RS_TRY(place(s, proto_first, proto_count, &x));
    /* mirrored (det < 0) and sheared, turned about y */
    sc = rs_xform_scale(-1.1, 1.0, 1.0);
    sh = rs_xform_identity();
    sh.m[0][1] = 0.3;
    r = rs_xform_rotate_euler(0.0, 25.0, 0.0);
    t = rs_xform_translate(-3.1, 0.0, 0.6);
    x = rs_xform_compose(&sh, &sc);
    x = rs_xform_compose(&r, &x);
    x = rs_xform_compose(&t, &x);
    RS_TRY(place(s, proto_first, proto_count, &x));
    return RS_OK;
}

/* The punctual lights, the environment map and the camera. */
static rs_status gc_lights_map_camera(rs_scene *s, uint32_t sky_image)
{
    rs_camera_desc cam;
    /* punctual lights */
    RS_TRY(add_punctual(s, RS_PUNCTUAL_POINT, rs_v3(1.5f, 2.5f, 2.5f), rs_v3(0, 0, 0),
                        rs_v3(6, 5, 4), 0, 0));
    RS_TRY(add_punctual(s, RS_PUNCTUAL_SPOT, rs_v3(-1.0f, 3.5f, 3.0f), rs_v3(0.2f, -1.0f, -0.8f),
                        rs_v3(30, 30, 36), 15.0f, 30.0f));
    RS_TRY(add_punctual(s, RS_PUNCTUAL_DIRECTIONAL, rs_v3(0, 0, 0), rs_v3(-0.4f, -1.0f, -0.3f),
                        rs_v3(0.8f, 0.75f, 0.7f), 0, 0));

    /* the environment map, turned 40 degrees about y, slightly tinted */
    {
        float rot[9];
        double a = 40.0 * GC_PI / 180.0;
        rot[0] = (float)cos(a), rot[1] = 0, rot[2] = (float)sin(a);
        rot[3] = 0, rot[4] = 1, rot[5] = 0;
        rot[6] = (float)-sin(a), rot[7] = 0, rot[8] = (float)cos(a);
        RS_TRY(rs_scene_set_environment(s, sky_image, rs_v3(1.0f, 0.95f, 0.9f), rot));
    }

    cam = s->camera; /* the scene's defaults, then the view, through the scene's API */
    cam.from = rs_v3(0.0f, 3.4f, 9.0f);
    cam.at = rs_v3(0.0f, 0.5f, 0.0f);
    cam.up = rs_v3(0, 1, 0);
    cam.vfov_deg = 40.0f;
    cam.aperture = 0.08f;
    cam.focus_dist = 9.0f;
    cam.shutter_open = 0.0f;
    cam.shutter_close = 1.0f;
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background(s, rs_v3(0, 0, 0)); /* the map replaces it */
    rs_scene_set_image_size(s, 96, 64);
    return RS_OK;
}

rs_status rs_builtin_build_gpucheck(rs_scene *s)
{
    gc_tex t;
    RS_TRY(gc_textures(s, &t));
    RS_TRY(gc_floor_and_back_row(s, &t));
    RS_TRY(gc_middle_row(s, &t));
    RS_TRY(gc_lights_and_patches(s, &t));
    RS_TRY(gc_pyramids(s, &t));
    return gc_lights_map_camera(s, t.sky_image);
}
