/* scenes/builtin.c — the built-in scenes. */
#include "scenes/builtin.h"

#include <stdlib.h>
#include <sys/stat.h>

#include "core/try.h"
#include "scenes/builtin_gpucheck.h"
#include "scenes/mesh.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

static rs_material lambertian(float r, float g, float b)
{
    return rs_mat_lambertian(rs_v3(r, g, b));
}

static rs_material light(float r, float g, float b) { return rs_mat_light(rs_v3(r, g, b), 0); }

/* The room of Shirley's Cornell box ("Ray Tracing: The Rest of Your Life" v4), exactly: quads
 * as corner Q and edges u, v; the light emits only downward (its u x v is -y).  Returns the
 * white material in *white_out. */
/* A built-in scene's camera: from `from` looking at `at`, y up, a vertical field of view of
 * `vfov` degrees, the lens and shutter the scene's defaults.  The builders set it (and the image
 * size and background) through the scene's API, as the file loaders do. */
static rs_camera_desc look(const rs_scene *s, rs_vec3 from, rs_vec3 at, float vfov)
{
    rs_camera_desc c = s->camera;
    c.from = from;
    c.at = at;
    c.up = rs_v3(0, 1, 0);
    c.vfov_deg = vfov;
    return c;
}

static rs_status build_cornell_room(rs_scene *s, uint32_t *white_out)
{
    rs_material m;
    rs_camera_desc cam;
    uint32_t red, white, green, lit;
    m = lambertian(.65f, .05f, .05f);
    RS_TRY(rs_scene_add_material(s, &m, &red));
    m = lambertian(.73f, .73f, .73f);
    RS_TRY(rs_scene_add_material(s, &m, &white));
    m = lambertian(.12f, .45f, .15f);
    RS_TRY(rs_scene_add_material(s, &m, &green));
    m = light(15, 15, 15);
    RS_TRY(rs_scene_add_material(s, &m, &lit));

    RS_TRY(rs_scene_add_quad(s, rs_v3(555, 0, 0), rs_v3(0, 0, 555), rs_v3(0, 555, 0), green));
    RS_TRY(rs_scene_add_quad(s, rs_v3(0, 0, 555), rs_v3(0, 0, -555), rs_v3(0, 555, 0), red));
    RS_TRY(rs_scene_add_quad(s, rs_v3(213, 554, 227), rs_v3(130, 0, 0), rs_v3(0, 0, 105), lit));
    RS_TRY(rs_scene_add_quad(s, rs_v3(0, 555, 0), rs_v3(555, 0, 0), rs_v3(0, 0, 555), white));
    RS_TRY(rs_scene_add_quad(s, rs_v3(0, 0, 555), rs_v3(555, 0, 0), rs_v3(0, 0, -555), white));
    RS_TRY(rs_scene_add_quad(s, rs_v3(555, 0, 555), rs_v3(-555, 0, 0), rs_v3(0, 555, 0), white));
    *white_out = white;

    cam = look(s, rs_v3(278, 278, -800), rs_v3(278, 278, 0), 40.0f);
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background(s, rs_v3(0, 0, 0));
    rs_scene_set_image_size(s, 600, 600);
    return RS_OK;
}

static rs_status build_cornell(rs_scene *s)
{
    uint32_t white;
    RS_TRY(build_cornell_room(s, &white));
    RS_TRY(rs_scene_add_box(s, rs_v3(0, 0, 0), rs_v3(165, 330, 165), 15.0f, rs_v3(265, 0, 295),
                            white));
    RS_TRY(rs_scene_add_box(s, rs_v3(0, 0, 0), rs_v3(165, 165, 165), -18.0f, rs_v3(130, 0, 65),
                            white));
    return RS_OK;
}

