/* scenes/builtin_gpucheck.h — builtin:gpucheck (scenes/builtin_gpucheck.c), registered by
 * scenes/builtin.c: the scene that reaches every device function of the megakernel. */
#ifndef RS_SCENES_BUILTIN_GPUCHECK_H
#define RS_SCENES_BUILTIN_GPUCHECK_H

#include "scenes/scene.h"

/* Adds the scene's materials, textures, geometry, lights, map and camera to s (not finalized). */
rs_status rs_builtin_build_gpucheck(rs_scene *s);

#endif
