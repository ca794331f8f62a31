/* scenes/light_bvh.h — the light BVH over a scene's bounded lights (issue 29): emitters
 * (triangles, quads, spheres) and point and spot lights, each with its bounds, power and the cone
 * of directions it emits into (rs_light_node, scenes/scene.h).  Built by rs_scene_finalize once
 * the lights are known; shading/light_bvh.h picks a light from it by each node's importance
 * at the shading point.  Directional lights and the environment map stay out of it (they have
 * no position), picked by power as before.
 *
 * The build is deterministic (the same scene gives the same tree on every machine): top-down,
 * each node split where 12 buckets along its centroids' longest axis give the least
 * power x surface area x cone measure (Conty and Kulla 2018's cost); a node whose lights cannot
 * be told apart by centroid is split by their order.  Depth is at most 62, so every light's
 * path from the root fits rs_scene.light_trail's 64 bits: a cost split is taken only while both
 * sides could still be split in halves within that depth, and halves below that. */
#ifndef RS_SCENES_LIGHT_BVH_H
#define RS_SCENES_LIGHT_BVH_H

#include "scenes/scene.h"

#ifdef __cplusplus
extern "C" {
#endif
/* (Re)builds s->light_nodes, s->light_trail and s->light_bvh_mass from s->lights (the scene's
 * other arrays as finalize left them).  No bounded light: no tree (NULL, 0). */
rs_status rs_scene_build_light_bvh(rs_scene *s);
/* For the tests: the deepest a leaf may be (1 to 62, the default 62; values outside are clamped).
 * Lights whose cost splits would go deeper are split in halves by order from where they must (a
 * limit below ceil(log2 n) for n lights cannot hold: they are then halved from the root). */
void rs_light_bvh_set_depth_limit(int depth);
/* The union of two normal cones (pbrt-v4's DirectionCone::Union): axis w, cos of the half-angle
 * (-1: all directions).  For the tests. */
void rs_light_cone_union(const float wa[3], float ca, const float wb[3], float cb, float w[3],
                         float *c);
#ifdef __cplusplus
}
#endif
#endif
