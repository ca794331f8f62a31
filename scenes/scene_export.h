/* scenes/scene_export.h — a scene written as a scene file (docs/scene-format.md), so that a
 * built-in scene (or any other) can be read, edited and rendered as a file: `raystream export`.
 *
 * Everything the format can say is written: the camera, the image size, the background (colour,
 * sky or environment map), textures, every material (named m0, m1, ...), and each primitive as
 * an object (spheres, moving spheres, quads, triangles with UVs; a box as its six quads).  Floats
 * are printed with 9 significant digits, so each reads back as the same float.  Image textures
 * and the environment map are written beside the file as FILE-image-N.exr (linear float).
 * Triangles' vertex normals, punctual lights and the newer materials' textures are not in the
 * format's objects: a scene with those is refused rather than written without them. */
#ifndef RS_SCENES_SCENE_EXPORT_H
#define RS_SCENES_SCENE_EXPORT_H

#include "scenes/scene.h"

#ifdef __cplusplus
extern "C" {
#endif
/* Writes `s` (finalized) to `path` (a .json file), replacing it only once complete. */
rs_status rs_scene_export_json(const rs_scene *s, const char *path);
#ifdef __cplusplus
}
#endif
#endif
