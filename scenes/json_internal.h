/* scenes/json_internal.h — what the JSON scene reader's files share (internal to scenes/, built
 * only with cJSON; scenes/scene_json_none.c stands in without it), along pbrt-v4's parser ->
 * scene line: the reader only calls rs_scene_add_* and rs_scene_set_* and never writes into the
 * scene struct itself.
 *
 *   json_values.c     fields: typed values with ranges, unknown keys with a suggestion, the
 *                     JSON paths messages name (objects[3].radius)
 *   json_materials.c  textures and materials
 *   json_objects.c    objects, transforms, meshes, punctual lights, groups and instances
 *   scene_json.c      the file: its checks, camera, image, background, and the order of the rest
 *
 * Calls run one way: scene_json.c -> json_objects.c -> json_materials.c -> json_values.c. */
#ifndef RS_SCENES_JSON_INTERNAL_H
#define RS_SCENES_JSON_INTERNAL_H

#include <cjson/cJSON.h>
#include <stdio.h>

#include "scenes/scene.h"
#include "scenes/transform.h"

#define MAX_NAMES     4096
#define MAX_NESTING   16 /* instances within instances */
#define MAX_OVERRIDES 64 /* a mesh's materials replaced by name */
/* Groups that are not instanced are copied into the scene (and nested groups into their
 * prototype): this bounds what a file of a few lines can make (ten groups of ten instances of each
 * other would be 10^10 primitives).  Placed triangles are bounded by RS_MAX_INST_PRIMS. */
#define MAX_PRIMS RS_SCENE_MAX_COPIED_PRIMS

typedef struct named {
    const char *name;
    uint32_t id;
} named;

/* A named group of objects that instances place (top-level "groups").  A group of triangles
 * (triangle, mesh and instances of such groups) is instanced at the top level: read once into a
 * prototype that every instance shares (core/geom.h); any other group is copied. */
typedef struct group {
    const char *name;
    const cJSON *objects;
    uint32_t prims; /* primitives one instance makes, once known */
    int known;
    int shape;         /* 0: not yet known, 1: triangles only, -1: copied */
    int made;          /* the prototype is read */
    uint32_t first, n; /* the prototype's triangles (inst_tris) */
    uint32_t placed;   /* instances of it */
} group;

/* A mesh object's triangles as its file gave them (before any transform), so that a mesh that
 * instances place many times is read once. */
typedef struct mesh_copy {
    const cJSON *node;
    uint32_t n;
    rs_tri *tris;
    uint32_t *mat;
    float *uv, *normal; /* 6 and 9 per triangle, or NULL */
} mesh_copy;

typedef struct ctx {
    mesh_copy *meshes;
    uint32_t n_meshes, cap_meshes;
    const char *label;
    const char *base_dir;
    FILE *log; /* a line per mesh imported, or NULL */
    rs_scene *scene;
    group groups[MAX_NAMES];
    uint32_t n_groups;
    const group *stack[MAX_NESTING]; /* the groups being expanded, outermost first */
    uint32_t depth;
    char instance_path[256]; /* the outermost instance being expanded, for messages */
    named textures[MAX_NAMES];
    uint32_t n_textures;
    named materials[MAX_NAMES];
    uint32_t n_materials;
    /* per top-level object, the scene's spheres, quads, triangles and instances before it: a
     * primitive rs_scene_finalize refuses is named as the object that made it */
    uint32_t (*obj_start)[4];
    uint32_t n_obj;
} ctx;

/* ---- json_values.c: fields and their checks ---- */

/* Sets the error "LABEL: PATH: message" (control characters printed as '?') and returns
 * RS_ERR_ARG; FAIL(c, path, ...) is the short form. */
rs_status rs_json_field_error(const ctx *c, const char *path, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
#define FAIL(c, path, ...) rs_json_field_error((c), (path), __VA_ARGS__)

/* Fails on any key of `obj` that is not in the NULL-terminated list `keys`, naming the closest
 * known key when one is within a third of its length (at least 2 edits). */
rs_status rs_json_check_keys(const ctx *c, const cJSON *obj, const char *path,
                             const char *const *keys);

/* out = path.key (key alone at the top level), cut to n - 1 characters. */
void rs_json_subpath(char *out, size_t n, const char *path, const char *key);

/* A number in [lo, hi]; `def` when absent and not required. */
rs_status rs_json_get_num(const ctx *c, const cJSON *obj, const char *path, const char *key,
                          int required, double def, double lo, double hi, float *out);

/* Three numbers, [x, y, z], at it (path p). */
rs_status rs_json_vec3_of(const ctx *c, const cJSON *it, const char *p, rs_vec3 *out);

/* A vector of 3 numbers; `def` when absent and not required. */
rs_status rs_json_get_vec3(const ctx *c, const cJSON *obj, const char *path, const char *key,
                           int required, rs_vec3 def, rs_vec3 *out);

/* A colour: 3 numbers >= 0. */
rs_status rs_json_get_color(const ctx *c, const cJSON *obj, const char *path, const char *key,
                            int required, rs_vec3 def, rs_vec3 *out);

/* A reflectance (or transmittance): a colour with every component in [0, 1]. */
rs_status rs_json_get_reflectance(const ctx *c, const cJSON *obj, const char *path, const char *key,
                                  int required, rs_vec3 def, rs_vec3 *out);

/* true or false; `def` when absent. */
rs_status rs_json_get_bool(const ctx *c, const cJSON *obj, const char *path, const char *key,
                           int def, int *out);

/* A string, or *out NULL when absent. */
rs_status rs_json_get_string(const ctx *c, const cJSON *obj, const char *path, const char *key,
                             const char **out);

/* The id of `name` in list[0, n): 1, or 0 when it is not there. */
int rs_json_lookup(const named *list, uint32_t n, const char *name, uint32_t *id);

/* A file named in the scene, relative to the scene file's folder unless absolute. */
rs_status rs_json_resolve_path(const ctx *c, const char *file, char *out, size_t n);

/* `n` finite numbers (|x| <= 1e30) from array `a` into out. */
rs_status rs_json_read_floats(ctx *c, const cJSON *a, const char *p, int n, const char *what,
                              float *out);

/* ---- json_materials.c: textures and materials ---- */

/* A texture definition textures.NAME. */
rs_status rs_json_read_texture(ctx *c, const cJSON *t, const char *path, const char *name);

/* A material definition materials.NAME. */
rs_status rs_json_read_material(ctx *c, const cJSON *m, const char *path, const char *name);

/* The material an object names (its "material" key), as a scene material id. */
rs_status rs_json_object_material(ctx *c, const cJSON *o, const char *path, uint32_t *id);

/* ---- json_objects.c: objects, transforms, groups and instances ---- */

/* A rotation: [x, y, z] (degrees about x, then y, then z), {"axis": [x, y, z], "degrees": a},
 * or {"matrix": [9 numbers, row by row]} (orthonormal with determinant 1 to 1e-4). */
rs_status rs_json_read_rotation(ctx *c, const cJSON *it, const char *q, rs_xform *out);

/* One object of objects[] (or of a group being placed) under the transform `parent`. */
rs_status rs_json_read_object(ctx *c, const cJSON *o, const char *path, const rs_xform *parent);

#endif
