/* scenes/scene_json.h — scene files in JSON (the format is documented in docs/scene-format.md).
 *
 * The reader is strict, like pbrt's: an unknown key, a wrong type, a value out of range or a
 * name that is not defined is an error, reported in one line naming the file and the JSON path
 * of the offending field ("scene.json: materials.red.albedo: expected 3 numbers"), or the line
 * for a syntax error.  Relative file names (image textures, meshes) are relative to the scene
 * file. */
#ifndef RS_SCENES_SCENE_JSON_H
#define RS_SCENES_SCENE_JSON_H

#include <stddef.h>
#include <stdio.h>

#include "scenes/scene.h"

#ifdef __cplusplus
extern "C" {
#endif
/* Reads and finalizes the scene in file `path`.  RS_ERR_IO if it cannot be read, RS_ERR_ARG for
 * bad content. */
rs_status rs_scene_load_json(const char *path, rs_scene **out);
/* The same from text in memory; `label` names it in messages, `base_dir` resolves relative
 * file names (NULL: the working directory). */
rs_status rs_scene_parse_json(const char *text, size_t len, const char *label,
                              const char *base_dir, rs_scene **out);
/* The same, writing a line per mesh file imported (its triangles and materials, the faces it
 * dropped and why) to `log` (NULL: nothing). */
rs_status rs_scene_load_json_ex(const char *path, FILE *log, rs_scene **out);
rs_status rs_scene_parse_json_ex(const char *text, size_t len, const char *label,
                                 const char *base_dir, FILE *log, rs_scene **out);
/* Adds to `s` the material the JSON object `text` describes, as a scene file's "materials"
 * entry does (docs/scene-format.md; a texture may be a colour, not the name of one), its id in
 * *id.  `label` names it in messages.  RS_ERR_ARG with one line for a bad object. */
rs_status rs_scene_add_material_json(rs_scene *s, const char *text, const char *label,
                                     uint32_t *id);
/* Adds the punctual light the JSON object `text` describes, as a scene file's "objects" entry
 * of type point_light, spot_light or directional_light (with its "transform" if any).
 * RS_ERR_ARG with one line for a bad object or another type. */
rs_status rs_scene_add_light_json(rs_scene *s, const char *text, const char *label);
#ifdef __cplusplus
}
#endif
#endif
