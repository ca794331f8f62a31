/* tests/scenes_mesh_test.c — mesh import through Assimp: placement (scale, rotations, translation,
 * fit), UVs and normals kept, OBJ / PLY / glTF read; malformed files (truncated, out-of-range
 * indices, NaN coordinates, empty, not a mesh) give an error naming the file or drop and count
 * the bad faces — never a crash; the shared test models load with their known triangle counts,
 * and the BVH over each gives brute force's closest hits.  The models are read from
 * ../shared/models (or $RS_MODELS_DIR); without them those cases skip with a printed reason. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "accel/bvh.h"
#include "scenes/builtin.h"
#include "scenes/mesh.h"
#include "scenes/ply_strips.h"
#include "test_files.h"
#include "test_rand.h"

#ifndef RS_SOURCE_DIR
#  define RS_SOURCE_DIR "."
#endif
#define DATA RS_SOURCE_DIR "/tests/data/"

static rs_scene *new_scene(uint32_t *mat)
{
    rs_scene *s;
    rs_material m = rs_mat_lambertian(rs_v3(.5f, .5f, .5f));
    assert_int_equal(rs_scene_create("mesh", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &m, mat), RS_OK);
    return s;
}

static int near(float a, float b) { return fabsf(a - b) <= 1e-5f * (1.0f + fabsf(b)); }

static void test_obj_placement_uv_normals(void **state)
{
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const rs_tri *t;
    (void)state;
    /* (x, y, z) -> scale (2, 3, 4) -> rotate 90 deg about y: (x, y, z) -> (z, y, -x) -> +10 x */
    o.scale = rs_v3(2, 3, 4);
    o.rotate_deg = rs_v3(0, 90, 0);
    o.translate = rs_v3(10, 0, 0);
    assert_int_equal(rs_scene_add_mesh(s, DATA "tri.obj", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    assert_int_equal(info.dropped, 0u);
    t = &s->tris[0];
    /* v1 = (1,0,0) -> (2,0,0) -> (0,0,-2) -> (10,0,-2); v2 = (0,1,0) -> (0,3,0) -> (10,3,0);
     * exactly: quarter turns are exact (rs_xform_rotate_euler) and the rest is exact in binary */
    assert_true(t->v0.x == 10 && t->v0.y == 0 && t->v0.z == 0);
    assert_true(t->v1.x == 10 && t->v1.y == 0 && t->v1.z == -2);
    assert_true(t->v2.x == 10 && t->v2.y == 3 && t->v2.z == 0);
    assert_non_null(s->tri_uv);
    assert_true(near(s->tri_uv[2], 1) && near(s->tri_uv[3], 0) && near(s->tri_uv[5], 1));
    /* the normal (0,0,1) scales by 1/4 and rotates to (1,0,0) (then renormalised) */
    assert_non_null(s->tri_normal);
    assert_true(s->tri_normal[0] == 1 && s->tri_normal[1] == 0 && s->tri_normal[2] == 0);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    rs_scene_destroy(s);
}

/* The placement's normals go by the inverse transpose, with a normal that is not along an axis:
 * scale (2, 1, 1), then a quarter turn about z, (x, y, z) -> (-y, x, z), is M = R S, and
 * M^-T = R S^-1 takes n = (0.48, 0.64, 0.6) to R (0.24, 0.64, 0.6) = (-0.64, 0.24, 0.6), over
 * its length sqrt(0.8272).  The plain matrix would give R (0.96, 0.64, 0.6) = (-0.64, 0.96, 0.6)
 * and M^-1 = S^-1 R^T gives (0.32, -0.48, 0.6), while a normal along an axis (as above) cannot
 * tell them apart.  The triangle lies across n: its placed face normal agrees. */
static void test_obj_normals_inverse_transpose(void **state)
{
    char dir[] = "/tmp/rs_nrm_XXXXXX", path[256];
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const float k = 1.0f / sqrtf(0.8272f);
    const rs_tri *t;
    rs_vec3 face;
    int i;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/tilted.obj", dir);
    /* v1 - v0 = a across n, v2 - v0 = n x a */
    write_file(path, "v 0 0 0\nv 0.64 -0.48 0\nv 0.288 0.384 -0.64\nvn 0.48 0.64 0.6\n"
                     "f 1//1 2//1 3//1\n");
    o.scale = rs_v3(2, 1, 1);
    o.rotate_deg = rs_v3(0, 0, 90);
    assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    assert_non_null(s->tri_normal);
    t = &s->tris[0];
    /* v1: (0.64, -0.48, 0) -> (1.28, -0.48, 0) -> (0.48, 1.28, 0) */
    assert_true(near(t->v1.x, 0.48f) && near(t->v1.y, 1.28f) && near(t->v1.z, 0));
    face = rs_v3_normalize(rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0)));
    for (i = 0; i < 3; ++i) {
        const float *nv = &s->tri_normal[3 * i];
        if (!(near(nv[0], -0.64f * k) && near(nv[1], 0.24f * k) && near(nv[2], 0.6f * k)))
            fail_msg("vertex %d's normal (%g, %g, %g), want (%g, %g, %g)", i, nv[0], nv[1], nv[2],
                     -0.64f * k, 0.24f * k, 0.6f * k);
        assert_true(rs_v3_dot(face, rs_v3(nv[0], nv[1], nv[2])) > 1.0f - 1e-5f);
    }
    rs_scene_destroy(s);
    remove(path);
    rmdir(dir);
}

