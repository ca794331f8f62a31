/* core/sampling.h — direction sampling routines and orthonormal bases, shared by host and device.
 *
 * Each sampler maps two uniform numbers in [0, 1) to a direction in a local frame whose z axis
 * is the surface normal, and has a matching pdf over solid angle.  Derivations (inversion of the
 * CDF; see the thesis's Table 5.1, whose power-cosine and sphere rows carry typos):
 *   uniform hemisphere  p = 1 / (2 pi):   z = u1,            phi = 2 pi u2
 *   cosine hemisphere   p = cos / pi:     r = sqrt(u1),      phi = 2 pi u2 (Malley's method) */
#ifndef RS_CORE_SAMPLING_H
#define RS_CORE_SAMPLING_H

#include "core/vec3.h"

#define RS_PI     3.14159265358979323846f
#define RS_INV_PI 0.31830988618379067154f

typedef struct rs_onb {
    rs_vec3 t, b, n;
} rs_onb;

/* A right-handed frame around unit vector n (Duff et al. 2017, "Building an orthonormal basis,
 * revisited": no branch on the axis, no singularity). */
RS_HD rs_onb rs_onb_from_normal(rs_vec3 n)
{
    rs_onb f;
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    f.t = rs_v3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
    f.b = rs_v3(b, sign + n.y * n.y * a, -n.y);
    f.n = n;
    return f;
}

RS_HD rs_vec3 rs_onb_to_world(const rs_onb *f, rs_vec3 l)
{
    return rs_v3_add(rs_v3_add(rs_v3_scale(f->t, l.x), rs_v3_scale(f->b, l.y)),
                     rs_v3_scale(f->n, l.z));
}

RS_HD rs_vec3 rs_sample_uniform_hemisphere(float u1, float u2)
{
    float z = u1;
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    float phi = 2.0f * RS_PI * u2;
    return rs_v3(r * cosf(phi), r * sinf(phi), z);
}

RS_HD float rs_pdf_uniform_hemisphere(float cos_theta)
{
    return cos_theta > 0.0f ? 0.5f * RS_INV_PI : 0.0f;
}

RS_HD rs_vec3 rs_sample_cosine_hemisphere(float u1, float u2)
{
    float r = sqrtf(u1);
    float phi = 2.0f * RS_PI * u2;
    return rs_v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u1)));
}

RS_HD float rs_pdf_cosine_hemisphere(float cos_theta)
{
    return cos_theta > 0.0f ? cos_theta * RS_INV_PI : 0.0f;
}

#endif
