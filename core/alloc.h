/* core/alloc.h — the one allocator hook.  Every allocation of the library goes through here so
 * that tests can make the n-th allocation fail (rs_alloc_fail_after) and check that each caller
 * cleans up and reports RS_ERR_NOMEM.  Sizes are overflow-checked. */
#ifndef RS_CORE_ALLOC_H
#define RS_CORE_ALLOC_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif
/* n * size bytes, uninitialised, or NULL if the product overflows or memory is short. */
void *rs_alloc(size_t n, size_t size);
/* n * size zeroed bytes, or NULL. */
void *rs_calloc(size_t n, size_t size);
/* 64-byte aligned n * size bytes (for stream arrays), or NULL.  Free with rs_free. */
void *rs_alloc_aligned(size_t n, size_t size);
void rs_free(void *p);
/* Test hook: the allocation after the next `n` ones fails; n < 0 switches failures off. */
void rs_alloc_fail_after(long n);
/* Test hook: fn(user, p, bytes) after every allocation that succeeds (bytes >= 1, the block's
 * usable size as asked for; 1 for a zero-byte request), and fn(user, p, 0) from rs_free(p) for
 * p != NULL before p is freed.  NULL switches it off.  Set it only while no other thread
 * allocates; fn is called from whatever thread allocates, so it must be thread-safe where the
 * code it observes allocates on several threads. */
typedef void (*rs_alloc_observer)(void *user, void *p, size_t bytes);
void rs_alloc_set_observer(rs_alloc_observer fn, void *user);
/* Overflow-checked a * b; returns 0 and leaves *out alone on overflow. */
int rs_mul_size(size_t a, size_t b, size_t *out);
/* Bytes this process may still allocate, for checks before a large allocation whose size is
 * known from a small input (an image's header): the address-space limit (ulimit -v) less what
 * is mapped now, at most the machine's physical memory; 0 when neither can be read. */
uint64_t rs_memory_budget(void);
#ifdef __cplusplus
}
#endif
#endif
