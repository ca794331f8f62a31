/* tests/shading_light_bvh_test.c — the light BVH (scenes/light_bvh.h, shading/light_bvh.h) on a
 * scene of 300 emitters of every shape (one- and two-sided quads and triangles, spheres, a
 * moving sphere), point and spot lights and a directional light (which stays out of the tree):
 *   - every light with a position is in the tree once, the directional one is not; the build is
 *     deterministic (two builds, the same bytes); the BVH's share of the power is right;
 *   - at 300 random points: the pick probabilities of the tree's lights sum to at most 1 (the rest:
 *     picks that end where both children are dark, counted by the chi-square); every light that
 *     can send light to the point (a one-sided emitter facing it, a spot whose cone holds it, any
 *     other) has a probability above 0, and one facing away has 0; a pick's probability equals
 *     rs_light_bvh_pmf of the light it picked, bit for bit;
 *   - at three points, 400,000 picks against the pmf (and the picks that end without a light
 *     against 1 - their sum): chi-square at alpha = 0.001;
 *   - the cone union holds both cones (directions inside either are inside it). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/rng.h"
#include "scenes/light_bvh.h"
#include "shading/light_bvh.h"

static uint64_t g_s = 0x5eed11u;

static float rnd(void)
{
    g_s = g_s * 6364136223846793005ull + 1442695040888963407ull;
    return (float)((g_s >> 40) * (1.0 / 16777216.0));
}

static rs_vec3 rnd_v(float lo, float hi)
{
    return rs_v3(lo + (hi - lo) * rnd(), lo + (hi - lo) * rnd(), lo + (hi - lo) * rnd());
}

static rs_vec3 rnd_dir(void)
{
    float z = 2.0f * rnd() - 1.0f, phi = 6.2831853f * rnd(), r = sqrtf(1.0f - z * z);
    return rs_v3(r * cosf(phi), r * sinf(phi), z);
}

static rs_scene *make_scene(void)
{
    rs_scene *s = NULL;
    uint32_t one, two, pbr, diffuse, i;
    rs_material m;
    rs_punctual p;
    assert_int_equal(rs_scene_create("lights", &s), RS_OK);
    m = rs_mat_light(rs_v3(4, 3, 2), 0);
    assert_int_equal(rs_scene_add_material(s, &m, &one), RS_OK);
    m = rs_mat_light(rs_v3(1, 2, 3), 1);
    assert_int_equal(rs_scene_add_material(s, &m, &two), RS_OK);
    m = rs_mat_pbr(rs_v3_splat(0.5f), 0.0f, 0.5f);
    m.emission = rs_v3(0.5f, 0.5f, 0.2f);
    assert_int_equal(rs_scene_add_material(s, &m, &pbr), RS_OK);
    m = rs_mat_lambertian(rs_v3_splat(0.5f));
    assert_int_equal(rs_scene_add_material(s, &m, &diffuse), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-20, -1, -20), rs_v3(40, 0, 0), rs_v3(0, 0, 40),
                                       diffuse),
                     RS_OK); /* a floor that is not a light */
    for (i = 0; i < 120; ++i) {
        rs_vec3 q = rnd_v(-10, 10), u = rs_v3_scale(rnd_dir(), 0.2f + rnd()),
                v = rs_v3_scale(rnd_dir(), 0.2f + rnd());
        assert_int_equal(rs_scene_add_quad(s, q, u, v, i % 3 == 0 ? two : one), RS_OK);
    }
    for (i = 0; i < 150; ++i) {
        rs_vec3 a = rnd_v(-10, 10);
        assert_int_equal(rs_scene_add_triangle(s, a, rs_v3_add(a, rs_v3_scale(rnd_dir(), 0.5f)),
                                               rs_v3_add(a, rs_v3_scale(rnd_dir(), 0.5f)),
                                               i % 5 == 0 ? pbr : one),
                         RS_OK);
    }
    for (i = 0; i < 20; ++i)
        assert_int_equal(rs_scene_add_sphere(s, rnd_v(-10, 10), 0.1f + 0.3f * rnd(), two), RS_OK);
    assert_int_equal(rs_scene_add_moving_sphere(s, rs_v3(0, 5, 0), 0.0f, rs_v3(3, 5, 0), 1.0f,
                                                0.4f, two),
                     RS_OK);
    s->camera.shutter_open = 0.0f;
    s->camera.shutter_close = 1.0f;
    memset(&p, 0, sizeof p);
    for (i = 0; i < 6; ++i) {
        p.type = i % 2 ? RS_PUNCTUAL_SPOT : RS_PUNCTUAL_POINT;
        p.pos = rnd_v(-10, 10);
        p.dir = rnd_dir();
        p.intensity = rs_v3(5, 5, 5);
        p.cos_inner = 0.9f;
        p.cos_outer = 0.7f;
        assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    }
    p.type = RS_PUNCTUAL_DIRECTIONAL;
    p.dir = rs_v3(0, -1, 0);
    p.intensity = rs_v3(1, 1, 1);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

