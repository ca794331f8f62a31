/* scenes/gltf_check_none.c — rs_gltf_preflight without cJSON: nothing to check with. */
#include "scenes/gltf_check.h"

rs_status rs_gltf_preflight(const char *path, int glb)
{
    (void)path, (void)glb;
    return RS_OK;
}
