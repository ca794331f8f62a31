/* scenes/mesh_assimp.h — what the Assimp-based loaders share, internal to scenes/ and built only
 * with Assimp (scenes/mesh_none.c stands in for all of them without it):
 *
 *   mesh_import.c     a file into an Assimp scene: every file through core/file.h, PLY headers
 *                     and glTF starts checked first, triangle-strip PLYs decoded by our own reader
 *   mesh_materials.c  an Assimp material as a scene material, with its textures
 *   mesh.c            a mesh file's triangles placed in a scene (rs_scene_add_mesh, mesh.h)
 *   gltf_scene.c      a glTF file as a whole scene (rs_scene_load_gltf, gltf.h)
 *
 * The calls run one way: gltf_scene.c and mesh.c call mesh_import.c and mesh_materials.c, and
 * gltf_scene.c mesh.c's faces. */
#ifndef RS_SCENES_MESH_ASSIMP_H
#define RS_SCENES_MESH_ASSIMP_H

#include <assimp/scene.h>

#include "scenes/gltf_check.h"
#include "scenes/mesh.h"
#include "scenes/transform.h"

/* ---- mesh_import.c ---- */

/* Whether `path`'s extension is `ext` (lower case, no dot), in any case. */
int rs_mesh_ext_is(const char *path, const char *ext);

/* Imports `path` through core/file.h with Assimp's `flags` (points and lines dropped, our own
 * checks instead of Assimp's validation) into *out: a scene with at least one mesh and a root
 * node, or an error (set) and *out NULL.  Released by rs_mesh_release. */
rs_status rs_mesh_import(const char *path, unsigned int flags, const struct aiScene **out);
void rs_mesh_release(const struct aiScene *as);

/* For a scene our strip reader made: its strips and the joins between them, into *strips and
 * *joins (left as they are for Assimp's scenes). */
void rs_mesh_strips_of(const struct aiScene *as, uint32_t *strips, uint32_t *joins);

/* ---- mesh_materials.c ---- */

/* A scene material for Assimp material am of scene as (x: its glTF extensions, or NULL), its
 * textures looked up beside `mesh` in `dir`; a missing texture is an error when `strict`. */
rs_status rs_mesh_add_file_material(rs_scene *s, const struct aiScene *as,
                                    const struct aiMaterial *am, const rs_gltf_mat_ext *x,
                                    const char *mesh, const char *dir, int strict, uint32_t *id);

/* The override for file material am (its index in o->override_names), or -1. */
int rs_mesh_override_of(const struct aiMaterial *am, const rs_mesh_opts *o);

/* Every override must name a material of the file. */
rs_status rs_mesh_check_overrides(const struct aiScene *as, const char *path,
                                  const rs_mesh_opts *o);

/* ---- mesh.c ---- */

/* The triangles of Assimp mesh m, placed by xf (NULL: as the file has them), with material mat;
 * the faces dropped are counted in *info. */
rs_status rs_mesh_add_faces(rs_scene *s, const struct aiMesh *m, const rs_xform *xf, uint32_t mat,
                            rs_mesh_info *info);

/* A glTF file's extensions (none for another file), with a warning for those not read. */
rs_status rs_mesh_file_extensions(const char *path, rs_gltf_ext *e);

/* Material k's extensions (NULL: none, or not a glTF file). */
const rs_gltf_mat_ext *rs_mesh_material_ext(const rs_gltf_ext *e, uint32_t k);

#endif