/* The corners of test_placement_nonaxis's triangle (as its OBJ writes them). */
static const float nonaxis_v[3][3] = {{1, 2, 3}, {2, 2, 3}, {1, 3, 3}};

/* The placement is scale, then rotations about x, y, z, then the translation, in double and
 * rounded once.  Scale (2, 3, 5), rotations (90, 0, 90) (together the turn by 120 degrees about
 * (1, 1, 1): (x, y, z) -> (z, x, y)), translation (10, 20, 30): (1, 2, 3) -> (2, 6, 15) ->
 * (15, 2, 6) -> (25, 22, 36), exactly; (2, 2, 3) -> (25, 24, 36); (1, 3, 3) -> (25, 22, 39).
 * The normal n = (0.48, 0.64, 0.6) goes by M^-T = R S^-1: (0.24, 0.64/3, 0.12) ->
 * (0.12, 0.24, 0.64/3), normalised.  Then rotations (30, 45, 60), not quarter turns, against
 * the rotation written out in double here: each coordinate within one float ulp of it. */
static void test_placement_nonaxis(void **state)
{
    static const double deg[3] = {30, 45, 60};
    char dir[] = "/tmp/rs_place_XXXXXX", path[256];
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const rs_tri *t;
    double l = sqrt(0.12 * 0.12 + 0.24 * 0.24 + (0.64 / 3) * (0.64 / 3));
    int i, j;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/tri.obj", dir);
    write_file(path, "v 1 2 3\nv 2 2 3\nv 1 3 3\nvn 0.48 0.64 0.6\nf 1//1 2//1 3//1\n");
    o.scale = rs_v3(2, 3, 5);
    o.rotate_deg = rs_v3(90, 0, 90);
    o.translate = rs_v3(10, 20, 30);
    assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    t = &s->tris[0];
    assert_true(t->v0.x == 25 && t->v0.y == 22 && t->v0.z == 36);
    assert_true(t->v1.x == 25 && t->v1.y == 24 && t->v1.z == 36);
    assert_true(t->v2.x == 25 && t->v2.y == 22 && t->v2.z == 39);
    assert_true(info.bounds.lo.y == 22 && info.bounds.hi.z == 39);
    for (i = 0; i < 3; ++i) {
        const float *nv = &s->tri_normal[3 * i];
        if (!(fabs(nv[0] - 0.12 / l) < 1e-7 && fabs(nv[1] - 0.24 / l) < 1e-7 &&
              fabs(nv[2] - 0.64 / 3 / l) < 1e-7))
            fail_msg("vertex %d's normal (%.9g, %.9g, %.9g), want (%.9g, %.9g, %.9g)", i, nv[0],
                     nv[1], nv[2], 0.12 / l, 0.24 / l, 0.64 / 3 / l);
    }

    o.rotate_deg = rs_v3((float)deg[0], (float)deg[1], (float)deg[2]);
    assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
    t = &s->tris[1];
    for (i = 0; i < 3; ++i) {
        const float *v = nonaxis_v[i];
        const rs_vec3 *pv = i == 0 ? &t->v0 : i == 1 ? &t->v1 : &t->v2;
        const float got[3] = {pv->x, pv->y, pv->z};
        double p[3] = {2.0 * v[0], 3.0 * v[1], 5.0 * v[2]}, q[3];
        double c[3], sn[3];
        for (j = 0; j < 3; ++j) {
            c[j] = cos(deg[j] * (3.14159265358979323846 / 180));
            sn[j] = sin(deg[j] * (3.14159265358979323846 / 180));
        }
        /* about x, then y, then z: right-handed */
        q[0] = p[0];
        q[1] = c[0] * p[1] - sn[0] * p[2];
        q[2] = sn[0] * p[1] + c[0] * p[2];
        p[0] = c[1] * q[0] + sn[1] * q[2];
        p[1] = q[1];
        p[2] = -sn[1] * q[0] + c[1] * q[2];
        q[0] = c[2] * p[0] - sn[2] * p[1] + 10;
        q[1] = sn[2] * p[0] + c[2] * p[1] + 20;
        q[2] = p[2] + 30;
        for (j = 0; j < 3; ++j)
            if (!(fabs(got[j] - q[j]) <= ldexp(1.0, ilogb(q[j]) - 23)))
                fail_msg("vertex %d coordinate %d: %.9g, want %.12g (within an ulp)", i, j, got[j],
                         q[j]);
    }
    rs_scene_destroy(s);
    remove(path);
    rmdir(dir);
}

