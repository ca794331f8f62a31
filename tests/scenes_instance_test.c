/* tests/scenes_instance_test.c — instances over the two-level BVH (core/geom.h, accel/bvh.c,
 * scenes/json_objects.c):
 *   - a scene file's top-level instances of groups of triangles (nested groups, a mesh file with
 *     UVs and normals, rotations, a non-uniform scale, a mirror, a 4x4 matrix) are placed, not
 *     copied: one prototype, five instances; a group with an emitter is copied;
 *   - that scene renders bit for bit the image of its flattened twin (rs_scene_flatten_instances)
 *     on every path: the stream engine with the binary, 4- and 8-wide traversals, the brute-force
 *     leaf, the CPU megakernel, the GPU fallback's trace and its megakernel;
 *   - random rays find the same closest hit (primitive, t, u, v) and the same occlusion in the
 *     instanced BVH (by three builders, on the binary, 4- and 8-wide traversals) as brute force
 *     over the twin's triangles;
 *   - an instance places a group's triangles, UVs and normals exactly where copying it does;
 *   - bad instances (a singular transform, coordinates past 1e30) get one line naming the
 *     object. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "accel/bvh4.h"
#include "accel/bvh8.h"
#include "render_util.h"
#include "scenes/scene_json.h"
#include "test_files.h"

#define SIZE 32

/* Two triangles of the group "leaf" (one with UVs and vertex normals), "tree" = two leaves and a
 * mesh file with UVs and normals; "glow" holds an emitter.  Five trees are placed. */
static const char *const k_scene =
    "{\"camera\":{\"from\":[0,2.5,9],\"at\":[0,0.6,0],\"vfov\":45},"
    "\"image\":{\"width\":32,\"height\":32},"
    "\"background\":{\"horizon\":[0.3,0.3,0.35],\"zenith\":[0.1,0.2,0.4]},"
    "\"textures\":{\"chk\":{\"type\":\"checker\",\"a\":[0.9,0.9,0.9],\"b\":[0.2,0.3,0.8],"
    "\"scale\":0.25},"
    "\"st\":{\"type\":\"stripes\",\"a\":[0.9,0.2,0.1],\"b\":[0.9,0.9,0.2],\"scale\":5}},"
    "\"materials\":{\"floor\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5]},"
    "\"cloth\":{\"type\":\"disney_diffuse\",\"texture\":\"st\",\"roughness\":0.5},"
    "\"gloss\":{\"type\":\"phong\",\"texture\":\"chk\",\"ks\":[0.3,0.3,0.3],\"exponent\":40,"
    "\"importance_sampling\":true},"
    "\"glass\":{\"type\":\"rough_dielectric\",\"ior\":1.5,\"roughness\":0.2},"
    "\"lamp\":{\"type\":\"light\",\"emission\":[5,5,4],\"two_sided\":true}},"
    "\"groups\":{"
    "\"leaf\":[{\"type\":\"triangle\",\"vertices\":[[-0.5,0,0],[0.5,0,0],[0,1,0.2]],"
    "\"uv\":[0,0,1,0,0.5,1],\"normals\":[0,0.3,1, 0.3,0,1, 0,0,1],\"material\":\"cloth\"},"
    "{\"type\":\"triangle\",\"vertices\":[[-0.3,0,0.3],[0.4,0.2,0.4],[0,0.8,-0.3]],"
    "\"material\":\"gloss\"}],"
    "\"tree\":[{\"type\":\"instance\",\"group\":\"leaf\"},"
    "{\"type\":\"instance\",\"group\":\"leaf\",\"transform\":[{\"rotate\":[0,90,0]},"
    "{\"translate\":[0,0.5,0]}]},"
    "{\"type\":\"mesh\",\"file\":\"pyr.obj\",\"material\":\"glass\","
    "\"transform\":{\"translate\":[0,0,0.6]}}],"
    "\"glow\":[{\"type\":\"triangle\",\"vertices\":[[-0.4,0,0],[0.4,0,0],[0,0.5,0]],"
    "\"material\":\"lamp\"}]},"
    "\"objects\":["
    "{\"type\":\"quad\",\"q\":[-6,0,6],\"u\":[12,0,0],\"v\":[0,0,-12],\"material\":\"floor\"},"
    "{\"type\":\"quad\",\"q\":[-1,4,-1],\"u\":[2,0,0],\"v\":[0,0,2],\"material\":\"lamp\"},"
    "{\"type\":\"instance\",\"group\":\"tree\"},"
    "{\"type\":\"instance\",\"group\":\"tree\",\"transform\":[{\"rotate\":[10,20,30]},"
    "{\"translate\":[-2,0.2,0]}]},"
    "{\"type\":\"instance\",\"group\":\"tree\",\"transform\":[{\"scale\":[1,2,0.5]},"
    "{\"translate\":[2,0,0]}]},"
    "{\"type\":\"instance\",\"group\":\"tree\",\"transform\":[{\"scale\":[-1,1,1]},"
    "{\"rotate\":{\"axis\":[0,1,0],\"degrees\":40}},{\"translate\":[0.5,0,-2]}]},"
    "{\"type\":\"instance\",\"group\":\"tree\",\"transform\":{\"matrix\":"
    "[0.8,0,0.3,-1.5, 0,0.9,0,0, -0.3,0,0.8,1.8, 0,0,0,1]}},"
    "{\"type\":\"instance\",\"group\":\"glow\",\"transform\":{\"translate\":[1.5,0,2]}},"
    "{\"type\":\"triangle\",\"vertices\":[[1,0,-1],[2,0,-1],[1.5,1.5,-1]],\"material\":\"gloss\"},"
    "{\"type\":\"sphere\",\"center\":[-2.5,0.4,2],\"radius\":0.4,\"material\":\"gloss\"}]}";

