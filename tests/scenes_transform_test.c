/* tests/scenes_transform_test.c — transforms, groups and instances, and mesh objects in scene
 * files:
 *   - the transform steps compose in the stated order and match matrices worked by hand; Euler
 *     angles follow the mesh placement's convention (x, then y, then z, right-handed), and
 *     rs_xform_normal is the inverse transpose, the one that rs_scene_transform_since uses;
 *   - a transformed sphere, quad, triangle and box land where the transform puts them, and a
 *     mirroring transform keeps every surface's outward normal (quads, triangles and their vertex
 *     normals); vertex normals go by the inverse transpose (a rotation then a non-uniform scale,
 *     against values worked by hand);
 *   - a scene of instances (nested, with transforms) renders the same image, bit for bit, as the
 *     same objects written out one by one with the instances' transforms;
 *   - a mesh object reads its file relative to the scene, keeps or replaces its materials by name,
 *     is read once however often instances place it, and refuses a replacement the file lacks;
 *   - a file of a few lines that would instance past the primitive budget is refused quickly. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "render_util.h"
#include "scenes/scene_export.h"
#include "scenes/scene_json.h"
#include "scenes/transform.h"
#include "test_files.h"

#define CAM "\"camera\":{\"from\":[0,1,9],\"at\":[0,0,0]},\"image\":{\"width\":24,\"height\":24}"
#define MATS                                                                                       \
  "\"materials\":{\"m\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.4,0.3]},"                       \
  "\"l\":{\"type\":\"light\",\"emission\":[4,4,4]}}"

static rs_scene *parse(const char *json)
{
    rs_scene *s = NULL;
    rs_status st = rs_scene_parse_json(json, strlen(json), "t.json", NULL, &s);
    if (st != RS_OK)
        fail_msg("parse failed: %s", rs_error_message());
    return s;
}

static void expect_v3(rs_vec3 a, float x, float y, float z)
{
    if (fabsf(a.x - x) > 1e-5f || fabsf(a.y - y) > 1e-5f || fabsf(a.z - z) > 1e-5f)
        fail_msg("(%g, %g, %g) != (%g, %g, %g)", a.x, a.y, a.z, x, y, z);
}

/* The steps compose in order: scale, then rotate 90 degrees about z, then translate, takes
 * (1, 0, 0) to (2, 0, 0), then (0, 2, 0), then (5, 2, 0); an axis-angle rotation about (1,1,1) by
 * 120 degrees cycles the axes; Euler angles are x, then y, then z. */
static void test_steps_compose_in_order(void **state)
{
    static const double z[3] = {0, 0, 1}, d[3] = {1, 1, 1};
    rs_xform s = rs_xform_scale(2, 2, 2), r = rs_xform_rotate_axis(z, 90);
    rs_xform t = rs_xform_translate(5, 0, 0), rs_, trs, cyc, e, ex;
    double k;
    (void)state;
    rs_ = rs_xform_compose(&r, &s);
    trs = rs_xform_compose(&t, &rs_);
    expect_v3(rs_xform_point(&trs, rs_v3(1, 0, 0)), 5, 2, 0);
    expect_v3(rs_xform_vector(&trs, rs_v3(1, 0, 0)), 0, 2, 0);
    assert_true(rs_xform_is_similarity(&trs, &k));
    assert_true(fabs(k - 2.0) < 1e-12);
    assert_true(fabs(rs_xform_det(&trs) - 8.0) < 1e-12);
    cyc = rs_xform_rotate_axis(d, 120);
    expect_v3(rs_xform_point(&cyc, rs_v3(1, 0, 0)), 0, 1, 0);
    expect_v3(rs_xform_point(&cyc, rs_v3(0, 1, 0)), 0, 0, 1);
    /* Euler (90, 90, 0): x first takes y to z, then y takes z to x */
    e = rs_xform_rotate_euler(90, 90, 0);
    expect_v3(rs_xform_point(&e, rs_v3(0, 1, 0)), 1, 0, 0);
    ex = rs_xform_scale(1, 3, 1);
    assert_false(rs_xform_is_similarity(&ex, &k));
    ex = rs_xform_scale(1, 0, 1);
    assert_non_null(rs_xform_invalid(&ex));
    assert_null(rs_xform_invalid(&trs));
    /* quarter turns are exact: no 6e-17 left where a 0 belongs */
    assert_true(r.m[0][0] == 0.0 && r.m[0][1] == -1.0 && r.m[1][0] == 1.0);
}

