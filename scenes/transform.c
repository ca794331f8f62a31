/* scenes/transform.c — affine transforms of scene objects (see transform.h). */
#include "scenes/transform.h"

#include <math.h>
#include <string.h>

#include "core/try.h"

#define DEG (3.14159265358979323846 / 180.0)

rs_xform rs_xform_identity(void)
{
    rs_xform x;
    memset(&x, 0, sizeof x);
    x.m[0][0] = x.m[1][1] = x.m[2][2] = 1.0;
    return x;
}

rs_xform rs_xform_translate(double a, double b, double c)
{
    rs_xform x = rs_xform_identity();
    x.t[0] = a;
    x.t[1] = b;
    x.t[2] = c;
    return x;
}

rs_xform rs_xform_scale(double a, double b, double c)
{
    rs_xform x = rs_xform_identity();
    x.m[0][0] = a;
    x.m[1][1] = b;
    x.m[2][2] = c;
    return x;
}

/* Rodrigues' formula: R = cos I + sin [k]x + (1 - cos) k k^T for the unit axis k. */
rs_xform rs_xform_rotate_axis(const double axis[3], double deg)
{
    rs_xform x = rs_xform_identity();
    double l = sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
    double k[3], c, s, C;
    int i, j;
    if (!(l > 0))
        return x;
    for (i = 0; i < 3; ++i)
        k[i] = axis[i] / l;
    /* whole quarter turns exactly: cos(90 deg) is 6e-17 in double, not 0 */
    if (fmod(deg, 90.0) == 0.0) {
        static const double cs[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
        int q = (int)fmod(fmod(deg / 90.0, 4.0) + 4.0, 4.0);
        c = cs[q][0];
        s = cs[q][1];
    } else {
        c = cos(deg * DEG);
        s = sin(deg * DEG);
    }
    C = 1.0 - c;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            x.m[i][j] = (i == j ? c : 0.0) + C * k[i] * k[j];
    x.m[0][1] -= s * k[2];
    x.m[0][2] += s * k[1];
    x.m[1][0] += s * k[2];
    x.m[1][2] -= s * k[0];
    x.m[2][0] -= s * k[1];
    x.m[2][1] += s * k[0];
    return x;
}

rs_xform rs_xform_rotate_euler(double rx, double ry, double rz)
{
    static const double ax[3] = {1, 0, 0}, ay[3] = {0, 1, 0}, az[3] = {0, 0, 1};
    rs_xform a = rs_xform_rotate_axis(ax, rx), b = rs_xform_rotate_axis(ay, ry);
    rs_xform c = rs_xform_rotate_axis(az, rz), ba = rs_xform_compose(&b, &a);
    return rs_xform_compose(&c, &ba);
}

rs_xform rs_xform_compose(const rs_xform *a, const rs_xform *b)
{
    rs_xform x;
    int i, j, k;
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j) {
            double sum = 0;
            for (k = 0; k < 3; ++k)
                sum += a->m[i][k] * b->m[k][j];
            x.m[i][j] = sum;
        }
        x.t[i] = a->t[i];
        for (k = 0; k < 3; ++k)
            x.t[i] += a->m[i][k] * b->t[k];
    }
    return x;
}

double rs_xform_det(const rs_xform *x)
{
    const double(*m)[3] = x->m;
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
           m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

int rs_xform_is_identity(const rs_xform *x)
{
    rs_xform id = rs_xform_identity();
    return memcmp(x, &id, sizeof id) == 0;
}

static double max_entry(const rs_xform *x)
{
    double big = 0;
    int i, j;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            big = fmax(big, fabs(x->m[i][j]));
    return big;
}

const char *rs_xform_invalid(const rs_xform *x)
{
    double big, det;
    int i, j;
    for (i = 0; i < 3; ++i) {
        if (!isfinite(x->t[i]) || fabs(x->t[i]) > 1e30)
            return "the translation is not finite (or beyond 1e30)";
        for (j = 0; j < 3; ++j)
            if (!isfinite(x->m[i][j]) || fabs(x->m[i][j]) > 1e30)
                return "a matrix entry is not finite (or beyond 1e30)";
    }
    big = max_entry(x);
    det = rs_xform_det(x);
    if (!(big > 0) || !(fabs(det) > 1e-12 * big * big * big))
        return "the matrix is singular (it flattens objects: a zero scale?)";
    return NULL;
}

int rs_xform_is_similarity(const rs_xform *x, double *scale)
{
    double g[3][3], s2;
    int i, j, k;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            g[i][j] = 0;
            for (k = 0; k < 3; ++k)
                g[i][j] += x->m[k][i] * x->m[k][j];
        }
    s2 = (g[0][0] + g[1][1] + g[2][2]) / 3.0;
    *scale = sqrt(s2);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j)
            if (fabs(g[i][j] - (i == j ? s2 : 0.0)) > 1e-5 * s2)
                return 0;
    return s2 > 0;
}

