/* tests/shading_camera_test.c — shading/camera.h: rs_camera_make and rs_camera_ray.
 *
 * The camera frame, derived the way RTIOW (v4) does it:
 *   w = normalize(from - at)          points backwards, out of the screen
 *   u = normalize(cross(up, w))       image right
 *   v = cross(w, u)                   image up
 * so pixel (0, 0), the top-left, looks along -w, up (+v) and to the left (-u).  For the Cornell
 * camera (from (278,278,-800), at (278,278,0), up +y): w = -z, u = cross(+y, -z) = -x, v = +y;
 * image-right is world -x and the top-left pixel looks toward +x, +y.
 *
 * What is checked, over the Cornell camera and random cameras (fixed seed):
 *   - rs_camera_make's own fields: for the Cornell camera against the values this frame gives
 *     (worked by hand), for random ones against what each field means (the viewport's size,
 *     perpendicular axes, handedness, the image centre f ahead, the lens axes), not against a
 *     second derivation of the frame (frame_of below only measures the rays' angles);
 *   - the image centre looks exactly at `at` (odd square images, and even / non-square ones);
 *   - the top-left corner ray makes vfov/2 with the view direction vertically and
 *     atan(aspect * tan(vfov/2)) horizontally, with or without an explicit focus distance;
 *   - pixel (0, 0) is the top-left, x grows to image-right (u) and y grows downwards (-v);
 *   - directions are unit length; neighbouring pixels' edges coincide (jx = 1 meets jx = 0);
 *   - aperture 0: every origin is exactly `from`; tmin 0, tmax huge;
 *   - with an aperture: origins lie on the lens plane (through `from`, normal w) within the lens
 *     radius, at radius R sqrt(l1) (uniform-area polar map), and rays through one image point
 *     meet on the focus plane, where the pinhole ray meets it. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "shading/camera.h"

#define PI_D 3.14159265358979323846

#include "test_rand.h"

/* ---- helpers ------------------------------------------------------------------------------- */

/* The frame in double, independently of the camera's own arithmetic. */
typedef struct frame {
    double u[3], v[3], w[3];
} frame;

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize3(double *a)
{
    double l = sqrt(dot3(a, a));
    a[0] /= l;
    a[1] /= l;
    a[2] /= l;
}

static void cross3(const double *a, const double *b, double *out)
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

static frame frame_of(rs_vec3 from, rs_vec3 at, rs_vec3 up)
{
    frame f;
    double upd[3] = {up.x, up.y, up.z};
    f.w[0] = (double)from.x - at.x;
    f.w[1] = (double)from.y - at.y;
    f.w[2] = (double)from.z - at.z;
    normalize3(f.w);
    cross3(upd, f.w, f.u);
    normalize3(f.u);
    cross3(f.w, f.u, f.v);
    return f;
}

static void to3(rs_vec3 a, double *out)
{
    out[0] = a.x;
    out[1] = a.y;
    out[2] = a.z;
}

/* a equals (x, y, z) to `rel` of the largest of |x|, |y|, |z| (exactly for rel 0). */
static void expect_v3_near(rs_vec3 a, double x, double y, double z, double rel, const char *what)
{
    double tol = rel * fmax(fabs(x), fmax(fabs(y), fabs(z)));
    if (!(fabs(a.x - x) <= tol && fabs(a.y - y) <= tol && fabs(a.z - z) <= tol))
        fail_msg("%s: (%.9g, %.9g, %.9g), want (%.9g, %.9g, %.9g)", what, a.x, a.y, a.z, x, y, z);
}

/* A random camera: position in [-100, 100]^3, looking 1 .. 1000 units away, an up vector at
 * least ~10 degrees from the view direction, vfov 5 .. 150 degrees, 1 .. 640 pixels a side. */
typedef struct cam_case {
    rs_vec3 from, at, up;
    float vfov;
    uint32_t w, h;
} cam_case;

