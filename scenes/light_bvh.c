/* scenes/light_bvh.c — see light_bvh.h. */
#include "scenes/light_bvh.h"

#include <math.h>
#include <stdatomic.h>
#include <string.h>

#include "core/alloc.h"
#include "core/geom.h"

#define BUCKETS   12
#define MAX_DEPTH 62

/* The deepest a leaf may be (MAX_DEPTH; smaller only in the tests, which check that the bound
 * holds, rs_light_bvh_set_depth_limit). */
static _Atomic int g_depth_limit = MAX_DEPTH;

void rs_light_bvh_set_depth_limit(int depth)
{
    g_depth_limit = depth < 1 ? 1 : depth > MAX_DEPTH ? MAX_DEPTH : depth;
}

/* The levels a subtree of n lights split in halves needs below its root: ceil(log2 n). */
static int halving_levels(uint32_t n)
{
    int k = 0;
    while (k < 32 && (1ull << k) < n)
        ++k;
    return k;
}
#define PI_D      3.14159265358979323846

/* One light as the build sees it. */
typedef struct rec {
    float lo[3], hi[3], c[3]; /* bounds, centroid */
    float w[3], cos_o, cos_e, phi;
    int two_sided;
    uint32_t light;
} rec;

/* A set of lights' bounds, cone and power. */
typedef struct bound {
    float lo[3], hi[3], w[3], cos_o, cos_e, phi;
    int two_sided, empty;
} bound;

static double clampd(double x, double a, double b) { return x < a ? a : x > b ? b : x; }

static void normalize3(float v[3])
{
    double l = sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]);
    if (l > 0)
        for (int i = 0; i < 3; ++i)
            v[i] = (float)(v[i] / l);
}

void rs_light_cone_union(const float wa[3], float ca, const float wb[3], float cb, float w[3],
                         float *c)
{
    double ta = acos(clampd(ca, -1, 1)), tb = acos(clampd(cb, -1, 1));
    double d = clampd((double)wa[0] * wb[0] + (double)wa[1] * wb[1] + (double)wa[2] * wb[2], -1, 1);
    double td = acos(d), to, tr, k[3], kl, v[3], kv, ct, st;
    int i;
    if (fmin(td + tb, PI_D) <= ta) {
        memcpy(w, wa, 3 * sizeof *w);
        *c = ca;
        return;
    }
    if (fmin(td + ta, PI_D) <= tb) {
        memcpy(w, wb, 3 * sizeof *w);
        *c = cb;
        return;
    }
    to = 0.5 * (ta + td + tb);
    k[0] = (double)wa[1] * wb[2] - (double)wa[2] * wb[1];
    k[1] = (double)wa[2] * wb[0] - (double)wa[0] * wb[2];
    k[2] = (double)wa[0] * wb[1] - (double)wa[1] * wb[0];
    kl = sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2]);
    if (to >= PI_D || kl == 0.0) { /* the whole sphere */
        memcpy(w, wa, 3 * sizeof *w);
        *c = -1.0f;
        return;
    }
    /* wa turned toward wb by to - ta about k (Rodrigues) */
    tr = to - ta;
    ct = cos(tr);
    st = sin(tr);
    for (i = 0; i < 3; ++i)
        k[i] /= kl;
    kv = k[0] * wa[0] + k[1] * wa[1] + k[2] * wa[2];
    v[0] = wa[0] * ct + (k[1] * wa[2] - k[2] * wa[1]) * st + k[0] * kv * (1 - ct);
    v[1] = wa[1] * ct + (k[2] * wa[0] - k[0] * wa[2]) * st + k[1] * kv * (1 - ct);
    v[2] = wa[2] * ct + (k[0] * wa[1] - k[1] * wa[0]) * st + k[2] * kv * (1 - ct);
    for (i = 0; i < 3; ++i)
        w[i] = (float)v[i];
    normalize3(w);
    *c = (float)cos(to);
}

static void bound_empty(bound *b)
{
    memset(b, 0, sizeof *b);
    b->empty = 1;
    for (int i = 0; i < 3; ++i) {
        b->lo[i] = INFINITY;
        b->hi[i] = -INFINITY;
    }
}

static void bound_add(bound *b, const rec *r)
{
    int i;
    for (i = 0; i < 3; ++i) {
        b->lo[i] = fminf(b->lo[i], r->lo[i]);
        b->hi[i] = fmaxf(b->hi[i], r->hi[i]);
    }
    if (b->empty) {
        memcpy(b->w, r->w, sizeof b->w);
        b->cos_o = r->cos_o;
        b->cos_e = r->cos_e;
    } else {
        float w[3], c;
        rs_light_cone_union(b->w, b->cos_o, r->w, r->cos_o, w, &c);
        memcpy(b->w, w, sizeof w);
        b->cos_o = c;
        b->cos_e = fminf(b->cos_e, r->cos_e);
    }
    b->phi += r->phi;
    b->two_sided |= r->two_sided;
    b->empty = 0;
}

