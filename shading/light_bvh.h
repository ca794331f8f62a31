/* shading/light_bvh.h — picking a light from the scene's light BVH (scenes/light_bvh.h) by its
 * estimated contribution at a point: each node's importance is Conty and Kulla's (2018) bound,
 * as pbrt-v4's LightBounds::Importance computes it but without the receiver's normal:
 *
 *     phi cos(max(0, theta_w - theta_o - theta_b)) / max(d^2, |diagonal| / 2), and 0 where that
 *     angle is beyond the node's emission cone (cos <= cos_e),
 *
 * d the distance from the point to the bounds' centre, theta_w the angle between the cone's axis
 * and the direction from the centre to the point (its absolute cosine for two-sided emitters),
 * theta_o the cone's half-angle, theta_b the half-angle the bounds subtend from the point.  The
 * bound never says 0 for a light that can reach the point, so every such light keeps a pick
 * probability above 0 (tests/shading_light_bvh_test.c).  Traversal goes down by the two
 * children's importances; rs_light_bvh_pmf retraces one light's path (rs_scene.light_trail) with
 * the same arithmetic, so a pick's probability and the pmf agree bit for bit.  A tree of one
 * light picks it with probability 1 wherever x is (where it cannot reach x, its sample carries
 * nothing, as with the power sampler): the one-light scene costs no importance at all.
 *
 * Leaving the normal out keeps the pick a function of the point alone, so the MIS weight of a
 * light that a BSDF sample hit can be computed at the next vertex from the ray's origin. */
#ifndef RS_SHADING_LIGHT_BVH_H
#define RS_SHADING_LIGHT_BVH_H

#include "core/hd.h"
#include "core/vec3.h"
#include "scenes/scene.h"

/* The importance of node `nd` at point x. */
RS_HD float rs_light_node_importance(const rs_light_node *nd, rs_vec3 x)
{
    rs_vec3 lo = rs_v3(nd->lo[0], nd->lo[1], nd->lo[2]), hi = rs_v3(nd->hi[0], nd->hi[1], nd->hi[2]);
    rs_vec3 pc = rs_v3_scale(rs_v3_add(lo, hi), 0.5f), to = rs_v3_sub(x, pc);
    float d2 = rs_v3_dot(to, to), diag = rs_v3_length(rs_v3_sub(hi, lo));
    float cos_w, sin_w, cos_b, sin_b, cos_x, sin_x, cos_p, sin_o;
    float r2 = 0.25f * diag * diag; /* the bounds' sphere */
    int inside = x.x >= lo.x && x.y >= lo.y && x.z >= lo.z && x.x <= hi.x && x.y <= hi.y &&
                 x.z <= hi.z;
    if (inside || !(d2 > r2)) {
        cos_b = -1.0f; /* every direction */
    } else {
        cos_b = sqrtf(rs_fmaxf(0.0f, 1.0f - r2 / d2));
    }
    sin_b = sqrtf(rs_fmaxf(0.0f, 1.0f - cos_b * cos_b));
    cos_w = d2 > 0.0f ? rs_v3_dot(rs_v3(nd->w[0], nd->w[1], nd->w[2]), to) / sqrtf(d2) : 1.0f;
    if (nd->flags & RS_LIGHT_NODE_TWO_SIDED)
        cos_w = fabsf(cos_w);
    cos_w = rs_fminf(rs_fmaxf(cos_w, -1.0f), 1.0f);
    sin_w = sqrtf(rs_fmaxf(0.0f, 1.0f - cos_w * cos_w));
    sin_o = sqrtf(rs_fmaxf(0.0f, 1.0f - nd->cos_o * nd->cos_o));
    /* cos(max(0, theta_w - theta_o)), then minus theta_b */
    if (cos_w > nd->cos_o) {
        cos_x = 1.0f;
        sin_x = 0.0f;
    } else {
        cos_x = cos_w * nd->cos_o + sin_w * sin_o;
        sin_x = sqrtf(rs_fmaxf(0.0f, 1.0f - cos_x * cos_x));
    }
    cos_p = cos_x > cos_b ? 1.0f : cos_x * cos_b + sin_x * sin_b;
    if (cos_p <= nd->cos_e)
        return 0.0f;
    return nd->phi * cos_p / rs_fmaxf(d2, 0.5f * diag);
}

/* The probability of going to the first child of interior node `n` from x (its importance over
 * both children's); -1 when neither child can light x. */
RS_HD float rs_light_bvh_first(const rs_scene *s, uint32_t n, rs_vec3 x)
{
    float i0 = rs_light_node_importance(&s->light_nodes[n + 1], x);
    float i1 = rs_light_node_importance(&s->light_nodes[s->light_nodes[n].child], x);
    if (!(i0 + i1 > 0.0f))
        return -1.0f;
    return i0 / (i0 + i1);
}

/* Picks a light of the BVH for point x with u in [0, 1): its index in s->lights and, in *pmf,
 * the probability of that pick among the BVH's lights.  0 when no light of it can reach x. */
RS_HD int rs_light_bvh_pick(const rs_scene *s, rs_vec3 x, float u, uint32_t *light, float *pmf)
{
    uint32_t n = 0;
    float p = 1.0f;
    if (!s->light_nodes)
        return 0;
    while (!(s->light_nodes[n].flags & RS_LIGHT_NODE_LEAF)) {
        float p0 = rs_light_bvh_first(s, n, x);
        if (p0 < 0.0f)
            return 0;
        if (u < p0) {
            u = rs_fminf(u / p0, 0x1.fffffep-1f);
            p *= p0;
            n = n + 1;
        } else {
            u = rs_fminf((u - p0) / (1.0f - p0), 0x1.fffffep-1f);
            p *= 1.0f - p0;
            n = s->light_nodes[n].child;
        }
    }
    *light = s->light_nodes[n].child;
    *pmf = p;
    return p > 0.0f;
}

/* The probability that rs_light_bvh_pick picks light l for point x (0 for a light outside the
 * BVH or one that cannot reach x). */
RS_HD float rs_light_bvh_pmf(const rs_scene *s, rs_vec3 x, uint32_t l)
{
    uint64_t trail;
    uint32_t n = 0;
    float p = 1.0f;
    if (!s->light_nodes || !(trail = s->light_trail[l]))
        return 0.0f;
    while (!(s->light_nodes[n].flags & RS_LIGHT_NODE_LEAF)) {
        float p0 = rs_light_bvh_first(s, n, x);
        if (p0 < 0.0f)
            return 0.0f;
        if (trail & 1u) {
            p *= 1.0f - p0;
            n = s->light_nodes[n].child;
        } else {
            p *= p0;
            n = n + 1;
        }
        trail >>= 1;
    }
    return p;
}

#endif
