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
 *   dielectric + RS_MAT_EXACT_FRESNEL: the same with the exact Fresnel equations
 *   conductor         f = F(wo.h) D(h) G2 / (4 cos_o cos_i) (GGX, shading/microfacet.h), F from
 *                     the complex index eta + i k, or Schlick's from the colour albedo
 *                                                            sampled: visible normals (Heitz 2018)
 *   rough dielectric  Walter et al. 2007 with the exact Fresnel F(wo.h): reflection
 *                     F D G2 / (4 cos_o cos_i), transmission
 *                     (1 - F) D G2 |wi.h| |wo.h| / (cos_o |cos_i| (wi.h + wo.h / eta)^2), eta the
 *                     index across over the index on wo's side; tinted by albedo.  Radiance is
 *                     not scaled by eta^2 across the surface, as the smooth dielectric's is not
 *                     (a closed object's entry and exit cancel).
 *                                                            sampled: a visible normal, then
 *                     reflection with probability F, else refraction (pbrt-v4)
 *   pbr (glTF)        (1 - metallic) (Fd spec + (1 - Fd) base / pi) + metallic Fm spec, spec the
 *                     GGX term D G2 / (4 cos_o cos_i), Fd Schlick's with F0 = 0.04, Fm Schlick's
 *                     with F0 = base, both at wo.h (the glTF 2.0 specification's BRDF)
 *                                                            sampled: visible normals or cosine,
 *                     picked by the lobes' estimated weights at wo (rs_pbr_spec_prob).
 *                     KHR_materials_specular: Fd from F0 = ((ior-1)/(ior+1))^2 specularColor,
 *                     weighted; KHR_materials_clearcoat: the specification's fresnel_coat,
 *                     (1 - c Fc) f_base + c Fc D G2 / (4 cos_o cos_i) with the coat's alpha, Fc
 *                     Schlick's with F0 = 0.04 at n.wo, c the coat factor; sampled: the coat's
 *                     visible normals with probability c Fc, else the base as above;
 *                     KHR_materials_sheen under the coat: f_sheen + s f_base, f_sheen the
 *                     Charlie sheen (Conty & Kulla 2017: D = (2 + 1/a) sin(h)^(1/a) / 2pi,
 *                     their visibility, colour sheenColor), s = min(1 - max(sheenColor)
 *                     E(cos_o), 1 - max(sheenColor) E(cos_i)), E its albedo (sheen_table.h);
 *                     sampled: cosine with probability max(sheenColor) E(cos_o), else the base
 * A conductor or rough dielectric with alpha below RS_GGX_DELTA_ALPHA is perfectly smooth: a
 * mirror weighted by its Fresnel, or glass with the exact Fresnel (delta).
 *
 * Materials flagged RS_MAT_UNIFORM_SAMPLING draw uniform hemisphere directions instead of the
 * sampler above (the same f: only the noise changes). */
#ifndef RS_SHADING_BSDF_H
#define RS_SHADING_BSDF_H

#include "core/sampling.h"
#include "scenes/scene.h"
#include "shading/microfacet.h"
#include "shading/sheen_table.h"

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
    return m->type == RS_MAT_METAL || m->type == RS_MAT_DIELECTRIC ||
           ((m->type == RS_MAT_CONDUCTOR || m->type == RS_MAT_ROUGH_DIELECTRIC) &&
            m->alpha < RS_GGX_DELTA_ALPHA);
}

/* Whether a non-delta material sends light through the surface (wi on the far side). */
RS_HD int rs_material_transmits(const rs_material *m)
{
    return m->type == RS_MAT_ROUGH_DIELECTRIC && m->alpha >= RS_GGX_DELTA_ALPHA;
}

RS_HD rs_vec3 rs_conductor_fresnel(const rs_material *m, rs_vec3 albedo, float c)
{
    return (m->flags & RS_MAT_F0_COLOR) ? rs_fresnel_schlick3(c, albedo)
                                        : rs_fresnel_conductor(c, m->eta, m->k);
}

/* The pbr material's dielectric layer's Fresnel at cos c: Schlick's from its F0 colour, times
 * its weight (glTF's KHR_materials_specular: F0 = ((ior - 1) / (ior + 1))^2 specularColor held
 * to 1, weight specularFactor; the base's diffuse gets 1 - the largest component). */
RS_HD rs_vec3 rs_pbr_dielectric_fresnel(const rs_material *m, float c)
{
    return rs_v3_scale(rs_fresnel_schlick3(c, m->specular), m->spec_weight);
}

/* glTF's clearcoat: its weight c Fc at wo (c the coat factor, Fc Schlick's with the coat's
 * F0 = 0.04, ior 1.5, at n.wo, as KHR_materials_clearcoat's fresnel_coat takes it). */
RS_HD float rs_pbr_coat_weight(const rs_material *m, float co)
{
    float c = 1.0f - rs_fminf(rs_fmaxf(co, 0.0f), 1.0f), c2 = c * c;
    return m->coat * (0.04f + 0.96f * c2 * c2 * c);
}

/* glTF's sheen (KHR_materials_sheen, its "Charlie" distribution and visibility; Conty and Kulla
 * 2017): the exponent's fit l(x) and the visibility's lambda, at roughness a (>= 0.07). */
RS_HD float rs_sheen_l(float x, float a)
{
    float t = (1.0f - a) * (1.0f - a);
    float A = 21.5473f + (25.3245f - 21.5473f) * t, B = 3.82987f + (3.32435f - 3.82987f) * t;
    float C = 0.19823f + (0.16801f - 0.19823f) * t, D = -1.97760f + (-1.27393f + 1.97760f) * t;
    float E = -4.32054f + (-4.85967f + 4.32054f) * t;
    return A / (1.0f + B * rs_powf(x, C)) + D * x + E;
}

RS_HD float rs_sheen_lambda(float c, float a)
{
    c = rs_fminf(fabsf(c), 1.0f); /* a cosine rounded above 1 would take rs_powf of x < 0 */
    return c < 0.5f ? rs_expf(rs_sheen_l(c, a))
                    : rs_expf(2.0f * rs_sheen_l(0.5f, a) - rs_sheen_l(1.0f - c, a));
}

/* The sheen BRDF (colour 1): D V with cos_o, cos_i > 0 and ch = n.h, a = max(rough, 0.07). */
RS_HD float rs_sheen_brdf(float rough, float co, float ci, float ch)
{
    float a = rs_fmaxf(rough, 0.07f), s2h = rs_fmaxf(0.0f, 1.0f - ch * ch);
    float d = (2.0f + 1.0f / a) * rs_powf(s2h, 0.5f / a) * (0.5f * RS_INV_PI);
    return d / ((1.0f + rs_sheen_lambda(co, a) + rs_sheen_lambda(ci, a)) * 4.0f * co * ci);
}

/* The sheen BRDF's directional albedo at cos c, roughness `rough`: the table, bilinear. */
RS_HD float rs_sheen_albedo(float rough, float c)
{
    float x = rs_fminf(rs_fmaxf(c, 0.0f), 1.0f) * (RS_SHEEN_TABLE_N - 1);
    float y = rs_fminf(rs_fmaxf(rough, 0.0f), 1.0f) * (RS_SHEEN_TABLE_N - 1);
    int i = (int)x, j = (int)y;
    float fx, fy;
    i = i > RS_SHEEN_TABLE_N - 2 ? RS_SHEEN_TABLE_N - 2 : i;
    j = j > RS_SHEEN_TABLE_N - 2 ? RS_SHEEN_TABLE_N - 2 : j;
    fx = x - (float)i;
    fy = y - (float)j;
    return (1.0f - fy) * ((1.0f - fx) * rs_sheen_table_at(j, i) + fx * rs_sheen_table_at(j, i + 1)) +
           fy * ((1.0f - fx) * rs_sheen_table_at(j + 1, i) + fx * rs_sheen_table_at(j + 1, i + 1));
}

/* The probability that pbr sampling draws the sheen's (cosine) lobe at cos_o co. */
RS_HD float rs_pbr_sheen_prob(const rs_material *m, float co)
{
    return rs_fminf(rs_v3_max_comp(m->sheen) * rs_sheen_albedo(m->sheen_rough, co), 1.0f);
}

/* The probability that pbr sampling picks the specular lobe: its estimated share of the
 * reflected light at wo (Fresnel at cos_o for both layers). */
RS_HD float rs_pbr_spec_prob(const rs_material *m, rs_vec3 base, float co)
{
    float fd = rs_v3_max_comp(rs_pbr_dielectric_fresnel(m, co));
    float ws = (1.0f - m->metallic) * fd +
               m->metallic * rs_luminance(rs_fresnel_schlick3(co, base));
    float wd = (1.0f - m->metallic) * (1.0f - fd) * rs_luminance(base);
    return ws + wd > 0.0f ? ws / (ws + wd) : 1.0f;
}

/* The GGX specular term D G2 / (4 cos_o cos_i) and the pdf of sampling wi by a visible normal;
 * h = unit(wo + wi). */
RS_HD float rs_ggx_reflect(float alpha, rs_vec3 n, rs_vec3 wo, rs_vec3 wi, float co, float ci,
                           float *pdf, float *wo_h)
{
    rs_vec3 h = rs_v3_normalize(rs_v3_add(wo, wi));
    float ch = rs_v3_dot(n, h), s2 = rs_v3_length2(rs_v3_cross(n, h));
    *wo_h = rs_v3_dot(wo, h);
    *pdf = *wo_h > 0.0f ? rs_ggx_visible_pdf(alpha, co, ch, s2, *wo_h) / (4.0f * *wo_h) : 0.0f;
    return rs_ggx_d(alpha, ch, s2) * rs_ggx_g2(alpha, co, ci) / (4.0f * co * ci);
}

/* The rough dielectric's f (untinted) and pdf for (wo, wi), n on wo's side, `front`: wo
 * outside. */
RS_HD float rs_rough_glass(const rs_material *m, int front, rs_vec3 n, rs_vec3 wo, rs_vec3 wi,
                           float *pdf)
{
    float co = rs_v3_dot(n, wo), ci = rs_v3_dot(n, wi), eta = front ? m->ior : 1.0f / m->ior;
    float etap, wo_h, wi_h, ch, s2, F, D, G, vis, denom;
    int reflect = ci > 0.0f;
    rs_vec3 h;
    *pdf = 0.0f;
    if (!(co > 0.0f) || ci == 0.0f)
        return 0.0f;
    etap = reflect ? 1.0f : eta;
    h = rs_v3_add(rs_v3_scale(wi, etap), wo);
    if (rs_v3_is_zero(h))
        return 0.0f;
    h = rs_v3_normalize(h);
    if (rs_v3_dot(h, n) < 0.0f)
        h = rs_v3_neg(h);
    wo_h = rs_v3_dot(wo, h);
    wi_h = rs_v3_dot(wi, h);
    if (wi_h * ci < 0.0f || !(wo_h > 0.0f))
        return 0.0f; /* a microfacet seen from its back */
    ch = rs_v3_dot(n, h);
    s2 = rs_v3_length2(rs_v3_cross(n, h));
    F = rs_fresnel_dielectric(wo_h, eta);
    D = rs_ggx_d(m->alpha, ch, s2);
    G = rs_ggx_g2(m->alpha, co, fabsf(ci));
    vis = rs_ggx_visible_pdf(m->alpha, co, ch, s2, wo_h);
    if (reflect) {
        *pdf = vis / (4.0f * wo_h) * F;
        return D * G * F / (4.0f * co * ci);
    }
    denom = (wi_h + wo_h / etap) * (wi_h + wo_h / etap);
    if (!(denom > 0.0f))
        return 0.0f;
    *pdf = vis * fabsf(wi_h) / denom * (1.0f - F);
    return D * (1.0f - F) * G * fabsf(wi_h * wo_h) / (fabsf(ci) * co * denom);
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

/* f(wo, wi) of a non-delta material; zero when wi is below the surface (unless the material
 * transmits).  `albedo` is the material's albedo after texturing; `front`: wo is on the side the
 * geometric normal faces (only a transmitting material reads it). */
RS_HD_COLD rs_vec3 rs_bsdf_eval_ggx(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                    rs_vec3 wi, int front);
RS_HD_COLD float rs_bsdf_pdf_ggx(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                 rs_vec3 wi, int front);

RS_HD_HOT rs_vec3 rs_bsdf_eval_side(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                rs_vec3 wi, int front)
{
    float ci = rs_v3_dot(n, wi), co = rs_v3_dot(n, wo);
    if (m->type >= RS_MAT_CONDUCTOR)
        return rs_bsdf_eval_ggx(m, albedo, n, wo, wi, front);
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
            ca > 0.0f ? (m->exponent + 2.0f) * 0.5f * RS_INV_PI * rs_powf(ca, m->exponent) : 0.0f;
        return rs_v3_add(rs_v3_scale(albedo, RS_INV_PI), rs_v3_scale(m->specular, lobe));
    }
    default: return rs_v3_splat(0.0f);
    }
}

