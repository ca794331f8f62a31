/* scenes/gltf_check.h — a glTF file checked before Assimp reads it, by our own reader of its JSON
 * (cJSON), so that what would crash, exhaust memory or silently read another file is refused with
 * one line naming the file and the field:
 *   - a .glb's header and chunk lengths against the file's size (a 900-byte file claiming a 4 GiB
 *     chunk made Assimp allocate it before refusing);
 *   - the node tree: children that are nodes, no node with two parents or on a cycle, at most
 *     RS_GLTF_MAX_DEPTH levels (Assimp's node reader recurses: ~30,000 levels overflowed the
 *     stack);
 *   - buffers[].uri and images[].uri: data: URIs or relative paths to files that exist (Assimp
 *     took a file of the same base name beside the scene for a missing one, and reads no URLs).
 * Without cJSON (gltf_check_none.c) nothing is checked here. */
#ifndef RS_SCENES_GLTF_CHECK_H
#define RS_SCENES_GLTF_CHECK_H

#include "core/status.h"

#define RS_GLTF_MAX_DEPTH 256 /* nodes within nodes */

/* Checks `path`, a .glb when `glb` else a .gltf (JSON).  RS_OK, or an error (set). */
rs_status rs_gltf_preflight(const char *path, int glb);

#endif