/* The final scene of "The Rest of Your Life": the short box becomes a glass sphere. */
static rs_status build_cornell_glass(rs_scene *s)
{
    uint32_t white, glass;
    rs_material m = rs_mat_dielectric(1.5f);
    RS_TRY(build_cornell_room(s, &white));
    RS_TRY(rs_scene_add_material(s, &m, &glass));
    RS_TRY(rs_scene_add_box(s, rs_v3(0, 0, 0), rs_v3(165, 330, 165), 15.0f, rs_v3(265, 0, 295),
                            white));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(190, 90, 190), 90.0f, glass));
    return RS_OK;
}

/* splitmix64: the scene generators' own fixed-seed random numbers. */
static double scene_rand(uint64_t *st)
{
    uint64_t z = (*st += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

static float rand_range(uint64_t *st, float lo, float hi)
{
    return lo + (hi - lo) * (float)scene_rand(st);
}

/* One of the small spheres at c: diffuse (moving up over the shutter with `bouncing`), metal or
 * glass as `choose` says, its colour from *st. */
static rs_status add_small_sphere(rs_scene *s, uint64_t *st, rs_vec3 c, float choose,
                                  int bouncing)
{
    rs_material m;
    uint32_t id;
    if (choose < 0.8f) {
        rs_vec3 c1 =
            rs_v3((float)scene_rand(st), (float)scene_rand(st), (float)scene_rand(st));
        rs_vec3 c2 =
            rs_v3((float)scene_rand(st), (float)scene_rand(st), (float)scene_rand(st));
        m = rs_mat_lambertian(rs_v3_mul(c1, c2));
        RS_TRY(rs_scene_add_material(s, &m, &id));
        if (bouncing)
            RS_TRY(rs_scene_add_moving_sphere(
                s, c, 0.0f, rs_v3_add(c, rs_v3(0, rand_range(st, 0, 0.5f), 0)), 1.0f, 0.2f,
                id));
        else
            RS_TRY(rs_scene_add_sphere(s, c, 0.2f, id));
    } else if (choose < 0.95f) {
        m = rs_mat_metal(rs_v3(rand_range(st, .5f, 1), rand_range(st, .5f, 1),
                               rand_range(st, .5f, 1)),
                         rand_range(st, 0, .5f));
        RS_TRY(rs_scene_add_material(s, &m, &id));
        RS_TRY(rs_scene_add_sphere(s, c, 0.2f, id));
    } else {
        m = rs_mat_dielectric(1.5f);
        RS_TRY(rs_scene_add_material(s, &m, &id));
        RS_TRY(rs_scene_add_sphere(s, c, 0.2f, id));
    }
    return RS_OK;
}

/* The random spheres of "Ray Tracing in One Weekend" (v4, §14) — the thesis's Fig. 6.9 scene.
 * With `bouncing`, RTNW's first scene instead: the diffuse spheres move up by up to 0.5 during
 * the shutter and the ground is a checker.  Same layout rules; our own fixed-seed numbers. */
static rs_status build_random_spheres(rs_scene *s, int bouncing)
{
    uint64_t st = 0x5eedULL;
    rs_material m;
    rs_camera_desc cam;
    uint32_t id;
    int a, b;
    if (bouncing) {
        rs_texture checker;
        uint32_t tex;
        memset(&checker, 0, sizeof checker);
        checker.type = RS_TEX_CHECKER;
        checker.a = rs_v3(.2f, .3f, .1f);
        checker.b = rs_v3(.9f, .9f, .9f);
        checker.scale = 0.32f;
        RS_TRY(rs_scene_add_texture(s, &checker, &tex));
        m = rs_mat_lambertian(rs_v3_splat(1.0f));
        m.albedo_tex = tex;
    } else {
        m = rs_mat_lambertian(rs_v3(.5f, .5f, .5f));
    }
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(0, -1000, 0), 1000.0f, id));
    for (a = -11; a < 11; ++a)
        for (b = -11; b < 11; ++b) {
            float choose = (float)scene_rand(&st);
            rs_vec3 c = rs_v3((float)a + 0.9f * (float)scene_rand(&st), 0.2f,
                              (float)b + 0.9f * (float)scene_rand(&st));
            if (rs_v3_length(rs_v3_sub(c, rs_v3(4, 0.2f, 0))) <= 0.9f)
                continue;
            RS_TRY(add_small_sphere(s, &st, c, choose, bouncing));
        }
    m = rs_mat_dielectric(1.5f);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(0, 1, 0), 1.0f, id));
    m = rs_mat_lambertian(rs_v3(.4f, .2f, .1f));
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-4, 1, 0), 1.0f, id));
    m = rs_mat_metal(rs_v3(.7f, .6f, .5f), 0.0f);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(4, 1, 0), 1.0f, id));

    cam = look(s, rs_v3(13, 2, 3), rs_v3(0, 0, 0), 20.0f);
    /* RTIOW v4's defocus angle 0.6 deg at focus distance 10 is a lens of diameter
     * 2 * 10 * tan(0.3 deg) = 0.105 */
    cam.aperture = 0.105f;
    cam.focus_dist = 10.0f;
    if (bouncing) {
        cam.shutter_open = 0.0f;
        cam.shutter_close = 1.0f;
    }
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background_gradient(s, rs_v3(1, 1, 1), rs_v3(.5f, .7f, 1.0f));
    rs_scene_set_image_size(s, 1200, 675);
    return RS_OK;
}

