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

#include <math.h>
#include <stdint.h>

#include "core/status.h"

#define RS_GLTF_MAX_DEPTH 256 /* nodes within nodes */

/* Checks `path`, a .glb when `glb` else a .gltf (JSON).  RS_OK, or an error (set). */
rs_status rs_gltf_preflight(const char *path, int glb);

/* The glTF extensions raystream reads (docs/scene-format.md says what each becomes). */
#define RS_GLTF_READ_EXTENSIONS                                                                   \
    "KHR_lights_punctual", "KHR_texture_transform", "KHR_materials_transmission",                 \
        "KHR_materials_ior", "KHR_materials_emissive_strength", "KHR_materials_volume",           \
        "KHR_materials_specular", "KHR_materials_unlit", "KHR_materials_clearcoat", \
        "KHR_materials_sheen"

/* What raystream takes from a material's extensions through the file's own JSON (Assimp 5.2
 * drops emissive strength, unlit and the specular colour; reading them all here keeps one
 * place; the extensions' textures are not read).  Each field holds the extension's default where the material lacks it. */
typedef struct rs_gltf_mat_ext {
    float emissive_strength;    /* KHR_materials_emissive_strength: 1 */
    float ior;                  /* KHR_materials_ior: 1.5 */
    float specular;             /* KHR_materials_specular specularFactor: 1 */
    float specular_color[3];    /* specularColorFactor: 1, 1, 1 */
    float attenuation_distance; /* KHR_materials_volume: infinity (none) */
    float attenuation_color[3]; /* 1, 1, 1 */
    int unlit;                  /* KHR_materials_unlit */
    float clearcoat;            /* KHR_materials_clearcoat clearcoatFactor: 0 */
    float clearcoat_roughness;  /* clearcoatRoughnessFactor: 0 */
    float sheen_color[3];       /* KHR_materials_sheen sheenColorFactor: 0, 0, 0 */
    float sheen_roughness;      /* sheenRoughnessFactor: 0 */
} rs_gltf_mat_ext;

typedef struct rs_gltf_ext {
    uint32_t n_materials;
    rs_gltf_mat_ext *materials; /* per glTF material, in the file's order (Assimp's too) */
    char used[512];   /* the file's extensionsUsed that raystream reads, ", "-separated */
    char unread[512]; /* those it does not */
} rs_gltf_ext;

/* The extensions of glTF file `path` (a .glb when `glb`), already checked by rs_gltf_preflight.
 * A value outside its extension's range (an ior below 1, a negative strength, a colour outside
 * [0, 1], a distance not above 0) is an error naming the material and the field.  Without
 * cJSON: RS_OK with no materials and empty lists.  Free with rs_gltf_ext_free. */
rs_status rs_gltf_read_ext(const char *path, int glb, rs_gltf_ext *out);
void rs_gltf_ext_free(rs_gltf_ext *e);

/* The extension defaults (what a material without any gets). */
static inline rs_gltf_mat_ext rs_gltf_mat_ext_default(void)
{
    rs_gltf_mat_ext m;
    m.emissive_strength = 1.0f;
    m.ior = 1.5f;
    m.specular = 1.0f;
    m.specular_color[0] = m.specular_color[1] = m.specular_color[2] = 1.0f;
    m.attenuation_distance = INFINITY;
    m.attenuation_color[0] = m.attenuation_color[1] = m.attenuation_color[2] = 1.0f;
    m.unlit = 0;
    m.clearcoat = 0.0f;
    m.clearcoat_roughness = 0.0f;
    m.sheen_color[0] = m.sheen_color[1] = m.sheen_color[2] = 0.0f;
    m.sheen_roughness = 0.0f;
    return m;
}

#endif