/* A negative scale mirrors: the face keeps its outward side (its corners 1 and 2 swapped, with
 * their UVs and normals), as the scene file's transforms keep it, and agrees with its vertex
 * normals.  tri.obj faces +z; scale (-1, 1, 1) keeps it facing +z. */
static void test_placement_mirror(void **state)
{
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const rs_tri *t;
    rs_vec3 face;
    int i;
    (void)state;
    o.scale = rs_v3(-1, 1, 1);
    assert_int_equal(rs_scene_add_mesh(s, DATA "tri.obj", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    t = &s->tris[0];
    /* the file's (1,0,0) -> (-1,0,0), now the third corner; (0,1,0) the second */
    assert_true(t->v1.x == 0 && t->v1.y == 1 && t->v2.x == -1 && t->v2.y == 0);
    assert_true(s->tri_uv[2] == 0 && s->tri_uv[3] == 1 && s->tri_uv[4] == 1 && s->tri_uv[5] == 0);
    face = rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0));
    assert_true(face.z > 0);
    for (i = 0; i < 3; ++i)
        assert_true(s->tri_normal[3 * i] == 0 && s->tri_normal[3 * i + 1] == 0 &&
                    s->tri_normal[3 * i + 2] == 1);
    rs_scene_destroy(s);
}

/* A placement that cannot be one is refused before the file is read, the message unchanged. */
static void test_placement_refused(void **state)
{
    static const float bad[][3] = {{0, 1, 1}, {1, 1, -0.0f}, {NAN, 1, 1}, {1, INFINITY, 1}};
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    size_t i;
    (void)state;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        o.scale = rs_v3(bad[i][0], bad[i][1], bad[i][2]);
        rs_error_clear();
        assert_int_equal(rs_scene_add_mesh(s, DATA "tri.obj", &o, &info), RS_ERR_ARG);
        assert_string_equal(rs_error_message(), DATA "tri.obj: scale must be finite and non-zero");
    }
    assert_int_equal(s->n_tris, 0u);
    rs_scene_destroy(s);
}

/* A mesh placed by nothing is stored as the file has it, bit for bit as the float placement by
 * the identity stored it (so that unplaced meshes and glTF nodes render as they did): a -0
 * coordinate as +0, and a normal's zero signs as the rotations by 0 degrees left them
 * ((1, -0, -0) -> (1, +0, -0): core/sampling.h's basis reads the sign of n.z). */
static void test_unplaced_as_stored(void **state)
{
    char dir[] = "/tmp/rs_ident_XXXXXX", path[256];
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    const rs_tri *t;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/tri.obj", dir);
    write_file(path, "v -0 0.1 -0\nv 0.7 -0 0.3\nv 0.2 0.9 -0.4\nvn 1 -0 -0\nvn 0 0.6 0.8\n"
                     "vn -0 -0.6 -0.8\nf 1//1 2//2 3//3\n");
    assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    t = &s->tris[0];
    assert_true(t->v0.x == 0 && !signbit(t->v0.x) && t->v0.y == 0.1f && !signbit(t->v0.z));
    assert_true(t->v1.x == 0.7f && !signbit(t->v1.y) && t->v1.z == 0.3f);
    assert_true(t->v2.x == 0.2f && t->v2.y == 0.9f && t->v2.z == -0.4f);
    assert_true(s->tri_normal[0] == 1 && !signbit(s->tri_normal[1]) && signbit(s->tri_normal[2]));
    rs_scene_destroy(s);
    remove(path);
    rmdir(dir);
}