rs_vec3 rs_xform_point(const rs_xform *x, rs_vec3 p)
{
    double r[3];
    int i;
    for (i = 0; i < 3; ++i)
        r[i] = x->m[i][0] * p.x + x->m[i][1] * p.y + x->m[i][2] * p.z + x->t[i];
    return rs_v3((float)r[0], (float)r[1], (float)r[2]);
}

rs_vec3 rs_xform_vector(const rs_xform *x, rs_vec3 v)
{
    double r[3];
    int i;
    for (i = 0; i < 3; ++i)
        r[i] = x->m[i][0] * v.x + x->m[i][1] * v.y + x->m[i][2] * v.z;
    return rs_v3((float)r[0], (float)r[1], (float)r[2]);
}

/* The inverse transpose of the linear part times det (the cofactor matrix): normals map by it up
 * to a positive factor when det > 0 (the sign is fixed by the caller). */
static void cofactor(const rs_xform *x, double c[3][3])
{
    const double(*m)[3] = x->m;
    int i, j;
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
            c[i][j] = m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1];
        }
}

/* n by the cofactor matrix c, times `sign` (-1 where det < 0: the cofactor's normals point in),
 * normalised in double and rounded once; a zero normal ("use the face's") stays zero. */
static void normal_by(const double c[3][3], double sign, const float n[3], float out[3])
{
    double r[3], l;
    int j;
    for (j = 0; j < 3; ++j)
        r[j] = c[j][0] * n[0] + c[j][1] * n[1] + c[j][2] * n[2];
    l = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (l > 0)
        l = sign / l;
    for (j = 0; j < 3; ++j)
        out[j] = (float)(r[j] * l);
}

rs_vec3 rs_xform_normal(const rs_xform *x, rs_vec3 n)
{
    double cof[3][3];
    float in[3], out[3];
    in[0] = n.x;
    in[1] = n.y;
    in[2] = n.z;
    cofactor(x, cof);
    normal_by(cof, rs_xform_det(x) < 0 ? -1.0 : 1.0, in, out);
    return rs_v3(out[0], out[1], out[2]);
}

static int in_range(rs_vec3 a)
{
    return isfinite(a.x) && isfinite(a.y) && isfinite(a.z) && fabsf(a.x) <= 1e30f &&
           fabsf(a.y) <= 1e30f && fabsf(a.z) <= 1e30f;
}

rs_scene_mark rs_scene_mark_now(const rs_scene *s)
{
    rs_scene_mark m;
    m.n_spheres = s->n_spheres;
    m.n_quads = s->n_quads;
    m.n_tris = s->n_tris;
    m.n_punctuals = s->n_punctuals;
    return m;
}

static rs_status out_of_range(void)
{
    return rs_error_set(RS_ERR_ARG, "the transform moves a coordinate beyond 1e30 (absurd scale?)");
}

/* Triangle i placed by x (cof: its cofactor matrix, for the vertex normals); a mirroring x
 * swaps v1 and v2 (with their UVs and normals) so that the triangle keeps its side. */