static cam_case random_case(uint64_t *s)
{
    cam_case c;
    rs_vec3 dir;
    c.from = rs_v3(rnd_range(s, -100, 100), rnd_range(s, -100, 100), rnd_range(s, -100, 100));
    dir = rnd_unit(s);
    c.at = rs_v3_madd(c.from, dir, powf(10.0f, rnd_range(s, 0.0, 3.0)));
    do {
        c.up = rs_v3_scale(rnd_unit(s), rnd_range(s, 0.5, 2.0));
    } while (rs_v3_length(rs_v3_cross(rs_v3_normalize(c.up), dir)) < 0.17f);
    c.vfov = rnd_range(s, 5.0, 150.0);
    c.w = 1u + (uint32_t)(splitmix64(s) % 640u);
    c.h = 1u + (uint32_t)(splitmix64(s) % 640u);
    return c;
}

static rs_vec3 cornell_from(void) { return rs_v3(278.0f, 278.0f, -800.0f); }
static rs_vec3 cornell_at(void) { return rs_v3(278.0f, 278.0f, 0.0f); }

/* ---- the image centre ---------------------------------------------------------------------- */

static void expect_points_at(const rs_ray *r, rs_vec3 from, rs_vec3 at, double tol,
                             const char *what)
{
    double d[3], want[3] = {(double)at.x - from.x, (double)at.y - from.y, (double)at.z - from.z};
    double c;
    to3(r->d, d);
    normalize3(want);
    c = dot3(d, want) / sqrt(dot3(d, d));
    /* 1 - cos(angle) ~ angle^2 / 2 */
    if (!(acos(fmin(c, 1.0)) <= tol))
        fail_msg("%s: the centre ray is %.3g rad off the view direction", what, acos(fmin(c, 1.0)));
}

static void test_centre_looks_at_target(void **state)
{
    uint64_t s = 0xcab;
    int i;
    (void)state;
    {
        /* the Cornell camera, odd square image: the middle pixel's centre */
        rs_camera c = rs_camera_make(cornell_from(), cornell_at(), rs_v3(0, 1, 0), 40.0f, 0.0f,
                                     0.0f, 101, 101);
        rs_ray r = rs_camera_ray(&c, 50, 50, 0.5f, 0.5f, 0.0f, 0.0f);
        assert_float_equal(r.d.x, 0.0f, 1e-6f);
        assert_float_equal(r.d.y, 0.0f, 1e-6f);
        assert_float_equal(r.d.z, 1.0f, 1e-6f);
    }
    for (i = 0; i < 20000; ++i) {
        cam_case k = random_case(&s);
        float ap = (i & 1) ? rnd_range(&s, 0.0, 2.0) : 0.0f;
        float fd = (i & 2) ? rnd_range(&s, 0.5, 50.0) : 0.0f;
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, 0.0f, fd, k.w, k.h);
        rs_ray r;
        char what[96];
        /* float rounding: the centre is corner + du * w/2 + dv * h/2, a difference of terms as
         * large as the viewport and the camera position, each good to ~1e-7 of its size */
        double focus = fd > 0.0f ? fd : rs_v3_length(rs_v3_sub(k.from, k.at));
        double half_v = tan(0.5 * k.vfov * PI_D / 180.0), aspect = (double)k.w / k.h;
        double big = fabs(k.from.x) + fabs(k.from.y) + fabs(k.from.z);
        double tol = 1e-6 * (big / focus + 1.0 + half_v * (1.0 + aspect));
        snprintf(what, sizeof what, "camera %d (%ux%u, vfov %.1f, focus %.2f)", i, k.w, k.h, k.vfov,
                 fd);
        /* the centre of the image: pixel w/2 (h/2) with offset 0 when even, 0.5 when odd */
        r = rs_camera_ray(&c, k.w / 2, k.h / 2, (k.w & 1) ? 0.5f : 0.0f, (k.h & 1) ? 0.5f : 0.0f,
                          0.0f, 0.0f);
        expect_points_at(&r, k.from, k.at, tol, what);
        /* with an aperture, the pinhole-centre lens sample (l1 = 0) is the same ray */
        c = rs_camera_make(k.from, k.at, k.up, k.vfov, ap, fd, k.w, k.h);
        r = rs_camera_ray(&c, k.w / 2, k.h / 2, (k.w & 1) ? 0.5f : 0.0f, (k.h & 1) ? 0.5f : 0.0f,
                          0.0f, 0.0f);
        expect_points_at(&r, k.from, k.at, tol, what);
    }
}