static rs_status build_rtiow_final(rs_scene *s) { return build_random_spheres(s, 0); }

static rs_status build_bouncing_spheres(rs_scene *s) { return build_random_spheres(s, 1); }

/* A UV grid made in memory: 8 x 4 coloured cells with dark lines, so that the orientation and
 * filtering of image textures can be seen (and tested) without a file. */
static rs_status add_uv_grid_image(rs_scene *s, uint32_t *id)
{
    enum { W = 256, H = 128 };
    static float rgb[W * H * 3];
    int x, y;
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            float *p = &rgb[3 * (y * W + x)];
            int cx = x / (W / 8), cy = y / (H / 4);
            int line = (x % (W / 8)) < 2 || (y % (H / 4)) < 2;
            p[0] = line ? 0.02f : 0.15f + 0.8f * (float)cx / 7.0f;
            p[1] = line ? 0.02f : 0.15f + 0.8f * (float)cy / 3.0f;
            p[2] = line ? 0.02f : ((cx + cy) & 1 ? 0.7f : 0.2f);
        }
    return rs_scene_add_image(s, W, H, rgb, id);
}

/* The materials scene's textures: the floor's checker, a 3D checker, stripes and a UV grid. */
static rs_status materials_textures(rs_scene *s, uint32_t *t_floor, uint32_t *t_checker,
                                    uint32_t *t_stripes, uint32_t *t_image)
{
    rs_texture tex;
    uint32_t image;
    memset(&tex, 0, sizeof tex);
    tex.type = RS_TEX_CHECKER;
    tex.a = rs_v3(.75f, .75f, .75f);
    tex.b = rs_v3(.25f, .25f, .28f);
    tex.scale = 1.0f;
    RS_TRY(rs_scene_add_texture(s, &tex, t_floor));
    tex.a = rs_v3(.9f, .8f, .1f);
    tex.b = rs_v3(.1f, .2f, .6f);
    tex.scale = 0.3f;
    RS_TRY(rs_scene_add_texture(s, &tex, t_checker));
    tex.type = RS_TEX_STRIPES;
    tex.a = rs_v3(.85f, .85f, .85f);
    tex.b = rs_v3(.7f, .1f, .1f);
    tex.scale = 12.0f;
    RS_TRY(rs_scene_add_texture(s, &tex, t_stripes));
    RS_TRY(add_uv_grid_image(s, &image));
    tex.type = RS_TEX_IMAGE;
    tex.image = image;
    RS_TRY(rs_scene_add_texture(s, &tex, t_image));
    return RS_OK;
}

/* Every material and texture side by side, on a checker floor under an area light and a sky:
 *   back row:   Disney diffuse at roughness 0, 0.5, 1; Lambertian; uniform-hemisphere diffuse
 *   middle row: Phong at exponents 10, 100, 1000; fuzzy metal; mirror
 *   front row:  glass; 3D checker; stripes; image texture; a sphere light */
