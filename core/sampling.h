/* core/sampling.h — direction sampling routines and orthonormal bases, shared by host and device.
 *
 * Each sampler maps two uniform numbers in [0, 1) to a direction in a local frame whose z axis
 * is the axis of the distribution, and has a matching pdf over solid angle.  Each comes from
 * inverting the CDF of theta with phi uniform (thesis §A.3.1, whose Table 5.1 has two typos:
 * the power-cosine z is u^(1/(n+1)), not u^(n+1), and the uniform-sphere z is 1 - 2u):
 *   uniform sphere      p = 1 / (4 pi)               z = 1 - 2 u1
 *   uniform hemisphere  p = 1 / (2 pi)               z = u1
 *   cosine hemisphere   p = cos / pi                 z = sqrt(1 - u1)   (Malley: r = sqrt(u1))
 *   power cosine        p = (n + 1) cos^n / (2 pi)   z = u1^(1 / (n + 1))
 *   uniform cone        p = 1 / (2 pi (1 - cmax))    1 - z = u1 (1 - cmax)
 * and phi = 2 pi u2 for all of them.  The pdfs are tested (integral = 1, chi-square). */
#ifndef RS_CORE_SAMPLING_H
#define RS_CORE_SAMPLING_H

#include "core/hdmath.h"
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
    float r = sqrtf(rs_fmaxf(0.0f, 1.0f - z * z)), s, c;
    rs_sincosf(2.0f * RS_PI * u2, &s, &c);
    return rs_v3(r * c, r * s, z);
}

RS_HD float rs_pdf_uniform_hemisphere(float cos_theta)
{
    return cos_theta > 0.0f ? 0.5f * RS_INV_PI : 0.0f;
}

RS_HD rs_vec3 rs_sample_cosine_hemisphere(float u1, float u2)
{
    float r = sqrtf(u1), s, c;
    rs_sincosf(2.0f * RS_PI * u2, &s, &c);
    return rs_v3(r * c, r * s, sqrtf(rs_fmaxf(0.0f, 1.0f - u1)));
}

RS_HD float rs_pdf_cosine_hemisphere(float cos_theta)
{
    return cos_theta > 0.0f ? cos_theta * RS_INV_PI : 0.0f;
}

/* Direction from cos(theta) and phi = 2 pi u2 around the z axis. */
RS_HD rs_vec3 rs_dir_from_z(float z, float u2)
{
    float r = sqrtf(rs_fmaxf(0.0f, 1.0f - z * z)), s, c;
    rs_sincosf(2.0f * RS_PI * u2, &s, &c);
    return rs_v3(r * c, r * s, z);
}

RS_HD rs_vec3 rs_sample_uniform_sphere(float u1, float u2)
{
    return rs_dir_from_z(1.0f - 2.0f * u1, u2);
}

RS_HD float rs_pdf_uniform_sphere(void) { return 0.25f * RS_INV_PI; }

/* cos^n lobe around z, normalised over the hemisphere: p = (n + 1) / (2 pi) cos^n(theta). */
RS_HD rs_vec3 rs_sample_power_cosine(float n, float u1, float u2)
{
    return rs_dir_from_z(rs_powf(u1, 1.0f / (n + 1.0f)), u2);
}

RS_HD float rs_pdf_power_cosine(float n, float cos_theta)
{
    return cos_theta > 0.0f ? (n + 1.0f) * 0.5f * RS_INV_PI * rs_powf(cos_theta, n) : 0.0f;
}

/* Uniform over the cone of directions within angle theta_max of z, given omc = 1 - cos(theta_max).
 * Sampled in 1 - cos(theta) = u1 omc and sin(theta) = sqrt(s (2 - s)) (as pbrt-v4), never via a
 * float cos(theta) near 1: a small cone (a far sphere light) keeps every polar angle it has. */
RS_HD rs_vec3 rs_sample_uniform_cone(float omc, float u1, float u2)
{
    float s = u1 * omc;
    float r = sqrtf(rs_fmaxf(0.0f, s * (2.0f - s))), sp, cp;
    rs_sincosf(2.0f * RS_PI * u2, &sp, &cp);
    return rs_v3(r * cp, r * sp, 1.0f - s);
}

RS_HD float rs_pdf_uniform_cone(float omc) { return 1.0f / (2.0f * RS_PI * omc); }

/* Uniform point on a triangle as barycentrics (b1, b2) of v1 and v2 (sqrt warp). */
RS_HD void rs_sample_triangle(float u1, float u2, float *b1, float *b2)
{
    float su = sqrtf(u1);
    *b1 = su * (1.0f - u2);
    *b2 = su * u2;
}

/* Mirror direction of w about unit normal n (both pointing away from the surface). */
RS_HD rs_vec3 rs_reflect(rs_vec3 w, rs_vec3 n)
{
    return rs_v3_sub(rs_v3_scale(n, 2.0f * rs_v3_dot(n, w)), w);
}

#endif
