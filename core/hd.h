/* core/hd.h — the only file that knows which compiler is reading.
 *
 * Code shared by the CPU and the CUDA device is written once, in headers, with every function
 * marked RS_HD.  Under nvcc that expands to `static inline __host__ __device__`; under a C11
 * compiler to `static inline`.  Such headers must compile as C11 and as CUDA C++: no `restrict`
 * (use RS_RESTRICT), no compound literals, no VLAs, no _Generic, no malloc and no stdio. */
#ifndef RS_CORE_HD_H
#define RS_CORE_HD_H

/* Which pass is reading, for the few functions whose device form differs (intrinsics, the device
 * copies of constant tables), so that no other file names a compiler: RS_CUDA_SOURCE under nvcc
 * (its host and device passes alike), RS_DEVICE_PASS in its device pass only. */
#if defined(__CUDACC__)
#  define RS_CUDA_SOURCE 1
#else
#  define RS_CUDA_SOURCE 0
#endif
#if defined(__CUDA_ARCH__)
#  define RS_DEVICE_PASS 1
#else
#  define RS_DEVICE_PASS 0
#endif

/* RS_HD_COLD: the same for a function off the common path (the GGX materials, normal maps,
 * textured material parameters), kept out of line so that its callers stay small enough to be
 * inlined where the common materials are shaded (measured: inlined, these made the Cornell box's
 * shading 19% more instructions). */
#if defined(__CUDACC__)
#  define RS_HD_COLD     static __noinline__ __host__ __device__
#elif defined(__GNUC__)
#  define RS_HD_COLD     static __attribute__((noinline, unused))
#else
#  define RS_HD_COLD     static
#endif

/* RS_HD_HOT: a function called once per path vertex that must stay inlined in its caller (the
 * shading loop): kept out of line, rs_shade_next_event cost the Cornell box 15% more shading
 * instructions, and rs_light_sample_one, rs_bsdf_sample and rs_bsdf_pdf_side 6% of its time (a
 * vector of three floats passed by value is stored in two pieces and read back in one: the load
 * waits for both stores, a store-forwarding stall at each call). */
#if defined(__CUDACC__)
#  define RS_HD_HOT      static __forceinline__ __host__ __device__
#elif defined(__GNUC__)
#  define RS_HD_HOT      static inline __attribute__((always_inline))
#else
#  define RS_HD_HOT      static inline
#endif

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

/* Relaxed atomic adds to memory every thread of a device writes (the wavefront's film): CUDA's
 * atomicAdd in the device pass, the GCC/Clang builtin on the host (the GPU fallback's threads). */
#if defined(__CUDA_ARCH__)
#  define RS_ATOMIC_ADD_U64(p, v) atomicAdd((unsigned long long *)(p), (unsigned long long)(v))
#  define RS_ATOMIC_ADD_U32(p, v) atomicAdd((unsigned int *)(p), (unsigned int)(v))
#else
#  define RS_ATOMIC_ADD_U64(p, v) __atomic_fetch_add((p), (v), __ATOMIC_RELAXED)
#  define RS_ATOMIC_ADD_U32(p, v) __atomic_fetch_add((p), (v), __ATOMIC_RELAXED)
#endif

/* A primitive index meaning "no hit". */
#define RS_NO_HIT 0xffffffffu

#endif