static void bound_merge(bound *b, const bound *o)
{
    rec r;
    if (o->empty)
        return;
    memcpy(r.lo, o->lo, sizeof r.lo);
    memcpy(r.hi, o->hi, sizeof r.hi);
    memcpy(r.w, o->w, sizeof r.w);
    r.cos_o = o->cos_o;
    r.cos_e = o->cos_e;
    r.phi = o->phi;
    r.two_sided = o->two_sided;
    bound_add(b, &r);
}

/* Conty and Kulla's cost of a set: power x the cone's measure x surface area, stretched by how
 * much longer the node's longest side is than the split axis's (pbrt-v4's EvaluateCost). */
static double bound_cost(const bound *b, int axis)
{
    double to, te, tw, so, m, d[3], area, kr, dmax;
    int i;
    if (b->empty)
        return 0.0;
    to = acos(clampd(b->cos_o, -1, 1));
    te = acos(clampd(b->cos_e, -1, 1));
    tw = fmin(to + te, PI_D);
    so = sin(to);
    m = 2 * PI_D * (1 - cos(to)) +
        PI_D / 2 * (2 * tw * so - cos(to - 2 * tw) - 2 * to * so + cos(to));
    for (i = 0; i < 3; ++i)
        d[i] = (double)b->hi[i] - b->lo[i];
    area = 2 * (d[0] * d[1] + d[1] * d[2] + d[2] * d[0]);
    dmax = fmax(d[0], fmax(d[1], d[2]));
    kr = d[axis] > 0 ? dmax / d[axis] : 1.0;
    return b->phi * m * kr * (area > 0 ? area : 1e-12);
}

typedef struct builder {
    rec *recs, *tmp;
    rs_light_node *nodes;
    uint32_t n_nodes, cap;
    uint64_t *trail;
} builder;

static uint32_t new_node(builder *b)
{
    if (b->n_nodes == b->cap) {
        uint32_t cap = b->cap ? 2 * b->cap : 64;
        rs_light_node *n = (rs_light_node *)rs_alloc(cap, sizeof *n);
        if (!n)
            return UINT32_MAX;
        if (b->nodes)
            memcpy(n, b->nodes, (size_t)b->n_nodes * sizeof *n);
        rs_free(b->nodes);
        b->nodes = n;
        b->cap = cap;
    }
    memset(&b->nodes[b->n_nodes], 0, sizeof *b->nodes);
    return b->n_nodes++;
}

/* Where recs[begin, end) splits (two or more lights): by a cost split over buckets along the
 * centres' longest axis (a stable partition, the same order on every machine), else in halves by
 * order. */
static uint32_t split_at(builder *b, uint32_t begin, uint32_t end, int depth)
{
    uint32_t i, mid = begin + (end - begin) / 2; /* by order, unless the buckets find better */
    float clo[3] = {INFINITY, INFINITY, INFINITY}, chi[3] = {-INFINITY, -INFINITY, -INFINITY};
    int axis = 0, k;
    for (i = begin; i < end; ++i)
        for (k = 0; k < 3; ++k) {
            clo[k] = fminf(clo[k], b->recs[i].c[k]);
            chi[k] = fmaxf(chi[k], b->recs[i].c[k]);
        }
    for (k = 1; k < 3; ++k)
        if (chi[k] - clo[k] > chi[axis] - clo[axis])
            axis = k;
    /* a cost split may leave all but one light on one side; it is taken only while that
     * side could still be split in halves within the depth limit (halves: as deep as
     * ceil(log2 n) more), so no leaf is ever deeper than the limit, whatever the lights */
    if (depth + 1 + halving_levels(end - begin) <= g_depth_limit && chi[axis] > clo[axis]) {
        bound bk[BUCKETS];
        double best = INFINITY, scale = BUCKETS / ((double)chi[axis] - clo[axis]);
        int split = -1, j;
        for (j = 0; j < BUCKETS; ++j)
            bound_empty(&bk[j]);
        for (i = begin; i < end; ++i) {
            int q = (int)(((double)b->recs[i].c[axis] - clo[axis]) * scale);
            bound_add(&bk[q < BUCKETS ? q : BUCKETS - 1], &b->recs[i]);
        }
        for (j = 0; j < BUCKETS - 1; ++j) {
            bound l, r;
            double c;
            int t;
            bound_empty(&l);
            bound_empty(&r);
            for (t = 0; t <= j; ++t)
                bound_merge(&l, &bk[t]);
            for (t = j + 1; t < BUCKETS; ++t)
                bound_merge(&r, &bk[t]);
            if (l.empty || r.empty)
                continue;
            c = bound_cost(&l, axis) + bound_cost(&r, axis);
            if (c < best) {
                best = c;
                split = j;
            }
        }
        if (split >= 0) { /* a stable partition: the same order on every machine */
            uint32_t nl = 0, nr = 0, n = end - begin;
            for (i = begin; i < end; ++i) {
                int q = (int)(((double)b->recs[i].c[axis] - clo[axis]) * scale);
                q = q < BUCKETS ? q : BUCKETS - 1;
                if (q <= split)
                    b->tmp[nl++] = b->recs[i];
            }
            for (i = begin; i < end; ++i) {
                int q = (int)(((double)b->recs[i].c[axis] - clo[axis]) * scale);
                q = q < BUCKETS ? q : BUCKETS - 1;
                if (q > split)
                    b->tmp[nl + nr++] = b->recs[i];
            }
            memcpy(b->recs + begin, b->tmp, (size_t)n * sizeof *b->recs);
            mid = begin + nl;
        }
    }
    return mid;
}