/* Whether light l can send light to x at all. */
static int reaches(const rs_scene *s, uint32_t l, rs_vec3 x)
{
    uint32_t prim = s->lights[l].prim;
    if (prim & RS_LIGHT_PUNCTUAL) {
        const rs_punctual *p = &s->punctuals[prim & ~RS_LIGHT_PUNCTUAL];
        if (p->type == RS_PUNCTUAL_SPOT)
            return rs_v3_dot(rs_v3_normalize(rs_v3_sub(x, p->pos)), p->dir) > p->cos_outer;
        return 1;
    }
    if (prim < s->n_spheres)
        return 1;
    {
        const rs_material *m = rs_scene_prim_material(s, prim);
        rs_vec3 a, n;
        if ((m->flags & RS_MAT_TWO_SIDED) || m->type == RS_MAT_PBR)
            return 1;
        if (prim - s->n_spheres < s->n_quads) {
            const rs_quad *q = &s->quads[prim - s->n_spheres];
            a = q->q;
            n = rs_v3_cross(q->u, q->v);
        } else {
            rs_tri t = rs_scene_tri(s, prim);
            a = t.v0;
            n = rs_v3_cross(rs_v3_sub(t.v1, t.v0), rs_v3_sub(t.v2, t.v0));
        }
        return rs_v3_dot(n, rs_v3_sub(x, a)) > 0.0f;
    }
}

static void test_structure(void **state)
{
    rs_scene *s = make_scene();
    uint32_t l, in = 0, leaves = 0, n;
    double pw_in = 0, pw_all = 0;
    rs_light_node *copy;
    uint64_t *trail;
    (void)state;
    assert_non_null(s->light_nodes);
    for (l = 0; l < s->n_lights; ++l) {
        uint32_t prim = s->lights[l].prim;
        int dir = (prim & RS_LIGHT_PUNCTUAL) &&
                  s->punctuals[prim & ~RS_LIGHT_PUNCTUAL].type == RS_PUNCTUAL_DIRECTIONAL;
        pw_all += s->lights[l].power;
        if (dir) {
            assert_true(s->light_trail[l] == 0);
        } else {
            assert_true(s->light_trail[l] != 0);
            pw_in += s->lights[l].power;
            ++in;
        }
    }
    for (n = 0; n < s->n_light_nodes; ++n)
        if (s->light_nodes[n].flags & RS_LIGHT_NODE_LEAF) {
            uint32_t lt = s->light_nodes[n].child;
            ++leaves;
            assert_true(lt < s->n_lights && s->light_trail[lt] != 0);
        }
    print_message("%u lights, %u in the tree (%u leaves, %u nodes), share %.4f\n", s->n_lights, in,
                  leaves, s->n_light_nodes, (double)s->light_bvh_mass);
    assert_int_equal(leaves, in);
    assert_int_equal(s->n_light_nodes, 2 * in - 1);
    assert_true(fabs(s->light_bvh_mass - pw_in / pw_all) < 1e-6);
    /* deterministic: a second build gives the same bytes */
    copy = malloc(s->n_light_nodes * sizeof *copy);
    trail = malloc(s->n_lights * sizeof *trail);
    memcpy(copy, s->light_nodes, s->n_light_nodes * sizeof *copy);
    memcpy(trail, s->light_trail, s->n_lights * sizeof *trail);
    assert_int_equal(rs_scene_build_light_bvh(s), RS_OK);
    assert_memory_equal(copy, s->light_nodes, s->n_light_nodes * sizeof *copy);
    assert_memory_equal(trail, s->light_trail, s->n_lights * sizeof *trail);
    free(copy);
    free(trail);
    rs_scene_destroy(s);
}