/* A square pyramid with UVs and normals (6 triangles). */
static const char *const k_obj = "v -0.3 0 -0.3\nv 0.3 0 -0.3\nv 0.3 0 0.3\nv -0.3 0 0.3\n"
                                 "v 0 0.7 0\n"
                                 "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
                                 "vn 0 -1 0\nvn 0 0.4 -1\nvn 1 0.4 0\nvn 0 0.4 1\nvn -1 0.4 0\n"
                                 "f 1/1/1 3/3/1 2/2/1\nf 1/1/1 4/4/1 3/3/1\n"
                                 "f 1/1/2 2/2/2 5/5/2\nf 2/2/3 3/3/3 5/5/3\n"
                                 "f 3/3/4 4/4/4 5/5/4\nf 4/4/5 1/1/5 5/5/5\n";

typedef struct fixture {
    char dir[64];
    rs_scene *inst, *flat;
} fixture;

static rs_scene *load(const char *dir, int flatten)
{
    char path[128];
    rs_scene *s = NULL;
    snprintf(path, sizeof path, "%s/scene.json", dir);
    if (rs_scene_load_json(path, &s) != RS_OK)
        fail_msg("loading the scene: %s", rs_error_message());
    if (flatten) {
        assert_int_equal(rs_scene_flatten_instances(s), RS_OK);
        assert_int_equal(rs_scene_finalize(s), RS_OK);
    }
    return s;
}

static int setup(void **state)
{
    fixture *f = (fixture *)calloc(1, sizeof *f);
    char path[128];
    snprintf(f->dir, sizeof f->dir, "/tmp/rs_inst_XXXXXX");
    if (!mkdtemp(f->dir))
        return -1;
    snprintf(path, sizeof path, "%s/scene.json", f->dir);
    write_file(path, k_scene);
    snprintf(path, sizeof path, "%s/pyr.obj", f->dir);
    write_file(path, k_obj);
    f->inst = load(f->dir, 0);
    f->flat = load(f->dir, 1);
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = (fixture *)*state;
    rs_scene_destroy(f->inst);
    rs_scene_destroy(f->flat);
    remove_in(f->dir, "scene.json");
    remove_in(f->dir, "pyr.obj");
    rmdir(f->dir);
    free(f);
    return 0;
}

/* What was placed and what was copied. */
static void test_placed_not_copied(void **state)
{
    const fixture *f = (const fixture *)*state;
    const rs_scene *a = f->inst, *b = f->flat;
    /* the tree: 2 + 2 leaf triangles and the pyramid's 6, once; five placements */
    assert_int_equal(a->n_inst_tris, 10u);
    assert_int_equal(a->n_instances, 5u);
    assert_int_equal(a->n_inst_prims, 50u);
    assert_non_null(a->inst_tri_uv);
    assert_non_null(a->inst_tri_normal);
    /* the scene's own: a triangle and the copied glow */
    assert_int_equal(a->n_tris, 2u);
    assert_int_equal(b->n_tris, 52u);
    assert_int_equal(b->n_instances, 0u);
    assert_int_equal(a->n_lights, b->n_lights);
    assert_int_equal(a->n_lights, 2u); /* the lamp quad and the copied glow */
    assert_true(a->instances[3].mirror);
    assert_false(a->instances[2].mirror);
}