/* Builds the subtree of recs[begin, end) at `depth` whose path is `bits`; its root's index in
 * *out.  0 when out of memory. */
static int build(builder *b, uint32_t begin, uint32_t end, int depth, uint64_t bits, uint32_t *out)
{
    bound all;
    uint32_t i, mid, id, right;
    rs_light_node *nd;
    bound_empty(&all);
    for (i = begin; i < end; ++i)
        bound_add(&all, &b->recs[i]);
    id = new_node(b);
    if (id == UINT32_MAX)
        return 0;
    nd = &b->nodes[id];
    memcpy(nd->lo, all.lo, sizeof nd->lo);
    memcpy(nd->hi, all.hi, sizeof nd->hi);
    memcpy(nd->w, all.w, sizeof nd->w);
    nd->cos_o = all.cos_o;
    nd->cos_e = all.cos_e;
    nd->phi = all.phi;
    nd->flags = all.two_sided ? RS_LIGHT_NODE_TWO_SIDED : 0u;
    *out = id;
    if (end - begin == 1) {
        nd->flags |= RS_LIGHT_NODE_LEAF;
        nd->child = b->recs[begin].light;
        b->trail[b->recs[begin].light] = bits | (1ull << depth);
        return 1;
    }
    mid = split_at(b, begin, end, depth);
    {
        uint32_t left;
        if (!build(b, begin, mid, depth + 1, bits, &left) ||
            !build(b, mid, end, depth + 1, bits | (1ull << depth), &right))
            return 0;
        (void)left;
        b->nodes[id].child = right;
    }
    return 1;
}

