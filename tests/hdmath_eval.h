/* tests/hdmath_eval.h — one core/hdmath.h function by number, for gpu_trace_test's comparison of
 * the device's bits with the host's (the same dispatch compiled by nvcc for the GPU and by the C
 * compiler for the host). */
#ifndef RS_TESTS_HDMATH_EVAL_H
#define RS_TESTS_HDMATH_EVAL_H

#include "core/hdmath.h"

#define HDM_EVAL_N 10

/* f: 0 sin, 1 cos, 2 sincos's sine, 3 sincos's cosine, 4 tan, 5 exp, 6 log, 7 pow(x, y),
 * 8 acos, 9 atan2(x, y) */
RS_HD float hdm_eval(int f, float x, float y)
{
    float s, c;
    switch (f) {
    case 0: return rs_sinf(x);
    case 1: return rs_cosf(x);
    case 2: rs_sincosf(x, &s, &c); return s;
    case 3: rs_sincosf(x, &s, &c); return c;
    case 4: return rs_tanf(x);
    case 5: return rs_expf(x);
    case 6: return rs_logf(x);
    case 7: return rs_powf(x, y);
    case 8: return rs_acosf(x);
    default: return rs_atan2f(x, y);
    }
}

#ifdef __cplusplus
extern "C" {
#endif
/* out[i] = hdm_eval(f, x[i], y[i]) for i < n on CUDA device 0: 0, or -1 with the failing call
 * and CUDA's error in msg (tests/gpu_hdmath_eval.cu; tests/gpu_hdmath_eval_none.c: always -1). */
int hdm_eval_on_gpu(int f, const float *x, const float *y, float *out, size_t n, char *msg,
                    size_t msg_size);
#ifdef __cplusplus
}
#endif

#endif