/* The instanced scene and its twin give the same image bit for bit on every path. */
static void test_same_image_everywhere(void **state)
{
    const fixture *f = (const fixture *)*state;
    rt_args a = rt_defaults("", SIZE, 4);
    float *ref, *img;
    double sum = 0;
    int i, k;
    a.threads = 2;
    ref = rt_render_scene(f->flat, &a, NULL);
    assert_non_null(ref);
    for (i = 0; i < SIZE * SIZE * 3; ++i)
        sum += ref[i];
    assert_true(sum > 10.0); /* the picture shows something */
    for (k = 0; k < 8; ++k) {
        static const char *const names[] = {"stream, 4-wide", "stream, 8-wide",  "stream, binary",
                                            "brute force",    "cpu megakernel",  "gpu fallback",
                                            "fallback megakernel", "cpu + fallback"};
        rt_args c = a;
        if (k == 1 && !rs_bvh8_supported()) {
            print_message("no AVX2 here: the 8-wide case is skipped\n");
            continue;
        }
        c.bvh_width = k == 1 ? 8 : k == 2 ? 2 : 4;
        c.no_bvh = k == 3;
        c.megakernel = k == 4 || k == 6;
        c.fallback_only = k == 5 || k == 6;
        c.with_fallback = k == 7;
        c.chunk_size = k == 7 ? 256 : 0;
        img = rt_render_scene(f->inst, &c, NULL);
        assert_non_null(img);
        if (memcmp(img, ref, sizeof(float) * SIZE * SIZE * 3) != 0)
            fail_msg("%s: the instanced scene's image differs from the flattened one's",
                     names[k]);
        free(img);
    }
    free(ref);
}

/* A fixed-seed generator of floats in [0, 1) (xorshift64*). */
static float next_float(uint64_t *x)
{
    *x ^= *x >> 12;
    *x ^= *x << 25;
    *x ^= *x >> 27;
    return (float)((*x * 2685821657736338717ull) >> 40) * (1.0f / 16777216.0f);
}

/* Brute force over the twin's primitives: the closest hit by rs_hit_better. */
static int brute_closest(const rs_geom *g, rs_ray r, rs_hit *h)
{
    uint32_t p, n = rs_geom_prim_count(g);
    h->prim = RS_NO_HIT;
    h->t = r.tmax;
    for (p = 0; p < n; ++p) {
        float t, u, v;
        if (rs_geom_intersect(g, p, &r, &t, &u, &v) && rs_hit_better(t, p, h)) {
            h->t = t;
            h->u = u;
            h->v = v;
            h->prim = p;
        }
    }
    return h->prim != RS_NO_HIT;
}

static void expect_same_hit(const rs_hit *a, const rs_hit *b, const char *what, int i)
{
    if (a->prim != b->prim || (a->prim != RS_NO_HIT && (a->t != b->t || a->u != b->u ||
                                                         a->v != b->v)))
        fail_msg("ray %d, %s: prim %u t %.9g u %.9g v %.9g, brute force prim %u t %.9g u %.9g "
                 "v %.9g",
                 i, what, a->prim, a->t, a->u, a->v, b->prim, b->t, b->u, b->v);
}