static rs_status transform_triangle(rs_scene *s, uint32_t i, const rs_xform *x,
                                    const double cof[3][3], int mirror)
{
    rs_tri *t = &s->tris[i];
    rs_vec3 a = rs_xform_point(x, t->v0), b = rs_xform_point(x, t->v1);
    rs_vec3 c = rs_xform_point(x, t->v2);
    if (!in_range(a) || !in_range(b) || !in_range(c))
        return out_of_range();
    t->v0 = a;
    t->v1 = mirror ? c : b;
    t->v2 = mirror ? b : c;
    if (s->tri_uv && mirror) {
        float *uv = &s->tri_uv[6 * (size_t)i], u1 = uv[2], v1 = uv[3];
        uv[2] = uv[4];
        uv[3] = uv[5];
        uv[4] = u1;
        uv[5] = v1;
    }
    if (s->tri_normal) {
        float *vn = &s->tri_normal[9 * (size_t)i], out[9];
        int k, j;
        for (k = 0; k < 3; ++k)
            normal_by(cof, mirror ? -1.0 : 1.0, &vn[3 * k], &out[3 * k]);
        /* with v1 and v2 swapped, so are their normals */
        for (j = 0; j < 3; ++j) {
            vn[j] = out[j];
            vn[3 + j] = out[(mirror ? 6 : 3) + j];
            vn[6 + j] = out[(mirror ? 3 : 6) + j];
        }
    }
    return RS_OK;
}

rs_status rs_scene_transform_since(rs_scene *s, const rs_scene_mark *from, const rs_xform *x)
{
    const char *why = rs_xform_invalid(x);
    double cof[3][3], det, scale = 1.0;
    int mirror;
    uint32_t i;
    if (why)
        return rs_error_set(RS_ERR_ARG, "%s", why);
    det = rs_xform_det(x);
    mirror = det < 0;
    cofactor(x, cof);
    if (s->n_spheres > from->n_spheres && !rs_xform_is_similarity(x, &scale))
        return rs_error_set(RS_ERR_ARG, "a sphere can only be moved, rotated and scaled "
                                        "uniformly (this transform would make an ellipsoid)");
    for (i = from->n_spheres; i < s->n_spheres; ++i) {
        rs_sphere *sp = &s->spheres[i];
        double r = (double)sp->radius * scale;
        sp->center = rs_xform_point(x, sp->center);
        if (!in_range(sp->center) || !(r > 0) || r > 1e30)
            return out_of_range();
        sp->radius = (float)r;
        if (s->sphere_motion) {
            s->sphere_motion[i] = rs_xform_vector(x, s->sphere_motion[i]);
            if (!in_range(s->sphere_motion[i]))
                return out_of_range();
        }
    }
    for (i = from->n_quads; i < s->n_quads; ++i) {
        rs_quad *qd = &s->quads[i];
        rs_vec3 q = rs_xform_point(x, qd->q), u = rs_xform_vector(x, qd->u);
        rs_vec3 v = rs_xform_vector(x, qd->v);
        if (mirror) {
            /* the same parallelogram from the far end of u, so that u x v points out again */
            q = rs_v3_add(q, u);
            u = rs_v3_neg(u);
        }
        if (!in_range(q) || !in_range(u) || !in_range(v) || !in_range(rs_v3_add(q, u)))
            return out_of_range();
        *qd = rs_quad_make(q, u, v);
    }
    for (i = from->n_tris; i < s->n_tris; ++i)
        RS_TRY(transform_triangle(s, i, x, (const double(*)[3])cof, mirror));
    for (i = from->n_punctuals; i < s->n_punctuals; ++i) {
        rs_punctual *p = &s->punctuals[i];
        p->pos = rs_xform_point(x, p->pos);
        if (p->type != RS_PUNCTUAL_POINT) {
            rs_vec3 d = rs_xform_vector(x, p->dir);
            if (!in_range(p->pos) || rs_v3_is_zero(d) || !in_range(d))
                return out_of_range();
            p->dir = rs_v3_normalize(d);
        }
        if (!in_range(p->pos))
            return out_of_range();
    }
    s->finalized = 0;
    return RS_OK;
}