/* ---- field of view and orientation --------------------------------------------------------- */

/* Angles of direction d in the frame: vertical = atan(d.v / d.(-w)), horizontal = atan(d.u /
 * d.(-w)); both in radians. */
static void angles(const frame *f, rs_vec3 dir, double *horiz, double *vert)
{
    double d[3], fwd;
    to3(dir, d);
    fwd = -dot3(d, f->w);
    *horiz = atan2(dot3(d, f->u), fwd);
    *vert = atan2(dot3(d, f->v), fwd);
}

static void test_corner_angles(void **state)
{
    uint64_t s = 0xf0f;
    int i;
    (void)state;
    for (i = 0; i < 20000; ++i) {
        cam_case k = random_case(&s);
        float fd = (i & 1) ? rnd_range(&s, 0.5, 50.0) : 0.0f;
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, 0.0f, fd, k.w, k.h);
        frame f = frame_of(k.from, k.at, k.up);
        double half_v = 0.5 * k.vfov * PI_D / 180.0;
        double half_h = atan((double)k.w / k.h * tan(half_v));
        double h, v, tol = 2e-5 * (1.0 + tan(half_h));
        /* the top-left corner of pixel (0, 0): left (-u) and up (+v) */
        rs_ray r = rs_camera_ray(&c, 0, 0, 0.0f, 0.0f, 0.0f, 0.0f);
        angles(&f, r.d, &h, &v);
        if (!(fabs(v - half_v) <= tol && fabs(h + half_h) <= tol))
            fail_msg("camera %d (%ux%u, vfov %.2f): top-left corner at (h %.6f, v %.6f) rad, "
                     "want (%.6f, %.6f)",
                     i, k.w, k.h, k.vfov, h, v, -half_h, half_v);
        /* the bottom-right corner of the last pixel: right and down */
        r = rs_camera_ray(&c, k.w - 1, k.h - 1, 1.0f, 1.0f, 0.0f, 0.0f);
        angles(&f, r.d, &h, &v);
        if (!(fabs(v + half_v) <= tol && fabs(h - half_h) <= tol))
            fail_msg("camera %d: bottom-right corner at (h %.6f, v %.6f) rad, want (%.6f, %.6f)", i,
                     h, v, half_h, -half_v);
    }
}

