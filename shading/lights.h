/* shading/lights.h — sampling the scene's emitters (the thesis's "primitive PDF").
 *
 * A light is picked with probability proportional to its power (a CDF, binary search).  Then:
 *   quad, triangle   a point uniform by area:  p(w) = pick dist^2 / (area |cos theta_light|)
 *   sphere           a direction uniform in the cone the sphere subtends (seen from outside):
 *                    p(w) = pick / (2 pi (1 - cos theta_max)); from inside, uniform by area.
 * All pdfs are over solid angle at the shading point and include the pick probability. */
#ifndef RS_SHADING_LIGHTS_H
#define RS_SHADING_LIGHTS_H

#include "scenes/scene.h"

typedef struct rs_light_sample {
    rs_vec3 point; /* on the light */
    rs_vec3 wi;    /* unit direction from the shading point toward `point` */
    float dist;    /* distance to `point` */
    float pdf;     /* solid-angle pdf, pick probability included */
    rs_vec3 le;    /* radiance arriving along -wi (zero from the back of a one-sided light) */
} rs_light_sample;

/* Unit geometric normal of global primitive `prim` at point p on it, at `time` (spheres:
 * outward; quads: along u x v; triangles: along (v1 - v0) x (v2 - v0)). */
rs_vec3 rs_prim_normal(const rs_scene *s, uint32_t prim, rs_vec3 p, float time);

/* Radiance that material m emits from a surface of geometric normal ng toward a ray travelling
 * along d (that is, toward -d). */
rs_vec3 rs_emitted(const rs_material *m, rs_vec3 ng, rs_vec3 d);

/* Samples a light as seen from x at `time`.  Returns 0 (and no sample) if the scene has no
 * lights or the sample is degenerate (x on the light's plane, or inside a one-point light). */
int rs_light_sample_at(const rs_scene *s, rs_vec3 x, float time, float u_pick, float u1, float u2,
                       rs_light_sample *out);

/* The pdf rs_light_sample_at gives to direction w (unit) from x that reaches light `light` at
 * distance t where its normal is ng: what MIS needs when BSDF sampling hits an emitter. */
float rs_light_pdf_hit(const rs_scene *s, uint32_t light, rs_vec3 x, float time, rs_vec3 w, float t,
                       rs_vec3 ng);

/* The pdf of direction w (unit) from x summed over every light that the line x + t w meets,
 * ignoring occlusion (the mixture PDF's light term). */
float rs_lights_pdf_dir(const rs_scene *s, rs_vec3 x, float time, rs_vec3 w);

#endif