static void test_pmf(void **state)
{
    rs_scene *s = make_scene();
    int k, facing_away = 0, reached = 0;
    double min_sum = 1.0;
    (void)state;
    for (k = 0; k < 300; ++k) {
        rs_vec3 x = rnd_v(-12, 12);
        double sum = 0;
        uint32_t l;
        int j;
        for (l = 0; l < s->n_lights; ++l) {
            float p = rs_light_bvh_pmf(s, x, l);
            assert_true(p >= 0.0f && p <= 1.0f);
            sum += p;
            if (s->light_trail[l] == 0) {
                assert_true(p == 0.0f);
                continue;
            }
            if (reaches(s, l, x)) {
                ++reached;
                if (!(p > 0.0f))
                    fail_msg("light %u reaches (%g %g %g) but its pick probability is 0", l,
                             (double)x.x, (double)x.y, (double)x.z);
            } else if (p == 0.0f) {
                ++facing_away;
            }
        }
        /* at most 1: a pick that finds both children of a node dark ends without a light (as
         * pbrt-v4's does), which is unbiased as long as no light down there reaches x (checked
         * above); the chi-square test counts those ends too */
        if (!(sum <= 1.0 + 1e-5 && sum > 0.5))
            fail_msg("point %d (%g %g %g): the pick probabilities sum to %.6f", k, (double)x.x,
                     (double)x.y, (double)x.z, sum);
        min_sum = sum < min_sum ? sum : min_sum;
        for (j = 0; j < 20; ++j) {
            uint32_t got = 0;
            float pm;
            if (rs_light_bvh_pick(s, x, rnd(), &got, &pm))
                assert_true(pm == rs_light_bvh_pmf(s, x, got));
        }
    }
    print_message("300 points: %d lights that reach a point all > 0; %d facing away at 0; the "
                  "probabilities sum to %.4f at least\n",
                  reached, facing_away, min_sum);
    assert_true(facing_away > 1000); /* the one-sided emitters' backs are culled */
    rs_scene_destroy(s);
}

static void test_chi_square(void **state)
{
    static const rs_vec3 pts[3] = {{0, 0, 0}, {9, -0.5f, 9}, {-3, 7, 2}};
    rs_scene *s = make_scene();
    const int n = 400000;
    double *pm = malloc(s->n_lights * sizeof *pm);
    long *count = calloc(s->n_lights, sizeof *count);
    int k, i;
    (void)state;
    for (k = 0; k < 3; ++k) {
        uint32_t l;
        double chi = 0, pool_e = 0, pool_o = 0;
        int dof = -1;
        memset(count, 0, s->n_lights * sizeof *count);
        for (l = 0; l < s->n_lights; ++l)
            pm[l] = rs_light_bvh_pmf(s, pts[k], l);
        long none = 0;
        double none_e = (double)n;
        for (i = 0; i < n; ++i) {
            uint32_t got = 0;
            float p;
            if (rs_light_bvh_pick(s, pts[k], rnd(), &got, &p))
                count[got]++;
            else
                ++none;
        }
        for (l = 0; l < s->n_lights; ++l)
            none_e -= pm[l] * n;
        if (none_e >= 5) { /* the picks that ended without a light: 1 - the sum */
            chi += ((double)none - none_e) * ((double)none - none_e) / none_e;
            ++dof;
        }
        for (l = 0; l < s->n_lights; ++l) {
            double e = pm[l] * n;
            if (e < 5) { /* pooled */
                pool_e += e;
                pool_o += (double)count[l];
                if (e == 0)
                    assert_int_equal(count[l], 0);
                continue;
            }
            chi += ((double)count[l] - e) * ((double)count[l] - e) / e;
            ++dof;
        }
        if (pool_e >= 5) {
            chi += (pool_o - pool_e) * (pool_o - pool_e) / pool_e;
            ++dof;
        }
        /* the 0.999 quantile, Wilson-Hilferty */
        {
            double z = 3.0902, c = 2.0 / (9.0 * dof);
            double crit = dof * pow(1 - c + z * sqrt(c), 3);
            print_message("point %d: chi-square %.1f, %d dof, critical (0.001) %.1f; %ld picks "
                          "found no light, %.1f expected\n",
                          k, chi, dof, crit, none, none_e);
            assert_true(chi < crit);
        }
    }
    free(pm);
    free(count);
    rs_scene_destroy(s);
}