static void test_cornell_orientation(void **state)
{
    const uint32_t w = 400, h = 300;
    rs_camera c =
        rs_camera_make(cornell_from(), cornell_at(), rs_v3(0, 1, 0), 40.0f, 0.0f, 0.0f, w, h);
    rs_ray tl = rs_camera_ray(&c, 0, 0, 0.5f, 0.5f, 0.0f, 0.0f);
    rs_ray tr = rs_camera_ray(&c, w - 1, 0, 0.5f, 0.5f, 0.0f, 0.0f);
    rs_ray bl = rs_camera_ray(&c, 0, h - 1, 0.5f, 0.5f, 0.0f, 0.0f);
    rs_ray br = rs_camera_ray(&c, w - 1, h - 1, 0.5f, 0.5f, 0.0f, 0.0f);
    rs_camera lens = rs_camera_make(cornell_from(), cornell_at(), rs_v3(0, 1, 0), 40.0f, 10.0f,
                                    0.0f, w, h);
    /* the viewport on the focus plane, 800 ahead: 2 tan(20 deg) 800 high, 4/3 of that wide */
    const double vh = 2.0 * tan(20.0 * PI_D / 180.0) * 800.0, vw = vh * 4.0 / 3.0;
    uint32_t x;
    (void)state;
    /* rs_camera_make's own output, against the frame derived in the header comment (u = -x,
     * v = +y, w = -z): one pixel right is vw / 400 along -x, one pixel down vh / 300 along -y;
     * the top-left corner, relative to the origin, is 800 ahead (+z), half the viewport to
     * image-left (+x) and up (+y); the lens axes are u and v times the radius 5 */
    expect_v3_near(c.origin, 278.0, 278.0, -800.0, 0.0, "origin");
    expect_v3_near(c.du, -vw / w, 0.0, 0.0, 1e-6, "du");
    expect_v3_near(c.dv, 0.0, -vh / h, 0.0, 1e-6, "dv");
    expect_v3_near(c.corner, vw / 2.0, vh / 2.0, 800.0, 1e-6, "corner");
    assert_true(c.lens_radius == 0.0f);
    expect_v3_near(lens.du, -vw / w, 0.0, 0.0, 1e-6, "du (with a lens)");
    expect_v3_near(lens.corner, vw / 2.0, vh / 2.0, 800.0, 1e-6, "corner (with a lens)");
    assert_true(lens.lens_radius == 5.0f);
    expect_v3_near(lens.lens_u, -5.0, 0.0, 0.0, 1e-6, "lens_u");
    expect_v3_near(lens.lens_v, 0.0, 5.0, 0.0, 1e-6, "lens_v");
    /* all look into the box (+z) */
    assert_true(tl.d.z > 0.8f && br.d.z > 0.8f);
    /* top-left: up and to camera-left, which is world +x */
    assert_true(tl.d.y > 0.0f && tl.d.x > 0.0f);
    assert_true(tr.d.y > 0.0f && tr.d.x < 0.0f);
    assert_true(bl.d.y < 0.0f && bl.d.x > 0.0f);
    assert_true(br.d.y < 0.0f && br.d.x < 0.0f);
    /* symmetric about the centre */
    assert_float_equal(tl.d.x, -tr.d.x, 1e-6f);
    assert_float_equal(tl.d.y, -bl.d.y, 1e-6f);
    /* x grows to image-right = world -x, monotonically; a row keeps its height */
    for (x = 1; x < w; ++x) {
        rs_ray a = rs_camera_ray(&c, x - 1, 7, 0.5f, 0.5f, 0.0f, 0.0f);
        rs_ray b = rs_camera_ray(&c, x, 7, 0.5f, 0.5f, 0.0f, 0.0f);
        assert_true(b.d.x < a.d.x);
        assert_float_equal(b.d.y / b.d.z, a.d.y / a.d.z, 1e-6f);
    }
    /* the top row of a 40-degree vertical field: the top edge is 20 degrees up */
    {
        rs_ray top = rs_camera_ray(&c, w / 2, 0, 0.0f, 0.0f, 0.0f, 0.0f);
        assert_float_equal(atan2f(top.d.y, top.d.z), 20.0f * (float)PI_D / 180.0f, 1e-6f);
        assert_float_equal(top.d.x, 0.0f, 1e-6f);
    }
}

