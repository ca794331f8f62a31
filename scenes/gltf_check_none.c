/* scenes/gltf_check_none.c — rs_gltf_preflight without cJSON: nothing to check with. */
#include "scenes/gltf_check.h"

#include <string.h>

rs_status rs_gltf_preflight(const char *path, int glb)
{
    (void)path, (void)glb;
    return RS_OK;
}

rs_status rs_gltf_read_ext(const char *path, int glb, rs_gltf_ext *out)
{
    (void)path, (void)glb;
    memset(out, 0, sizeof *out);
    return RS_OK;
}

void rs_gltf_ext_free(rs_gltf_ext *e) { (void)e; }
