/* tests/gpu_hdmath_eval_none.c — hdm_eval_on_gpu in a build without CUDA: always unavailable. */
#include <stdio.h>

#include "hdmath_eval.h"

int hdm_eval_on_gpu(int f, const float *x, const float *y, float *out, size_t n, char *msg,
                    size_t msg_size)
{
    (void)f, (void)x, (void)y, (void)out, (void)n;
    snprintf(msg, msg_size, "this build has no CUDA");
    return -1;
}
