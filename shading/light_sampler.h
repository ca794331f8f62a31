/* shading/light_sampler.h — how next-event estimation picks the light it samples: one type,
 * with each way's `sample` and its `pmf` side by side (pbrt-v4's LightSampler: Sample and PMF).
 *
 *   RS_LIGHT_SAMPLER_POWER  every light in proportion to its power, wherever the vertex is: the
 *                           scene's CDF (shading/lights.h, rs_light_sample_from with
 *                           RS_LIGHTS_ALL); pmf: the light's pick_pdf.
 *   RS_LIGHT_SAMPLER_BVH    the environment map with its pick probability as ever, a bounded light
 *                           by the light BVH's importance at the vertex (shading/light_bvh.h) with
 *                           the BVH's share of the lights' power, a directional light by power
 *                           among the directional ones; pmf: the same product, computed again
 *                           from the vertex where a BSDF sample found the light.
 *
 * MIS needs both halves to agree: the weight of a BSDF sample that hits light l uses
 * rs_light_sampler_pmf of the sampler that would have sampled it (tests/
 * render_light_sampler_test.c and tests/shading_light_bvh_test.c check the pair).  The mixture
 * integrator's light half and its punctual lights (RS_LIGHTS_AREA, RS_LIGHTS_DELTA) always pick
 * by power.  Everything is RS_HD: the CUDA megakernel picks with this very code. */
#ifndef RS_SHADING_LIGHT_SAMPLER_H
#define RS_SHADING_LIGHT_SAMPLER_H

#include "shading/lights.h"

/* How next-event estimation picks a light (--light-sampler; MIS only, the other modes pick by
 * power). */
typedef enum rs_light_sampler {
    RS_LIGHT_SAMPLER_POWER = 0, /* in proportion to each light's power, anywhere */
    RS_LIGHT_SAMPLER_BVH = 1    /* by the light BVH's importance at the point (light_bvh.h) */
} rs_light_sampler;

/* ---- by the light BVH ---- */

/* The probability that rs_light_sample_bvh picks light l for a vertex whose light pick was
 * taken at `at` (the vertex's offset origin; what MIS needs when a BSDF sample hits l). */
RS_HD float rs_light_pick_bvh(const rs_scene *s, uint32_t l, rs_vec3 at)
{
    if (s->light_trail && s->light_trail[l])
        return (1.0f - s->env_pick) * s->light_bvh_mass * rs_light_bvh_pmf(s, at, l);
    return s->lights[l].pick_pdf; /* a directional light: by power (never hit by a ray) */
}

/* The map with its pick probability as ever, else a bounded light picked by the
 * light BVH at `at` (with the BVH's share of the lights' power), else a directional light by
 * power among the directional ones; x, n_x, time, u1, u2 as rs_light_sample_from. */
RS_HD_COLD int rs_light_sample_bvh(const rs_scene *s, rs_vec3 x, rs_vec3 n_x, rs_vec3 at,
                                   float time, float u_pick, float u1, float u2,
                                   rs_light_sample *out)
{
    float env_pick = s->env_pick, m = s->light_bvh_mass, pick;
    uint32_t l = 0, i;
    if (!rs_scene_has_lights(s))
        return 0;
    out->env = 0;
    out->delta = 0;
    if (env_pick > 0.0f) {
        if (u_pick < env_pick)
            return rs_light_sample_env(s, x, n_x, env_pick, u1, u2, out);
        u_pick = (u_pick - env_pick) / (1.0f - env_pick);
    }
    if (s->n_lights == 0)
        return 0;
    if (u_pick < m && s->light_nodes) {
        float pmf;
        if (!rs_light_bvh_pick(s, at, rs_fminf(u_pick / m, 0x1.fffffep-1f), &l, &pmf))
            return 0;
        pick = (1.0f - env_pick) * m * pmf;
    } else {
        /* the directional lights, by their power (1 - m of it) */
        float total = 0.0f, acc = 0.0f, u;
        int found = 0;
        for (i = s->n_area_lights; i < s->n_lights; ++i)
            if (!s->light_trail || !s->light_trail[i])
                total += s->lights[i].power;
        u = (m < 1.0f ? (u_pick - m) / (1.0f - m) : 0.0f) * total;
        for (i = s->n_area_lights; i < s->n_lights && !found; ++i)
            if (!s->light_trail || !s->light_trail[i]) {
                acc += s->lights[i].power;
                if (u < acc || i + 1 == s->n_lights) {
                    l = i;
                    found = 1;
                }
            }
        if (!found || !(total > 0.0f))
            return 0;
        pick = s->lights[l].pick_pdf;
    }
    return rs_light_sample_one(s, l, pick, 1.0f, x, time, u1, u2, out);
}

/* ---- the sampler ---- */

/* A light sample for a surface vertex at x with unit normal n_x, whose shadow ray starts at `at`
 * (its offset origin, where the BVH's importance is taken), at `time`, by `sampler`
 * (rs_light_sampler); u_pick picks the light, u1 and u2 the point on it.  The pdf includes the
 * pick probability: rs_light_sampler_pmf's for that light. */
RS_HD int rs_light_sampler_sample(const rs_scene *s, uint32_t sampler, rs_vec3 x, rs_vec3 n_x,
                                  rs_vec3 at, float time, float u_pick, float u1, float u2,
                                  rs_light_sample *out)
{
    if (sampler == RS_LIGHT_SAMPLER_BVH)
        return rs_light_sample_bvh(s, x, n_x, at, time, u_pick, u1, u2, out);
    return rs_light_sample_from(s, RS_LIGHTS_ALL, x, n_x, time, u_pick, u1, u2, out);
}

/* The probability that rs_light_sampler_sample picks light l for a vertex whose offset origin is
 * `at`. */
RS_HD float rs_light_sampler_pmf(const rs_scene *s, uint32_t sampler, uint32_t l, rs_vec3 at)
{
    if (sampler == RS_LIGHT_SAMPLER_BVH)
        return rs_light_pick_bvh(s, l, at);
    return s->lights[l].pick_pdf;
}

#endif