static void test_hits_match_brute_force(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const uint32_t methods[] = {RS_BVH_SAH, RS_BVH_MEDIAN, RS_BVH_LBVH};
    rs_geom gf = rs_scene_geom(f->flat);
    uint32_t m;
    int hits = 0, inst_hits = 0, blocked = 0;
    for (m = 0; m < 3; ++m) {
        rs_geom gi = rs_scene_geom(f->inst);
        rs_bvh_build_opts o;
        rs_bvh *b = NULL;
        rs_bvh4 *b4 = NULL;
        rs_bvh8 *b8 = NULL;
        rs_bvh_view v;
        uint64_t rng;
        int i;
        memset(&o, 0, sizeof o);
        o.builder.method = methods[m];
        o.threads = 1;
        assert_int_equal(rs_bvh_build(&gi, &o, &b), RS_OK);
        rs_bvh_attach(b, &gi);
        assert_non_null(gi.blas_nodes);
        assert_int_equal(rs_bvh4_build(b, &gi, &b4), RS_OK);
        if (rs_bvh8_supported())
            assert_int_equal(rs_bvh8_build(b, &gi, &b8), RS_OK);
        v = rs_bvh_view_of(b);
        rng = 0x9e3779b97f4a7c15ull * (m + 1);
        for (i = 0; i < 4000; ++i) {
            rs_ray r;
            rs_hit want, got;
            int occ;
            /* from a box around the trees, toward a point among them */
            rs_vec3 to = rs_v3(6 * next_float(&rng) - 3, 2 * next_float(&rng),
                               6 * next_float(&rng) - 3);
            r.o = rs_v3(12 * next_float(&rng) - 6, 5 * next_float(&rng),
                        12 * next_float(&rng) - 6);
            r.d = rs_v3_sub(to, r.o);
            r.tmin = 1e-4f;
            r.tmax = i % 3 == 0 ? 0.8f : FLT_MAX; /* some rays end among the trees */
            r.time = 0;
            brute_closest(&gf, r, &want);
            rs_bvh_closest(&v, &gi, r, &got);
            expect_same_hit(&got, &want, "binary", i);
            rs_bvh4_closest(b4, &gi, r, &got);
            expect_same_hit(&got, &want, "4-wide", i);
            if (b8) {
                rs_bvh8_closest(b8, &gi, r, &got);
                expect_same_hit(&got, &want, "8-wide", i);
            }
            occ = want.prim != RS_NO_HIT;
            if (rs_bvh_occluded(&v, &gi, r) != occ || rs_bvh4_occluded(b4, &gi, r) != occ ||
                (b8 && rs_bvh8_occluded(b8, &gi, r) != occ))
                fail_msg("ray %d: occlusion differs from brute force (%d)", i, occ);
            hits += occ;
            inst_hits += want.prim != RS_NO_HIT && want.prim >= rs_scene_prim_count(f->inst);
            blocked += occ && r.tmax < 1.0f;
        }
        rs_bvh8_destroy(b8);
        rs_bvh4_destroy(b4);
        rs_bvh_destroy(b);
    }
    print_message("%d hits (%d on instances, %d on short rays) of 12000 rays\n", hits, inst_hits,
                  blocked);
    assert_true(inst_hits > 1000); /* the rays do reach the instances */
}

/* Placing a group is copying it: the triangles (vertices, UVs, normals) an instance places are
 * bit for bit those the copying path (scenes/transform.c, the one nested groups take) makes
 * under the same transform, mirrors included. */
static void test_placing_equals_copying(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const xf[] = {"{\"scale\":[-1,2,0.5]}",
                                     "[{\"rotate\":[10,-70,5]},{\"translate\":[3,1e3,-2]}]"};
    int k;
    for (k = 0; k < 2; ++k) {
        char text[2048], path[128];
        rs_scene *s = NULL;
        uint32_t i, own;
        snprintf(text, sizeof text,
                 "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},"
                 "\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5]}},"
                 "\"groups\":{\"g\":[{\"type\":\"triangle\",\"vertices\":[[0.1,0,0],[1,0.2,0],"
                 "[0,1,0.3]],\"uv\":[0,0,1,0.1,0.2,1],\"normals\":[0,0.6,0.8, 0.6,0,0.8, 0,0,1],"
                 "\"material\":\"m\"}],"
                 "\"copied\":[{\"type\":\"instance\",\"group\":\"g\",\"transform\":%s}]},"
                 "\"objects\":[{\"type\":\"instance\",\"group\":\"g\",\"transform\":%s},"
                 "{\"type\":\"instance\",\"group\":\"copied\"}]}",
                 xf[k], xf[k]);
        snprintf(path, sizeof path, "%s/copy.json", f->dir);
        write_file(path, text);
        assert_int_equal(rs_scene_load_json(path, &s), RS_OK);
        /* two prototypes: g itself, and "copied" (g copied under xf), placed by the identity */
        assert_int_equal(s->n_instances, 2u);
        assert_int_equal(s->instances[0].mirror, k == 0);
        own = rs_scene_prim_count(s);
        for (i = 0; i < 1; ++i) {
            float ua[6], ub[6], na[9], nb[9];
            rs_tri a = rs_scene_tri(s, own + i), b = rs_scene_tri(s, own + 1 + i);
            const float *pa = rs_scene_tri_uv(s, own + i, ua), *pb = rs_scene_tri_uv(s, own + 1 + i, ub);
            const float *qa = rs_scene_tri_normals(s, own + i, na);
            const float *qb = rs_scene_tri_normals(s, own + 1 + i, nb);
            int j;
            /* equal values (the identity placement turns a -0 into +0: that is all it changes) */
            for (j = 0; j < 9; ++j)
                if ((&a.v0.x)[j] != (&b.v0.x)[j] || qa[j] != qb[j] || (j < 6 && pa[j] != pb[j]))
                    fail_msg("transform %d, value %d: placed %.9g %.9g %.9g, copied %.9g %.9g "
                             "%.9g",
                             k, j, (&a.v0.x)[j], qa[j], j < 6 ? pa[j] : 0, (&b.v0.x)[j], qb[j],
                             j < 6 ? pb[j] : 0);
            /* and the face normal still points along the vertex normals (outward) */
            assert_true(rs_v3_dot(rs_v3_cross(rs_v3_sub(a.v1, a.v0), rs_v3_sub(a.v2, a.v0)),
                                  rs_v3(qa[0], qa[1], qa[2])) > 0);
        }
        rs_scene_destroy(s);
        remove_in(f->dir, "copy.json");
    }
}

