/* shading/microfacet.h — the GGX (Trowbridge-Reitz) microfacet distribution and the Fresnel
 * equations (RS_HD).
 *
 * Isotropic GGX of roughness alpha, for a microfacet normal h at angle theta_h to n:
 *   D(h)      = alpha^2 / (pi (cos^2 theta_h (alpha^2 - 1) + 1)^2)     (integral D cos = 1)
 *   Lambda(w) = (sqrt(1 + alpha^2 tan^2 theta) - 1) / 2
 *   G1(w)     = 1 / (1 + Lambda(w)),  G2(wo, wi) = 1 / (1 + Lambda(wo) + Lambda(wi))
 *               (Smith, height-correlated: Heitz 2014)
 *   D_wo(h)   = G1(wo) max(0, wo.h) D(h) / cos theta_o   (the normals visible from wo: their
 *               distribution integrates to 1, the "weak white furnace")
 * D_wo is sampled exactly by Heitz 2018, "Sampling the GGX distribution of visible normals".
 *
 * Fresnel: the exact dielectric equations (unpolarised), a conductor's from its complex index
 * eta + i k (pbrt-v4's FrComplex), and Schlick's approximation from a colour at normal
 * incidence (glTF's). */
#ifndef RS_SHADING_MICROFACET_H
#define RS_SHADING_MICROFACET_H

#include "core/sampling.h"

/* D(h) for cos_h = n.h and sin2_h = |n x h|^2 (taken from the cross product, not 1 - cos^2: near
 * the peak of a sharp lobe 1 - cos^2 cancels to a few float ulps, and D went 3e-4 wrong at
 * alpha = 0.02). */
RS_HD float rs_ggx_d(float alpha, float cos_h, float sin2_h)
{
    float a2 = alpha * alpha, t = sin2_h + a2 * cos_h * cos_h;
    if (!(cos_h > 0.0f) || !(t > 0.0f))
        return 0.0f;
    return a2 / (RS_PI * t * t);
}

/* Lambda of a direction at |cos theta| = c. */
RS_HD float rs_ggx_lambda(float alpha, float c)
{
    float c2 = c * c, t2;
    if (!(c2 > 0.0f))
        return 1e30f;
    t2 = rs_fmaxf(0.0f, 1.0f - c2) / c2;
    return 0.5f * (sqrtf(1.0f + alpha * alpha * t2) - 1.0f);
}

RS_HD float rs_ggx_g1(float alpha, float c) { return 1.0f / (1.0f + rs_ggx_lambda(alpha, c)); }

RS_HD float rs_ggx_g2(float alpha, float co, float ci)
{
    return 1.0f / (1.0f + rs_ggx_lambda(alpha, co) + rs_ggx_lambda(alpha, ci));
}

/* D_wo(h): the density of the visible normal h (cos_h = n.h, sin2_h = |n x h|^2, wo_h = wo.h,
 * co = n.wo > 0). */
RS_HD float rs_ggx_visible_pdf(float alpha, float co, float cos_h, float sin2_h, float wo_h)
{
    if (!(wo_h > 0.0f) || !(co > 0.0f))
        return 0.0f;
    return rs_ggx_g1(alpha, co) * wo_h * rs_ggx_d(alpha, cos_h, sin2_h) / co;
}

/* A visible normal for wo (local frame, z the normal, wo.z > 0) from (u1, u2): Heitz 2018. */
RS_HD rs_vec3 rs_ggx_sample_visible(float alpha, rs_vec3 wo, float u1, float u2)
{
    rs_vec3 vh = rs_v3_normalize(rs_v3(alpha * wo.x, alpha * wo.y, wo.z));
    float lensq = vh.x * vh.x + vh.y * vh.y;
    rs_vec3 t1 = lensq > 0.0f ? rs_v3_scale(rs_v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(lensq))
                              : rs_v3(1.0f, 0.0f, 0.0f);
    rs_vec3 t2 = rs_v3_cross(vh, t1), nh;
    float r = sqrtf(u1), sp, cp, p1, p2, s = 0.5f * (1.0f + vh.z);
    rs_sincosf(2.0f * RS_PI * u2, &sp, &cp);
    p1 = r * cp;
    p2 = r * sp;
    p2 = (1.0f - s) * sqrtf(rs_fmaxf(0.0f, 1.0f - p1 * p1)) + s * p2;
    nh = rs_v3_add(rs_v3_add(rs_v3_scale(t1, p1), rs_v3_scale(t2, p2)),
                   rs_v3_scale(vh, sqrtf(rs_fmaxf(0.0f, 1.0f - p1 * p1 - p2 * p2))));
    return rs_v3_normalize(rs_v3(alpha * nh.x, alpha * nh.y, rs_fmaxf(1e-7f, nh.z)));
}