static rs_status build_materials(rs_scene *s)
{
    static const float phong_n[3] = {10.0f, 100.0f, 1000.0f};
    rs_vec3 warm = rs_v3(.8f, .45f, .25f);
    rs_material m;
    rs_camera_desc cam;
    uint32_t id, t_floor, t_checker, t_stripes, t_image;
    int i;
    RS_TRY(materials_textures(s, &t_floor, &t_checker, &t_stripes, &t_image));

    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = t_floor;
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-20, 0, 20), rs_v3(40, 0, 0), rs_v3(0, 0, -40), id));

    for (i = 0; i < 3; ++i) { /* back row */
        m = rs_mat_disney_diffuse(warm, 0.5f * (float)i);
        RS_TRY(rs_scene_add_material(s, &m, &id));
        RS_TRY(rs_scene_add_sphere(s, rs_v3(-4.0f + 2.0f * (float)i, 0.8f, -2.2f), 0.8f, id));
    }
    m = rs_mat_lambertian(warm);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(2, 0.8f, -2.2f), 0.8f, id));
    m = rs_mat_diffuse_uniform(warm);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(4, 0.8f, -2.2f), 0.8f, id));

    for (i = 0; i < 3; ++i) { /* middle row */
        m = rs_mat_phong(rs_v3(.1f, .25f, .6f), rs_v3(.35f, .35f, .35f), phong_n[i]);
        RS_TRY(rs_scene_add_material(s, &m, &id));
        RS_TRY(rs_scene_add_sphere(s, rs_v3(-4.0f + 2.0f * (float)i, 0.8f, 0), 0.8f, id));
    }
    m = rs_mat_metal(rs_v3(.8f, .8f, .85f), 0.3f);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(2, 0.8f, 0), 0.8f, id));
    m = rs_mat_metal(rs_v3(.9f, .9f, .9f), 0.0f);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(4, 0.8f, 0), 0.8f, id));

    m = rs_mat_dielectric(1.5f); /* front row */
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-4, 0.8f, 2.2f), 0.8f, id));
    m = rs_mat_lambertian(rs_v3_splat(1.0f));
    m.albedo_tex = t_checker;
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(-2, 0.8f, 2.2f), 0.8f, id));
    m.albedo_tex = t_stripes;
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(0, 0.8f, 2.2f), 0.8f, id));
    m.albedo_tex = t_image;
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(2, 0.8f, 2.2f), 0.8f, id));
    m = rs_mat_light(rs_v3(4, 3.2f, 2), 0);
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(4, 0.8f, 2.2f), 0.5f, id));

    m = rs_mat_light(rs_v3(6, 6, 6), 0); /* the key light, facing down */
    RS_TRY(rs_scene_add_material(s, &m, &id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-3, 7, -3), rs_v3(6, 0, 0), rs_v3(0, 0, 6), id));

    cam = look(s, rs_v3(0, 6.5f, 11), rs_v3(0, 0.5f, 0), 38.0f);
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background_gradient(s, rs_v3(.12f, .12f, .12f), rs_v3(.25f, .35f, .5f));
    rs_scene_set_image_size(s, 960, 540);
    return RS_OK;
}

#ifndef RS_DEFAULT_MODELS_DIR
#  define RS_DEFAULT_MODELS_DIR "../shared/models"
#endif

const char *rs_builtin_models_dir(const char *dir)
{
    const char *env = getenv("RS_MODELS_DIR");
    if (dir && *dir)
        return dir;
    if (env && *env)
        return env;
    return RS_DEFAULT_MODELS_DIR;
}

