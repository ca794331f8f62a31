/* app/scene_load.c — the scene of a render or an export: a built-in one, a JSON scene file or a
 * glTF file, with --mesh and --envmap, read under the load watchdog (app/signals.h); and
 * `raystream export`, which writes it back as a scene file. */
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#include "app/checkpoint.h"
#include "app/render_run.h"
#include "app/signals.h"
#include "core/file.h"
#include "scenes/builtin.h"
#include "scenes/gltf.h"
#include "scenes/scene_export.h"
#include "scenes/scene_json.h"
#include "scenes/sky.h"

/* The stem of a file name: dir/bunny.ply -> bunny. */
static void file_stem(const char *path, char *out, size_t n)
{
    const char *slash = strrchr(path, '/'), *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    snprintf(out, n, "%.*s", dot ? (int)(dot - name) : (int)strlen(name), name);
}

/* builtin:NAME, with --mesh named after the mesh.  Returns an exit code. */
static int load_builtin(const rs_cli_options *o, render_run *r)
{
    rs_builtin_opts bo;
    rs_status bst;
    struct stat sb;
    if (o->mesh && stat(o->mesh, &sb) == 0 && S_ISDIR(sb.st_mode)) {
        rs_app_print("raystream: --mesh %s: is a folder, not a mesh file\n", o->mesh);
        return RS_EXIT_USAGE;
    }
    bo.models_dir = o->models;
    bo.mesh_file = o->mesh;
    bo.log = rs_app_log(o->quiet);
    bst = rs_builtin_create_ex(o->scene + 8, &bo, &r->scene);
    if (bst != RS_OK)
        return rs_app_fail(bst == RS_ERR_ARG && !o->mesh ? RS_EXIT_USAGE : RS_EXIT_RUNTIME, NULL);
    if (o->mesh)
        file_stem(o->mesh, r->name, sizeof r->name);
    else
        snprintf(r->name, sizeof r->name, "%s", o->scene + 8);
    return RS_EXIT_OK;
}

/* The scene: a built-in one (with --mesh, named after the mesh) or a JSON file.  Returns an
 * exit code. */
static int load_scene(const rs_cli_options *o, render_run *r)
{
    struct stat sb;
    if (strncmp(o->scene, "builtin:", 8) == 0)
        return load_builtin(o, r);
    if (stat(o->scene, &sb) != 0) {
        rs_app_print("raystream: %s: no such scene file (built-in scenes are named "
                     "builtin:NAME; see 'raystream scenes')\n",
                     o->scene);
        return RS_EXIT_USAGE;
    }
    if (S_ISDIR(sb.st_mode)) {
        rs_app_print("raystream: %s: is a folder, not a scene file\n", o->scene);
        return RS_EXIT_USAGE;
    }
    if (rs_is_gltf_path(o->scene)) {
        rs_gltf_opts go;
        go.camera = o->camera;
        go.log = rs_app_log(o->quiet);
        go.extensions = r->gltf_extensions;
        go.extensions_n = sizeof r->gltf_extensions;
        if (rs_scene_load_gltf(o->scene, &go, &r->scene) != RS_OK)
            return rs_app_fail(RS_EXIT_RUNTIME, NULL);
    } else if (rs_scene_load_json_ex(o->scene, rs_app_log(o->quiet), &r->scene) != RS_OK) {
        return rs_app_fail(RS_EXIT_RUNTIME, NULL);
    }
    if (o->flatten_instances && r->scene->n_instances) {
        /* the image is the instanced scene's bit for bit: so is its checkpoint key */
        if (o->checkpoint || o->resume)
            r->scene_hash = rs_checkpoint_scene_hash(r->scene);
        if (rs_scene_flatten_instances(r->scene) != RS_OK || rs_scene_finalize(r->scene) != RS_OK)
            return rs_app_fail(RS_EXIT_RUNTIME, "flattening the instances");
    }
    file_stem(o->scene, r->name, sizeof r->name);
    return RS_EXIT_OK;
}

static int apply_envmap(const rs_cli_options *o, render_run *r);

/* --background sky[:...], or a glTF file's default sky (a glTF file has no environment). */
static int apply_sky(const rs_cli_options *o, render_run *r)
{
    rs_sky_params p;
    char why[200];
    if (o->background_kind == RS_BG_SKY) {
        if (!rs_sky_parse(o->background + 3, &p, why, sizeof why)) {
            rs_app_print("raystream: --background %s: %s\n", o->background, why);
            return RS_EXIT_USAGE;
        }
    } else {
        const rs_camera_desc *c = &r->scene->camera;
        rs_sky_default_for_camera(c->from, c->at, &p);
        snprintf(r->lighting, sizeof r->lighting,
                 "the default sky (sky:elevation=45,azimuth=%.0f: the sun behind the camera, to "
                 "its left; a glTF file has no environment: --background to change)",
                 (double)p.azimuth_deg);
    }
    if (rs_scene_set_sky(r->scene, &p) != RS_OK || rs_scene_finalize(r->scene) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "the sky");
    return RS_EXIT_OK;
}