/* The mesh placement's rotations, as scenes/mesh.c computed them in float before it placed
 * meshes by rs_xform: about x, then y, then z, right-handed, in degrees.  Kept here as the
 * reference that rs_xform_rotate_euler has the same convention (order and signs). */
static rs_vec3 float_rotate_xyz(rs_vec3 p, rs_vec3 deg)
{
    const float k = 0.017453292519943295f;
    float cx = cosf(deg.x * k), sx = sinf(deg.x * k), cy = cosf(deg.y * k), sy = sinf(deg.y * k);
    float cz = cosf(deg.z * k), sz = sinf(deg.z * k);
    rs_vec3 a = rs_v3(p.x, cx * p.y - sx * p.z, sx * p.y + cx * p.z);
    rs_vec3 b = rs_v3(cy * a.x + sy * a.z, a.y, -sy * a.x + cy * a.z);
    return rs_v3(cz * b.x - sz * b.y, sz * b.x + cz * b.y, b.z);
}

/* rs_xform_rotate_euler(rx, ry, rz) is the mesh placement's rotation: the float reference above
 * agrees to float precision for angles of every sign and size (so a swapped order or a flipped
 * sign, which moves points by O(1), cannot pass); and Euler (90, 0, 90) is exactly the turn by
 * 120 degrees about (1, 1, 1), which cycles x -> y -> z -> x. */
static void test_euler_is_mesh_rotation(void **state)
{
    static const double d[3] = {1, 1, 1};
    static const float angles[][3] = {{30, 0, 0},   {0, 40, 0},        {0, 0, 50},
                                      {30, 45, 60}, {-75, 120, -10},   {200, -33, 91},
                                      {90, 0, 90},  {-17.5f, 63, 271}, {359, 1, -181}};
    static const float pts[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.3f, -1.7f, 2.2f}};
    rs_xform e, cyc;
    size_t a, i, j;
    (void)state;
    for (a = 0; a < sizeof angles / sizeof angles[0]; ++a) {
        rs_vec3 deg = rs_v3(angles[a][0], angles[a][1], angles[a][2]);
        e = rs_xform_rotate_euler(deg.x, deg.y, deg.z);
        assert_true(fabs(rs_xform_det(&e) - 1.0) < 1e-12);
        for (i = 0; i < sizeof pts / sizeof pts[0]; ++i) {
            rs_vec3 p = rs_v3(pts[i][0], pts[i][1], pts[i][2]);
            rs_vec3 want = float_rotate_xyz(p, deg), got = rs_xform_point(&e, p);
            if (rs_v3_length(rs_v3_sub(got, want)) > 2e-6f * (1.0f + rs_v3_length(p)))
                fail_msg("euler (%g, %g, %g) of (%g, %g, %g): (%.9g, %.9g, %.9g), the float "
                         "placement (%.9g, %.9g, %.9g)",
                         deg.x, deg.y, deg.z, p.x, p.y, p.z, got.x, got.y, got.z, want.x, want.y,
                         want.z);
        }
    }
    e = rs_xform_rotate_euler(90, 0, 90);
    cyc = rs_xform_rotate_axis(d, 120);
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            assert_true(e.m[i][j] == ((j + 1) % 3 == i ? 1.0 : 0.0)); /* exact quarter turns */
            assert_true(fabs(cyc.m[i][j] - e.m[i][j]) < 1e-15);
        }
}

/* rs_xform_normal is the inverse transpose, normalised, pointing the way the transformed surface
 * faces whatever det's sign: M = diag(2, 3, 5), then 120 degrees about (1, 1, 1), takes
 * n = (0.48, 0.64, 0.6) to R (0.24, 0.64/3, 0.12) = (0.12, 0.24, 0.64/3) over its length; the
 * mirror diag(-2, 3, 5) then R flips its first step's x.  It equals the vertex normal
 * rs_scene_transform_since stores, bit for bit (one computation for both). */
