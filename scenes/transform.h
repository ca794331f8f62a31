/* scenes/transform.h — affine transforms of scene objects (the scene file's `transform` key).
 *
 * A transform is x' = M x + t with M a 3x3 matrix, kept in double precision: it is built from the
 * scene file's steps (a 4x4 matrix, translate, rotate about an axis or by Euler angles, scale),
 * composed, and applied to an object's primitives once, at load time, each coordinate rounded to
 * float once.  Normals go by the inverse transpose.  A transform that mirrors (det M < 0) keeps
 * each surface's orientation: quads and triangles have two of their edges or vertices swapped so
 * that their normals follow the transformed outward normal (as pbrt does).
 *
 * Objects are flattened: an instance of a named group copies the group's primitives, transformed
 * (docs/scene-format.md).  A sphere stays a sphere only under a similarity (rotation, uniform
 * scale, translation); anything else is refused for spheres. */
#ifndef RS_SCENES_TRANSFORM_H
#define RS_SCENES_TRANSFORM_H

#include "scenes/scene.h"

typedef struct rs_xform {
    double m[3][3]; /* the linear part, row-major: x'_i = sum_j m[i][j] x_j + t[i] */
    double t[3];
} rs_xform;

/* Where a scene's primitive arrays stood before an object was added: the object's primitives are
 * those after these counts. */
typedef struct rs_scene_mark {
    uint32_t n_spheres, n_quads, n_tris, n_punctuals;
} rs_scene_mark;

#ifdef __cplusplus
extern "C" {
#endif
rs_xform rs_xform_identity(void);
rs_xform rs_xform_translate(double x, double y, double z);
rs_xform rs_xform_scale(double x, double y, double z);
/* Right-handed rotation by `deg` degrees about `axis` (need not be unit; must not be zero). */
rs_xform rs_xform_rotate_axis(const double axis[3], double deg);
/* Rotation about x by rx, then about y by ry, then about z by rz (degrees). */
rs_xform rs_xform_rotate_euler(double rx, double ry, double rz);
/* a after b: (a o b)(x) = a(b(x)). */
rs_xform rs_xform_compose(const rs_xform *a, const rs_xform *b);
double rs_xform_det(const rs_xform *x);
int rs_xform_is_identity(const rs_xform *x);
/* NULL if x can place objects; else why not ("not finite", "singular (det = ...)"): a
 * transform whose linear part is singular or nearly so (|det| below 1e-12 of its largest entry
 * cubed), or with an entry beyond 1e30, is refused. */
const char *rs_xform_invalid(const rs_xform *x);
/* Whether x is a similarity (M^T M = s^2 I to 1e-5 relative); *scale = s. */
int rs_xform_is_similarity(const rs_xform *x, double *scale);

rs_vec3 rs_xform_point(const rs_xform *x, rs_vec3 p);
rs_vec3 rs_xform_vector(const rs_xform *x, rs_vec3 v);
/* Surface normal n under x: by the inverse transpose of the linear part (pointing the way the
 * transformed surface's normal does, whatever the sign of det), normalised in double and rounded
 * once, as rs_scene_transform_since moves vertex normals; a zero normal stays zero. */
rs_vec3 rs_xform_normal(const rs_xform *x, rs_vec3 n);

rs_scene_mark rs_scene_mark_now(const rs_scene *s);
/* Applies x to every primitive added since `from` (spheres, their motion, quads, triangles and
 * their vertex normals) and every punctual light (positions, and directions by the linear part,
 * normalised; intensities stay).  RS_ERR_ARG (message: what went wrong, no file or path: the caller
 * prefixes them) if x is invalid, a sphere would become an ellipsoid, or a coordinate would
 * leave the range of a float. */
rs_status rs_scene_transform_since(rs_scene *s, const rs_scene_mark *from, const rs_xform *x);
#ifdef __cplusplus
}
#endif
#endif
