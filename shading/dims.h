/* shading/dims.h — which group of four random numbers each decision uses at one bounce.
 * Changing a number here changes every image: the groups must stay distinct.  With the sobol and
 * zsobol samplers (core/sobol.h, core/zsobol.h) each group is two stratified 2D points: (x0, x1)
 * and (x2, x3), except the light's, whose point (u1, u2) is one pair and (pick, choice) the other
 * (rs_path_rand). */
#ifndef RS_SHADING_DIMS_H
#define RS_SHADING_DIMS_H

enum {
    RS_DIM_CAMERA = 0, /* pixel jitter x, y; lens u, v (bounce 0 only) */
    RS_DIM_BSDF = 1,   /* direction u1, u2; lobe or Fresnel choice; Russian roulette */
    RS_DIM_LIGHT = 2,  /* light pick; point u1, u2; mixture choice (light or BSDF) */
    RS_DIM_TIME = 3    /* shutter time; unused x3 (bounce 0 only) */
};

#endif
