/* scenes/scene.h — the flat scene: arrays of each primitive type, a material per primitive, the
 * emitters prepared for light sampling, the camera and the background.
 *
 * Build it with the rs_scene_add_* calls, then rs_scene_finalize() once: that validates the
 * geometry (finite coordinates, non-degenerate quads and spheres), numbers the primitives
 * globally (spheres, then quads, then triangles; see core/geom.h) and builds the light table.
 * After finalize the scene is read-only and may be shared by any number of threads. */
#ifndef RS_SCENES_SCENE_H
#define RS_SCENES_SCENE_H

#include "core/geom.h"
#include "core/status.h"

typedef enum rs_material_type {
    RS_MAT_LAMBERTIAN = 0,   /* ideal diffuse reflector, albedo */
    RS_MAT_DIFFUSE_LIGHT = 1 /* emitter of constant radiance; reflects nothing */
} rs_material_type;

/* Material flags. */
#define RS_MAT_TWO_SIDED 1u /* a light emits on both sides (else only where its normal points) */

typedef struct rs_material {
    uint32_t type;    /* rs_material_type, stored fixed-width */
    uint32_t flags;   /* RS_MAT_* */
    rs_vec3 albedo;   /* reflectance in [0, 1] per channel */
    rs_vec3 emission; /* radiance emitted (W / (m^2 sr)), for lights */
} rs_material;

/* An emitter that light sampling can pick: a quad or triangle with an emissive material. */
typedef struct rs_light {
    uint32_t prim;  /* global primitive index */
    float area;     /* surface area */
    float power;    /* pi * area * luminance(emission) * (2 if two-sided): selection weight */
    float pick_pdf; /* power / total power: probability that sampling picks this light */
} rs_light;

typedef struct rs_camera_desc {
    rs_vec3 from, at, up;
    float vfov_deg;   /* vertical field of view, degrees */
    float aperture;   /* lens diameter; 0 for a pinhole */
    float focus_dist; /* distance to the plane in focus; 0 means |at - from| */
} rs_camera_desc;

typedef struct rs_scene {
    char name[64];
    rs_sphere *spheres;
    uint32_t *sphere_mat;
    uint32_t n_spheres, cap_spheres;
    rs_quad *quads;
    uint32_t *quad_mat;
    uint32_t n_quads, cap_quads;
    rs_tri *tris;
    uint32_t *tri_mat;
    uint32_t n_tris, cap_tris;
    rs_material *materials;
    uint32_t n_materials, cap_materials;

    /* built by rs_scene_finalize */
    rs_light *lights;
    float *light_cdf; /* n_lights + 1 entries, cdf[0] = 0, cdf[n] = 1 */
    uint32_t n_lights;
    int32_t *prim_light; /* per global primitive: index into lights, or -1 */
    int finalized;

    rs_camera_desc camera;
    rs_vec3 background;     /* radiance of rays that leave the scene */
    uint32_t width, height; /* the scene's preferred image size */
} rs_scene;

rs_status rs_scene_create(const char *name, rs_scene **out);
void rs_scene_destroy(rs_scene *s);

/* Each add returns RS_OK or RS_ERR_NOMEM / RS_ERR_ARG (a material id out of range). */
rs_status rs_scene_add_material(rs_scene *s, const rs_material *m, uint32_t *id);
rs_status rs_scene_add_sphere(rs_scene *s, rs_vec3 center, float radius, uint32_t mat);
/* Parallelogram Q + a u + b v, a, b in [0, 1]; its normal is u x v. */
rs_status rs_scene_add_quad(rs_scene *s, rs_vec3 q, rs_vec3 u, rs_vec3 v, uint32_t mat);
rs_status rs_scene_add_triangle(rs_scene *s, rs_vec3 v0, rs_vec3 v1, rs_vec3 v2, uint32_t mat);
/* Axis-aligned box [lo, hi] as six outward-facing quads, rotated by `rot_y_deg` about the y axis
 * (through the origin) and then moved by `offset` (RTNW's box + rotate_y + translate). */
rs_status rs_scene_add_box(rs_scene *s, rs_vec3 lo, rs_vec3 hi, float rot_y_deg, rs_vec3 offset,
                           uint32_t mat);

rs_status rs_scene_finalize(rs_scene *s);

rs_geom rs_scene_geom(const rs_scene *s);
uint32_t rs_scene_prim_count(const rs_scene *s);
/* The material of global primitive `prim`. */
const rs_material *rs_scene_prim_material(const rs_scene *s, uint32_t prim);

#endif
