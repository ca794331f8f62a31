/* scenes/mesh.h — triangle meshes from files through Assimp's C API: OBJ (+MTL), PLY, glTF 2.0,
 * FBX, ...  Faces are triangulated; vertex normals and UVs are kept where the file has them
 * (smooth normals are generated where it has none); the mesh is placed by scale, rotations about
 * x, y, z, and a translation, in that order (the thesis's transforms), or fitted into a box: one
 * rs_xform (scenes/transform.h), points and normals (by the inverse transpose) in double, rounded
 * once; a negative scale mirrors and keeps the faces' outward side.  A mesh placed by the
 * identity keeps the file's coordinates exactly (its normals renormalised in float).
 *
 * Bad data never crashes or hangs the import: a file Assimp cannot read is an RS_ERR_ARG naming
 * it; faces with non-finite or out-of-range vertices, of zero area, or that are points or lines,
 * are dropped and counted by reason, and a mesh that loses more faces than it keeps is an
 * RS_ERR_ARG too (naming the file and the counts), not a render of what is left.  A PLY of
 * triangle strips (`element tristrips`, which Assimp does not read: it made one triangle of a
 * whole model) is decoded by scenes/ply_strips.h.
 * Assimp reads every file through core/file.h (the mesh, its MTL, a glTF's buffers), and so do
 * the textures a mesh names: one that is not a regular file of a sane size (a FIFO, /dev/zero, a
 * folder) fails the import, naming it; one that is merely missing does not.  A PLY file must
 * reach end_header within 64 KiB (Assimp's reader spins for ever on a cut header) and hold the
 * data its header declares: a line per element instance in ascii, the fixed-size properties'
 * bytes in binary (Assimp aborts the process on a cut ascii body). */
#ifndef RS_SCENES_MESH_H
#define RS_SCENES_MESH_H

#include "scenes/scene.h"

/* Use the materials the file defines (MTL, glTF) instead of one given material. */
#define RS_MESH_FILE_MATERIALS 0xffffffffu

typedef struct rs_mesh_opts {
    rs_vec3 scale;      /* per axis (1, 1, 1 for none) */
    rs_vec3 rotate_deg; /* about x, then y, then z, in degrees (rs_xform_rotate_euler) */
    rs_vec3 translate;
    uint32_t material;  /* a scene material id, or RS_MESH_FILE_MATERIALS */
    int fit;            /* ignore scale/translate: scale uniformly so the largest extent is
                           fit_size, and stand the mesh on fit_base (its bottom centre) */
    float fit_size;
    rs_vec3 fit_base;
    /* With RS_MESH_FILE_MATERIALS: the file's materials named override_names[k] take the scene
     * material override_ids[k] instead (the others are converted as usual).  A name the file
     * does not have is an error naming the file's materials. */
    const char *const *override_names;
    const uint32_t *override_ids;
    uint32_t n_overrides;
    int strict_textures; /* a texture the file names that is missing or unreadable is an error
                            (else a warning, and the material keeps its colour) */
} rs_mesh_opts;

typedef struct rs_mesh_info {
    uint32_t triangles;  /* added to the scene */
    uint32_t dropped;    /* faces dropped, the sum of the four below */
    uint32_t dropped_index, dropped_nonfinite, dropped_area, dropped_shape;
                         /* out-of-range vertex index; non-finite vertex; zero area; not a
                            triangle after triangulation (a point or a line) */
    uint32_t materials;  /* materials added from the file */
    uint32_t strips, joins; /* a PLY of triangle strips: the strips decoded, and the triangles
                               that only joined them (a repeated vertex: not counted as dropped) */
    rs_aabb bounds;      /* of the placed mesh */
} rs_mesh_info;

#ifdef __cplusplus
extern "C" {
#endif
/* "N faces dropped (why)" for `info` into buf[n] (empty when none were dropped); returns buf. */
const char *rs_mesh_dropped_text(const rs_mesh_info *info, char *buf, size_t n);
/* Identity placement with material `mat`. */
rs_mesh_opts rs_mesh_opts_default(uint32_t mat);
/* Imports every mesh of the file into the scene (not finalized). */
rs_status rs_scene_add_mesh(rs_scene *s, const char *path, const rs_mesh_opts *opts,
                            rs_mesh_info *info);
#ifdef __cplusplus
}
#endif
#endif