/* The record of light l, or 0 when it has no place in the tree (directional). */
static int light_rec(const rs_scene *s, uint32_t l, rec *r)
{
    const rs_light *lt = &s->lights[l];
    uint32_t prim = lt->prim, k;
    memset(r, 0, sizeof *r);
    r->light = l;
    r->phi = lt->power;
    r->w[2] = 1.0f;
    r->cos_o = -1.0f; /* every direction, unless below */
    r->cos_e = 0.0f;  /* cos(pi / 2) */
    if (prim & RS_LIGHT_PUNCTUAL) {
        const rs_punctual *p = &s->punctuals[prim & ~RS_LIGHT_PUNCTUAL];
        if (p->type == RS_PUNCTUAL_DIRECTIONAL)
            return 0;
        r->lo[0] = r->hi[0] = p->pos.x;
        r->lo[1] = r->hi[1] = p->pos.y;
        r->lo[2] = r->hi[2] = p->pos.z;
        if (p->type == RS_PUNCTUAL_SPOT) {
            r->w[0] = p->dir.x;
            r->w[1] = p->dir.y;
            r->w[2] = p->dir.z;
            normalize3(r->w);
            r->cos_o = p->cos_inner;
            r->cos_e = (float)cos(fmax(0.0, acos(clampd(p->cos_outer, -1, 1)) -
                                               acos(clampd(p->cos_inner, -1, 1))));
        }
    } else if (prim < s->n_spheres) {
        rs_geom g = rs_scene_geom(s);
        rs_vec3 c0 = rs_geom_sphere_center(&g, prim, g.time0);
        rs_vec3 c1 = rs_geom_sphere_center(&g, prim, g.time1);
        float rad = fabsf(s->spheres[prim].radius);
        r->lo[0] = fminf(c0.x, c1.x) - rad;
        r->lo[1] = fminf(c0.y, c1.y) - rad;
        r->lo[2] = fminf(c0.z, c1.z) - rad;
        r->hi[0] = fmaxf(c0.x, c1.x) + rad;
        r->hi[1] = fmaxf(c0.y, c1.y) + rad;
        r->hi[2] = fmaxf(c0.z, c1.z) + rad;
    } else {
        const rs_material *m = rs_scene_prim_material(s, prim);
        rs_vec3 v[4], n;
        int nv;
        if (prim - s->n_spheres < s->n_quads) {
            const rs_quad *q = &s->quads[prim - s->n_spheres];
            v[0] = q->q;
            v[1] = rs_v3_add(q->q, q->u);
            v[2] = rs_v3_add(q->q, q->v);
            v[3] = rs_v3_add(v[1], q->v);
            n = rs_v3_cross(q->u, q->v);
            nv = 4;
        } else {
            rs_tri t = rs_scene_tri(s, prim);
            v[0] = t.v0;
            v[1] = t.v1;
            v[2] = t.v2;
            n = rs_v3_cross(rs_v3_sub(t.v1, t.v0), rs_v3_sub(t.v2, t.v0));
            nv = 3;
        }
        r->lo[0] = r->lo[1] = r->lo[2] = INFINITY;
        r->hi[0] = r->hi[1] = r->hi[2] = -INFINITY;
        for (k = 0; k < (uint32_t)nv; ++k) {
            r->lo[0] = fminf(r->lo[0], v[k].x);
            r->lo[1] = fminf(r->lo[1], v[k].y);
            r->lo[2] = fminf(r->lo[2], v[k].z);
            r->hi[0] = fmaxf(r->hi[0], v[k].x);
            r->hi[1] = fmaxf(r->hi[1], v[k].y);
            r->hi[2] = fmaxf(r->hi[2], v[k].z);
        }
        r->w[0] = n.x;
        r->w[1] = n.y;
        r->w[2] = n.z;
        normalize3(r->w);
        r->cos_o = 1.0f; /* one direction: the normal */
        r->two_sided = (m->flags & RS_MAT_TWO_SIDED) || m->type == RS_MAT_PBR;
    }
    for (k = 0; k < 3; ++k)
        r->c[k] = 0.5f * (r->lo[k] + r->hi[k]);
    return 1;
}

rs_status rs_scene_build_light_bvh(rs_scene *s)
{
    builder b;
    uint32_t l, n = 0, root;
    double in = 0.0, all = 0.0;
    rs_free(s->light_nodes);
    rs_free(s->light_trail);
    s->light_nodes = NULL;
    s->light_trail = NULL;
    s->n_light_nodes = 0;
    s->light_bvh_mass = 0.0f;
    s->light_bvh_built = 1;
    if (s->n_lights == 0)
        return RS_OK;
    {
        /* bounded before anything is allocated: a small file can hold millions of emitters */
        uint64_t need = (uint64_t)s->n_lights *
                        (2 * sizeof(rec) + 2 * sizeof(uint64_t) + 2 * sizeof(rs_light_node));
        uint64_t budget = rs_memory_budget();
        if (budget && need > budget)
            return rs_error_set(RS_ERR_NOMEM,
                                "the light BVH over %u lights takes %.0f MB, more than the %.0f "
                                "MB this process may use (--light-sampler power needs none)",
                                s->n_lights, (double)need / 1048576.0,
                                (double)budget / 1048576.0);
    }
    memset(&b, 0, sizeof b);
    b.recs = (rec *)rs_alloc(s->n_lights, sizeof *b.recs);
    b.tmp = (rec *)rs_alloc(s->n_lights, sizeof *b.tmp);
    b.trail = (uint64_t *)rs_calloc(s->n_lights, sizeof *b.trail);
    if (!b.recs || !b.tmp || !b.trail)
        goto nomem;
    for (l = 0; l < s->n_lights; ++l) {
        all += s->lights[l].power;
        if (s->lights[l].power > 0.0f && light_rec(s, l, &b.recs[n])) {
            in += s->lights[l].power;
            ++n;
        }
    }
    if (n == 0) {
        rs_free(b.recs);
        rs_free(b.tmp);
        rs_free(b.trail);
        return RS_OK;
    }
    if (!build(&b, 0, n, 0, 0, &root))
        goto nomem;
    rs_free(b.recs);
    rs_free(b.tmp);
    s->light_nodes = b.nodes;
    s->n_light_nodes = b.n_nodes;
    s->light_trail = b.trail;
    s->light_bvh_mass = all > 0 ? (float)(in / all) : 0.0f;
    return RS_OK;
nomem:
    rs_free(b.recs);
    rs_free(b.tmp);
    rs_free(b.trail);
    rs_free(b.nodes);
    return rs_error_set(RS_ERR_NOMEM, "out of memory building the light BVH (%u lights)",
                        s->n_lights);
}