static void test_xform_normal(void **state)
{
    static const double d[3] = {1, 1, 1};
    rs_xform r = rs_xform_rotate_axis(d, 120), sc = rs_xform_scale(2, 3, 5);
    rs_xform mi = rs_xform_scale(-2, 3, 5), x = rs_xform_compose(&r, &sc);
    rs_xform xm = rs_xform_compose(&r, &mi);
    rs_vec3 n = rs_v3(0.48f, 0.64f, 0.6f), got, want;
    rs_vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const float nrm[9] = {0.48f, 0.64f, 0.6f, 0, 0, 1, 0, 0, 0};
    rs_scene_mark mark;
    rs_scene *t;
    int pass, k;
    double l;
    (void)state;
    l = sqrt(0.12 * 0.12 + 0.24 * 0.24 + (0.64 / 3) * (0.64 / 3));
    got = rs_xform_normal(&x, n);
    expect_v3(got, (float)(0.12 / l), (float)(0.24 / l), (float)(0.64 / 3 / l));
    got = rs_xform_normal(&xm, n);
    expect_v3(got, (float)(0.12 / l), (float)(-0.24 / l), (float)(0.64 / 3 / l));
    want = rs_xform_normal(&x, rs_v3(0, 0, 0));
    assert_true(want.x == 0 && want.y == 0 && want.z == 0);
    for (pass = 0; pass < 2; ++pass) {
        const rs_xform *xf = pass ? &xm : &x;
        rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
        uint32_t id;
        assert_int_equal(rs_scene_create("t", &t), RS_OK);
        assert_int_equal(rs_scene_add_material(t, &m, &id), RS_OK);
        mark = rs_scene_mark_now(t);
        assert_int_equal(rs_scene_add_triangle_full(t, v, NULL, nrm, id), RS_OK);
        assert_int_equal(rs_scene_transform_since(t, &mark, xf), RS_OK);
        /* a mirror swaps vertices 1 and 2 with their normals */
        for (k = 0; k < 3; ++k) {
            int from = pass && k ? 3 - k : k;
            want = rs_xform_normal(xf, rs_v3(nrm[3 * from], nrm[3 * from + 1], nrm[3 * from + 2]));
            assert_memory_equal(&t->tri_normal[3 * k], &want, 3 * sizeof(float));
        }
        rs_scene_destroy(t);
    }
}

/* Each primitive kind under a transform given as a matrix and as steps. */
static void test_objects_move(void **state)
{
    rs_scene *s;
    rs_vec3 n;
    (void)state;
    s = parse("{" CAM "," MATS ",\"objects\":["
              "{\"type\":\"sphere\",\"center\":[1,0,0],\"radius\":0.5,\"material\":\"m\","
              "\"transform\":[{\"scale\":2},{\"rotate\":{\"axis\":[0,0,1],\"degrees\":90}},"
              "{\"translate\":[0,0,3]}]},"
              "{\"type\":\"quad\",\"q\":[0,0,0],\"u\":[1,0,0],\"v\":[0,1,0],\"material\":\"m\","
              "\"transform\":{\"matrix\":[1,0,0,7, 0,1,0,8, 0,0,1,9, 0,0,0,1]}},"
              "{\"type\":\"triangle\",\"vertices\":[[0,0,0],[1,0,0],[0,1,0]],\"material\":\"m\","
              "\"transform\":{\"scale\":[1,2,3]}},"
              "{\"type\":\"box\",\"min\":[0,0,0],\"max\":[1,1,1],\"material\":\"m\","
              "\"transform\":{\"translate\":[-4,0,0]}}]}");
    assert_int_equal(s->n_spheres, 1u);
    expect_v3(s->spheres[0].center, 0, 2, 3);
    assert_true(fabsf(s->spheres[0].radius - 1.0f) < 1e-6f);
    expect_v3(s->quads[0].q, 7, 8, 9);
    expect_v3(s->quads[0].u, 1, 0, 0);
    expect_v3(s->tris[0].v1, 1, 0, 0);
    expect_v3(s->tris[0].v2, 0, 2, 0);
    /* the box's six quads moved together; its first (front, +z) face keeps its normal */
    assert_int_equal(s->n_quads, 7u);
    expect_v3(s->quads[1].q, -4, 0, 1);
    n = rs_v3_cross(s->quads[1].u, s->quads[1].v);
    assert_true(n.z > 0);
    rs_scene_destroy(s);
}

/* A mirror (scale x by -1) keeps outward normals: the box's +x face, now at x = -1, faces -x;
 * a triangle facing +z still faces +z, its vertex normals too. */