static void test_ply_and_gltf(void **state)
{
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    (void)state;
    assert_int_equal(rs_scene_add_mesh(s, DATA "cube.ply", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 12u); /* 6 quads, triangulated */
    assert_true(near(info.bounds.lo.x, 0) && near(info.bounds.hi.y, 1) &&
                near(info.bounds.hi.z, 1));
    /* glTF: the node's translation (0, 0, 2) is baked into the vertices */
    assert_int_equal(rs_scene_add_mesh(s, DATA "tri.gltf", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    assert_true(near(info.bounds.lo.z, 2) && near(info.bounds.hi.z, 2));
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    rs_scene_destroy(s);
}

static void test_fit(void **state)
{
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    (void)state;
    o.fit = 1;
    o.fit_size = 300.0f;
    o.fit_base = rs_v3(278, 0, 278);
    assert_int_equal(rs_scene_add_mesh(s, DATA "cube.ply", &o, &info), RS_OK);
    assert_true(near(info.bounds.hi.x - info.bounds.lo.x, 300));
    assert_true(near(info.bounds.lo.y, 0));
    assert_true(near(0.5f * (info.bounds.lo.x + info.bounds.hi.x), 278));
    assert_true(near(0.5f * (info.bounds.lo.z + info.bounds.hi.z), 278));
    rs_scene_destroy(s);
}

/* Bad files: an error whose one-line message names the file, or dropped faces counted. */
static void test_malformed(void **state)
{
    /* cut_body.ply and bad_number.ply: found by tests/fuzz/fuzz_mesh (Assimp aborted on the
     * first, leaked on the second) */
    /* empty_face.ply too: Assimp's PLY reader makes faces without indices from face lines it
     * cannot read (and from "0"), and its post-processing crashed (SIGBUS) on them;
     * strips_no_triangle.ply: a strip file whose strips make no triangle, which the fuzzer found
     * handed to Assimp's release (an alloc-dealloc mismatch under ASan) */
    static const char *const errors[] = {"truncated.ply",          "cut_body.ply",
                                         "bad_number.ply",         "face_past_vertices.ply",
                                         "empty_face.ply",         "mostly_bad.obj",
                                         "strips_no_triangle.ply",
                                         "bad_index.obj",          "empty.obj",
                                         "garbage.obj",            "missing.obj",
                                         ""};
    uint32_t mat;
    rs_scene *s = new_scene(&mat);
    rs_mesh_opts o = rs_mesh_opts_default(mat);
    rs_mesh_info info;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof errors / sizeof errors[0]; ++k) {
        char path[512];
        rs_status st;
        snprintf(path, sizeof path, DATA "%s", errors[k]);
        rs_error_clear();
        st = rs_scene_add_mesh(s, path, &o, &info);
        if (st == RS_OK)
            fail_msg("%s imported without an error", path);
        assert_true(st == RS_ERR_ARG || st == RS_ERR_IO);
        assert_non_null(strstr(rs_error_message(), path));
        assert_null(strchr(rs_error_message(), '\n'));
        print_message("%s -> %s\n", errors[k][0] ? errors[k] : "(a folder)", rs_error_message());
    }
    rs_error_clear();
    /* a NaN vertex: its face is dropped and counted, the good one kept */
    assert_int_equal(rs_scene_add_mesh(s, DATA "nan.obj", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    assert_int_equal(info.dropped, 1u);
    assert_int_equal(info.dropped_nonfinite, 1u);
    assert_int_equal(info.dropped_index + info.dropped_area + info.dropped_shape, 0u);
    {
        char why[160];
        assert_string_equal(rs_mesh_dropped_text(&info, why, sizeof why),
                            "1 faces dropped (1 non-finite vertex)");
    }
    /* strips: decoded (Assimp reads none and made one triangle of the file) */
    rs_error_clear();
    assert_int_equal(rs_scene_add_mesh(s, DATA "tristrips.ply", &o, &info), RS_OK);
    assert_int_equal(info.triangles, 2u);
    assert_int_equal(info.strips, 1u);
    /* more faces lost than kept: an error with the counts by reason */
    rs_error_clear();
    assert_int_equal(rs_scene_add_mesh(s, DATA "mostly_bad.obj", &o, &info), RS_ERR_ARG);
    assert_non_null(strstr(rs_error_message(), "3 faces dropped (1 non-finite vertex, 2 zero area)"));
    rs_error_clear();
    /* a truncated OBJ: either its good face survives or the file is refused; never a crash */
    if (rs_scene_add_mesh(s, DATA "truncated.obj", &o, &info) == RS_OK)
        assert_int_equal(info.triangles, 1u);
    else
        assert_non_null(strstr(rs_error_message(), "truncated.obj"));
    rs_error_clear();
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    rs_scene_destroy(s);
}

/* Imports `path` with the file's own materials and expects an error whose one-line message
 * has `a` and `b`. */
static void expect_mesh_error(const char *path, const char *a, const char *b)
{
    rs_scene *s;
    rs_mesh_opts o = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    rs_mesh_info info;
    rs_status st;
    assert_int_equal(rs_scene_create("kinds", &s), RS_OK);
    rs_error_clear();
    st = rs_scene_add_mesh(s, path, &o, &info);
    if (st == RS_OK)
        fail_msg("%s imported without an error", path);
    assert_true(st == RS_ERR_ARG || st == RS_ERR_IO);
    print_message("  %s -> %s\n", path, rs_error_message());
    assert_null(strchr(rs_error_message(), '\n'));
    if (!strstr(rs_error_message(), a) || (b && !strstr(rs_error_message(), b)))
        fail_msg("message '%s' lacks '%s' or '%s'", rs_error_message(), a, b ? b : "");
    rs_error_clear();
    rs_scene_destroy(s);
}

#define TRI_OBJ "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl mat\nf 1/1 2/2 3/3\n"

/* Every file an import opens is a regular file of a sane size, or the import fails naming it:
 * the mesh itself, an OBJ's mtllib and its map_Kd texture, each as a FIFO (its open would
 * block), /dev/zero (through a symlink: never ends), a folder; a sparse 5 GiB mesh.  A missing
 * MTL or texture is still only a default material or a warning, as before.  alarm() turns a
 * regression (a hang) into a failure. */
static void test_file_kinds(void **state)
{
    char dir[] = "/tmp/rs_mesh_XXXXXX", p[256], obj[256], mtl[256];
    static const struct {
        const char *mtllib, *words;
    } libs[] = {{"fifo.mtl", "not a regular file"},
                {"zero.mtl", "not a regular file"},
                {"sub", "is a folder"}};
    static const struct {
        const char *map, *words;
    } maps[] = {{"fifo.png", "not a regular file"},
                {"/dev/zero", "not a regular file"},
                {"sub", "is a folder"}};
    rs_scene *s;
    rs_mesh_opts o = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    static const char *const names[] = {"fifo.mtl", "fifo.png", "fifo.obj", "zero.mtl",
                                        "zero.obj", "big.obj",  "m.obj",    "m.mtl"};
    rs_mesh_info info;
    char text[512];
    int fd;
    size_t k;
    (void)state;
    alarm(120);
    assert_non_null(mkdtemp(dir));
#define IN(name) (snprintf(p, sizeof p, "%s/%s", dir, (name)), p)
    assert_int_equal(mkfifo(IN("fifo.mtl"), 0600), 0);
    assert_int_equal(mkfifo(IN("fifo.png"), 0600), 0);
    assert_int_equal(mkfifo(IN("fifo.obj"), 0600), 0);
    assert_int_equal(symlink("/dev/zero", IN("zero.mtl")), 0);
    assert_int_equal(symlink("/dev/zero", IN("zero.obj")), 0);
    assert_int_equal(mkdir(IN("sub"), 0700), 0);
    fd = open(IN("big.obj"), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    assert_true(fd >= 0);
    assert_int_equal(ftruncate(fd, (off_t)5 << 30), 0); /* sparse: no disk used */
    close(fd);
    snprintf(obj, sizeof obj, "%s/m.obj", dir);
    snprintf(mtl, sizeof mtl, "%s/m.mtl", dir);

    expect_mesh_error(IN("fifo.obj"), "fifo.obj", "not a regular file");
    expect_mesh_error(IN("zero.obj"), "zero.obj", "not a regular file");
    expect_mesh_error(IN("sub"), "sub", "is a folder");
    expect_mesh_error(IN("big.obj"), "big.obj", "larger than 4 GiB");
    for (k = 0; k < sizeof libs / sizeof libs[0]; ++k) {
        snprintf(text, sizeof text, "mtllib %s\n" TRI_OBJ, libs[k].mtllib);
        write_file(obj, text);
        expect_mesh_error(obj, libs[k].mtllib, libs[k].words);
    }
    for (k = 0; k < sizeof maps / sizeof maps[0]; ++k) {
        snprintf(text, sizeof text, "newmtl mat\nKd 0.5 0.5 0.5\nmap_Kd %s\n", maps[k].map);
        write_file(mtl, text);
        write_file(obj, "mtllib m.mtl\n" TRI_OBJ);
        expect_mesh_error(obj, maps[k].map, maps[k].words);
    }
    /* a missing MTL or texture: imported (default material, or the colour and a warning) */
    assert_int_equal(rs_scene_create("kinds", &s), RS_OK);
    remove(mtl); /* Assimp falls back to m.mtl for a missing MTL */
    write_file(obj, "mtllib none.mtl\n" TRI_OBJ);
    assert_int_equal(rs_scene_add_mesh(s, obj, &o, &info), RS_OK);
    write_file(mtl, "newmtl mat\nKd 0.5 0.5 0.5\nmap_Kd none.png\n");
    write_file(obj, "mtllib m.mtl\n" TRI_OBJ);
    assert_int_equal(rs_scene_add_mesh(s, obj, &o, &info), RS_OK);
    assert_int_equal(info.triangles, 1u);
    rs_scene_destroy(s);
    rs_error_clear();
    alarm(0);
    for (k = 0; k < sizeof names / sizeof names[0]; ++k)
        remove(IN(names[k]));
    rmdir(IN("sub"));
#undef IN
    rmdir(dir);
}

/* A PLY whose header is cut before end_header (Assimp's reader spins on it for ever), one
 * that declares more elements than its bytes could hold, an ascii list longer than the file,
 * and a .ply that is not PLY: each an error naming the file, at once. */
static void test_ply_headers(void **state)
{
    static const struct {
        const char *text, *words;
    } cases[] = {
        {"ply\nformat ascii 1.0\n", "PLY header has no end_header"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n", "no end_header"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_hea", "no end_header"},
        {"ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\n"
         "property float z\nend_header\n0 0 0\n",
         "declares 4000000000 elements"},
        {"solid cube\nendsolid\n", "not a PLY file"},
        /* found by tests/fuzz/fuzz_mesh: Assimp aborts the process (an ai_assert in its
         * triangulation) on an ascii body cut before the declared elements; the same as
         * tests/data/cut_body.ply, which test_malformed loads */
        {"ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
         "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n",
         "14 elements, but its ascii data has only 3 lines"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0",
         "4 elements, but its ascii data has only 3 lines"},
        /* found by tests/fuzz/fuzz_mesh: Assimp read this mangled line's count as 2^32 - 1
         * and asked for 64 GiB */
        {"ply\nformat ascii 1.0\nelement 66666666666666666666666voperty lar int vertex\n"
         "end_header\n0 0 0\n",
         "line 3 is not 'element NAME COUNT'"},
        {"ply\nformat ascii 1.0\nelement vertex 4294967296\nproperty float x\nend_header\n0\n",
         "line 3 is not 'element NAME COUNT'"},
        /* found by tests/fuzz/fuzz_mesh: Assimp reads an ascii list's length from its leading
         * digits as 32 bits whatever its type and reserves as many values (30 GiB here): a
         * length the file cannot hold is refused, with its data line (the 2nd face's, line 5;
         * the first's 3 fits) */
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n4555555555t z\n",
         "PLY data line 5: a list of 4555555555 items, more than"},
        {"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n455555555555555555555555555 0 1 2",
         "PLY data line 4: a list of over 10^12 items"},
        /* binary: 3 vertices of 12 bytes and a face of at least 1 need 37 bytes, not 20 */
        {"ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
         "property float y\nproperty float z\nelement face 1\n"
         "property list uchar int vertex_indices\nend_header\n0123456789abcdefghij",
         "at least 37 bytes, but its binary data has only 20"},
        /* a file of triangle strips: the same header parser (scenes/ply_header.h), strict for
         * our own reader, which refuses any line it would not understand */
        {"ply\nformat binary_middle_endian 1.0\nelement vertex 0\nproperty float x\n"
         "element tristrips 0\nproperty list int int vertex_indices\nend_header\n",
         "line 2: unknown format 'binary_middle_endian'"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty half x\nelement tristrips 0\n"
         "property list int int vertex_indices\nend_header\n0\n",
         "line 4: unknown type 'half'"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement tristrips 0\n"
         "property list float int vertex_indices\nend_header\n0\n",
         "line 6: bad list property"},
        {"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nelement tristrips 0\n"
         "property list int int vertex_indices\nvertex_order ccw\nend_header\n0\n",
         "line 7: unexpected 'vertex_order'"},
    };
    char dir[] = "/tmp/rs_ply_XXXXXX", path[256];
    size_t k;
    (void)state;
    alarm(60);
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/cut.ply", dir);
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        write_file(path, cases[k].text);
        expect_mesh_error(path, path, cases[k].words);
    }
    {
        /* the strip reader on its own bounds the header's counts by the file's size too (it
         * used to rely on the import's check, and would have asked for 48 GB here) */
        rs_ply_strips strips;
        write_file(path, "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n"
                         "property float y\nproperty float z\nelement tristrips 1\n"
                         "property list int int vertex_indices\nend_header\n0 0 0\n");
        rs_error_clear();
        assert_int_equal(rs_ply_read_strips(path, &strips), RS_ERR_ARG);
        assert_non_null(strstr(rs_error_message(), "declares 4000000001 elements, more than"));
        assert_null(strips.vertices);
        rs_error_clear();
    }
    alarm(0);
    remove(path);
    rmdir(dir);
}

static const char *models_dir(void)
{
    static char dir[1024];
    const char *env = getenv("RS_MODELS_DIR");
    struct stat sb;
    snprintf(dir, sizeof dir, "%s", env && *env ? env : RS_SOURCE_DIR "/../shared/models");
    return stat(dir, &sb) == 0 ? dir : NULL;
}

/* Closest hits through the BVH equal brute force for rays aimed at the model. */
static void check_bvh(const rs_scene *s, uint32_t nrays)
{
    rs_geom g = rs_scene_geom(s);
    rs_bvh *b;
    rs_bvh_view v;
    rs_aabb box = {{1e30f, 1e30f, 1e30f}, {-1e30f, -1e30f, -1e30f}};
    uint64_t st = 11;
    uint32_t i, k, n = rs_geom_prim_count(&g), hits = 0;
    assert_int_equal(rs_bvh_build(&g, NULL, &b), RS_OK);
    v = rs_bvh_view_of(b);
    for (i = 0; i < n; ++i) {
        rs_aabb pb = rs_geom_prim_bounds(&g, i);
        box.lo = rs_v3_min(box.lo, pb.lo);
        box.hi = rs_v3_max(box.hi, pb.hi);
    }
    for (k = 0; k < nrays; ++k) {
        rs_vec3 c = rs_v3_scale(rs_v3_add(box.lo, box.hi), 0.5f);
        rs_vec3 ext = rs_v3_sub(box.hi, box.lo);
        rs_vec3 target = rs_v3_add(c, rs_v3_mul(rnd_box(&st, 0.5f), ext));
        rs_vec3 o = rs_v3_add(c, rs_v3_scale(rnd_unit(&st), 2.0f * rs_v3_max_comp(ext)));
        rs_ray r = mk_ray(o, rs_v3_sub(target, o), 0.0f, 1e30f);
        rs_hit h;
        float best = 1e30f, t, u, w;
        uint32_t best_prim = RS_NO_HIT;
        for (i = 0; i < n; ++i)
            if (rs_geom_intersect(&g, i, &r, &t, &u, &w) && t < best) {
                best = t;
                best_prim = i;
            }
        rs_bvh_closest(&v, &g, r, &h);
        if (h.prim != best_prim)
            assert_true(best_prim != RS_NO_HIT && h.t == best); /* a tie at equal t */
        hits += best_prim != RS_NO_HIT;
    }
    print_message("  BVH: %u nodes, depth %u; %u of %u rays hit, all as brute force\n", b->n_nodes,
                  b->depth, hits, nrays);
    assert_true(hits > nrays / 4);
    rs_bvh_destroy(b);
}

static void test_shared_models(void **state)
{
    static const struct {
        const char *file;
        uint32_t min_tris, max_tris;
        int has_uv;
    } models[] = {
        {"teapot/teapot.obj", 6320, 6320, 0},          {"bunny/bun_zipper.ply", 69000, 69451, 0},
        {"bunny/stanford-bunny.obj", 69000, 69451, 0}, {"dragon/dragon_100k.ply", 99000, 100000, 0},
        {"spot/spot_triangulated.obj", 5856, 5856, 1},
    };
    const char *dir = models_dir();
    size_t k;
    (void)state;
    if (!dir) {
        print_message("SKIP: no test models (../shared/models or $RS_MODELS_DIR)\n");
        skip();
    }
    for (k = 0; k < sizeof models / sizeof models[0]; ++k) {
        uint32_t mat;
        rs_scene *s = new_scene(&mat);
        rs_mesh_opts o = rs_mesh_opts_default(mat);
        rs_mesh_info info;
        char path[1100];
        snprintf(path, sizeof path, "%s/%s", dir, models[k].file);
        assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
        print_message("%s: %u triangles, %u dropped\n", models[k].file, info.triangles,
                      info.dropped);
        assert_true(info.triangles >= models[k].min_tris && info.triangles <= models[k].max_tris);
        assert_int_equal(info.triangles + info.dropped >= models[k].min_tris, 1);
        if (models[k].has_uv)
            assert_non_null(s->tri_uv);
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        check_bvh(s, info.triangles > 50000 ? 1500 : 4000);
        rs_scene_destroy(s);
    }
}

/* The Cornell box OBJ + MTL: its materials come along, the light (Ke) becomes an emitter. */
static void test_obj_mtl_materials(void **state)
{
    const char *dir = models_dir();
    rs_scene *s;
    rs_mesh_opts o;
    rs_mesh_info info;
    char path[1100];
    (void)state;
    if (!dir) {
        print_message("SKIP: no test models\n");
        skip();
    }
    assert_int_equal(rs_scene_create("cornell-obj", &s), RS_OK);
    o = rs_mesh_opts_default(RS_MESH_FILE_MATERIALS);
    snprintf(path, sizeof path, "%s/cornell-box/cornell_box.obj", dir);
    assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_OK);
    assert_int_equal(info.triangles, 32u);
    assert_true(info.materials >= 4u);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_true(s->n_lights >= 1u);
    rs_scene_destroy(s);
}

static void test_builtin_mesh_scenes(void **state)
{
    rs_scene *s;
    rs_builtin_opts bo = {"/nonexistent-models", NULL, NULL};
    (void)state;
    rs_error_clear();
    assert_int_equal(rs_builtin_create_ex("cornell-teapot", &bo, &s), RS_ERR_IO);
    assert_non_null(strstr(rs_error_message(), "--models"));
    rs_error_clear();
    if (!models_dir()) {
        print_message("SKIP: no test models\n");
        skip();
    }
    bo.models_dir = models_dir();
    assert_int_equal(rs_builtin_create_ex("cornell-teapot", &bo, &s), RS_OK);
    assert_int_equal(s->n_tris, 6320u);
    rs_scene_destroy(s);
    assert_int_equal(rs_builtin_create_ex("cornell-bunny-teapot", &bo, &s), RS_OK);
    assert_true(s->n_tris > 75000u);
    rs_scene_destroy(s);
}

/* ---- triangle strips ----------------------------------------------------------------------- */

/* A 3 x 2 grid of vertices (x right, y up, z = 0), as PLY with double coordinates and an extra
 * uchar property, in `fmt`; its strips: 0 1 2 3 (two triangles), restart, 2 3 4 5, then 5 5 and
 * 2 2 (joins), restart, and an index past the vertices.  The first triangle, (0,0) (0,1) (1,0),
 * faces -z, and so must every other. */
static void write_strip_ply(const char *path, const char *fmt)
{
    static const double xy[6][2] = {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 0}, {2, 1}};
    static const int32_t idx[] = {0, 1, 2, 3, -1, 2, 3, 4, 5, 5, 5, 2, 2, -1, 4, 5, 9};
    const int n_idx = (int)(sizeof idx / sizeof idx[0]);
    int ascii = strcmp(fmt, "ascii") == 0, big = strcmp(fmt, "binary_big_endian") == 0, i, k;
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fprintf(f,
            "ply\nformat %s 1.0\ncomment strips test\nelement vertex 6\nproperty double x\n"
            "property double y\nproperty uchar quality\nproperty double z\n"
            "element tristrips 1\nproperty list int int vertex_indices\nend_header\n",
            fmt);
    for (i = 0; i < 6; ++i) {
        double v[3] = {xy[i][0], xy[i][1], 0.0};
        unsigned char q = 7;
        if (ascii) {
            fprintf(f, "%g %g %u %g\n", v[0], v[1], q, v[2]);
            continue;
        }
        for (k = 0; k < 4; ++k) {
            unsigned char b[8];
            int j;
            if (k == 2) {
                fwrite(&q, 1, 1, f);
                continue;
            }
            memcpy(b, &v[k < 2 ? k : 2], 8);
            for (j = 0; j < 8; ++j)
                fputc(b[big ? 7 - j : j], f);
        }
    }
    if (ascii) {
        fprintf(f, "%d", n_idx);
        for (i = 0; i < n_idx; ++i)
            fprintf(f, " %d", idx[i]);
        fprintf(f, "\n");
    } else {
        int32_t all[1 + sizeof idx / sizeof idx[0]];
        all[0] = n_idx;
        memcpy(all + 1, idx, sizeof idx);
        for (i = 0; i <= n_idx; ++i) {
            unsigned char b[4];
            int j;
            memcpy(b, &all[i], 4);
            for (j = 0; j < 4; ++j)
                fputc(b[big ? 3 - j : j], f);
        }
    }
    fclose(f);
}

static void test_strips(void **state)
{
    static const char *const fmts[] = {"ascii", "binary_little_endian", "binary_big_endian"};
    char dir[] = "/tmp/rs_strips_XXXXXX", path[256];
    rs_tri first[8];
    uint32_t n_first = 0;
    size_t k;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/grid.ply", dir);
    for (k = 0; k < 3; ++k) {
        uint32_t mat, i;
        rs_scene *s = new_scene(&mat);
        rs_mesh_opts o = rs_mesh_opts_default(mat);
        rs_mesh_info info;
        write_strip_ply(path, fmts[k]);
        rs_error_clear();
        if (rs_scene_add_mesh(s, path, &o, &info) != RS_OK)
            fail_msg("%s: %s", fmts[k], rs_error_message());
        /* strip 1: 2 triangles; strip 2: 2, then the joins 4 5 5, 5 5 5, 5 5 2, 5 2 2, 2 2 ...;
         * strip 3: 4 5 9, whose 9 is past the 6 vertices (dropped) */
        print_message("%-21s %u triangles, %u strips, %u joins, %u dropped\n", fmts[k],
                      info.triangles, info.strips, info.joins, info.dropped);
        assert_int_equal(info.strips, 3u);
        assert_int_equal(info.triangles, 4u);
        assert_int_equal(info.dropped, 1u);
        assert_int_equal(info.dropped_index, 1u);
        assert_true(info.joins >= 4u);
        for (i = 0; i < s->n_tris; ++i) {
            const rs_tri *t = &s->tris[i];
            rs_vec3 n = rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0));
            assert_true(n.z < 0.0f); /* alternate triangles reversed: all face as the first */
            assert_true(fabsf(rs_v3_length(n) - 1.0f) < 1e-6f);
        }
        if (k == 0) {
            n_first = s->n_tris;
            memcpy(first, s->tris, n_first * sizeof *first);
        } else {
            /* the three encodings give the same triangles */
            assert_int_equal(s->n_tris, n_first);
            assert_memory_equal(s->tris, first, n_first * sizeof *first);
        }
        rs_scene_destroy(s);
    }
    {
        /* cut in its data: one line naming the file */
        uint32_t mat;
        rs_scene *s = new_scene(&mat);
        rs_mesh_opts o = rs_mesh_opts_default(mat);
        rs_mesh_info info;
        FILE *f;
        long size;
        write_strip_ply(path, "binary_little_endian");
        f = fopen(path, "r+b");
        fseek(f, 0, SEEK_END);
        size = ftell(f);
        fclose(f);
        assert_int_equal(truncate(path, size - 20), 0);
        rs_error_clear();
        assert_int_equal(rs_scene_add_mesh(s, path, &o, &info), RS_ERR_ARG);
        print_message("%s\n", rs_error_message());
        assert_non_null(strstr(rs_error_message(), path));
        assert_null(strchr(rs_error_message(), '\n'));
        rs_error_clear();
        rs_scene_destroy(s);
    }
    remove(path);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_placement_uv_normals),
        cmocka_unit_test(test_obj_normals_inverse_transpose),
        cmocka_unit_test(test_placement_nonaxis),
        cmocka_unit_test(test_placement_mirror),
        cmocka_unit_test(test_placement_refused),
        cmocka_unit_test(test_unplaced_as_stored),
        cmocka_unit_test(test_ply_and_gltf),
        cmocka_unit_test(test_fit),
        cmocka_unit_test(test_malformed),
        cmocka_unit_test(test_strips),
        cmocka_unit_test(test_file_kinds),
        cmocka_unit_test(test_ply_headers),
        cmocka_unit_test(test_shared_models),
        cmocka_unit_test(test_obj_mtl_materials),
        cmocka_unit_test(test_builtin_mesh_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