static void test_pixel_axes_random(void **state)
{
    uint64_t s = 0xa1e5;
    int i;
    (void)state;
    for (i = 0; i < 5000; ++i) {
        cam_case k = random_case(&s);
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, 0.0f, 0.0f, k.w, k.h);
        frame f = frame_of(k.from, k.at, k.up);
        uint32_t px = (uint32_t)(splitmix64(&s) % k.w), py = (uint32_t)(splitmix64(&s) % k.h);
        float jx = rnd_range(&s, 0.0, 1.0), jy = rnd_range(&s, 0.0, 1.0);
        rs_ray a = rs_camera_ray(&c, px, py, jx, jy, 0.0f, 0.0f);
        rs_ray right = rs_camera_ray(&c, px, py, jx + 0.5f, jy, 0.0f, 0.0f);
        rs_ray down = rs_camera_ray(&c, px, py, jx, jy + 0.5f, 0.0f, 0.0f);
        double da[3], dr[3], dd[3], ha, va, hr, vr, hd, vd;
        to3(a.d, da);
        to3(right.d, dr);
        to3(down.d, dd);
        angles(&f, a.d, &ha, &va);
        angles(&f, right.d, &hr, &vr);
        angles(&f, down.d, &hd, &vd);
        /* moving right turns toward +u and keeps the image row; moving down turns toward -v */
        assert_true(hr > ha);
        assert_true(vd < va);
        /* the image plane's rows are straight: tan of the vertical angle, measured per unit
         * forward distance, is unchanged by a step right */
        assert_true(fabs(dot3(dr, f.v) / -dot3(dr, f.w) - dot3(da, f.v) / -dot3(da, f.w)) <=
                    1e-4 * (1.0 + fabs(dot3(da, f.v) / -dot3(da, f.w))));
        assert_true(fabs(dot3(dd, f.u) / -dot3(dd, f.w) - dot3(da, f.u) / -dot3(da, f.w)) <=
                    1e-4 * (1.0 + fabs(dot3(da, f.u) / -dot3(da, f.w))));
        /* pixel edges meet: (px, jx = 1) is (px + 1, jx = 0) */
        if (px + 1 < k.w) {
            rs_ray e1 = rs_camera_ray(&c, px, py, 1.0f, jy, 0.0f, 0.0f);
            rs_ray e2 = rs_camera_ray(&c, px + 1, py, 0.0f, jy, 0.0f, 0.0f);
            assert_true(rs_v3_length(rs_v3_sub(e1.d, e2.d)) <= 1e-5f);
        }
    }
}

/* rs_camera_make's fields for random cameras, against what they mean rather than against a
 * second derivation of the frame: the origin is `from`; du and dv are perpendicular to each other,
 * to the view direction and (du) to `up`; |du| width and |dv| height are the viewport,
 * 2 tan(vfov / 2) f high and width / height of that wide, f the focus distance; du x dv points
 * ahead, toward `at` (image-right, image-down), and dv against `up`; the image centre,
 * corner + du width / 2 + dv height / 2, is the point f ahead; the lens axes lie along du and
 * -dv, each as long as the lens radius. */
static void test_make_fields(void **state)
{
    uint64_t s = 0xf1e1d;
    int i;
    (void)state;
    for (i = 0; i < 20000; ++i) {
        cam_case k = random_case(&s);
        float ap = (i & 1) ? rnd_range(&s, 0.01, 4.0) : 0.0f;
        float fd = (i & 2) ? rnd_range(&s, 0.5, 50.0) : 0.0f;
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, ap, fd, k.w, k.h);
        double view[3] = {(double)k.at.x - k.from.x, (double)k.at.y - k.from.y,
                          (double)k.at.z - k.from.z};
        double up[3], du[3], dv[3], lu[3], lv[3], n[3], corner[3], centre[3], f, vh, vw, ldu, ldv;
        int a;
        to3(k.up, up);
        to3(c.du, du);
        to3(c.dv, dv);
        to3(c.lens_u, lu);
        to3(c.lens_v, lv);
        f = fd > 0.0f ? fd : sqrt(dot3(view, view));
        normalize3(view);
        normalize3(up);
        vh = 2.0 * tan(0.5 * k.vfov * PI_D / 180.0) * f;
        vw = vh * k.w / k.h;
        ldu = sqrt(dot3(du, du));
        ldv = sqrt(dot3(dv, dv));
        assert_true(c.origin.x == k.from.x && c.origin.y == k.from.y && c.origin.z == k.from.z);
        if (!(fabs(ldu * k.w - vw) <= 1e-5 * vw && fabs(ldv * k.h - vh) <= 1e-5 * vh))
            fail_msg("camera %d: viewport %g x %g, want %g x %g", i, ldu * k.w, ldv * k.h, vw, vh);
        assert_true(fabs(dot3(du, dv)) <= 1e-5 * ldu * ldv);
        assert_true(fabs(dot3(du, view)) <= 1e-5 * ldu);
        assert_true(fabs(dot3(dv, view)) <= 1e-5 * ldv);
        assert_true(fabs(dot3(du, up)) <= 1e-5 * ldu);
        cross3(du, dv, n);
        assert_true(dot3(n, view) >= (1.0 - 1e-5) * ldu * ldv);
        assert_true(dot3(dv, up) < 0.0);
        to3(c.corner, corner);
        for (a = 0; a < 3; ++a)
            centre[a] = corner[a] + du[a] * (0.5 * k.w) + dv[a] * (0.5 * k.h) - view[a] * f;
        /* float rounding: terms as large as the viewport */
        if (!(sqrt(dot3(centre, centre)) <= 1e-5 * (f + vw + vh)))
            fail_msg("camera %d: the image centre is %g off the point %g ahead", i,
                     sqrt(dot3(centre, centre)), f);
        assert_true(c.lens_radius == 0.5f * ap);
        if (ap > 0.0f) {
            double r = 0.5 * ap;
            assert_true(fabs(sqrt(dot3(lu, lu)) - r) <= 1e-5 * r);
            assert_true(fabs(sqrt(dot3(lv, lv)) - r) <= 1e-5 * r);
            assert_true(dot3(lu, du) >= (1.0 - 1e-5) * r * ldu);
            assert_true(-dot3(lv, dv) >= (1.0 - 1e-5) * r * ldv);
        } else {
            assert_true(dot3(lu, lu) == 0.0 && dot3(lv, lv) == 0.0);
        }
    }
}

