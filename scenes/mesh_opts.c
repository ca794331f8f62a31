/* scenes/mesh_opts.c — the mesh options' defaults (in every build, with or without Assimp). */
#include <string.h>
#include <strings.h>

#include "scenes/gltf.h"
#include "scenes/mesh.h"

rs_mesh_opts rs_mesh_opts_default(uint32_t mat)
{
    rs_mesh_opts o;
    memset(&o, 0, sizeof o);
    o.scale = rs_v3(1, 1, 1);
    o.material = mat;
    return o;
}

int rs_is_gltf_path(const char *path)
{
    const char *dot = strrchr(path, '.'), *slash = strrchr(path, '/');
    if (!dot || (slash && dot < slash))
        return 0;
    return strcasecmp(dot, ".gltf") == 0 || strcasecmp(dot, ".glb") == 0;
}
