/* shading/bsdf.h — the thesis's materials as BSDFs (RS_HD: plain data in, numbers out).
 *
 * Conventions: directions are unit vectors pointing away from the surface; wo toward the viewer,
 * wi toward the light.  n is the unit normal on wo's side (dot(n, wo) > 0); `front` says whether
 * that side is the geometric front (outside), which only the dielectric needs.
 *
 *   lambertian        f = a / pi                              sampled: cosine
 *   diffuse-uniform   f cos = a / (2 pi)  (the thesis's uniform-hemisphere diffuse, RTIOW v1's
 *                     "hemispherical scattering": energy-conserving, not reciprocal)
 *                                                            sampled: uniform hemisphere
 *   disney-diffuse    f = a / pi (1 + (F90 - 1)(1 - cos_i)^5)(1 + (F90 - 1)(1 - cos_o)^5),
 *                     F90 = 1/2 + 2 roughness cos^2(theta_d)   (Burley 2012, §5.3)
 *                                                            sampled: cosine
 *   phong             f = kd / pi + ks (n + 2) / (2 pi) cos^n(alpha), alpha between wi and the
 *                     mirror direction of wo (Lafortune & Willems 1994): energy-conserving when
 *                     kd + ks <= 1               sampled: cosine or the power-cosine lobe,
 *                     picked in proportion to the luminances of kd and ks
 *   metal             mirror direction + fuzz * (a random unit vector) (RTIOW); weight a; delta
 *   dielectric        reflect with Schlick's Fresnel, else refract (RTIOW); total internal
 *                     reflection; weight a (the tint, white for clear glass); delta
 *
 * Materials flagged RS_MAT_UNIFORM_SAMPLING draw uniform hemisphere directions instead of the
 * sampler above (the same f: only the noise changes). */
#ifndef RS_SHADING_BSDF_H
#define RS_SHADING_BSDF_H

#include "core/sampling.h"
#include "scenes/scene.h"

typedef struct rs_scatter {
    rs_vec3 wi;     /* sampled direction */
    rs_vec3 weight; /* f cos / pdf, or the lobe's weight for a delta sample */
    float pdf;      /* solid-angle pdf of wi; 0 for a delta sample */
    int delta;      /* 1: specular: no light sampling, no MIS */
    int transmit;   /* 1: wi crosses the surface (refraction) */
} rs_scatter;

