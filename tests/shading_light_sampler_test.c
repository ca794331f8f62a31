/* tests/shading_light_sampler_test.c — the light sampler's two halves agree (shading/
 * light_sampler.h), for both ways of picking: by power and by the light BVH.
 *
 * The scene: 24 one- and two-sided parallelogram and triangle emitters of different powers around
 * a diffuse floor, a point light, a directional light and a constant background (a uniform sky,
 * sampled as a light with its own pick probability).  At 40 random vertices on the floor (a
 * tilted normal, so a one-sided emitter may face away) and for each sampler:
 *   - the pmfs of the lights and the sky's pick sum to 1 within 1e-5 (by power), to at most 1 (the
 *     BVH: a pick that finds both children dark ends without a light; pbrt-v4's does the same);
 *   - each sample's pdf is rs_light_pdf_hit_pick of the light it came from with
 *     rs_light_sampler_pmf's pick, within 1e-5 relative (the pdf MIS gives a BSDF sample that
 *     hits that light: the pair must agree or the weights do not sum to one); the light is the
 *     emitter that holds the sample's point (brute force), a punctual light's pdf its pmf
 *     exactly;
 *   - over 20,000 samples at each of four vertices, how often each light (and the sky, and no
 *     light) is picked against the pmfs: chi-square at alpha = 0.001 (cells of expected count < 5
 *     pooled).
 * A sampler whose pmf is not its sample's pick fails: the BVH's pmf without the environment's
 * share (1 - env_pick) fails the sum and the chi-square, the power pmf read from the next light
 * the pdf check and the chi-square (both tried). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/intersect.h"
#include "scenes/light_bvh.h"
#include "shading/light_sampler.h"
#include "test_rand.h"

static uint64_t g_s = 0x11647u;

/* uniform in [0, 1) with 24 bits: never 1, as a sampler's numbers */
static float rnd(void) { return (float)(splitmix64(&g_s) >> 40) * 0x1.0p-24f; }

static rs_vec3 rnd_v(float lo, float hi)
{
    return rs_v3(rnd_range(&g_s, lo, hi), rnd_range(&g_s, lo, hi), rnd_range(&g_s, lo, hi));
}

static rs_scene *make_scene(void)
{
    rs_scene *s = NULL;
    uint32_t mats[3], diffuse, i;
    rs_material m;
    rs_punctual p;
    rs_scene_set_extras(1, 1);
    assert_int_equal(rs_scene_create("sampler", &s), RS_OK);
    m = rs_mat_light(rs_v3(4, 3, 2), 0);
    assert_int_equal(rs_scene_add_material(s, &m, &mats[0]), RS_OK);
    m = rs_mat_light(rs_v3(1, 2, 3), 1);
    assert_int_equal(rs_scene_add_material(s, &m, &mats[1]), RS_OK);
    m = rs_mat_light(rs_v3(9, 9, 9), 0);
    assert_int_equal(rs_scene_add_material(s, &m, &mats[2]), RS_OK);
    m = rs_mat_lambertian(rs_v3_splat(0.5f));
    assert_int_equal(rs_scene_add_material(s, &m, &diffuse), RS_OK);
    assert_int_equal(
        rs_scene_add_quad(s, rs_v3(-20, -1, -20), rs_v3(40, 0, 0), rs_v3(0, 0, 40), diffuse),
        RS_OK);
    for (i = 0; i < 12; ++i) {
        rs_vec3 q = rs_v3_add(rnd_v(-6, 6), rs_v3(0, 7, 0));
        assert_int_equal(rs_scene_add_quad(s, q, rs_v3_scale(rnd_unit(&g_s), 0.3f + rnd()),
                                           rs_v3_scale(rnd_unit(&g_s), 0.3f + rnd()), mats[i % 3]),
                         RS_OK);
    }
    for (i = 0; i < 12; ++i) {
        rs_vec3 a = rs_v3_add(rnd_v(-6, 6), rs_v3(0, 7, 0));
        assert_int_equal(rs_scene_add_triangle(
                             s, a, rs_v3_add(a, rs_v3_scale(rnd_unit(&g_s), 0.8f)),
                             rs_v3_add(a, rs_v3_scale(rnd_unit(&g_s), 0.8f)), mats[(i + 1) % 3]),
                         RS_OK);
    }
    memset(&p, 0, sizeof p);
    p.type = RS_PUNCTUAL_POINT;
    p.pos = rs_v3(1, 6, -2);
    p.intensity = rs_v3(2, 2, 2);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    p.type = RS_PUNCTUAL_DIRECTIONAL;
    p.dir = rs_v3(0.3f, -1, 0.2f);
    p.intensity = rs_v3(0.01f, 0.01f, 0.01f);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    s->background = rs_v3(0.002f, 0.003f, 0.004f); /* a uniform sky, sampled as a light */
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_true(s->env_pick > 0.0f && s->env_uniform);
    assert_non_null(s->light_nodes);
    return s;
}

