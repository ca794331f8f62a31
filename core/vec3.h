/* core/vec3.h — three-float vectors and colours, shared by host and device.
 * 12 bytes, no padding, so arrays of rs_vec3 have the same bytes on CPU and GPU. */
#ifndef RS_CORE_VEC3_H
#define RS_CORE_VEC3_H

#include <math.h>
#include "core/hd.h"
#include "core/hdmath.h"

/* fmaxf and fminf, inline.  The host's libm functions are calls (gcc may not turn them into
 * maxss / minss, whose NaN rule differs), 5% of the shade stage's instructions with the call
 * around them.  These give glibc's results bit for bit: the larger (smaller) of two numbers,
 * the second where they compare equal (so -0 and +0 give the second, as glibc's maxss does), and
 * the other where one is NaN (checked against libm on zeros, infinities, NaNs in
 * core_vec3_test).  The device keeps CUDA's own. */
RS_HD float rs_fmaxf(float a, float b)
{
#if RS_DEVICE_PASS
    return fmaxf(a, b);
#else
    return a > b ? a : (b != b ? a : b);
#endif
}

RS_HD float rs_fminf(float a, float b)
{
#if RS_DEVICE_PASS
    return fminf(a, b);
#else
    return a < b ? a : (b != b ? a : b);
#endif
}

typedef struct rs_vec3 {
    float x, y, z;
} rs_vec3;

RS_HD rs_vec3 rs_v3(float x, float y, float z)
{
    rs_vec3 r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}
RS_HD rs_vec3 rs_v3_splat(float s) { return rs_v3(s, s, s); }
RS_HD rs_vec3 rs_v3_add(rs_vec3 a, rs_vec3 b) { return rs_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
RS_HD rs_vec3 rs_v3_sub(rs_vec3 a, rs_vec3 b) { return rs_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
RS_HD rs_vec3 rs_v3_mul(rs_vec3 a, rs_vec3 b) { return rs_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
RS_HD rs_vec3 rs_v3_scale(rs_vec3 a, float s) { return rs_v3(a.x * s, a.y * s, a.z * s); }
RS_HD rs_vec3 rs_v3_neg(rs_vec3 a) { return rs_v3(-a.x, -a.y, -a.z); }
/* a + b * s */
RS_HD rs_vec3 rs_v3_madd(rs_vec3 a, rs_vec3 b, float s)
{
    return rs_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s);
}
RS_HD float rs_v3_dot(rs_vec3 a, rs_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
RS_HD rs_vec3 rs_v3_cross(rs_vec3 a, rs_vec3 b)
{
    return rs_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
RS_HD float rs_v3_length2(rs_vec3 a) { return rs_v3_dot(a, a); }
RS_HD float rs_v3_length(rs_vec3 a) { return sqrtf(rs_v3_dot(a, a)); }
/* Unit vector along a; a must not be zero. */
RS_HD rs_vec3 rs_v3_normalize(rs_vec3 a) { return rs_v3_scale(a, 1.0f / rs_v3_length(a)); }
RS_HD rs_vec3 rs_v3_min(rs_vec3 a, rs_vec3 b)
{
    return rs_v3(rs_fminf(a.x, b.x), rs_fminf(a.y, b.y), rs_fminf(a.z, b.z));
}
RS_HD rs_vec3 rs_v3_max(rs_vec3 a, rs_vec3 b)
{
    return rs_v3(rs_fmaxf(a.x, b.x), rs_fmaxf(a.y, b.y), rs_fmaxf(a.z, b.z));
}
RS_HD float rs_v3_max_comp(rs_vec3 a) { return rs_fmaxf(a.x, rs_fmaxf(a.y, a.z)); }
RS_HD float rs_v3_get(rs_vec3 a, int axis) { return axis == 0 ? a.x : (axis == 1 ? a.y : a.z); }
RS_HD int rs_v3_is_zero(rs_vec3 a) { return a.x == 0.0f && a.y == 0.0f && a.z == 0.0f; }
/* Every component finite (x - x is 0 for a finite x, NaN for an infinite or NaN one). */
RS_HD int rs_v3_is_finite(rs_vec3 a)
{
    return a.x - a.x == 0.0f && a.y - a.y == 0.0f && a.z - a.z == 0.0f;
}

/* Rotation about the y axis by `deg` degrees (right-handed, as RTIOW's rotate_y). */
RS_HD rs_vec3 rs_v3_rotate_y(rs_vec3 p, float deg)
{
    float c, s;
    rs_sincosf(deg * 0.017453292519943295f, &s, &c);
    return rs_v3(c * p.x + s * p.z, p.y, -s * p.x + c * p.z);
}

#endif
