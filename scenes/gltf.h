/* scenes/gltf.h — glTF 2.0 files (.gltf, .glb) as whole scenes, through Assimp.
 *
 * The node hierarchy with each node's transform (a mirroring one keeps surfaces' orientation,
 * scenes/transform.h); every mesh primitive as triangles with the metallic-roughness material
 * (base colour, metallic-roughness, emissive and normal textures, external or embedded); the first
 * perspective camera, or the one named by `camera`, else one that frames the whole model; the
 * KHR_lights_punctual point, spot and directional lights (glTF's candela and lux taken as W/sr and
 * W/m^2); the material extensions of scenes/gltf_check.h.  A file with no light of any kind (no
 * punctual light, no emissive material) gets a uniform white background here; the CLI gives a
 * glTF file the default sky instead (app/scene_load.c).
 *
 * A missing or unreadable texture, a broken file, a camera name that is not in the file, and a
 * mesh that loses most of its faces are errors naming the file; nothing is rendered. */
#ifndef RS_SCENES_GLTF_H
#define RS_SCENES_GLTF_H

#include <stdio.h>

#include "scenes/scene.h"

typedef struct rs_gltf_opts {
    const char *camera; /* a camera's node name, or NULL: the first */
    FILE *log;          /* a line of what was loaded, or NULL */
    char *extensions;   /* where not NULL: the extensions the file uses that raystream read,
                           ", "-separated, into extensions[extensions_n] */
    size_t extensions_n;
} rs_gltf_opts;

#ifdef __cplusplus
extern "C" {
#endif
/* Whether `path` names a glTF file by its extension (.gltf, .glb). */
int rs_is_gltf_path(const char *path);
/* Reads and finalizes the scene of glTF file `path`. */
rs_status rs_scene_load_gltf(const char *path, const rs_gltf_opts *opts, rs_scene **out);
#ifdef __cplusplus
}
#endif
#endif
