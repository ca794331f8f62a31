/* core/try.h — RS_TRY(expr): evaluates expr, an rs_status, and returns it from the enclosing
 * function (which returns rs_status) unless it is RS_OK.  The message stays the one the failing
 * call recorded (core/status.h: the first failure names the cause).  Host C code only (the
 * scene builders and readers); CUDA calls have their own, gpu/cuda_check.h's CUDA_TRY. */
#ifndef RS_CORE_TRY_H
#define RS_CORE_TRY_H

#include "core/status.h"

#define RS_TRY(expr)                                                                               \
  do {                                                                                             \
    rs_status rs_try_st_ = (expr);                                                                 \
    if (rs_try_st_ != RS_OK)                                                                       \
      return rs_try_st_;                                                                           \
  } while (0)

#endif