/* The object-space widening of an instance's bottom-level boxes (core/geom.h).  Its triangles
 * are tested where rs_instance_point puts them, each coordinate within half an ulp of the exact
 * transform, so up to 2^-24 (|M| R + |t|) away from it in world space and |M^-1| times that in
 * object space (R the prototype's largest coordinate, norms the rows' largest absolute sums);
 * the object-space ray, transformed in double and rounded once, is as close.  The margin is 2^8
 * times that bound (and at least 2^-16 R), so the boxes cull nothing the world-space test could
 * hit, and they grow by well under a thousandth of the prototype. */
static float instance_margin(const double m[12], const double inv[12], double r)
{
    double nm = 0, ni = 0, nt = 0;
    int i;
    for (i = 0; i < 3; ++i) {
        double a = fabs(m[4 * i]) + fabs(m[4 * i + 1]) + fabs(m[4 * i + 2]);
        double b = fabs(inv[4 * i]) + fabs(inv[4 * i + 1]) + fabs(inv[4 * i + 2]);
        nm = a > nm ? a : nm;
        ni = b > ni ? b : ni;
        nt = fabs(m[4 * i + 3]) > nt ? fabs(m[4 * i + 3]) : nt;
    }
    return (float)(0x1.0p-16 * (ni * (nm * r + nt) + r));
}

rs_status rs_scene_add_instance(rs_scene *s, uint32_t first, uint32_t count, const double m[12])
{
    rs_xform x;
    rs_instance in;
    double cof[3][3], det, r = 0;
    const char *why;
    uint32_t i, j;
    if (count == 0 || (uint64_t)first + count > s->n_inst_tris)
        return rs_error_set(RS_ERR_ARG, "an instance of triangles %u..%u (the prototypes have %u)",
                            first, first + count, s->n_inst_tris);
    if ((uint64_t)s->n_inst_prims + count > RS_MAX_INST_PRIMS)
        return rs_error_set(RS_ERR_ARG, "the instances would place more than 2^30 triangles");
    for (i = 0; i < 3; ++i) {
        for (j = 0; j < 3; ++j)
            x.m[i][j] = m[4 * i + j];
        x.t[i] = m[4 * i + 3];
    }
    if ((why = rs_xform_invalid(&x)) != NULL)
        return rs_error_set(RS_ERR_ARG, "%s", why);
    memset(&in, 0, sizeof in);
    det = rs_xform_det(&x);
    cofactor(&x, cof);
    for (i = 0; i < 12; ++i)
        in.m[i] = m[i];
    for (i = 0; i < 3; ++i) {
        double t = 0;
        for (j = 0; j < 3; ++j) {
            in.inv[4 * i + j] = cof[j][i] / det; /* M^-1 = adj(M) / det, adj = cof^T */
            in.cof[3 * i + j] = cof[i][j];
        }
        for (j = 0; j < 3; ++j)
            t -= in.inv[4 * i + j] * m[4 * j + 3];
        in.inv[4 * i + 3] = t;
    }
    in.mirror = det < 0;
    in.first_tri = first;
    in.n_tris = count;
    in.box.lo = rs_v3_splat(INFINITY);
    in.box.hi = rs_v3_splat(-INFINITY);
    for (i = first; i < first + count; ++i) {
        const rs_tri *t = &s->inst_tris[i];
        rs_tri w = rs_instance_tri(&in, t);
        if (!in_range(w.v0) || !in_range(w.v1) || !in_range(w.v2))
            return out_of_range();
        in.box.lo = rs_v3_min(in.box.lo, rs_v3_min(w.v0, rs_v3_min(w.v1, w.v2)));
        in.box.hi = rs_v3_max(in.box.hi, rs_v3_max(w.v0, rs_v3_max(w.v1, w.v2)));
        for (j = 0; j < 3; ++j) {
            rs_vec3 v = j == 0 ? t->v0 : j == 1 ? t->v1 : t->v2;
            double a = fmax(fabs((double)v.x), fmax(fabs((double)v.y), fabs((double)v.z)));
            r = a > r ? a : r;
        }
    }
    in.margin = instance_margin(in.m, in.inv, r);
    return rs_scene_push_instance(s, &in);
}
