/* shading/lights.c — see lights.h. */
#include "shading/lights.h"

#include <float.h>

rs_vec3 rs_prim_normal(const rs_scene *s, uint32_t prim, rs_vec3 p)
{
    if (prim < s->n_spheres) {
        const rs_sphere *sp = &s->spheres[prim];
        return rs_v3_scale(rs_v3_sub(p, sp->center), 1.0f / sp->radius);
    }
    prim -= s->n_spheres;
    if (prim < s->n_quads)
        return rs_v3_normalize(s->quads[prim].w);
    prim -= s->n_quads;
    {
        const rs_tri *t = &s->tris[prim];
        return rs_v3_normalize(rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0)));
    }
}

rs_vec3 rs_emitted(const rs_material *m, rs_vec3 ng, rs_vec3 d)
{
    if (m->type != RS_MAT_DIFFUSE_LIGHT)
        return rs_v3_splat(0.0f);
    if ((m->flags & RS_MAT_TWO_SIDED) || rs_v3_dot(ng, d) < 0.0f)
        return m->emission;
    return rs_v3_splat(0.0f);
}

static uint32_t pick_light(const rs_scene *s, float u)
{
    /* the largest l with cdf[l] <= u, skipping zero-probability lights */
    uint32_t lo = 0, hi = s->n_lights;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (s->light_cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

int rs_light_sample_at(const rs_scene *s, rs_vec3 x, float u_pick, float u1, float u2,
                       rs_light_sample *out)
{
    uint32_t l, prim;
    const rs_light *lt;
    rs_vec3 p, n, to;
    float d2, cos_l;
    if (s->n_lights == 0)
        return 0;
    l = pick_light(s, u_pick);
    lt = &s->lights[l];
    prim = lt->prim - s->n_spheres;
    if (prim < s->n_quads) {
        const rs_quad *q = &s->quads[prim];
        p = rs_v3_add(q->q, rs_v3_add(rs_v3_scale(q->u, u1), rs_v3_scale(q->v, u2)));
    } else {
        /* uniform on a triangle: b0 = 1 - sqrt(u1), b1 = sqrt(u1) (1 - u2), b2 = sqrt(u1) u2 */
        const rs_tri *t = &s->tris[prim - s->n_quads];
        float su = sqrtf(u1);
        p = rs_v3_add(
            rs_v3_add(rs_v3_scale(t->v0, 1.0f - su), rs_v3_scale(t->v1, su * (1.0f - u2))),
            rs_v3_scale(t->v2, su * u2));
    }
    n = rs_prim_normal(s, lt->prim, p);
    to = rs_v3_sub(p, x);
    d2 = rs_v3_dot(to, to);
    if (!(d2 > 0.0f))
        return 0;
    out->dist = sqrtf(d2);
    out->wi = rs_v3_scale(to, 1.0f / out->dist);
    cos_l = fabsf(rs_v3_dot(n, out->wi));
    if (!(cos_l > 1e-7f))
        return 0;
    out->point = p;
    out->pdf = lt->pick_pdf * d2 / (lt->area * cos_l);
    out->le = rs_emitted(rs_scene_prim_material(s, lt->prim), n, out->wi);
    return 1;
}

float rs_light_pdf_hit(const rs_scene *s, uint32_t light, rs_vec3 w, float t, rs_vec3 ng)
{
    const rs_light *lt = &s->lights[light];
    float cos_l = fabsf(rs_v3_dot(ng, w));
    if (!(cos_l > 1e-7f))
        return 0.0f;
    return lt->pick_pdf * t * t / (lt->area * cos_l);
}

float rs_lights_pdf_dir(const rs_scene *s, rs_vec3 x, rs_vec3 w)
{
    rs_geom g = rs_scene_geom(s);
    rs_ray r;
    float pdf = 0.0f;
    uint32_t l;
    r.o = x;
    r.d = w;
    r.tmin = 0.0f;
    r.tmax = FLT_MAX;
    for (l = 0; l < s->n_lights; ++l) {
        float t, u, v;
        uint32_t prim = s->lights[l].prim;
        if (rs_geom_intersect(&g, prim, &r, &t, &u, &v))
            pdf += rs_light_pdf_hit(s, l, w, t, rs_prim_normal(s, prim, rs_ray_at(&r, t)));
    }
    return pdf;
}