/* --background R,G,B: a constant radiance, sampled as a light when not black. */
static int apply_color(const rs_cli_options *o, render_run *r)
{
    r->scene->env_image = RS_NO_TEXTURE;
    r->scene->background_sky = 0;
    r->scene->background =
        rs_v3(o->background_rgb[0], o->background_rgb[1], o->background_rgb[2]);
    if (rs_scene_finalize(r->scene) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "--background");
    return RS_EXIT_OK;
}

/* --background (or --envmap) in place of the scene's own; with neither, a glTF file gets the
 * default sky. */
static int apply_background(const rs_cli_options *o, render_run *r)
{
    if (o->background_kind == RS_BG_SKY ||
        (o->background_kind == RS_BG_NONE && rs_is_gltf_path(o->scene)))
        return apply_sky(o, r);
    if (o->background_kind == RS_BG_COLOR)
        return apply_color(o, r);
    return apply_envmap(o, r);
}

/* --envmap FILE: the scene's background becomes the map, sampled as a light. */
static int apply_envmap(const rs_cli_options *o, render_run *r)
{
    uint32_t image;
    if (!o->envmap)
        return RS_EXIT_OK;
    if (rs_file_check(o->envmap, RS_FILE_MAX_IMAGE_BYTES, NULL) != RS_OK ||
        rs_scene_load_image(r->scene, o->envmap, &image) != RS_OK ||
        rs_scene_set_environment(r->scene, image, rs_v3_splat(o->envmap_scale), NULL) != RS_OK ||
        rs_scene_finalize(r->scene) != RS_OK) {
        char msg[600];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        if (strncmp(msg, o->envmap, strlen(o->envmap)) != 0)
            rs_error_set(RS_ERR_ARG, "--envmap %s: %s", o->envmap, msg);
        else
            rs_error_set(RS_ERR_ARG, "--envmap %s", msg);
        return rs_app_fail(RS_EXIT_RUNTIME, NULL);
    }
    return RS_EXIT_OK;
}

typedef struct load_args {
    const rs_cli_options *o;
    render_run *r;
} load_args;

static int load_and_light(void *arg)
{
    load_args *a = (load_args *)arg;
    int code = load_scene(a->o, a->r);
    if (code == RS_EXIT_OK)
        code = apply_background(a->o, a->r);
    return code;
}

int rs_run_load_scene(const rs_cli_options *o, render_run *r)
{
    load_args a;
    a.o = o;
    a.r = r;
    /* only what this render reads: the light BVH for --light-sampler bvh, the mip pyramids for
     * trilinear textures (a large scene or texture spent gigabytes on them otherwise) */
    rs_scene_set_extras(o->light_sampler == RS_LIGHT_SAMPLER_BVH,
                        o->texture_filter == RS_TEXTURE_TRILINEAR);
    if (r->library) /* a library never ends its program */
        return load_and_light(&a);
    return rs_load_watch_run(o->mesh ? o->mesh : o->scene, load_and_light, &a);
}

/* raystream export SCENE -o FILE.json */
int rs_cmd_export(const rs_cli_options *o)
{
    render_run r;
    int code;
    size_t n = o->output ? strlen(o->output) : 0;
    if (!o->output || n < 5 || strcmp(o->output + n - 5, ".json") != 0) {
        rs_app_print("raystream: export needs -o FILE.json\n");
        return RS_EXIT_USAGE;
    }
    memset(&r, 0, sizeof r);
    if ((code = rs_run_load_scene(o, &r)) == RS_EXIT_OK) {
        /* the format's instances are written as the copies they render as */
        if (r.scene->n_instances &&
            (rs_scene_flatten_instances(r.scene) != RS_OK || rs_scene_finalize(r.scene) != RS_OK))
            code = rs_app_fail(RS_EXIT_RUNTIME, NULL);
        else if (rs_scene_export_json(r.scene, o->output) != RS_OK)
            code = rs_app_fail(RS_EXIT_RUNTIME, NULL);
        else if (!o->quiet)
            rs_app_print("raystream: wrote %s (%u spheres, %u quads, %u triangles)\n", o->output,
                         r.scene->n_spheres, r.scene->n_quads, r.scene->n_tris);
    }
    rs_run_release(&r);
    return code;
}