static void test_cone_union(void **state)
{
    int k, j;
    (void)state;
    for (k = 0; k < 2000; ++k) {
        float wa[3], wb[3], w[3], ca = 2 * rnd() - 1, cb = 2 * rnd() - 1, c;
        rs_vec3 a = rnd_dir(), b = rnd_dir();
        wa[0] = a.x, wa[1] = a.y, wa[2] = a.z;
        wb[0] = b.x, wb[1] = b.y, wb[2] = b.z;
        if (k % 4 == 0)
            ca = 1.0f; /* a single direction */
        rs_light_cone_union(wa, ca, wb, cb, w, &c);
        for (j = 0; j < 20; ++j) {
            rs_vec3 d = rnd_dir(), cw = rs_v3(w[0], w[1], w[2]);
            int in_a = rs_v3_dot(d, a) >= ca, in_b = rs_v3_dot(d, b) >= cb;
            if (in_a || in_b)
                assert_true(rs_v3_dot(d, cw) >= c - 1e-4f);
        }
        /* the axes themselves */
        assert_true(a.x * w[0] + a.y * w[1] + a.z * w[2] >= c - 1e-4f);
        assert_true(b.x * w[0] + b.y * w[1] + b.z * w[2] >= c - 1e-4f);
    }
}

/* Two equal lights facing a point straight on, one 1 and one 3 away: their importances are
 * power x cos / distance^2 (Conty and Kulla), so the near one is picked 9 times as often as the
 * far one (issue 41: the importance without its 1 / d^2 passed every other test here). */