/* The GGX materials' f (out of line: see RS_HD_COLD). */
RS_HD_COLD rs_vec3 rs_bsdf_eval_ggx(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                    rs_vec3 wi, int front)
{
    float ci = rs_v3_dot(n, wi), co = rs_v3_dot(n, wo), pdf, wo_h, spec;
    if (rs_material_transmits(m))
        return rs_v3_scale(albedo, rs_rough_glass(m, front, n, wo, wi, &pdf));
    if (!(ci > 0.0f && co > 0.0f) || m->type == RS_MAT_ROUGH_DIELECTRIC)
        return rs_v3_splat(0.0f);
    spec = rs_ggx_reflect(m->alpha, n, wo, wi, co, ci, &pdf, &wo_h);
    if (m->type == RS_MAT_CONDUCTOR)
        return rs_v3_scale(rs_conductor_fresnel(m, albedo, wo_h), spec);
    {
        rs_vec3 fr = rs_pbr_dielectric_fresnel(m, wo_h);
        float fd = rs_v3_max_comp(fr);
        rs_vec3 diel =
            rs_v3_add(rs_v3_scale(fr, spec), rs_v3_scale(albedo, (1.0f - fd) * RS_INV_PI));
        rs_vec3 metal = rs_v3_scale(rs_fresnel_schlick3(wo_h, albedo), spec);
        rs_vec3 f = rs_v3_add(rs_v3_scale(diel, 1.0f - m->metallic), rs_v3_scale(metal, m->metallic));
        if (!rs_v3_is_zero(m->sheen)) {
            /* the sheen over the base, the base scaled by what the sheen does not take */
            float mx = rs_v3_max_comp(m->sheen), ch = rs_v3_dot(n, rs_v3_normalize(rs_v3_add(wo, wi)));
            float sc = rs_fminf(1.0f - mx * rs_sheen_albedo(m->sheen_rough, co),
                                1.0f - mx * rs_sheen_albedo(m->sheen_rough, ci));
            f = rs_v3_add(rs_v3_scale(f, sc),
                          rs_v3_scale(m->sheen, rs_sheen_brdf(m->sheen_rough, co, ci, ch)));
        }
        if (m->coat > 0.0f) {
            float wc = rs_pbr_coat_weight(m, co), pc, hc;
            float coat = rs_ggx_reflect(m->coat_alpha, n, wo, wi, co, ci, &pc, &hc);
            f = rs_v3_add(rs_v3_scale(f, 1.0f - wc), rs_v3_splat(wc * coat));
        }
        return f;
    }
}

