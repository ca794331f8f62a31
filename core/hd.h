/* core/hd.h — the only file that knows which compiler is reading.
 *
 * Code shared by the CPU and the CUDA device is written once, in headers, with every function
 * marked RS_HD.  Under nvcc that expands to `static inline __host__ __device__`; under a C11
 * compiler to `static inline`.  Such headers must compile as C11 and as CUDA C++: no `restrict`
 * (use RS_RESTRICT), no compound literals, no VLAs, no _Generic, no malloc and no stdio. */
#ifndef RS_CORE_HD_H
#define RS_CORE_HD_H

#if defined(__CUDACC__)
#  define RS_HD          static inline __host__ __device__
#  define RS_RESTRICT    __restrict__
#  define RS_ALIGN(n)    __align__(n)
#  define RS_CONST_TABLE static __device__ const
#else
#  define RS_HD static inline
#  if defined(__cplusplus)
#    define RS_RESTRICT __restrict__
#  else
#    define RS_RESTRICT restrict
#  endif
#  define RS_ALIGN(n)    _Alignas(n)
#  define RS_CONST_TABLE static const
#endif

#if defined(RS_CHECKS) && !defined(__CUDA_ARCH__)
#  include <assert.h>
#  define RS_ASSERT(x) assert(x)
#else
#  define RS_ASSERT(x) ((void)0)
#endif

#include <stdint.h>

/* a * b rounded on its own, never contracted with a following add into a fused multiply-add.
 * Host C11 code is not contracted (ISO C mode); nvcc contracts by default, so device code says
 * so explicitly.  Used where exact cancellation matters (the watertight triangle test). */
#if defined(__CUDA_ARCH__)
#  define RS_MUL_EXACT(a, b) __fmul_rn((a), (b))
#else
#  define RS_MUL_EXACT(a, b) ((a) * (b))
#endif

/* A primitive index meaning "no hit". */
#define RS_NO_HIT 0xffffffffu

#endif
