/* core/cores.c — see cores.h. */
#define _GNU_SOURCE /* sched_getaffinity, CPU_COUNT */
#include "core/cores.h"

#include <sched.h>
#include <unistd.h>

void rs_cores_init(rs_cores *c, int total)
{
    c->total = total < 1 ? 1 : total;
    atomic_init(&c->free, c->total);
}

int rs_cores_acquire(rs_cores *c, int want)
{
    int f, n;
    if (want < 1)
        want = 1;
    if (!c)
        return want;
    f = atomic_load(&c->free);
    do {
        n = f >= want ? want : (f > 1 ? f : 1);
    } while (!atomic_compare_exchange_weak(&c->free, &f, f - n));
    return n;
}

void rs_cores_release(rs_cores *c, int n)
{
    if (c)
        atomic_fetch_add(&c->free, n);
}

int rs_cores_allowed(void)
{
#ifdef __linux__
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set);
#endif
    {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        return n > 0 ? (int)n : 1;
    }
}