/* A vertex on the floor with a tilted normal, and its offset origin. */
static void vertex(rs_vec3 *x, rs_vec3 *n, rs_vec3 *at)
{
    *x = rs_v3(-8.0f + 16.0f * rnd(), -1.0f, -8.0f + 16.0f * rnd());
    *n = rs_v3_normalize(rs_v3(0.6f * rnd() - 0.3f, 1.0f, 0.6f * rnd() - 0.3f));
    *at = rs_v3_add(*x, rs_v3_scale(*n, 1e-4f));
}

/* The light a sample came from: -1 for the sky, the directional or the point light, or the
 * emitter that holds the sample's point (brute force over every emitter: a ray from just above
 * the point straight down its normal hits it at once); -3 where none is. */
static int32_t source(const rs_scene *s, const rs_light_sample *ls, rs_vec3 *ng)
{
    uint32_t l;
    if (ls->env && !ls->delta)
        return -1;
    if (ls->delta) {
        for (l = 0; l < s->n_lights; ++l) {
            uint32_t prim = s->lights[l].prim;
            if (prim & RS_LIGHT_PUNCTUAL) {
                const rs_punctual *p = &s->punctuals[prim & ~RS_LIGHT_PUNCTUAL];
                if ((p->type == RS_PUNCTUAL_DIRECTIONAL) == (ls->env != 0))
                    return (int32_t)l;
            }
        }
        return -3;
    }
    for (l = 0; l < s->n_area_lights; ++l) {
        uint32_t prim = s->lights[l].prim;
        rs_vec3 n = rs_prim_normal(s, prim, ls->point, 0.0f);
        rs_ray r;
        float t = 0, u, v;
        int hit;
        r.o = rs_v3_add(ls->point, rs_v3_scale(n, 1e-3f));
        r.d = rs_v3_neg(n);
        r.tmin = 0.0f;
        r.tmax = 2e-3f;
        r.time = 0.0f;
        if (prim < s->n_spheres + s->n_quads)
            hit = rs_isect_quad(&s->quads[prim - s->n_spheres], &r, &t, &u, &v);
        else {
            rs_tri tr = rs_scene_tri(s, prim);
            hit = rs_isect_tri(&tr, &r, &t, &u, &v);
        }
        if (hit) {
            *ng = n;
            return (int32_t)l;
        }
    }
    return -3;
}

static void check_pdfs(uint32_t sampler)
{
    rs_scene *s = make_scene();
    int k, j, checked = 0, env = 0, delta = 0;
    double max_rel = 0.0, min_sum = 2.0;
    for (k = 0; k < 40; ++k) {
        rs_vec3 x, n, at;
        double sum;
        uint32_t l;
        vertex(&x, &n, &at);
        sum = s->env_pick;
        for (l = 0; l < s->n_lights; ++l)
            sum += rs_light_sampler_pmf(s, sampler, l, at);
        if (sampler == RS_LIGHT_SAMPLER_POWER ? fabs(sum - 1.0) > 1e-5
                                              : !(sum <= 1.0 + 1e-5 && sum > 0.5))
            fail_msg("sampler %u, vertex %d: the picks sum to %.7f", sampler, k, sum);
        min_sum = sum < min_sum ? sum : min_sum;
        for (j = 0; j < 200; ++j) {
            rs_light_sample ls;
            float want;
            rs_vec3 ng = rs_v3_splat(0.0f);
            int32_t src;
            if (!rs_light_sampler_sample(s, sampler, x, n, at, 0.0f, rnd(), rnd(), rnd(), &ls))
                continue;
            src = source(s, &ls, &ng);
            assert_true(src != -3);
            if (src == -1) { /* the sky: its pick as ever, by either sampler */
                ++env;
                continue;
            }
            if (ls.delta) { /* a punctual light's pdf is its pick alone */
                if (!(ls.pdf == rs_light_sampler_pmf(s, sampler, (uint32_t)src, at)))
                    fail_msg("sampler %u, vertex %d, punctual light %d: pdf %g, pmf %g", sampler,
                             k, src, (double)ls.pdf,
                             (double)rs_light_sampler_pmf(s, sampler, (uint32_t)src, at));
                ++delta;
                continue;
            }
            want = rs_light_pdf_hit_pick(s, (uint32_t)src,
                                         rs_light_sampler_pmf(s, sampler, (uint32_t)src, at), x,
                                         0.0f, ls.wi, ls.dist, ng);
            {
                double rel = fabs((double)ls.pdf - want) / want;
                if (!(rel <= 1e-5))
                    fail_msg("sampler %u, vertex %d, light %d: the sample's pdf %g, the pmf's %g",
                             sampler, k, src, (double)ls.pdf, (double)want);
                max_rel = rel > max_rel ? rel : max_rel;
            }
            ++checked;
        }
    }
    print_message("sampler %u: %d emitter samples' pdfs within %.2g of the pmf's (%d punctual, "
                  "%d from the sky); the picks sum to %.5f at least\n",
                  sampler, checked, max_rel, delta, env, min_sum);
    assert_true(checked > 3000 && env > 100 && delta > 50);
    rs_scene_destroy(s);
}

