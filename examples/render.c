/* examples/render.c — the C API's example (docs/api.md): renders a scene given on the command line
 * (or builtin:cornell), or a small scene built here with a mesh from arrays, and writes it.
 *
 *   cc render.c $(pkg-config --cflags --libs raystream) -o render
 *   ./render builtin:cornell cornell.exr spp=16 width=300   # SCENE OUT [OPTION=VALUE ...]
 *   ./render --build built.png                              # the scene below
 * The options are `raystream render`'s (without "--"); the default here is spp=16. */
#include <raystream.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Prints the progress on one line; returning non-zero would cancel the render. */
static int progress(void *user, double fraction)
{
    (void)user;
    fprintf(stderr, "\r%5.1f%%", 100.0 * fraction);
    return 0;
}

/* A red ground triangle pair (a mesh from arrays), a glass sphere and a quad light. */
static raystream_status build(raystream_scene **out)
{
    static const float positions[] = {-4, 0, -4, 4, 0, -4, 4, 0, 4, -4, 0, 4};
    static const uint32_t indices[] = {0, 2, 1, 0, 3, 2};
    const float center[3] = {0, 1, 0}, q[3] = {-1, 3.5f, -1}, u[3] = {2, 0, 0}, v[3] = {0, 0, 2};
    const float from[3] = {0, 2, 6}, at[3] = {0, 1, 0}, up[3] = {0, 1, 0};
    uint32_t red, glass, light;
    raystream_scene *s;
    raystream_status st = raystream_scene_create(&s);
    if (st != RAYSTREAM_OK)
        return st;
    if ((st = raystream_scene_add_material(s,
                                           "{\"type\": \"lambertian\", \"albedo\": [0.7, 0.2, "
                                           "0.2]}",
                                           &red)) != RAYSTREAM_OK ||
        (st = raystream_scene_add_material(s, "{\"type\": \"dielectric\", \"ior\": 1.5}",
                                           &glass)) != RAYSTREAM_OK ||
        (st = raystream_scene_add_material(s, "{\"type\": \"light\", \"emission\": [8, 8, 8]}",
                                           &light)) != RAYSTREAM_OK ||
        (st = raystream_scene_add_mesh(s, positions, 4, indices, 2, NULL, NULL, red)) !=
            RAYSTREAM_OK ||
        (st = raystream_scene_add_sphere(s, center, 1.0f, glass)) != RAYSTREAM_OK ||
        (st = raystream_scene_add_quad(s, q, u, v, light)) != RAYSTREAM_OK ||
        (st = raystream_scene_set_camera(s, from, at, up, 40.0f, 0.0f, 0.0f)) != RAYSTREAM_OK ||
        (st = raystream_scene_set_image_size(s, 320, 240)) != RAYSTREAM_OK) {
        raystream_scene_release(s);
        return st;
    }
    *out = s;
    return RAYSTREAM_OK;
}

int main(int argc, char **argv)
{
    const char *scene = argc > 1 ? argv[1] : "builtin:cornell";
    const char *out = argc > 2 ? argv[2] : "out.exr";
    raystream_options *opt;
    raystream_scene *built = NULL;
    raystream_image *img = NULL;
    raystream_status st;
    int i;
    if (raystream_options_create(&opt) != RAYSTREAM_OK ||
        raystream_options_set(opt, "spp", "16") != RAYSTREAM_OK) {
        fprintf(stderr, "render: %s\n", raystream_last_error());
        return 2;
    }
    for (i = 3; i < argc; ++i) { /* NAME=VALUE */
        char name[64];
        const char *eq = strchr(argv[i], '=');
        snprintf(name, sizeof name, "%.*s", eq ? (int)(eq - argv[i]) : 0, argv[i]);
        if (!eq || raystream_options_set(opt, name, eq + 1) != RAYSTREAM_OK) {
            fprintf(stderr, "render: %s: %s\n", argv[i],
                    eq ? raystream_last_error() : "expected OPTION=VALUE");
            raystream_options_release(opt);
            return 2;
        }
    }
    raystream_options_set_progress(opt, progress, NULL);
    if (strcmp(scene, "--build") == 0)
        st = build(&built);
    else
        st = RAYSTREAM_OK;
    if (st == RAYSTREAM_OK)
        st = built ? raystream_render(built, opt, &img) : raystream_render_scene(scene, opt, &img);
    fprintf(stderr, "\n");
    if (st == RAYSTREAM_OK)
        st = raystream_image_write(img, out);
    if (st != RAYSTREAM_OK)
        fprintf(stderr, "render: %s\n", raystream_last_error());
    else
        printf("%s: %ux%u, %.0f spp (raystream %s)\n", out, raystream_image_width(img),
               raystream_image_height(img), raystream_image_spp(img), raystream_version_string());
    raystream_image_release(img);
    raystream_scene_release(built);
    raystream_options_release(opt);
    return st == RAYSTREAM_OK ? 0 : 1;
}
