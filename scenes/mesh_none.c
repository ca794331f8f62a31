/* scenes/mesh_none.c — meshes in a build without Assimp (RS_DEPS=OPTIONAL on a machine without
 * libassimp-dev): every import says so; scenes of spheres, quads and boxes still work. */
#include <string.h>

#include "scenes/gltf.h"
#include "scenes/mesh.h"

rs_status rs_scene_add_mesh(rs_scene *s, const char *path, const rs_mesh_opts *opts,
                            rs_mesh_info *info)
{
    (void)s, (void)opts;
    if (info)
        memset(info, 0, sizeof *info);
    return rs_error_set(RS_ERR_IO, "%s: this build has no Assimp and reads no mesh files", path);
}

rs_status rs_scene_load_gltf(const char *path, const rs_gltf_opts *opts, rs_scene **out)
{
    (void)opts;
    *out = NULL;
    return rs_error_set(RS_ERR_IO, "%s: this build has no Assimp and reads no glTF files", path);
}