static void expect_error(const char *dir, const char *objects, const char *want)
{
    char path[128], text[4096];
    rs_scene *s = NULL;
    snprintf(text, sizeof text,
             "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5]}},"
             "\"groups\":{\"g\":[{\"type\":\"triangle\",\"vertices\":[[0,0,0],[100,0,0],"
             "[0,1,0]],\"material\":\"m\"}]},\"objects\":[%s]}",
             objects);
    snprintf(path, sizeof path, "%s/bad.json", dir);
    write_file(path, text);
    assert_int_not_equal(rs_scene_load_json(path, &s), RS_OK);
    assert_null(s);
    if (!strstr(rs_error_message(), want) || strchr(rs_error_message(), '\n'))
        fail_msg("expected one line with '%s', got '%s'", want, rs_error_message());
    rs_error_clear();
    remove_in(dir, "bad.json");
}

static void test_bad_instances(void **state)
{
    const fixture *f = (const fixture *)*state;
    expect_error(f->dir,
                 "{\"type\":\"instance\",\"group\":\"g\",\"transform\":{\"matrix\":"
                 "[1,0,0,0, 1,0,0,0, 0,0,1,0, 0,0,0,1]}}",
                 "objects[0].transform: the matrix is singular");
    expect_error(f->dir,
                 "{\"type\":\"instance\",\"group\":\"g\"},"
                 "{\"type\":\"instance\",\"group\":\"g\",\"transform\":{\"scale\":1e29}}",
                 "objects[1]: the transform moves a coordinate beyond 1e30");
}

/* --flatten-instances copies at most 2^24 primitives, checked before the first copy: 20,000
 * placements of a 1,000-triangle group (2e7) are refused at once, and the scene is unchanged
 * (it started to copy 10^8 triangles before). */
static void test_flatten_capped(void **state)
{
    rs_scene *s;
    uint32_t i, mat, first, count;
    double m[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
    rs_material w = rs_mat_lambertian(rs_v3(0.5f, 0.5f, 0.5f));
    (void)state;
    assert_int_equal(rs_scene_create("capped", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &w, &mat), RS_OK);
    for (i = 0; i < 1000; ++i)
        assert_int_equal(rs_scene_add_triangle(s, rs_v3((float)i, 0, 0), rs_v3((float)i + 1, 0, 0),
                                               rs_v3((float)i, 1, 0), mat),
                         RS_OK);
    assert_int_equal(rs_scene_make_prototype(s, 0, &first, &count), RS_OK);
    for (i = 0; i < 20000; ++i) {
        m[11] = (double)i;
        assert_int_equal(rs_scene_add_instance(s, first, count, m), RS_OK);
    }
    rs_error_clear();
    assert_int_equal(rs_scene_flatten_instances(s), RS_ERR_ARG);
    print_message("%s\n", rs_error_message());
    assert_non_null(strstr(rs_error_message(), "more than 2^24"));
    assert_int_equal(s->n_instances, 20000u);
    assert_int_equal(s->n_tris, 0u);
    rs_error_clear();
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_placed_not_copied),
        cmocka_unit_test(test_same_image_everywhere),
        cmocka_unit_test(test_hits_match_brute_force),
        cmocka_unit_test(test_placing_equals_copying),
        cmocka_unit_test(test_bad_instances),
        cmocka_unit_test(test_flatten_capped),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