/* Adds model `rel` (under the models folder) fitted to `size` with its base at `base`. */
static rs_status add_model(rs_scene *s, const rs_builtin_opts *o, const char *rel, float size,
                           rs_vec3 base, float rot_y, uint32_t mat)
{
    char path[1024];
    struct stat sb;
    rs_mesh_opts mo = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const char *dir = rs_builtin_models_dir(o ? o->models_dir : NULL);
    snprintf(path, sizeof path, "%s/%s", dir, rel);
    if (stat(path, &sb) != 0)
        return rs_error_set(RS_ERR_IO,
                            "builtin:%s needs %s from the test models, not found in '%s' (use "
                            "--models DIR)",
                            s->name, rel, dir);
    mo.rotate_deg = rs_v3(0, rot_y, 0);
    mo.fit = 1;
    mo.fit_size = size;
    mo.fit_base = base;
    return rs_scene_add_mesh(s, path, &mo, &info);
}

/* The thesis's Fig. 6.8: a Phong teapot in the Cornell box (the boxes removed). */
static rs_status build_cornell_teapot(rs_scene *s, const rs_builtin_opts *o)
{
    uint32_t white, teapot;
    rs_material m = rs_mat_phong(rs_v3(.15f, .3f, .55f), rs_v3(.35f, .35f, .35f), 60.0f);
    RS_TRY(build_cornell_room(s, &white));
    RS_TRY(rs_scene_add_material(s, &m, &teapot));
    return add_model(s, o, "teapot/teapot.obj", 330.0f, rs_v3(278, 0, 260), 25.0f, teapot);
}

/* The thesis's Figs. 6.2 and 6.4: the Stanford bunny and the teapot in the Cornell box. */
static rs_status build_cornell_bunny_teapot(rs_scene *s, const rs_builtin_opts *o)
{
    uint32_t white, teapot, bunny;
    rs_material m = rs_mat_metal(rs_v3(.85f, .75f, .55f), 0.15f);
    RS_TRY(build_cornell_room(s, &white));
    RS_TRY(rs_scene_add_material(s, &m, &teapot));
    m = rs_mat_lambertian(rs_v3(.75f, .72f, .68f));
    RS_TRY(rs_scene_add_material(s, &m, &bunny));
    RS_TRY(add_model(s, o, "bunny/bun_zipper.ply", 290.0f, rs_v3(375, 0, 345), -20.0f, bunny));
    return add_model(s, o, "teapot/teapot.obj", 270.0f, rs_v3(185, 0, 185), 30.0f, teapot);
}

/* `--mesh FILE`: any mesh, scaled to fit and centred on the Cornell box's floor, with its own
 * materials (a file without any gets a light grey). */
static rs_status build_cornell_mesh(rs_scene *s, const rs_builtin_opts *o)
{
    uint32_t white;
    rs_mesh_opts mo = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    rs_mesh_info info;
    if (!o || !o->mesh_file)
        return rs_error_set(RS_ERR_ARG, "builtin:cornell-mesh needs a mesh file (--mesh FILE)");
    RS_TRY(build_cornell_room(s, &white));
    mo.fit = 1;
    mo.fit_size = 330.0f;
    mo.fit_base = rs_v3(278, 0, 278);
    RS_TRY(rs_scene_add_mesh(s, o->mesh_file, &mo, &info));
    if (o->log) {
        char why[160], strips[64] = "";
        if (info.strips)
            snprintf(strips, sizeof strips, " (from %u triangle strips)", info.strips);
        fprintf(o->log, "raystream: %s: %u triangles%s, %u material%s from the file%s%s\n",
                o->mesh_file, info.triangles, strips, info.materials,
                info.materials == 1 ? "" : "s", info.dropped ? "; " : "",
                rs_mesh_dropped_text(&info, why, sizeof why));
    } else if (info.dropped) {
        char why[160];
        fprintf(stderr, "raystream: warning: %s: %s; %u triangles kept\n", o->mesh_file,
                rs_mesh_dropped_text(&info, why, sizeof why), info.triangles);
    }
    return RS_OK;
}

/* White furnace: a diffuse sphere of albedo 0.5 filling the whole view, under a uniform white
 * background of radiance 1.  Every pixel's expected value is exactly 0.5 (the sphere is convex,
 * so each bounce leaves it and sees the background). */
