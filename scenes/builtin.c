/* scenes/builtin.c — the built-in scenes. */
#include "scenes/builtin.h"

#include <stdio.h>
#include <string.h>

static rs_material lambertian(float r, float g, float b)
{
    rs_material m;
    memset(&m, 0, sizeof m);
    m.type = RS_MAT_LAMBERTIAN;
    m.albedo = rs_v3(r, g, b);
    return m;
}

static rs_material light(float r, float g, float b)
{
    rs_material m;
    memset(&m, 0, sizeof m);
    m.type = RS_MAT_DIFFUSE_LIGHT;
    m.emission = rs_v3(r, g, b);
    return m;
}

#define TRY(expr)                                                                                  \
  do {                                                                                             \
    rs_status st_ = (expr);                                                                        \
    if (st_ != RS_OK)                                                                              \
      return st_;                                                                                  \
  } while (0)

/* The two-box Cornell box of Shirley's "Ray Tracing: The Rest of Your Life" (v4), exactly:
 * quads as corner Q and edges u, v; the light emits only downward (its u x v is -y). */
static rs_status build_cornell(rs_scene *s)
{
    rs_material m;
    uint32_t red, white, green, lit;
    m = lambertian(.65f, .05f, .05f);
    TRY(rs_scene_add_material(s, &m, &red));
    m = lambertian(.73f, .73f, .73f);
    TRY(rs_scene_add_material(s, &m, &white));
    m = lambertian(.12f, .45f, .15f);
    TRY(rs_scene_add_material(s, &m, &green));
    m = light(15, 15, 15);
    TRY(rs_scene_add_material(s, &m, &lit));

    TRY(rs_scene_add_quad(s, rs_v3(555, 0, 0), rs_v3(0, 0, 555), rs_v3(0, 555, 0), green));
    TRY(rs_scene_add_quad(s, rs_v3(0, 0, 555), rs_v3(0, 0, -555), rs_v3(0, 555, 0), red));
    TRY(rs_scene_add_quad(s, rs_v3(213, 554, 227), rs_v3(130, 0, 0), rs_v3(0, 0, 105), lit));
    TRY(rs_scene_add_quad(s, rs_v3(0, 555, 0), rs_v3(555, 0, 0), rs_v3(0, 0, 555), white));
    TRY(rs_scene_add_quad(s, rs_v3(0, 0, 555), rs_v3(555, 0, 0), rs_v3(0, 0, -555), white));
    TRY(rs_scene_add_quad(s, rs_v3(555, 0, 555), rs_v3(-555, 0, 0), rs_v3(0, 555, 0), white));

    TRY(rs_scene_add_box(s, rs_v3(0, 0, 0), rs_v3(165, 330, 165), 15.0f, rs_v3(265, 0, 295),
                         white));
    TRY(rs_scene_add_box(s, rs_v3(0, 0, 0), rs_v3(165, 165, 165), -18.0f, rs_v3(130, 0, 65),
                         white));

    s->camera.from = rs_v3(278, 278, -800);
    s->camera.at = rs_v3(278, 278, 0);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 40.0f;
    s->background = rs_v3(0, 0, 0);
    s->width = s->height = 600;
    return RS_OK;
}

/* White furnace: a diffuse sphere of albedo 0.5 filling the whole view, under a uniform white
 * background of radiance 1.  Every pixel's expected value is exactly 0.5 (the sphere is convex,
 * so each bounce leaves it and sees the background). */
static rs_status build_furnace(rs_scene *s)
{
    rs_material m = lambertian(0.5f, 0.5f, 0.5f);
    uint32_t grey;
    TRY(rs_scene_add_material(s, &m, &grey));
    TRY(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, grey));
    s->camera.from = rs_v3(0, 0, 5);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.up = rs_v3(0, 1, 0);
    /* the sphere subtends asin(1/5) = 11.5 deg; a 14 deg frame's corners are 9.9 deg off axis */
    s->camera.vfov_deg = 14.0f;
    s->background = rs_v3(1, 1, 1);
    s->width = s->height = 64;
    return RS_OK;
}

typedef struct builtin {
    const char *name;
    const char *description;
    rs_status (*build)(rs_scene *s);
} builtin;

static const builtin g_builtins[] = {
    {"cornell", "the two-box Cornell box of Ray Tracing: The Rest of Your Life (default)",
     build_cornell},
    {"furnace", "white furnace: an albedo-0.5 diffuse sphere under a white sky (renders 0.5)",
     build_furnace},
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
    int i;
    *out = NULL;
    for (i = 0; i < N_BUILTINS; ++i) {
        rs_scene *s;
        rs_status st;
        if (strcmp(name, g_builtins[i].name) != 0)
            continue;
        st = rs_scene_create(name, &s);
        if (st == RS_OK)
            st = g_builtins[i].build(s);
        if (st == RS_OK)
            st = rs_scene_finalize(s);
        if (st != RS_OK) {
            rs_scene_destroy(s);
            return st;
        }
        *out = s;
        return RS_OK;
    }
    {
        char known[256] = "";
        for (i = 0; i < N_BUILTINS; ++i) {
            strncat(known, i ? ", " : "", sizeof known - strlen(known) - 1);
            strncat(known, g_builtins[i].name, sizeof known - strlen(known) - 1);
        }
        return rs_error_set(RS_ERR_ARG, "unknown built-in scene '%s' (known: %s)", name, known);
    }
}