RS_HD float rs_luminance(rs_vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

RS_HD int rs_material_is_delta(const rs_material *m)
{
    return m->type == RS_MAT_METAL || m->type == RS_MAT_DIELECTRIC;
}

/* Probability that Phong sampling picks the diffuse lobe. */
RS_HD float rs_phong_diffuse_prob(rs_vec3 kd, rs_vec3 ks)
{
    float d = rs_luminance(kd), s = rs_luminance(ks);
    return d + s > 0.0f ? d / (d + s) : 1.0f;
}

RS_HD float rs_schlick(float cos_theta, float eta)
{
    float r0 = (1.0f - eta) / (1.0f + eta);
    float m = 1.0f - cos_theta;
    r0 *= r0;
    return r0 + (1.0f - r0) * m * m * m * m * m;
}

/* f(wo, wi) of a non-delta material; zero when wi is below the surface.  `albedo` is the
 * material's albedo after texturing. */
RS_HD rs_vec3 rs_bsdf_eval(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, rs_vec3 wi)
{
    float ci = rs_v3_dot(n, wi), co = rs_v3_dot(n, wo);
    if (!(ci > 0.0f && co > 0.0f))
        return rs_v3_splat(0.0f);
    switch (m->type) {
    case RS_MAT_LAMBERTIAN: return rs_v3_scale(albedo, RS_INV_PI);
    case RS_MAT_DIFFUSE_UNIFORM: return rs_v3_scale(albedo, 0.5f * RS_INV_PI / ci);
    case RS_MAT_DISNEY_DIFFUSE: {
        rs_vec3 h = rs_v3_add(wi, wo);
        float cd = rs_v3_dot(wi, h) / rs_v3_length(h); /* cos(theta_d) */
        float f90 = 0.5f + 2.0f * m->roughness * cd * cd;
        float mi = 1.0f - ci, mo = 1.0f - co;
        float fi = 1.0f + (f90 - 1.0f) * mi * mi * mi * mi * mi;
        float fo = 1.0f + (f90 - 1.0f) * mo * mo * mo * mo * mo;
        return rs_v3_scale(albedo, RS_INV_PI * fi * fo);
    }
    case RS_MAT_PHONG: {
        float ca = rs_v3_dot(rs_reflect(wo, n), wi);
        float lobe =
            ca > 0.0f ? (m->exponent + 2.0f) * 0.5f * RS_INV_PI * powf(ca, m->exponent) : 0.0f;
        return rs_v3_add(rs_v3_scale(albedo, RS_INV_PI), rs_v3_scale(m->specular, lobe));
    }
    default: return rs_v3_splat(0.0f);
    }
}

/* The pdf with which rs_bsdf_sample draws wi (non-delta materials). */
RS_HD float rs_bsdf_pdf(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, rs_vec3 wi)
{
    float ci = rs_v3_dot(n, wi);
    if (!(ci > 0.0f) || !(rs_v3_dot(n, wo) > 0.0f))
        return 0.0f;
    if ((m->flags & RS_MAT_UNIFORM_SAMPLING) || m->type == RS_MAT_DIFFUSE_UNIFORM)
        return rs_pdf_uniform_hemisphere(ci);
    if (m->type == RS_MAT_PHONG) {
        float pd = rs_phong_diffuse_prob(albedo, m->specular);
        float ca = rs_v3_dot(rs_reflect(wo, n), wi);
        return pd * rs_pdf_cosine_hemisphere(ci) +
               (1.0f - pd) * rs_pdf_power_cosine(m->exponent, ca);
    }
    return rs_pdf_cosine_hemisphere(ci);
}

/* Draws wi for wo from three uniform numbers.  Returns 0 when the sample carries nothing (below
 * the surface, absorbed): the path ends there. */
RS_HD int rs_bsdf_sample(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, int front,
                         float u1, float u2, float u3, rs_scatter *out)
{
    rs_onb frame;
    rs_vec3 f;
    float ci;
    out->delta = 0;
    out->transmit = 0;
    out->pdf = 0.0f;
    if (m->type == RS_MAT_METAL) {
        rs_vec3 r =
            rs_v3_add(rs_reflect(wo, n), rs_v3_scale(rs_sample_uniform_sphere(u1, u2), m->fuzz));
        if (!(rs_v3_dot(r, n) > 0.0f) || rs_v3_is_zero(r))
            return 0; /* fuzzed below the surface: absorbed (RTIOW) */
        out->wi = rs_v3_normalize(r);
        out->weight = albedo;
        out->delta = 1;
        return 1;
    }
    if (m->type == RS_MAT_DIELECTRIC) {
        float eta = front ? 1.0f / m->ior : m->ior;
        float co = rs_fminf(rs_v3_dot(wo, n), 1.0f);
        float so = sqrtf(rs_fmaxf(0.0f, 1.0f - co * co));
        out->delta = 1;
        out->weight = albedo;
        if (eta * so > 1.0f || rs_schlick(co, eta) > u3) {
            out->wi = rs_reflect(wo, n);
        } else {
            /* Snell: the perpendicular part scales by eta, the parallel part fills the rest */
            rs_vec3 perp = rs_v3_scale(rs_v3_madd(rs_v3_neg(wo), n, co), eta);
            rs_vec3 par = rs_v3_scale(n, -sqrtf(fabsf(1.0f - rs_v3_length2(perp))));
            out->wi = rs_v3_normalize(rs_v3_add(perp, par));
            out->transmit = 1;
        }
        return 1;
    }
    if (m->type == RS_MAT_DIFFUSE_LIGHT)
        return 0;
    frame = rs_onb_from_normal(n);
    if ((m->flags & RS_MAT_UNIFORM_SAMPLING) || m->type == RS_MAT_DIFFUSE_UNIFORM) {
        out->wi = rs_onb_to_world(&frame, rs_sample_uniform_hemisphere(u1, u2));
    } else if (m->type == RS_MAT_PHONG && u3 >= rs_phong_diffuse_prob(albedo, m->specular)) {
        rs_onb lobe = rs_onb_from_normal(rs_reflect(wo, n));
        out->wi = rs_onb_to_world(&lobe, rs_sample_power_cosine(m->exponent, u1, u2));
    } else {
        out->wi = rs_onb_to_world(&frame, rs_sample_cosine_hemisphere(u1, u2));
    }
    ci = rs_v3_dot(n, out->wi);
    if (!(ci > 0.0f))
        return 0; /* a Phong lobe sample below the surface */
    out->pdf = rs_bsdf_pdf(m, albedo, n, wo, out->wi);
    if (!(out->pdf > 0.0f))
        return 0;
    f = rs_bsdf_eval(m, albedo, n, wo, out->wi);
    out->weight = rs_v3_scale(f, ci / out->pdf);
    return 1;
}

#endif