static rs_status build_furnace(rs_scene *s)
{
    rs_material m = lambertian(0.5f, 0.5f, 0.5f);
    rs_camera_desc cam;
    uint32_t grey;
    RS_TRY(rs_scene_add_material(s, &m, &grey));
    RS_TRY(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, grey));
    /* the sphere subtends asin(1/5) = 11.5 deg; a 14 deg frame's corners are 9.9 deg off axis */
    cam = look(s, rs_v3(0, 0, 5), rs_v3(0, 0, 0), 14.0f);
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background(s, rs_v3(1, 1, 1));
    rs_scene_set_image_size(s, 64, 64);
    return RS_OK;
}

/* Many lights (issue 29's light-sampler benchmark): a 24 x 24 floor and a back wall lit only
 * by a 14 x 14 grid of small emissive quads facing down at heights 0.6 to 1.4, each of its own
 * colour and strength (4 to 40, a few of them bright), and 24 small emissive spheres: 220
 * lights, most of them far from any one point, so that picking them by power wastes most
 * shadow rays. */
/* A number in [0, 1) from the scene's own generator (one statement each: a fixed order). */
static float many_rnd(uint64_t *r)
{
    *r = *r * 6364136223846793005ull + 1442695040888963407ull;
    return (float)((*r >> 40) * (1.0 / 16777216.0));
}

static rs_status build_many_lights(rs_scene *s)
{
    rs_material floor_m = lambertian(0.6f, 0.6f, 0.6f), wall_m = lambertian(0.4f, 0.5f, 0.6f);
    uint32_t floor_id, wall_id, i, j;
    uint64_t r = 0x9e3779b97f4a7c15ull;
    rs_camera_desc cam;
    RS_TRY(rs_scene_add_material(s, &floor_m, &floor_id));
    RS_TRY(rs_scene_add_material(s, &wall_m, &wall_id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-12, 0, -12), rs_v3(0, 0, 24), rs_v3(24, 0, 0), floor_id));
    RS_TRY(rs_scene_add_quad(s, rs_v3(-12, 0, -12), rs_v3(24, 0, 0), rs_v3(0, 6, 0), wall_id));
    for (j = 0; j < 14; ++j)
        for (i = 0; i < 14; ++i) {
            float x = -11.0f + 22.0f * ((float)i + 0.2f + 0.6f * many_rnd(&r)) / 14.0f;
            float z = -11.0f + 22.0f * ((float)j + 0.2f + 0.6f * many_rnd(&r)) / 14.0f;
            float y = 0.6f + 0.8f * many_rnd(&r), k = many_rnd(&r), cr, cg, cb;
            rs_material m;
            uint32_t id;
            k = 4.0f + 36.0f * k * many_rnd(&r);
            cr = 0.4f + 0.6f * many_rnd(&r);
            cg = 0.4f + 0.6f * many_rnd(&r);
            cb = 0.4f + 0.6f * many_rnd(&r);
            m = rs_mat_light(rs_v3(k * cr, k * cg, k * cb), 0);
            RS_TRY(rs_scene_add_material(s, &m, &id));
            /* u x v points down: the quad emits toward the floor */
            RS_TRY(rs_scene_add_quad(s, rs_v3(x, y, z), rs_v3(0.3f, 0, 0), rs_v3(0, 0, 0.3f), id));
        }
    for (i = 0; i < 24; ++i) {
        float k = 2.0f + 10.0f * many_rnd(&r), cx, cy, cz;
        rs_material m = rs_mat_light(rs_v3(k, 0.8f * k, 0.5f * k), 0);
        uint32_t id;
        cx = -11.0f + 22.0f * many_rnd(&r);
        cy = 0.15f + 0.3f * many_rnd(&r);
        cz = -11.0f + 22.0f * many_rnd(&r);
        RS_TRY(rs_scene_add_material(s, &m, &id));
        RS_TRY(rs_scene_add_sphere(s, rs_v3(cx, cy, cz), 0.1f, id));
    }
    cam = look(s, rs_v3(0, 9, 16), rs_v3(0, 0, -1), 50.0f);
    rs_scene_set_camera(s, &cam);
    rs_scene_set_background(s, rs_v3(0, 0, 0));
    rs_scene_set_image_size(s, 400, 300);
    return RS_OK;
}

