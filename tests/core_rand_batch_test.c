/* tests/core_rand_batch_test.c — core/rand_batch.h: many paths' random numbers at once.
 *
 * What is checked: for random seeds, pixels, samples, bounces and groups, and every batch length
 * from 0 to 40 (whole vectors and every tail), each number of rs_rand_batch_sobol and
 * rs_rand_batch_philox is bit for bit rs_sobol_float4's and rs_rng_float4's, on the scalar code
 * and on every vector code this CPU runs (the stream stages rely on it: their images must equal
 * the megakernels').  Also the edge words 0 and 0xffffffff.  Fixed seeds: every run is the same. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <string.h>

#include "core/rand_batch.h"
#include "core/sobol.h"
#include "test_rand.h"

#define MAXN 40

static void check_isa(rs_rand_isa isa)
{
    uint64_t s = 12345 + (uint64_t)isa;
    uint32_t n, t;
    for (t = 0; t < 200; ++t)
        for (n = 0; n <= MAXN; ++n) {
            uint32_t pixel[MAXN], sample[MAXN], i;
            rs_rng_f4 a[MAXN + 1], b[MAXN + 1];
            uint64_t seed = t % 3 == 0 ? t : splitmix64(&s);
            uint32_t bounce = (uint32_t)(splitmix64(&s) % 64), group = (uint32_t)(t % 4);
            for (i = 0; i < n; ++i) {
                uint64_t r = splitmix64(&s);
                pixel[i] = i % 7 == 0 ? 0u : i % 7 == 1 ? 0xffffffffu : (uint32_t)r;
                sample[i] = i % 5 == 0 ? 0u : i % 5 == 1 ? 0xffffffffu : (uint32_t)(r >> 40);
            }
            /* the entry after the last must stay untouched */
            memset(a, 0xab, sizeof a);
            memcpy(b, a, sizeof b);
            rs_rand_batch_sobol(seed, pixel, sample, bounce, group, n, a);
            for (i = 0; i < n; ++i)
                b[i] = rs_sobol_float4(seed, pixel[i], sample[i], bounce, group);
            assert_memory_equal(a, b, sizeof a);
            memset(a, 0xcd, sizeof a);
            memcpy(b, a, sizeof b);
            rs_rand_batch_philox(seed, pixel, sample, bounce, group, n, a);
            for (i = 0; i < n; ++i)
                b[i] = rs_rng_float4(seed, pixel[i], sample[i], bounce, group);
            assert_memory_equal(a, b, sizeof a);
        }
}

static void test_scalar(void **state)
{
    (void)state;
    assert_int_equal(rs_rand_batch_use(RS_RAND_ISA_SCALAR), RS_RAND_ISA_SCALAR);
    check_isa(RS_RAND_ISA_SCALAR);
    rs_rand_batch_use(RS_RAND_ISA_AUTO);
}

static void test_avx2(void **state)
{
    (void)state;
    if (rs_rand_batch_use(RS_RAND_ISA_AVX2) != RS_RAND_ISA_AVX2) {
        rs_rand_batch_use(RS_RAND_ISA_AUTO);
        skip();
    }
    check_isa(RS_RAND_ISA_AVX2);
    rs_rand_batch_use(RS_RAND_ISA_AUTO);
}

static void test_avx2_gfni(void **state)
{
    (void)state;
    if (rs_rand_batch_use(RS_RAND_ISA_AVX2_GFNI) != RS_RAND_ISA_AVX2_GFNI) {
        rs_rand_batch_use(RS_RAND_ISA_AUTO);
        print_message("skipped: this CPU has no GFNI\n");
        skip();
    }
    check_isa(RS_RAND_ISA_AVX2_GFNI);
    rs_rand_batch_use(RS_RAND_ISA_AUTO);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scalar),
        cmocka_unit_test(test_avx2),
        cmocka_unit_test(test_avx2_gfni),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
