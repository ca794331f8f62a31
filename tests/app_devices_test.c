/* tests/app_devices_test.c — the rules of app/devices.c that need no device:
 *   - rs_devices_auto_gpus, --devices auto's share of a machine's GPUs for one of its MPI ranks:
 *     one rank takes every GPU; with at least as many GPUs as ranks every GPU goes to exactly
 *     one rank, round robin, and every rank gets one; with fewer GPUs than ranks every rank
 *     takes exactly one, every GPU is used and the ranks per GPU differ by at most one; the
 *     examples of `raystream render --help`;
 *   - rs_devices_local_rank reads the launchers' node-local rank and size (Open MPI, MPICH,
 *     MVAPICH, PMI, Slurm) and refuses an incomplete or inconsistent pair.
 * It links app/devices.c and the lines it prints through (app/fail.c). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>

#include "app/devices.h"
#include "app/render_run.h"

#define MAX_GPUS 16

static void expect_gpus(int rank, int size, int n_gpus, int n, const int *want)
{
    int out[MAX_GPUS], got, i;
    got = rs_devices_auto_gpus(rank, size, n_gpus, out);
    assert_int_equal(got, n);
    for (i = 0; i < n; ++i)
        assert_int_equal(out[i], want[i]);
}

static void test_examples(void **state)
{
    static const int all4[] = {0, 1, 2, 3}, even[] = {0, 2}, odd[] = {1, 3}, zero[] = {0},
                     one[] = {1};
    (void)state;
    expect_gpus(0, 1, 4, 4, all4); /* one rank: every GPU */
    expect_gpus(0, 0, 4, 4, all4); /* no size known: the same */
    expect_gpus(0, 2, 4, 2, even); /* --help: 2 ranks, 4 GPUs */
    expect_gpus(1, 2, 4, 2, odd);
    expect_gpus(0, 3, 2, 1, zero); /* --help: 3 ranks, 2 GPUs: ranks 0 and 2 share gpu 0 */
    expect_gpus(1, 3, 2, 1, one);
    expect_gpus(2, 3, 2, 1, zero);
    expect_gpus(3, 2, 4, 2, odd);  /* a rank past the size wraps */
    expect_gpus(-1, 2, 4, 2, odd); /* ... also below 0 */
    expect_gpus(0, 4, 0, 0, NULL); /* no GPU */
    expect_gpus(0, 1, 0, 0, NULL);
    expect_gpus(0, 4, -3, 0, NULL);
}

/* Every (ranks, GPUs) up to 9 x 16: the shares against the rule's promises. */
static void test_shares(void **state)
{
    int size, n_gpus, rank, i;
    (void)state;
    for (size = 1; size <= 9; ++size)
        for (n_gpus = 0; n_gpus <= MAX_GPUS; ++n_gpus) {
            int users[MAX_GPUS] = {0}, lo = size, hi = 0;
            for (rank = 0; rank < size; ++rank) {
                int out[MAX_GPUS], n = rs_devices_auto_gpus(rank, size, n_gpus, out);
                if (n_gpus == 0) {
                    assert_int_equal(n, 0);
                    continue;
                }
                assert_true(n >= 1);
                if (n_gpus < size)
                    assert_int_equal(n, 1);
                for (i = 0; i < n; ++i) {
                    assert_true(out[i] >= 0 && out[i] < n_gpus);
                    if (i > 0)
                        assert_true(out[i] > out[i - 1]);
                    users[out[i]]++;
                }
            }
            for (i = 0; i < n_gpus; ++i) {
                lo = users[i] < lo ? users[i] : lo;
                hi = users[i] > hi ? users[i] : hi;
            }
            if (n_gpus == 0)
                continue;
            assert_true(lo >= 1);      /* every GPU used */
            assert_true(hi - lo <= 1); /* ... evenly */
            if (n_gpus >= size)
                assert_int_equal(hi, 1); /* by exactly one rank */
        }
}

static const char *const launcher_vars[] = {"OMPI_COMM_WORLD_LOCAL_RANK",
                                            "OMPI_COMM_WORLD_LOCAL_SIZE",
                                            "MPI_LOCALRANKID",
                                            "MPI_LOCALNRANKS",
                                            "MV2_COMM_WORLD_LOCAL_RANK",
                                            "MV2_COMM_WORLD_LOCAL_SIZE",
                                            "PMI_LOCAL_RANK",
                                            "PMI_LOCAL_SIZE",
                                            "SLURM_LOCALID",
                                            "SLURM_NTASKS_PER_NODE"};

static void clear_launcher(void)
{
    size_t i;
    for (i = 0; i < sizeof launcher_vars / sizeof launcher_vars[0]; ++i)
        unsetenv(launcher_vars[i]);
}

static void expect_local(int found, int rank, int size)
{
    int r = -7, s = -7;
    assert_int_equal(rs_devices_local_rank(&r, &s), found);
    assert_int_equal(r, rank);
    assert_int_equal(s, size);
}

static void test_local_rank_env(void **state)
{
    size_t i;
    (void)state;
    clear_launcher();
    expect_local(0, 0, 1); /* no launcher */
    for (i = 0; i < sizeof launcher_vars / sizeof launcher_vars[0]; i += 2) {
        clear_launcher();
        setenv(launcher_vars[i], "2", 1);
        expect_local(0, 0, 1); /* a rank without a size */
        setenv(launcher_vars[i + 1], "4", 1);
        expect_local(1, 2, 4);
        setenv(launcher_vars[i + 1], "2", 1);
        expect_local(0, 0, 1); /* rank 2 of 2 */
        setenv(launcher_vars[i + 1], "4x", 1);
        expect_local(0, 0, 1);
        setenv(launcher_vars[i], "-1", 1);
        setenv(launcher_vars[i + 1], "4", 1);
        expect_local(0, 0, 1);
    }
    /* Open MPI's pair comes before Slurm's (mpirun inside an allocation sets both) */
    clear_launcher();
    setenv("SLURM_LOCALID", "0", 1);
    setenv("SLURM_NTASKS_PER_NODE", "1", 1);
    setenv("OMPI_COMM_WORLD_LOCAL_RANK", "1", 1);
    setenv("OMPI_COMM_WORLD_LOCAL_SIZE", "3", 1);
    expect_local(1, 1, 3);
    clear_launcher();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_examples),
        cmocka_unit_test(test_shares),
        cmocka_unit_test(test_local_rank_env),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
