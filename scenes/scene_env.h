/* scenes/scene_env.h — the environment map's sampling distribution, built by rs_scene_finalize
 * (the lookups and sampling that use it are in shading/envmap.h). */
#ifndef RS_SCENES_SCENE_ENV_H
#define RS_SCENES_SCENE_ENV_H

#include "scenes/scene.h"

/* Builds s->env_marg_cdf and s->env_cond_cdf from the map (freeing any earlier ones) and sets
 * *power to the map's power as an emitter would count it: pi R^2 times the luminance integrated
 * over the sphere of directions, R the radius of the scene's bounding sphere (0 without a map or
 * for a black one, which then lights nothing and is not sampled).  RS_ERR_ARG for a texel that
 * is not finite or is negative; RS_ERR_NOMEM. */
rs_status rs_scene_env_build(rs_scene *s, double *power);

/* Radius of the bounding sphere of every primitive's bounds (1 for an empty scene). */
double rs_scene_bound_radius(const rs_scene *s);

#endif