RS_HD rs_vec3 rs_bsdf_eval(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, rs_vec3 wi)
{
    return rs_bsdf_eval_side(m, albedo, n, wo, wi, 1);
}

/* The pdf with which rs_bsdf_sample draws wi (non-delta materials). */
RS_HD_HOT float rs_bsdf_pdf_side(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                 rs_vec3 wi, int front)
{
    float ci = rs_v3_dot(n, wi);
    if (m->type >= RS_MAT_CONDUCTOR)
        return rs_bsdf_pdf_ggx(m, albedo, n, wo, wi, front);
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

RS_HD_COLD float rs_bsdf_pdf_ggx(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                 rs_vec3 wi, int front)
{
    float ci = rs_v3_dot(n, wi), co = rs_v3_dot(n, wo), pdf, wo_h;
    if (rs_material_transmits(m)) {
        rs_rough_glass(m, front, n, wo, wi, &pdf);
        return pdf;
    }
    if (!(ci > 0.0f) || !(co > 0.0f) || m->type == RS_MAT_ROUGH_DIELECTRIC)
        return 0.0f;
    rs_ggx_reflect(m->alpha, n, wo, wi, co, ci, &pdf, &wo_h);
    if (m->type == RS_MAT_PBR) {
        float ps = rs_pbr_spec_prob(m, albedo, co);
        pdf = ps * pdf + (1.0f - ps) * rs_pdf_cosine_hemisphere(ci);
        if (!rs_v3_is_zero(m->sheen)) {
            float qs = rs_pbr_sheen_prob(m, co);
            pdf = qs * rs_pdf_cosine_hemisphere(ci) + (1.0f - qs) * pdf;
        }
        if (m->coat > 0.0f) {
            float q = rs_pbr_coat_weight(m, co), pc, hc;
            rs_ggx_reflect(m->coat_alpha, n, wo, wi, co, ci, &pc, &hc);
            pdf = q * pc + (1.0f - q) * pdf;
        }
    }
    return pdf;
}

RS_HD float rs_bsdf_pdf(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, rs_vec3 wi)
{
    return rs_bsdf_pdf_side(m, albedo, n, wo, wi, 1);
}

/* wo's mirror image about the microfacet normal drawn from the visible normals of GGX alpha. */
RS_HD rs_vec3 rs_ggx_sample_reflect(float alpha, const rs_onb *frame, rs_vec3 wo, float u1,
                                    float u2, rs_vec3 *h_out)
{
    rs_vec3 wl = rs_v3(rs_v3_dot(wo, frame->t), rs_v3_dot(wo, frame->b), rs_v3_dot(wo, frame->n));
    rs_vec3 h = rs_onb_to_world(frame, rs_ggx_sample_visible(alpha, wl, u1, u2));
    *h_out = h;
    return rs_reflect(wo, h);
}

/* Smooth glass: reflection with the Fresnel probability (Schlick's, or exactly), else Snell's
 * refraction; total internal reflection; weight the tint. */
RS_HD int rs_sample_glass(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo, int front,
                          float u3, int exact, rs_scatter *out)
{
    float eta = front ? 1.0f / m->ior : m->ior;
    float co = rs_fminf(rs_v3_dot(wo, n), 1.0f);
    float so = sqrtf(rs_fmaxf(0.0f, 1.0f - co * co));
    out->delta = 1;
    out->weight = albedo;
    if (eta * so > 1.0f ||
        (exact ? rs_fresnel_dielectric(co, 1.0f / eta) : rs_schlick(co, eta)) > u3) {
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

/* The GGX materials' sampling (out of line: see RS_HD_COLD); out's flags are reset. */
RS_HD_COLD int rs_bsdf_sample_ggx(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                                  int front, float u1, float u2, float u3, rs_scatter *out)
{
    rs_onb frame;
    rs_vec3 f, h;
    float c;
    if (m->alpha < RS_GGX_DELTA_ALPHA && m->type == RS_MAT_CONDUCTOR) {
        out->wi = rs_reflect(wo, n);
        out->weight = rs_conductor_fresnel(m, albedo, rs_v3_dot(wo, n));
        out->delta = 1;
        return 1;
    }
    if (m->alpha < RS_GGX_DELTA_ALPHA && m->type == RS_MAT_ROUGH_DIELECTRIC)
        return rs_sample_glass(m, albedo, n, wo, front, u3, 1, out);
    frame = rs_onb_from_normal(n);
    if (m->type == RS_MAT_ROUGH_DIELECTRIC) {
        /* a visible normal, then reflection with probability F, else refraction about it */
        float eta = front ? m->ior : 1.0f / m->ior, wo_h, F;
        out->wi = rs_ggx_sample_reflect(m->alpha, &frame, wo, u1, u2, &h);
        wo_h = rs_v3_dot(wo, h);
        F = rs_fresnel_dielectric(wo_h, eta);
        if (!(u3 < F)) {
            /* Snell about h: wt = -wo / eta + (cos_i / eta - cos_t) h */
            float s2t = rs_fmaxf(0.0f, 1.0f - wo_h * wo_h) / (eta * eta);
            if (s2t >= 1.0f)
                return 0;
            out->wi = rs_v3_normalize(rs_v3_add(rs_v3_scale(wo, -1.0f / eta),
                                                rs_v3_scale(h, wo_h / eta - sqrtf(1.0f - s2t))));
            out->transmit = 1;
        }
        c = rs_v3_dot(n, out->wi);
        if (out->transmit ? !(c < 0.0f) : !(c > 0.0f))
            return 0; /* the microfacet sent it to the wrong side of the surface */
    } else {
        float q = m->type == RS_MAT_PBR && m->coat > 0.0f
                      ? rs_pbr_coat_weight(m, rs_v3_dot(n, wo)) : 0.0f;
        float qs;
        int coat = u3 < q, sheen = 0; /* the clearcoat's visible normals, with probability q */
        if (!coat && q > 0.0f)
            u3 = (u3 - q) / (1.0f - q); /* the rest's own pick, from what is left */
        if (!coat && m->type == RS_MAT_PBR && !rs_v3_is_zero(m->sheen)) {
            qs = rs_pbr_sheen_prob(m, rs_v3_dot(n, wo)); /* the sheen: cosine, probability qs */
            sheen = u3 < qs;
            if (!sheen)
                u3 = (u3 - qs) / (1.0f - qs);
        }
        if (coat)
            out->wi = rs_ggx_sample_reflect(m->coat_alpha, &frame, wo, u1, u2, &h);
        else if (sheen)
            out->wi = rs_onb_to_world(&frame, rs_sample_cosine_hemisphere(u1, u2));
        else if (m->type == RS_MAT_CONDUCTOR || u3 < rs_pbr_spec_prob(m, albedo, rs_v3_dot(n, wo)))
            out->wi = rs_ggx_sample_reflect(m->alpha, &frame, wo, u1, u2, &h);
        else
            out->wi = rs_onb_to_world(&frame, rs_sample_cosine_hemisphere(u1, u2));
        c = rs_v3_dot(n, out->wi);
        if (!(c > 0.0f))
            return 0; /* reflected below the surface */
    }
    f = rs_bsdf_eval_ggx(m, albedo, n, wo, out->wi, front);
    out->pdf = rs_bsdf_pdf_ggx(m, albedo, n, wo, out->wi, front);
    if (!(out->pdf > 0.0f))
        return 0;
    out->weight = rs_v3_scale(f, fabsf(c) / out->pdf);
    return 1;
}

/* Draws wi for wo from three uniform numbers.  Returns 0 when the sample carries nothing (below
 * the surface, absorbed): the path ends there. */
RS_HD_HOT int rs_bsdf_sample(const rs_material *m, rs_vec3 albedo, rs_vec3 n, rs_vec3 wo,
                             int front, float u1, float u2, float u3, rs_scatter *out)
{
    rs_onb frame;
    rs_vec3 f;
    float ci;
    out->delta = 0;
    out->transmit = 0;
    out->pdf = 0.0f;
    if (m->type >= RS_MAT_CONDUCTOR)
        return rs_bsdf_sample_ggx(m, albedo, n, wo, front, u1, u2, u3, out);
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
    if (m->type == RS_MAT_DIELECTRIC)
        return rs_sample_glass(m, albedo, n, wo, front, u3, (m->flags & RS_MAT_EXACT_FRESNEL) != 0,
                               out);
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
