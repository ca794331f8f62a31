/* core/ray.h — one ray, as traversal and intersection see it (the streams store rays as SoA). */
#ifndef RS_CORE_RAY_H
#define RS_CORE_RAY_H

#include "core/vec3.h"

typedef struct rs_ray {
    rs_vec3 o;  /* origin */
    rs_vec3 d;  /* direction; need not be unit length, t is measured in units of |d| */
    float tmin; /* the ray is the open segment o + t d, tmin < t < tmax */
    float tmax;
    float time; /* when the ray exists, in the shutter's units (moving spheres) */
} rs_ray;

RS_HD rs_vec3 rs_ray_at(const rs_ray *r, float t) { return rs_v3_madd(r->o, r->d, t); }

/* What a closest-hit query returns: distance, two barycentric-style coordinates whose meaning
 * depends on the primitive type (see core/intersect.h), and the primitive index or RS_NO_HIT. */
typedef struct rs_hit {
    float t, u, v;
    uint32_t prim;
} rs_hit;

#endif