/* ---- directions and origins ---------------------------------------------------------------- */

static void test_unit_directions_and_pinhole(void **state)
{
    uint64_t s = 0x0417;
    int i;
    (void)state;
    for (i = 0; i < 100000; ++i) {
        cam_case k = random_case(&s);
        float ap = (i & 1) ? rnd_range(&s, 0.01, 5.0) : 0.0f;
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, ap, 0.0f, k.w, k.h);
        uint32_t px = (uint32_t)(splitmix64(&s) % k.w), py = (uint32_t)(splitmix64(&s) % k.h);
        rs_ray r = rs_camera_ray(&c, px, py, rnd_range(&s, 0, 1), rnd_range(&s, 0, 1),
                                 rnd_range(&s, 0, 1), rnd_range(&s, 0, 1));
        float len = rs_v3_length(r.d);
        if (!(fabsf(len - 1.0f) <= 2e-6f))
            fail_msg("camera %d: |d| = %.9g", i, len);
        assert_true(r.tmin == 0.0f);
        assert_true(r.tmax >= 1e30f);
        if (ap == 0.0f) {
            /* a pinhole: every origin is `from`, bit for bit */
            assert_true(r.o.x == k.from.x && r.o.y == k.from.y && r.o.z == k.from.z);
        }
    }
}