static void test_inverse_square(void **state)
{
    rs_scene *s = NULL;
    rs_material m = rs_mat_light(rs_v3(2, 2, 2), 0);
    rs_vec3 x = rs_v3(0.3f, -0.2f, 0.1f);
    uint32_t id;
    float p0, p1;
    (void)state;
    assert_int_equal(rs_scene_create("two", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
    /* small squares centred above x, u x v pointing down at it */
    assert_int_equal(rs_scene_add_quad(s, rs_v3(x.x - 0.01f, x.y + 1.0f, x.z - 0.01f),
                                       rs_v3(0.02f, 0, 0), rs_v3(0, 0, 0.02f), id),
                     RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(x.x - 0.01f, x.y + 3.0f, x.z - 0.01f),
                                       rs_v3(0.02f, 0, 0), rs_v3(0, 0, 0.02f), id),
                     RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 2);
    assert_non_null(s->light_trail);
    p0 = rs_light_bvh_pmf(s, x, 0);
    p1 = rs_light_bvh_pmf(s, x, 1);
    print_message("lights 1 and 3 away: picked with %.5f and %.5f (ratio %.4f, 9 expected)\n",
                  (double)p0, (double)p1, (double)(p0 / p1));
    assert_true(fabs(p0 + p1 - 1.0) < 1e-5);
    assert_true(fabs(p0 / p1 - 9.0) < 0.01);
    rs_scene_destroy(s);
}

/* A scene whose cost splits are lopsided: clusters of four lights on a line, each cluster 1.1
 * times farther out and brighter than the one before, so that a node's bright far end goes to a
 * child of its own, level after level. */
static rs_scene *deep_scene(void)
{
    rs_scene *s = NULL;
    rs_material m;
    uint32_t id, i;
    assert_int_equal(rs_scene_create("deep", &s), RS_OK);
    for (i = 0; i < 4 * 285; ++i) {
        float c = 1e-3f * powf(1.1f, (float)(i / 4)), x = c * (1.0f + 0.002f * (float)(i % 4));
        m = rs_mat_light(rs_v3_splat(1e-2f * powf(1.1f, (float)(i / 4))), 1);
        assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
        assert_int_equal(rs_scene_add_quad(s, rs_v3(x, 0, 0), rs_v3(0.001f * c, 0, 0),
                                           rs_v3(0, 0, 0.001f * c), id),
                         RS_OK);
    }
    if (rs_scene_finalize(s) != RS_OK)
        fail_msg("finalize: %s", rs_error_message());
    assert_non_null(s->light_trail);
    return s;
}

/* The deepest light's depth (its trail's marker bit). */
static uint32_t deepest_light(const rs_scene *s)
{
    uint32_t l, deepest = 0;
    for (l = 0; l < s->n_lights; ++l) {
        uint32_t depth;
        assert_true(s->light_trail[l] != 0);
        depth = 63u - (uint32_t)__builtin_clzll(s->light_trail[l]);
        deepest = depth > deepest ? depth : deepest;
    }
    return deepest;
}

/* At point x: the pick probabilities of every light sum to 1 (within tol), and `picks` picks
 * each have their light's pmf as their probability, bit for bit. */
static void check_sum_and_picks(const rs_scene *s, rs_vec3 x, double tol, int picks)
{
    double sum = 0;
    uint32_t l;
    int j;
    for (l = 0; l < s->n_lights; ++l)
        sum += rs_light_bvh_pmf(s, x, l);
    if (!(fabs(sum - 1.0) < tol))
        fail_msg("at (%g %g %g) the pick probabilities sum to %.6f", (double)x.x, (double)x.y,
                 (double)x.z, sum);
    for (j = 0; j < picks; ++j) {
        uint32_t got = 0;
        float pm;
        if (rs_light_bvh_pick(s, x, rnd(), &got, &pm))
            assert_true(pm == rs_light_bvh_pmf(s, x, got));
    }
}

/* The tree's depth stays within its limit whatever the lights (the 64-bit trails hold 62
 * levels): with the default limit, and with a limit of 14 that the lopsided scene's cost splits
 * alone would pass three times over; the pick probabilities the trails give still sum to 1 and
 * match what the picker returns. */
static void test_depth_bounded(void **state)
{
    static const int limits[] = {62, 14};
    size_t c;
    (void)state;
    for (c = 0; c < sizeof limits / sizeof limits[0]; ++c) {
        rs_scene *s;
        uint32_t deepest;
        int k;
        rs_light_bvh_set_depth_limit(limits[c]);
        s = deep_scene();
        deepest = deepest_light(s);
        print_message("%u lights, depth limit %d: the deepest at depth %u\n", s->n_lights,
                      limits[c], deepest);
        assert_true(deepest <= (uint32_t)limits[c]);
        assert_true(deepest >= 11); /* ceil(log2 1140) */
        if (limits[c] == 62)
            assert_true(deepest > 40); /* the cost splits did go deep */
        for (k = 0; k < 20; ++k) {
            float along = 1e-3f * powf(1.1f, 285.0f * rnd());
            check_sum_and_picks(s, rs_v3(along, 1.0f + 5.0f * rnd(), rnd() - 0.5f), 1e-4, 20);
        }
        rs_scene_destroy(s);
    }
    rs_light_bvh_set_depth_limit(62);
}

/* The case: a million equal lights on a line 0.01 apart (the cost splits peel them off
 * one end at a time, depth 61 of the trail's 63 bits at 4 million before the bound): every light
 * in the tree within the default depth limit, its trail a path the picker follows (a pick's
 * probability is its pmf), and the pick probabilities at a point on the line summing to 1. */
static void test_million_collinear(void **state)
{
    enum { N = 1000000 };
    rs_scene *s = NULL;
    rs_material m = rs_mat_light(rs_v3_splat(1.0f), 1);
    uint32_t id, i, deepest;
    (void)state;
    assert_int_equal(rs_scene_create("collinear", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
    for (i = 0; i < N; ++i)
        assert_int_equal(rs_scene_add_quad(s, rs_v3(0.01f * (float)i, 0, 0), rs_v3(0.001f, 0, 0),
                                           rs_v3(0, 0, 0.001f), id),
                         RS_OK);
    if (rs_scene_finalize(s) != RS_OK)
        fail_msg("finalize: %s", rs_error_message());
    assert_non_null(s->light_trail);
    deepest = deepest_light(s);
    print_message("%u collinear lights: the deepest at depth %u (limit 62)\n", s->n_lights,
                  deepest);
    assert_true(deepest <= 62 && deepest >= 20); /* ceil(log2 10^6) = 20 */
    check_sum_and_picks(s, rs_v3(2500.0f, 1.0f, 0.0f), 1e-3, 200);
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_structure),
        cmocka_unit_test(test_pmf),
        cmocka_unit_test(test_chi_square),
        cmocka_unit_test(test_cone_union),
        cmocka_unit_test(test_depth_bounded),
        cmocka_unit_test(test_inverse_square),
        cmocka_unit_test(test_million_collinear),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