/* Unpolarised reflectance of a dielectric interface for cos_i = the cosine on the incident side
 * and eta = (index across) / (index on the incident side); 1 under total internal reflection. */
RS_HD float rs_fresnel_dielectric(float cos_i, float eta)
{
    float s2i, s2t, ct, rpa, rpe;
    cos_i = rs_fminf(1.0f, rs_fmaxf(-1.0f, cos_i));
    if (cos_i < 0.0f) {
        eta = 1.0f / eta;
        cos_i = -cos_i;
    }
    s2i = 1.0f - cos_i * cos_i;
    s2t = s2i / (eta * eta);
    if (s2t >= 1.0f)
        return 1.0f;
    ct = sqrtf(rs_fmaxf(0.0f, 1.0f - s2t));
    rpa = (eta * cos_i - ct) / (eta * cos_i + ct);
    rpe = (cos_i - eta * ct) / (cos_i + eta * ct);
    return 0.5f * (rpa * rpa + rpe * rpe);
}

typedef struct rs_cplx {
    float re, im;
} rs_cplx;

RS_HD rs_cplx rs_cplx_make(float re, float im)
{
    rs_cplx c;
    c.re = re;
    c.im = im;
    return c;
}
RS_HD rs_cplx rs_cplx_add(rs_cplx a, rs_cplx b) { return rs_cplx_make(a.re + b.re, a.im + b.im); }
RS_HD rs_cplx rs_cplx_sub(rs_cplx a, rs_cplx b) { return rs_cplx_make(a.re - b.re, a.im - b.im); }
RS_HD rs_cplx rs_cplx_mul(rs_cplx a, rs_cplx b)
{
    return rs_cplx_make(a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re);
}
RS_HD rs_cplx rs_cplx_div(rs_cplx a, rs_cplx b)
{
    float d = b.re * b.re + b.im * b.im;
    return rs_cplx_make((a.re * b.re + a.im * b.im) / d, (a.im * b.re - a.re * b.im) / d);
}
RS_HD float rs_cplx_norm(rs_cplx a) { return a.re * a.re + a.im * a.im; }
/* The principal square root. */
RS_HD rs_cplx rs_cplx_sqrt(rs_cplx z)
{
    float n = sqrtf(sqrtf(rs_cplx_norm(z))), t1, t2;
    if (n == 0.0f)
        return rs_cplx_make(0.0f, 0.0f);
    t1 = sqrtf(0.5f * (n * n + fabsf(z.re)));
    t2 = 0.5f * z.im / t1;
    if (z.re >= 0.0f)
        return rs_cplx_make(t1, t2);
    return rs_cplx_make(fabsf(t2), copysignf(t1, z.im));
}

/* Unpolarised reflectance of a conductor of index eta + i k at cos_i >= 0 (pbrt-v4's FrComplex). */
RS_HD float rs_fresnel_complex(float cos_i, float eta, float k)
{
    rs_cplx e = rs_cplx_make(eta, k), ci, s2t, ct, a, b, rpa, rpe;
    float c = rs_fminf(1.0f, rs_fmaxf(0.0f, cos_i));
    ci = rs_cplx_make(c, 0.0f);
    s2t = rs_cplx_div(rs_cplx_make(1.0f - c * c, 0.0f), rs_cplx_mul(e, e));
    ct = rs_cplx_sqrt(rs_cplx_sub(rs_cplx_make(1.0f, 0.0f), s2t));
    a = rs_cplx_mul(e, ci);
    rpa = rs_cplx_div(rs_cplx_sub(a, ct), rs_cplx_add(a, ct));
    b = rs_cplx_mul(e, ct);
    rpe = rs_cplx_div(rs_cplx_sub(ci, b), rs_cplx_add(ci, b));
    return 0.5f * (rs_cplx_norm(rpa) + rs_cplx_norm(rpe));
}

RS_HD rs_vec3 rs_fresnel_conductor(float cos_i, rs_vec3 eta, rs_vec3 k)
{
    return rs_v3(rs_fresnel_complex(cos_i, eta.x, k.x), rs_fresnel_complex(cos_i, eta.y, k.y),
                 rs_fresnel_complex(cos_i, eta.z, k.z));
}

RS_HD rs_vec3 rs_fresnel_schlick3(float cos_i, rs_vec3 f0)
{
    float m = 1.0f - rs_fminf(1.0f, rs_fmaxf(0.0f, cos_i)), m5 = m * m * m * m * m;
    return rs_v3_add(f0, rs_v3_scale(rs_v3_sub(rs_v3_splat(1.0f), f0), m5));
}

#endif