static void test_lens(void **state)
{
    uint64_t s = 0x1e45;
    int i, j;
    (void)state;
    for (i = 0; i < 5000; ++i) {
        cam_case k = random_case(&s);
        float ap = rnd_range(&s, 0.01, 4.0);
        float fd = (i & 1) ? rnd_range(&s, 1.0, 200.0) : 0.0f;
        rs_camera c = rs_camera_make(k.from, k.at, k.up, k.vfov, ap, fd, k.w, k.h);
        frame f = frame_of(k.from, k.at, k.up);
        double focus = fd > 0.0f ? fd : rs_v3_length(rs_v3_sub(k.from, k.at));
        double R = 0.5 * ap, scale = fabs(k.from.x) + fabs(k.from.y) + fabs(k.from.z) + focus;
        uint32_t px = (uint32_t)(splitmix64(&s) % k.w), py = (uint32_t)(splitmix64(&s) % k.h);
        float jx = rnd_range(&s, 0, 1), jy = rnd_range(&s, 0, 1);
        rs_ray pin = rs_camera_ray(&c, px, py, jx, jy, 0.0f, 0.0f);
        double pf[3];
        /* where the l1 = 0 (lens centre) ray meets the focus plane, i.e. (p - from).(-w) = focus */
        {
            double d[3], t;
            to3(pin.d, d);
            t = focus / -dot3(d, f.w);
            pf[0] = pin.o.x + t * d[0];
            pf[1] = pin.o.y + t * d[1];
            pf[2] = pin.o.z + t * d[2];
        }
        assert_true(pin.o.x == k.from.x && pin.o.y == k.from.y && pin.o.z == k.from.z);
        for (j = 0; j < 8; ++j) {
            float l1 = rnd_range(&s, 0, 1), l2 = rnd_range(&s, 0, 1);
            rs_ray r = rs_camera_ray(&c, px, py, jx, jy, l1, l2);
            double off[3] = {(double)r.o.x - k.from.x, (double)r.o.y - k.from.y,
                             (double)r.o.z - k.from.z};
            double rad = sqrt(dot3(off, off)), d[3], t, p[3], miss;
            /* on the lens plane (normal w through from), inside the lens, at radius R sqrt(l1):
             * float position error is ~1e-7 of the coordinates' size */
            assert_true(fabs(dot3(off, f.w)) <= 1e-6 * scale);
            assert_true(rad <= R + 1e-6 * scale);
            assert_true(fabs(rad - R * sqrt(l1)) <= 1e-5 * R + 1e-6 * scale);
            /* it meets the focus plane where the lens-centre ray does */
            to3(r.d, d);
            t = (focus + dot3(off, f.w)) / -dot3(d, f.w);
            p[0] = r.o.x + t * d[0] - pf[0];
            p[1] = r.o.y + t * d[1] - pf[1];
            p[2] = r.o.z + t * d[2] - pf[2];
            miss = sqrt(dot3(p, p));
            if (!(miss <= 2e-5 * (t + scale)))
                fail_msg("camera %d, lens sample %d: misses the focus point by %.3g (focus %.3g)",
                         i, j, miss, focus);
        }
    }
}

static void test_lens_disk_extent(void **state)
{
    /* The Cornell camera with aperture 10 (lens radius 5): l1 -> 1 reaches the rim, and l2 sweeps
     * the full circle in the (u, v) plane: world (-x, +y) with u = -x. */
    rs_camera c =
        rs_camera_make(cornell_from(), cornell_at(), rs_v3(0, 1, 0), 40.0f, 10.0f, 0.0f, 64, 64);
    rs_ray r;
    (void)state;
    assert_float_equal(c.lens_radius, 5.0f, 0.0f);
    r = rs_camera_ray(&c, 32, 32, 0.0f, 0.0f, 0.99999994f, 0.0f); /* phi = 0: +u = -x */
    assert_float_equal(r.o.x, 278.0f - 5.0f, 1e-3f);
    assert_float_equal(r.o.y, 278.0f, 1e-3f);
    assert_float_equal(r.o.z, -800.0f, 1e-3f);
    r = rs_camera_ray(&c, 32, 32, 0.0f, 0.0f, 0.99999994f, 0.25f); /* phi = 90: +v = +y */
    assert_float_equal(r.o.x, 278.0f, 1e-3f);
    assert_float_equal(r.o.y, 278.0f + 5.0f, 1e-3f);
    r = rs_camera_ray(&c, 32, 32, 0.0f, 0.0f, 0.25f, 0.5f); /* radius 2.5, phi = 180 */
    assert_float_equal(r.o.x, 278.0f + 2.5f, 1e-3f);
    assert_float_equal(r.o.y, 278.0f, 1e-3f);
    /* and the image centre still lands on `at`, 800 units ahead */
    {
        double t = 800.0 / r.d.z;
        assert_float_equal((float)(r.o.x + t * r.d.x), 278.0f, 2e-3f);
        assert_float_equal((float)(r.o.y + t * r.d.y), 278.0f, 2e-3f);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_centre_looks_at_target),
        cmocka_unit_test(test_corner_angles),
        cmocka_unit_test(test_cornell_orientation),
        cmocka_unit_test(test_make_fields),
        cmocka_unit_test(test_pixel_axes_random),
        cmocka_unit_test(test_unit_directions_and_pinhole),
        cmocka_unit_test(test_lens),
        cmocka_unit_test(test_lens_disk_extent),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