typedef struct builtin {
    const char *name;
    const char *description;
    rs_status (*build)(rs_scene *s);
    rs_status (*build_ex)(rs_scene *s, const rs_builtin_opts *o); /* scenes that read files */
} builtin;

static const builtin g_builtins[] = {
    {"cornell", "the two-box Cornell box of Ray Tracing: The Rest of Your Life (default)",
     build_cornell, NULL},
    {"cornell-glass", "the final scene of The Rest of Your Life: a glass sphere for the short box",
     build_cornell_glass, NULL},
    {"materials", "every material and texture side by side (Disney, Phong, metal, glass, ...)",
     build_materials, NULL},
    {"rtiow-final", "the random spheres of Ray Tracing in One Weekend (the thesis's Fig. 6.9)",
     build_rtiow_final, NULL},
    {"bouncing-spheres", "The Next Week's motion-blur scene: moving spheres, checker ground",
     build_bouncing_spheres, NULL},
    {"cornell-teapot", "a Phong Utah teapot in the Cornell box (thesis Fig. 6.8; needs the models)",
     NULL, build_cornell_teapot},
    {"cornell-bunny-teapot",
     "the Stanford bunny and a metal teapot in the Cornell box (thesis Figs. 6.2, 6.4)", NULL,
     build_cornell_bunny_teapot},
    {"furnace", "white furnace: an albedo-0.5 diffuse sphere under a white sky (renders 0.5)",
     build_furnace, NULL},
    {"many-lights", "a floor under 220 small lights of many colours (the light sampler's test)",
     build_many_lights, NULL},
    {"gpucheck", "every material, texture, light and primitive the GPU shades (the GPU check's)",
     rs_builtin_build_gpucheck, NULL},
};

#define N_BUILTINS ((int)(sizeof g_builtins / sizeof g_builtins[0]))

const char *rs_builtin_name(int i, const char **description)
{
    if (i < 0 || i >= N_BUILTINS)
        return NULL;
    if (description)
        *description = g_builtins[i].description;
    return g_builtins[i].name;
}

rs_status rs_builtin_create(const char *name, rs_scene **out)
{
    return rs_builtin_create_ex(name, NULL, out);
}

/* Creates scene `name` with one of the two builder forms, then finalizes it. */
static rs_status make_scene(const char *name, rs_status (*build)(rs_scene *),
                            rs_status (*build_ex)(rs_scene *, const rs_builtin_opts *),
                            const rs_builtin_opts *opts, rs_scene **out)
{
    rs_scene *s;
    rs_status st = rs_scene_create(name, &s);
    if (st == RS_OK)
        st = build ? build(s) : build_ex(s, opts);
    if (st == RS_OK)
        st = rs_scene_finalize(s);
    if (st != RS_OK) {
        rs_scene_destroy(s);
        return st;
    }
    *out = s;
    return RS_OK;
}

rs_status rs_builtin_create_ex(const char *name, const rs_builtin_opts *opts, rs_scene **out)
{
    int i;
    *out = NULL;
    if (strcmp(name, "cornell-mesh") == 0)
        return make_scene(name, NULL, build_cornell_mesh, opts, out);
    for (i = 0; i < N_BUILTINS; ++i)
        if (strcmp(name, g_builtins[i].name) == 0)
            return make_scene(name, g_builtins[i].build, g_builtins[i].build_ex, opts, out);
    {
        char known[256] = "";
        for (i = 0; i < N_BUILTINS; ++i) {
            strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
            strncat(known, g_builtins[i].name, sizeof known - strlen(known) - 1);
        }
        return rs_error_set(RS_ERR_ARG, "unknown built-in scene '%s' (known: %s)", name, known);
    }
}