static void check_frequencies(uint32_t sampler)
{
    enum { N = 20000 };
    rs_scene *s = make_scene();
    int k;
    for (k = 0; k < 4; ++k) {
        /* cells: lights 0..n-1, the sky, nothing */
        uint32_t nl = s->n_lights, c, l, j;
        double *expect = calloc(nl + 2, sizeof *expect), chi2 = 0.0, pooled_e = 0.0;
        long *count = calloc(nl + 2, sizeof *count), pooled_n = 0;
        int dof = -1;
        rs_vec3 x, n, at;
        assert_non_null(expect);
        assert_non_null(count);
        vertex(&x, &n, &at);
        expect[nl] = s->env_pick;
        expect[nl + 1] = 1.0;
        for (l = 0; l < nl; ++l)
            expect[l] = rs_light_sampler_pmf(s, sampler, l, at);
        for (l = 0; l <= nl; ++l)
            expect[nl + 1] -= expect[l];
        if (expect[nl + 1] < 1e-7)
            expect[nl + 1] = 0.0;
        for (j = 0; j < N; ++j) {
            rs_light_sample ls;
            rs_vec3 ng;
            int32_t src;
            /* no sample: a BVH pick that ended where both children are dark (or a degenerate
             * sample, x on a light's plane): the "nothing" cell */
            if (!rs_light_sampler_sample(s, sampler, x, n, at, 0.0f, rnd(), rnd(), rnd(), &ls)) {
                ++count[nl + 1];
                continue;
            }
            src = source(s, &ls, &ng);
            assert_true(src != -3);
            ++count[src == -1 ? nl : (uint32_t)src];
        }
        for (c = 0; c < nl + 2; ++c) {
            double e = expect[c] * N;
            if (e < 5.0) {
                pooled_e += e;
                pooled_n += count[c];
                continue;
            }
            chi2 += (count[c] - e) * (count[c] - e) / e;
            ++dof;
        }
        if (pooled_e >= 5.0) {
            chi2 += (pooled_n - pooled_e) * (pooled_n - pooled_e) / pooled_e;
            ++dof;
        } else if (pooled_n > 20) {
            fail_msg("sampler %u, vertex %d: %ld picks of lights the pmf says %.2f", sampler, k,
                     pooled_n, pooled_e);
        }
        /* alpha = 0.001: the Wilson-Hilferty approximation of the chi-square quantile */
        {
            double z = 3.0902, h = 2.0 / (9.0 * dof);
            double crit = dof * pow(1.0 - h + z * sqrt(h), 3.0);
            print_message("sampler %u, vertex %d: chi-square %.1f, %d degrees of freedom "
                          "(critical %.1f)\n",
                          sampler, k, chi2, dof, crit);
            assert_true(dof >= 8);
            assert_true(chi2 < crit);
        }
        free(expect);
        free(count);
    }
    rs_scene_destroy(s);
}

static void test_power_pdfs(void **state)
{
    (void)state;
    check_pdfs(RS_LIGHT_SAMPLER_POWER);
}

static void test_bvh_pdfs(void **state)
{
    (void)state;
    check_pdfs(RS_LIGHT_SAMPLER_BVH);
}

static void test_power_frequencies(void **state)
{
    (void)state;
    check_frequencies(RS_LIGHT_SAMPLER_POWER);
}

static void test_bvh_frequencies(void **state)
{
    (void)state;
    check_frequencies(RS_LIGHT_SAMPLER_BVH);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_power_pdfs),
        cmocka_unit_test(test_bvh_pdfs),
        cmocka_unit_test(test_power_frequencies),
        cmocka_unit_test(test_bvh_frequencies),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