static void test_mirror_keeps_orientation(void **state)
{
    rs_scene *s;
    rs_vec3 n;
    uint32_t i;
    int found = 0;
    (void)state;
    s = parse("{" CAM "," MATS ",\"objects\":["
              "{\"type\":\"box\",\"min\":[0,0,0],\"max\":[1,1,1],\"material\":\"m\","
              "\"transform\":{\"scale\":[-1,1,1]}}]}");
    for (i = 0; i < s->n_quads; ++i) {
        rs_vec3 c = rs_v3_add(s->quads[i].q,
                              rs_v3_scale(rs_v3_add(s->quads[i].u, s->quads[i].v), 0.5f));
        n = rs_v3_normalize(rs_v3_cross(s->quads[i].u, s->quads[i].v));
        /* every face's normal points away from the box's centre (-0.5, 0.5, 0.5) */
        assert_true(rs_v3_dot(n, rs_v3_sub(c, rs_v3(-0.5f, 0.5f, 0.5f))) > 0.49f);
        if (fabsf(c.x + 1.0f) < 1e-6f) {
            expect_v3(n, -1, 0, 0);
            found = 1;
        }
    }
    assert_true(found);
    rs_scene_destroy(s);

    {
        /* vertex normals through the inverse transpose; a non-uniform scale bends them */
        rs_scene *t;
        rs_vec3 v[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
        const float nrm[9] = {0, 0, 1, 0.6f, 0, 0.8f, 0, 0, 1};
        rs_scene_mark mark;
        rs_xform x = rs_xform_scale(-2, 1, 1);
        assert_int_equal(rs_scene_create("t", &t), RS_OK);
        {
            rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
            uint32_t id;
            assert_int_equal(rs_scene_add_material(t, &m, &id), RS_OK);
            mark = rs_scene_mark_now(t);
            assert_int_equal(rs_scene_add_triangle_full(t, v, NULL, nrm, id), RS_OK);
        }
        assert_int_equal(rs_scene_transform_since(t, &mark, &x), RS_OK);
        n = rs_v3_cross(rs_v3_sub(t->tris[0].v1, t->tris[0].v0),
                        rs_v3_sub(t->tris[0].v2, t->tris[0].v0));
        assert_true(n.z > 0);
        /* vertex 1 moved to slot 2 with its normal: (0.6, 0, 0.8) -> (-0.3, 0, 0.8) normalised */
        expect_v3(t->tris[0].v2, -2, 0, 0);
        expect_v3(rs_v3(t->tri_normal[6], t->tri_normal[7], t->tri_normal[8]),
                  -0.3f / sqrtf(0.73f), 0, 0.8f / sqrtf(0.73f));
        expect_v3(rs_v3(t->tri_normal[0], t->tri_normal[1], t->tri_normal[2]), 0, 0, 1);
        rs_scene_destroy(t);
    }
}

/* Vertex normals go by the inverse transpose of the linear part.  M = S R: a quarter turn about
 * z, (x, y, z) -> (-y, x, z), then a scale by 2 along x.  Then M^-T = S^-1 R, so the normal
 * n = (0.48, 0.64, 0.6) goes to R n = (-0.64, 0.48, 0.6), then to (-0.32, 0.48, 0.6), over its
 * length sqrt(0.6928).  Wrong matrices give other directions: M itself (-1.28, 0.48, 0.6), M^-1
 * (the cofactor read transposed) (0.64, -0.24, 0.6), M^T (0.64, -0.96, 0.6); a diagonal scale
 * alone would not tell M^-T from M^-1.  The triangle lies across n, so its transformed face
 * normal must agree with the transformed vertex normals. */
static void test_normals_inverse_transpose(void **state)
{
    static const double z[3] = {0, 0, 1};
    const float n[3] = {0.48f, 0.64f, 0.6f};
    /* v1 = a across n, v2 = n x a: (v1 - v0) x (v2 - v0) = |a|^2 n */
    rs_vec3 v[3] = {{0, 0, 0}, {0.64f, -0.48f, 0}, {0.288f, 0.384f, -0.64f}};
    float nrm[9];
    rs_xform r = rs_xform_rotate_axis(z, 90), sc = rs_xform_scale(2, 1, 1);
    rs_xform x = rs_xform_compose(&sc, &r);
    rs_scene_mark mark;
    rs_scene *t;
    rs_vec3 face;
    const float k = 1.0f / sqrtf(0.6928f);
    int i;
    (void)state;
    for (i = 0; i < 9; ++i)
        nrm[i] = n[i % 3];
    assert_int_equal(rs_scene_create("t", &t), RS_OK);
    {
        rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
        uint32_t id;
        assert_int_equal(rs_scene_add_material(t, &m, &id), RS_OK);
        mark = rs_scene_mark_now(t);
        assert_int_equal(rs_scene_add_triangle_full(t, v, NULL, nrm, id), RS_OK);
    }
    /* the face normal before: along n */
    face = rs_v3_normalize(rs_v3_cross(rs_v3_sub(t->tris[0].v1, t->tris[0].v0),
                                       rs_v3_sub(t->tris[0].v2, t->tris[0].v0)));
    expect_v3(face, n[0], n[1], n[2]);
    assert_int_equal(rs_scene_transform_since(t, &mark, &x), RS_OK);
    /* the vertices by M: (0.64, -0.48, 0) -> (0.48, 0.64, 0) -> (0.96, 0.64, 0) */
    expect_v3(t->tris[0].v1, 0.96f, 0.64f, 0);
    face = rs_v3_normalize(rs_v3_cross(rs_v3_sub(t->tris[0].v1, t->tris[0].v0),
                                       rs_v3_sub(t->tris[0].v2, t->tris[0].v0)));
    expect_v3(face, -0.32f * k, 0.48f * k, 0.6f * k);
    for (i = 0; i < 3; ++i)
        expect_v3(rs_v3(t->tri_normal[3 * i], t->tri_normal[3 * i + 1], t->tri_normal[3 * i + 2]),
                  -0.32f * k, 0.48f * k, 0.6f * k);
    rs_scene_destroy(t);
}

/* The instanced scene and the same objects written out give the same image bit for bit.  The
 * transforms are exact in binary (quarter turns, powers of two, small translations), so that
 * composing the instance's and the object's steps in either grouping gives the same matrix. */
#define ROW_OBJS(T)                                                                                \
  "{\"type\":\"sphere\",\"center\":[0,0.5,0],\"radius\":0.5,\"material\":\"m\",\"transform\":[" T  \
  "]},"                                                                                            \
  "{\"type\":\"box\",\"min\":[-0.5,0,-0.5],\"max\":[0.5,0.75,0.5],\"material\":\"m\","             \
  "\"transform\":[{\"translate\":[1.5,0,0]}" T "]},"                                               \
  "{\"type\":\"triangle\",\"vertices\":[[0,0,0],[1,0,0],[0,1,0]],\"material\":\"m\","              \
  "\"transform\":[{\"rotate\":[0,90,0]}" T "]}"

static void test_instances_equal_flattened(void **state)
{
    /* group "row" (three objects) placed by group "pair" twice; the scene places "pair" twice */
    const char *inst =
        "{" CAM "," MATS ",\"groups\":{"
        "\"row\":[" ROW_OBJS("") "],"
        "\"pair\":[{\"type\":\"instance\",\"group\":\"row\"},"
        "{\"type\":\"instance\",\"group\":\"row\",\"transform\":[{\"scale\":0.5},"
        "{\"rotate\":{\"axis\":[0,1,0],\"degrees\":180}},{\"translate\":[0,1,0]}]}]},"
        "\"objects\":[{\"type\":\"quad\",\"q\":[-1,3,-1],\"u\":[2,0,0],\"v\":[0,0,2],"
        "\"material\":\"l\"},"
        "{\"type\":\"instance\",\"group\":\"pair\",\"transform\":{\"translate\":[-2,0,0]}},"
        "{\"type\":\"instance\",\"group\":\"pair\",\"transform\":[{\"rotate\":[0,0,90]},"
        "{\"translate\":[2,-1,0]}]}]}";
#define P1 ",{\"translate\":[-2,0,0]}"
#define P2 ",{\"rotate\":[0,0,90]},{\"translate\":[2,-1,0]}"
#define HALF ",{\"scale\":0.5},{\"rotate\":{\"axis\":[0,1,0],\"degrees\":180}},{\"translate\":[0,1,0]}"
    const char *flat = "{" CAM "," MATS ",\"objects\":[{\"type\":\"quad\",\"q\":[-1,3,-1],"
                       "\"u\":[2,0,0],\"v\":[0,0,2],\"material\":\"l\"},"
                       ROW_OBJS(P1) "," ROW_OBJS(HALF P1) "," ROW_OBJS(P2) "," ROW_OBJS(HALF P2)
                       "]}";
    rs_scene *a, *b;
    rt_args args = rt_defaults("", 24, 8);
    float *ia, *ib;
    (void)state;
    /* the leading commas of the flattened steps: strip "[," */
    {
        char *f = strdup(flat), *p;
        while ((p = strstr(f, "[,{")) != NULL)
            memmove(p + 1, p + 2, strlen(p + 2) + 1);
        a = parse(inst);
        b = parse(f);
        free(f);
    }
    assert_int_equal(a->n_spheres, 4u);
    assert_int_equal(a->n_quads, 1u + 4u * 6u);
    assert_int_equal(a->n_tris, 4u);
    assert_int_equal(b->n_spheres, a->n_spheres);
    assert_int_equal(b->n_quads, a->n_quads);
    assert_int_equal(b->n_tris, a->n_tris);
    assert_memory_equal(a->spheres, b->spheres, a->n_spheres * sizeof *a->spheres);
    assert_memory_equal(a->quads, b->quads, a->n_quads * sizeof *a->quads);
    assert_memory_equal(a->tris, b->tris, a->n_tris * sizeof *a->tris);
    ia = rt_render_scene(a, &args, NULL);
    ib = rt_render_scene(b, &args, NULL);
    assert_non_null(ia);
    assert_non_null(ib);
    assert_memory_equal(ia, ib, 24 * 24 * 3 * sizeof(float));
    {
        /* and the picture is not empty: the light and the objects show */
        double sum = 0;
        int i;
        for (i = 0; i < 24 * 24 * 3; ++i)
            sum += ia[i];
        assert_true(sum > 1.0);
    }
    free(ia);
    free(ib);
    rs_scene_destroy(a);
    rs_scene_destroy(b);
}

static rs_status load_in(const char *dir, const char *json, rs_scene **s)
{
    char path[512];
    snprintf(path, sizeof path, "%s/scene.json", dir);
    write_file(path, json);
    *s = NULL;
    return rs_scene_load_json(path, s);
}

/* A mesh object: an OBJ with two materials next to the scene file, named relatively. */
static void test_mesh_objects(void **state)
{
    char dir[] = "/tmp/rs_xf_XXXXXX", p[512], *log_text = NULL;
    rs_scene *s;
    size_t log_len = 0;
    FILE *log;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(p, sizeof p, "%s/two.mtl", dir);
    write_file(p, "newmtl red\nKd 0.8 0.1 0.1\nnewmtl blue\nKd 0.1 0.1 0.8\n");
    snprintf(p, sizeof p, "%s/two.obj", dir);
    write_file(p, "mtllib two.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                  "usemtl red\nf 1 2 3\nusemtl blue\nf 2 4 3\n");

    /* its own materials */
    assert_int_equal(load_in(dir, "{" CAM "," MATS ",\"objects\":[{\"type\":\"mesh\","
                                  "\"file\":\"two.obj\"}]}", &s), RS_OK);
    assert_int_equal(s->n_tris, 2u);
    assert_true(s->n_materials >= 2u + 2u); /* Assimp may add its default material */
    assert_int_not_equal(s->tri_mat[0], s->tri_mat[1]);
    assert_true(s->materials[s->tri_mat[0]].albedo.x > 0.7f);
    assert_true(s->materials[s->tri_mat[1]].albedo.z > 0.7f);
    rs_scene_destroy(s);

    /* one replaced by name, placed twice by instances, moved: the file is read once (one log
     * line) and each copy carries its transform */
    snprintf(p, sizeof p, "%s/log.txt", dir);
    log = fopen(p, "w+");
    assert_non_null(log);
    {
        const char *json =
            "{" CAM "," MATS ",\"groups\":{\"g\":[{\"type\":\"mesh\",\"file\":\"two.obj\","
            "\"materials\":{\"blue\":\"m\"}}]},\"objects\":["
            "{\"type\":\"instance\",\"group\":\"g\"},"
            "{\"type\":\"instance\",\"group\":\"g\",\"transform\":{\"translate\":[0,0,5]}}]}";
        char path[512];
        snprintf(path, sizeof path, "%s/scene.json", dir);
        write_file(path, json);
        assert_int_equal(rs_scene_load_json_ex(path, log, &s), RS_OK);
    }
    /* a group of triangles: one shared prototype of 2, placed twice (numbers 0..3) */
    assert_int_equal(s->n_tris, 0u);
    assert_int_equal(s->n_inst_tris, 2u);
    assert_int_equal(s->n_instances, 2u);
    /* red from the file (and maybe Assimp's default); blue is the scene's m, id 0 */
    assert_true(s->n_materials >= 3u);
    assert_int_equal(s->inst_tri_mat[1], 0u);
    assert_ptr_equal(rs_scene_prim_material(s, 3), &s->materials[0]);
    assert_ptr_equal(rs_scene_prim_material(s, 0), rs_scene_prim_material(s, 2));
    expect_v3(rs_scene_tri(s, 2).v0, 0, 0, 5);
    expect_v3(rs_scene_tri(s, 0).v0, 0, 0, 0);
    /* flattened: the same four triangles, in the same order */
    {
        rs_tri t[4];
        uint32_t i;
        for (i = 0; i < 4; ++i)
            t[i] = rs_scene_tri(s, i);
        assert_int_equal(rs_scene_flatten_instances(s), RS_OK);
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        assert_int_equal(s->n_tris, 4u);
        assert_int_equal(s->n_instances, 0u);
        assert_memory_equal(s->tris, t, sizeof t);
        assert_int_equal(s->tri_mat[1], 0u);
        assert_int_equal(s->tri_mat[3], 0u);
    }
    rs_scene_destroy(s);
    log_len = (size_t)ftell(log);
    rewind(log);
    log_text = (char *)calloc(1, log_len + 1);
    assert_int_equal(fread(log_text, 1, log_len, log), log_len);
    fclose(log);
    print_message("log: %s", log_text);
    assert_non_null(strstr(log_text, "two.obj: 2 triangles, 1 material from the file"));
    /* the file read once (one import line), then one line for the group placed twice */
    assert_non_null(strstr(log_text, "group 'g': 2 triangles placed 2 times (instanced"));
    {
        size_t lines = 0, i;
        for (i = 0; i < log_len; ++i)
            lines += log_text[i] == '\n';
        assert_int_equal(lines, 2);
    }
    free(log_text);

    /* a replacement the file does not have names the ones it has */
    rs_error_clear();
    assert_int_equal(load_in(dir, "{" CAM "," MATS ",\"objects\":[{\"type\":\"mesh\","
                                  "\"file\":\"two.obj\",\"materials\":{\"green\":\"m\"}}]}", &s),
                     RS_ERR_ARG);
    assert_null(s);
    print_message("%s\n", rs_error_message());
    assert_non_null(strstr(rs_error_message(), "objects[0]"));
    assert_non_null(strstr(rs_error_message(), "no material named 'green'"));
    assert_non_null(strstr(rs_error_message(), "'red', 'blue'"));
    rs_error_clear();

    /* fitted, then moved */
    assert_int_equal(load_in(dir, "{" CAM "," MATS ",\"objects\":[{\"type\":\"mesh\","
                                  "\"file\":\"two.obj\",\"material\":\"m\",\"fit\":{\"size\":4,"
                                  "\"base\":[0,0,0]},\"transform\":{\"translate\":[0,1,0]}}]}", &s),
                     RS_OK);
    expect_v3(s->tris[0].v0, -2, 1, 0);
    expect_v3(s->tris[1].v1, 2, 5, 0);
    rs_scene_destroy(s);

    remove_in(dir, "two.mtl");
    remove_in(dir, "two.obj");
    remove_in(dir, "log.txt");
    remove_in(dir, "scene.json");
    rmdir(dir);
}

/* Lights in scene files: moved by their transform (a point's position; a spot's and a directional
 * light's direction by the linear part, normalised), copied by instances; and a scene written by
 * rs_scene_export_json reads back the same, vertex normals, UVs and lights included. */
static void test_lights_and_export(void **state)
{
    const char *json =
        "{" CAM "," MATS ",\"groups\":{\"lamp\":["
        "{\"type\":\"point_light\",\"position\":[0,1,0],\"intensity\":[3,2,1]},"
        "{\"type\":\"spot_light\",\"position\":[0,2,0],\"direction\":[0,-1,0],"
        "\"intensity\":[5,5,5],\"inner\":10,\"outer\":30}]},"
        "\"objects\":[{\"type\":\"instance\",\"group\":\"lamp\","
        "\"transform\":{\"translate\":[4,0,0]}},"
        "{\"type\":\"instance\",\"group\":\"lamp\",\"transform\":{\"rotate\":[90,0,0]}},"
        "{\"type\":\"directional_light\",\"direction\":[0,0,-2],\"irradiance\":[1,1,1],"
        "\"transform\":{\"rotate\":{\"axis\":[0,1,0],\"degrees\":90}}},"
        "{\"type\":\"triangle\",\"vertices\":[[0,0,0],[1,0,0],[0,1,0]],\"uv\":[0,0,1,0,0,1],"
        "\"normals\":[0,0,1,0.6,0,0.8,0,0,1],\"material\":\"m\"}]}";
    char dir[] = "/tmp/rs_exp_XXXXXX", path[256];
    rs_scene *s = parse(json), *t = NULL;
    (void)state;
    assert_int_equal(s->n_punctuals, 5u);
    expect_v3(s->punctuals[0].pos, 4, 1, 0);
    expect_v3(s->punctuals[1].pos, 4, 2, 0);
    expect_v3(s->punctuals[1].dir, 0, -1, 0);
    /* 90 degrees about x takes +y to +z */
    expect_v3(s->punctuals[2].pos, 0, 0, 1);
    expect_v3(s->punctuals[3].dir, 0, 0, -1);
    /* 90 degrees about y takes -z to -x; the direction is normalised */
    expect_v3(s->punctuals[4].dir, -1, 0, 0);
    assert_true(fabsf(s->punctuals[1].cos_inner - cosf(10 * 0.0174532925f)) < 1e-6f);
    assert_true(s->n_lights == 5u && s->n_area_lights == 0u);
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/out.json", dir);
    assert_int_equal(rs_scene_export_json(s, path), RS_OK);
    assert_int_equal(rs_scene_load_json(path, &t), RS_OK);
    assert_int_equal(t->n_tris, 1u);
    assert_memory_equal(t->tris, s->tris, sizeof *s->tris);
    assert_memory_equal(t->tri_uv, s->tri_uv, 6 * sizeof(float));
    assert_memory_equal(t->tri_normal, s->tri_normal, 9 * sizeof(float));
    assert_int_equal(t->n_punctuals, 5u);
    {
        uint32_t i;
        for (i = 0; i < 5; ++i) {
            assert_int_equal(t->punctuals[i].type, s->punctuals[i].type);
            assert_memory_equal(&t->punctuals[i].pos, &s->punctuals[i].pos, sizeof(rs_vec3));
            assert_memory_equal(&t->punctuals[i].dir, &s->punctuals[i].dir, sizeof(rs_vec3));
            assert_memory_equal(&t->punctuals[i].intensity, &s->punctuals[i].intensity,
                                sizeof(rs_vec3));
            /* the cone goes through degrees: within a float ulp or two */
            assert_true(fabsf(t->punctuals[i].cos_outer - s->punctuals[i].cos_outer) < 1e-6f);
        }
    }
    rs_scene_destroy(t);
    rs_scene_destroy(s);
    remove(path);
    rmdir(dir);
}

/* Ten groups, each ten instances of the next, around one box: 6 * 10^10 quads if copied.  The
 * reader stops at its budget with one line, in well under a second here. */
static void test_instance_budget(void **state)
{
    char json[8192];
    size_t n = 0;
    int g, k;
    rs_scene *s = (rs_scene *)0x1;
    (void)state;
    n += (size_t)snprintf(json + n, sizeof json - n, "{" CAM "," MATS ",\"groups\":{");
    for (g = 0; g < 10; ++g) {
        n += (size_t)snprintf(json + n, sizeof json - n, "\"g%d\":[", g);
        for (k = 0; k < 10; ++k)
            n += (size_t)snprintf(json + n, sizeof json - n,
                                  "%s{\"type\":\"instance\",\"group\":\"g%d\"}", k ? "," : "",
                                  g + 1);
        n += (size_t)snprintf(json + n, sizeof json - n, "],");
    }
    n += (size_t)snprintf(json + n, sizeof json - n,
                          "\"g10\":[{\"type\":\"box\",\"min\":[0,0,0],\"max\":[1,1,1],"
                          "\"material\":\"m\"}]},\"objects\":[{\"type\":\"instance\","
                          "\"group\":\"g0\"}]}");
    rs_error_clear();
    assert_int_equal(rs_scene_parse_json(json, n, "t.json", NULL, &s), RS_ERR_ARG);
    assert_null(s);
    print_message("%s\n", rs_error_message());
    assert_non_null(strstr(rs_error_message(), "would pass"));
    rs_error_clear();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_steps_compose_in_order),
        cmocka_unit_test(test_euler_is_mesh_rotation),
        cmocka_unit_test(test_xform_normal),
        cmocka_unit_test(test_objects_move),
        cmocka_unit_test(test_mirror_keeps_orientation),
        cmocka_unit_test(test_normals_inverse_transpose),
        cmocka_unit_test(test_instances_equal_flattened),
        cmocka_unit_test(test_mesh_objects),
        cmocka_unit_test(test_lights_and_export),
        cmocka_unit_test(test_instance_budget),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
