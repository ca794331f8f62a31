/* core/alloc.c — see alloc.h. */
#include "core/alloc.h"

#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

static atomic_long g_fail_after = -1;
static rs_alloc_observer g_observer; /* a test hook: set while single-threaded (alloc.h) */
static void *g_observer_user;

static void *observed(void *p, size_t bytes)
{
    if (p && g_observer)
        g_observer(g_observer_user, p, bytes ? bytes : 1);
    return p;
}

int rs_mul_size(size_t a, size_t b, size_t *out)
{
    if (a != 0 && b > SIZE_MAX / a)
        return 0;
    *out = a * b;
    return 1;
}

static int should_fail(void)
{
    long left = atomic_load(&g_fail_after);
    while (left >= 0) {
        if (atomic_compare_exchange_weak(&g_fail_after, &left, left - 1))
            return left == 0;
    }
    return 0;
}

void *rs_alloc(size_t n, size_t size)
{
    size_t bytes;
    if (!rs_mul_size(n, size, &bytes) || should_fail())
        return NULL;
    return observed(malloc(bytes ? bytes : 1), bytes);
}

void *rs_calloc(size_t n, size_t size)
{
    size_t bytes;
    if (!rs_mul_size(n, size, &bytes) || should_fail())
        return NULL;
    return observed(calloc(bytes ? n : 1, bytes ? size : 1), bytes);
}

void *rs_alloc_aligned(size_t n, size_t size)
{
    size_t bytes;
    void *p = NULL;
    if (!rs_mul_size(n, size, &bytes) || should_fail())
        return NULL;
    bytes = (bytes + 63) & ~(size_t)63;
    if (posix_memalign(&p, 64, bytes ? bytes : 64) != 0)
        return NULL;
    return observed(p, bytes ? bytes : 64);
}

void rs_free(void *p)
{
    if (p && g_observer)
        g_observer(g_observer_user, p, 0);
    free(p);
}

void rs_alloc_set_observer(rs_alloc_observer fn, void *user)
{
    g_observer_user = user;
    g_observer = fn;
}

void rs_alloc_fail_after(long n) { atomic_store(&g_fail_after, n < 0 ? -1 : n); }

uint64_t rs_memory_budget(void)
{
    struct rlimit rl;
    uint64_t budget = 0;
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0)
        budget = (uint64_t)pages * (uint64_t)page;
    if (getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
        unsigned long long size = 0;
        uint64_t left = (uint64_t)rl.rlim_cur;
        FILE *f = fopen("/proc/self/statm", "r"); /* pages mapped now */
        if (f) {
            if (fscanf(f, "%llu", &size) == 1 && page > 0)
                left = size * (uint64_t)page < left ? left - size * (uint64_t)page : 0;
            fclose(f);
        }
        if (budget == 0 || left < budget)
            budget = left;
    }
    return budget;
}
