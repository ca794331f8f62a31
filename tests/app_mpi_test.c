/* tests/app_mpi_test.c — `mpirun -n N raystream render ...` (app/distributed.c), run for real
 * with Open MPI's mpirun on this machine (--oversubscribe: more ranks than cores; and
 * --allow-run-as-root when root, as in CI).  Skipped, saying why, where the binary was built
 * without MPI or mpirun is missing.
 *
 * What is checked:
 *   - 2 and 3 ranks, the stream engine and the megakernel, automatic and odd pass sizes, the
 *     sobol and zsobol samplers: the image equals the one-process render bit for bit;
 *   - a rank slowed on purpose (RS_MPI_FAULT=slow:1:4) finishes fewer passes than rank 0, and
 *     the image is still the same;
 *   - a rank that kills itself after one pass (RS_MPI_FAULT=die:1:1): with --enable-recovery it
 *     is found dead after --mpi-timeout, its passes go to the others and the image is the same;
 *     without it, mpirun ends the job, and the run neither hangs nor writes a broken image;
 *   - --time-limit stops at whole passes: the image equals a one-process render of the samples
 *     it says it holds;
 *   - a rank killed without --enable-recovery: rank 0 writes a checkpoint of what the others
 *     finished, with gaps where the dead rank's passes were; resuming it on one process, on
 *     the megakernel and under mpirun gives the uninterrupted image bit for bit;
 *   - --checkpoint-interval under mpirun flushes every rank's film to rank 0 on the way;
 *   - Ctrl-C on mpirun ends every rank within seconds, with 128 + the signal or mpirun's code;
 *   - a rank that dies while it loads the scene or before MPI starts, under --enable-recovery:
 *     the others give up within the bound (--mpi-timeout; MPI_Init at least 10 s), one line
 *     names the rank or says MPI did not start, no image;
 *   - --adaptive (rank 0 decides each round from the merged film) with 2 and 3 ranks and odd
 *     pass sizes, after a rank died in an early round, and stopped by the time limit with a
 *     checkpoint resumed on one process and under mpirun: the one-process adaptive image;
 *   - --aov all --denoise under 2 ranks (the film's passes written on every rank, sent with
 *     its film): every channel of the EXR (the denoised beauty, the raw one, albedo, normal,
 *     depth, samples) is the one-process file's bit for bit (--aov all alone where OIDN is
 *     missing);
 *   - a bad RS_MPI_FAULT is refused by rank 0 alone, in one line. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define RS_HARNESS_NAME "app_mpi_test.c"
#include "cli_harness.h"

#define TIMEOUT_S 120.0
#define SIZE      "48"

static char g_skip[256];

/* mpirun with the flags this machine needs, then `args` (NULL-terminated), in f's folder */
/* recovery: 1 adds --enable-recovery; 2 gives the ranks 5 s from mpirun's SIGTERM to its
 * SIGKILL (odls_base_sigkill_timeout) */
static void mpirun(proc *p, const fixture *f, int ranks, int recovery, const char *const *args)
{
    const char *argv[MAX_ARGS + 1];
    char n[16];
    int k = 0, i;
    snprintf(n, sizeof n, "%d", ranks);
    argv[k++] = "-n";
    argv[k++] = n;
    argv[k++] = "--oversubscribe";
    if (geteuid() == 0)
        argv[k++] = "--allow-run-as-root";
    if (recovery == 1)
        argv[k++] = "--enable-recovery";
    if (recovery == 2) {
        argv[k++] = "--mca";
        argv[k++] = "odls_base_sigkill_timeout";
        argv[k++] = "5";
    }
    argv[k++] = "-x";
    argv[k++] = "RS_MPI_FAULT";
    argv[k++] = RS_BINARY;
    for (i = 0; args[i] && k < MAX_ARGS; ++i)
        argv[k++] = args[i];
    argv[k] = NULL;
    proc_start_prog(p, f->dir, "mpirun", argv);
    proc_finish(p, TIMEOUT_S);
}

/* the one-process render of `args` into `out` */
static image one_process(const fixture *f, const char *const *args, const char *out)
{
    const char *argv[MAX_ARGS + 1];
    proc p;
    image im;
    int k = 0, i;
    for (i = 0; args[i]; ++i)
        argv[k++] = args[i];
    argv[k++] = "-o";
    argv[k++] = out;
    argv[k] = NULL;
    run(&p, f->dir, TIMEOUT_S, argv);
    EXPECT(&p, exited_with(&p, 0), "the one-process render failed");
    im = read_image(&p, f, out);
    proc_free(&p);
    return im;
}

/* A number after `"key": ` in a JSON text (the first one after `after`, if given), or -1. */
static double json_number(const char *text, const char *after, const char *key)
{
    char pat[64];
    const char *s = after ? strstr(text, after) : text;
    if (!s)
        return -1;
    snprintf(pat, sizeof pat, "\"%s\": ", key);
    s = strstr(s, pat);
    return s ? atof(s + strlen(pat)) : -1;
}

static char *read_text(const fixture *f, const char *name)
{
    char path[256];
    size_t n = 0;
    path_in(f, name, path, sizeof path);
    return read_bytes(path, &n);
}

/* ---- the same image for any ranks -------------------------------------------------------- */

static void expect_same_as_one(const fixture *f, int ranks, const char *const *args,
                               const char *extra1, const char *extra2)
{
    const char *argv[MAX_ARGS + 1];
    image one, many;
    proc p;
    int k = 0, i;
    one = one_process(f, args, "one.exr");
    for (i = 0; args[i]; ++i)
        argv[k++] = args[i];
    argv[k++] = "-o";
    argv[k++] = "many.exr";
    if (extra1)
        argv[k++] = extra1;
    if (extra2)
        argv[k++] = extra2;
    argv[k] = NULL;
    mpirun(&p, f, ranks, 0, argv);
    EXPECT(&p, exited_with(&p, 0), "mpirun -n %d failed", ranks);
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "%d ranks did not give the one-process image", ranks);
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

static void test_same_image_any_ranks(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const stream[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                         SIZE, "--spp", "12", "-q", NULL};
    static const char *const mega[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                       SIZE, "--spp", "12", "--integrator", "megakernel", "-q",
                                       NULL};
    static const char *const zsobol[] = {"render", "builtin:rtiow-final", "--width", SIZE, "--height",
                                         SIZE, "--spp", "16", "--sampler", "zsobol", "-q", NULL};
    expect_same_as_one(f, 2, stream, NULL, NULL);
    expect_same_as_one(f, 3, stream, "--mpi-pass", "5"); /* passes of 5, 5 and 2 samples */
    expect_same_as_one(f, 2, mega, "--mpi-pass", "1");
    expect_same_as_one(f, 3, zsobol, "--mpi-pass", "3");
}

/* ---- adaptive sampling: rank 0 decides each round from the merged film ------------------- */

static void test_adaptive_same_image(void **state)
{
    const fixture *f = (const fixture *)*state;
    /* a threshold at which pixels stop after different rounds (the summary says how many) */
    static const char *const args[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                       SIZE, "--spp", "64", "--adaptive", "0.05", "-q", NULL};
    static const char *const zsobol[] = {"render", "builtin:rtiow-final", "--width", SIZE,
                                         "--height", SIZE, "--spp", "32", "--adaptive", "0.1",
                                         "--sampler", "zsobol", "-q", NULL};
    expect_same_as_one(f, 2, args, NULL, NULL);
    expect_same_as_one(f, 3, args, "--mpi-pass", "1"); /* each round in one-sample passes */
    expect_same_as_one(f, 3, zsobol, "--mpi-pass", "3");
}

/* Stopped by the time limit between or within rounds, with a checkpoint: resumed on one process
 * and under mpirun, it is the uninterrupted one-process render. */
static void test_adaptive_checkpoint_resume(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "256", "--adaptive", "0.02", "-q", NULL};
    static const char *const cut[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "256", "--adaptive", "0.02", "--time-limit",
                                      "0.4", "--mpi-pass", "2", "--checkpoint", "a.ckpt", "-q",
                                      "-o", "cut.exr", NULL};
    static const char *const resume[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                         "64", "--spp", "256", "--adaptive", "0.02", "--resume",
                                         "a.ckpt", "-q", NULL};
    const char *argv[MAX_ARGS + 1];
    image one, again, many;
    proc p;
    int k = 0, i;
    mpirun(&p, f, 2, 0, cut);
    EXPECT(&p, exited_with(&p, 0), "the time-limited adaptive job failed");
    proc_free(&p);
    one = one_process(f, ref, "one.exr");
    again = one_process(f, resume, "again.exr");
    EXPECT(&p, same_image(&one, &again),
           "an adaptive MPI checkpoint resumed on one process is not the one-process image");
    for (i = 0; resume[i]; ++i)
        argv[k++] = resume[i];
    argv[k++] = "-o";
    argv[k++] = "many.exr";
    argv[k] = NULL;
    mpirun(&p, f, 3, 0, argv);
    EXPECT(&p, exited_with(&p, 0), "resuming the adaptive checkpoint under mpirun failed");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many),
           "an adaptive MPI checkpoint resumed under mpirun is not the one-process image");
    rs_free(one.rgb);
    rs_free(again.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

/* A rank that dies in an early round: found dead, left out of the later rounds, same image. */
static void test_adaptive_killed_rank(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                       SIZE, "--spp", "64", "--adaptive", "0.05", "--mpi-pass",
                                       "1", "--mpi-timeout", "2", "-q", "-o", "many.exr", NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                      SIZE, "--spp", "64", "--adaptive", "0.05", "-q", NULL};
    image one, many;
    proc p;
    setenv("RS_MPI_FAULT", "die:2:2", 1);
    mpirun(&p, f, 3, 1, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, exited_with(&p, 0), "the adaptive job with a dead rank failed");
    EXPECT(&p, strstr(p.err.data, "rank 2") != NULL, "the dead rank was not reported");
    one = one_process(f, ref, "one.exr");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "the adaptive image changed with a dead rank");
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

/* ---- load balance ------------------------------------------------------------------------ */

static void test_slow_rank_gets_fewer_passes(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "48", "--mpi-pass", "2", "--threads", "1",
                                       "-q", "-o", "many.exr", "--stats-json", "s.json", NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "48", "-q", NULL};
    image one, many;
    proc p;
    char *json;
    double p0, p1;
    setenv("RS_MPI_FAULT", "slow:1:4", 1);
    mpirun(&p, f, 2, 0, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, exited_with(&p, 0), "the job with a slow rank failed");
    json = read_text(f, "s.json");
    EXPECT(&p, json != NULL, "no --stats-json");
    p0 = json_number(json, "\"rank\": 0", "passes");
    p1 = json_number(json, "\"rank\": 1", "passes");
    EXPECT(&p, p0 + p1 == 24, "the passes do not add up: %g + %g of 24", p0, p1);
    /* rank 1 takes 4x as long per pass: it should get about a fifth; well under half */
    EXPECT(&p, p1 >= 1 && p1 < p0 / 2, "the slow rank got %g passes against %g", p1, p0);
    one = one_process(f, ref, "one.exr");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "the image changed with a slow rank");
    free(json);
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

/* ---- a rank that dies -------------------------------------------------------------------- */

static void test_killed_rank_recovered(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "32", "--mpi-pass", "2", "--mpi-timeout",
                                       "2", "-q", "-o", "many.exr", "--stats-json", "s.json",
                                       NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "32", "-q", NULL};
    image one, many;
    proc p;
    char *json;
    setenv("RS_MPI_FAULT", "die:1:1", 1);
    mpirun(&p, f, 3, 1, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out && p.seconds < 60, "the job with a dead rank hung");
    EXPECT(&p, exited_with(&p, 0), "the job did not survive the dead rank");
    EXPECT(&p, strstr(p.err.data, "rank 1") && strstr(p.err.data, "silent"),
           "the dead rank was not named");
    json = read_text(f, "s.json");
    EXPECT(&p, json != NULL, "no --stats-json");
    EXPECT(&p, json_number(json, NULL, "ranks_lost") == 1, "ranks_lost is not 1");
    EXPECT(&p, json_number(json, NULL, "reissued") >= 1, "no pass was handed out again");
    one = one_process(f, ref, "one.exr");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "the passes handed out again changed the image");
    free(json);
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

static void test_killed_rank_does_not_hang(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "400", "--mpi-pass", "2", "-q", "-o",
                                       "many.exr", NULL};
    proc p;
    char path[256];
    setenv("RS_MPI_FAULT", "die:1:1", 1);
    mpirun(&p, f, 2, 0, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out && p.seconds < 30, "the job with a dead rank hung");
    EXPECT(&p, !exited_with(&p, 0), "mpirun said the job with a dead rank succeeded");
    path_in(f, "many.exr", path, sizeof path);
    if (file_exists(path)) { /* rank 0 had time to write what it had: a whole image */
        image im = read_image(&p, f, "many.exr");
        EXPECT(&p, im.w == 64 && im.h == 64, "a broken partial image");
        rs_free(im.rgb);
    }
    proc_free(&p);
}

/* A rank that dies while it starts, under --enable-recovery (where nothing ends the job for
 * us): at the end of its set-up (the scene loaded), and before MPI starts.  The others give up
 * within the bound, say which rank or why, and write nothing.  (Before the start-up agreement
 * was bounded, both hung for ever in MPI_Allreduce and MPI_Init.) */
static void test_rank_dead_while_starting(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "48", "--height",
                                       "48", "--spp", "8", "--mpi-timeout", "2", "-q", "-o",
                                       "many.exr", NULL};
    proc p;
    char path[256];
    setenv("RS_MPI_FAULT", "die-start:2", 1);
    mpirun(&p, f, 3, 1, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out && p.seconds < 30, "a rank dead while loading hung the others");
    EXPECT(&p, strstr(p.err.data, "rank 2 has been silent") != NULL,
           "rank 0 did not name the rank that died while starting");
    path_in(f, "many.exr", path, sizeof path);
    EXPECT(&p, !file_exists(path), "an image was written though a rank never started");
    proc_free(&p);
    setenv("RS_MPI_FAULT", "die-init:1", 1);
    mpirun(&p, f, 3, 1, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out && p.seconds < 40, "a rank dead before MPI_Init hung the others");
    EXPECT(&p, strstr(p.err.data, "MPI did not start within") != NULL,
           "no line says MPI did not start");
    EXPECT(&p, !file_exists(path), "an image was written though a rank never started");
    proc_free(&p);
}

/* The number of path ranges a checkpoint holds (app/checkpoint.h: after the scene name), or
 * -1. */
static int checkpoint_ranges(const fixture *f, const char *name)
{
    char path[256];
    size_t n = 0;
    uint32_t name_len, ranges;
    char *data;
    path_in(f, name, path, sizeof path);
    data = read_bytes(path, &n);
    if (!data || n < 100) {
        free(data);
        return -1;
    }
    memcpy(&name_len, data + 88, 4);
    if (92 + (size_t)name_len + 4 > n) {
        free(data);
        return -1;
    }
    memcpy(&ranges, data + 92 + name_len, 4);
    free(data);
    return (int)ranges;
}

static void expect_resumes_to(const fixture *f, const image *full, int ranks,
                              const char *integrator)
{
    const char *args[16] = {"render", "builtin:cornell", "--width", "64", "--height", "64",
                            "--spp", "200", "--resume", "ck.ckpt", "-q", "-o", "res.exr",
                            "--integrator", integrator, NULL};
    proc p;
    image im;
    if (ranks > 1)
        mpirun(&p, f, ranks, 0, args);
    else
        run(&p, f->dir, TIMEOUT_S, args);
    EXPECT(&p, exited_with(&p, 0), "resuming the checkpoint with gaps failed");
    im = read_image(&p, f, "res.exr");
    EXPECT(&p, same_image(full, &im), "the resumed image (%d rank%s, %s) is not the full one",
           ranks, ranks > 1 ? "s" : "", integrator);
    rs_free(im.rgb);
    proc_free(&p);
}

static void test_checkpoint_with_gaps(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "200", "--mpi-pass", "2", "--checkpoint",
                                       "ck.ckpt", "-q", "-o", "part.exr", NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "200", "-q", NULL};
    image full;
    proc p;
    char path[256];
    setenv("RS_MPI_FAULT", "die:1:2", 1);
    mpirun(&p, f, 2, 2, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out && !exited_with(&p, 0), "the job with a dead rank did not fail");
    path_in(f, "ck.ckpt", path, sizeof path);
    EXPECT(&p, file_exists(path), "no checkpoint of what the live ranks finished");
    EXPECT(&p, checkpoint_ranges(f, "ck.ckpt") >= 2,
           "the checkpoint has no gap (%d ranges): the dead rank's passes were not lost",
           checkpoint_ranges(f, "ck.ckpt"));
    EXPECT(&p, strstr(p.err.data, "rank 1") != NULL, "the lost rank was not named");
    proc_free(&p);
    full = one_process(f, ref, "full.exr");
    expect_resumes_to(f, &full, 1, "stream");
    expect_resumes_to(f, &full, 1, "megakernel");
    expect_resumes_to(f, &full, 2, "stream");
    rs_free(full.rgb);
}

static void test_periodic_checkpoints(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "64", "--mpi-pass", "1", "--checkpoint",
                                       "ck.ckpt", "--checkpoint-interval", "0.05", "-q", "-o",
                                       "many.exr", "--stats-json", "s.json", NULL};
    static const char *const ref[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                      "64", "--spp", "64", "-q", NULL};
    image one, many;
    proc p;
    char *json;
    setenv("RS_MPI_FAULT", "slow:1:2", 1);
    mpirun(&p, f, 2, 0, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, exited_with(&p, 0), "the job with periodic checkpoints failed");
    json = read_text(f, "s.json");
    EXPECT(&p, json && json_number(json, NULL, "flushes") >= 1, "no periodic flush happened");
    one = one_process(f, ref, "one.exr");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "the flushes changed the image");
    free(json);
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

/* ---- stopping ---------------------------------------------------------------------------- */

static void test_time_limit_whole_passes(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "100000", "--mpi-pass", "2",
                                       "--time-limit", "1", "-q", "-o", "many.exr",
                                       "--stats-json", "s.json", NULL};
    const char *ref[12] = {"render", "builtin:cornell", "--width", "64", "--height", "64",
                           "--spp", NULL, "-q", NULL};
    char spp[32];
    image one, many;
    proc p;
    char *json;
    double got;
    mpirun(&p, f, 2, 0, args);
    EXPECT(&p, exited_with(&p, 0), "the time-limited job failed");
    EXPECT(&p, p.seconds < 30, "the time limit did not stop the job");
    json = read_text(f, "s.json");
    EXPECT(&p, json != NULL, "no --stats-json");
    got = json_number(json, NULL, "spp");
    EXPECT(&p, got >= 2 && got < 100000 && (int)got % 2 == 0,
           "the film holds %g samples per pixel, not whole passes of 2", got);
    EXPECT(&p, strstr(json, "\"time_limited\": true") != NULL, "time_limited is not true");
    EXPECT(&p, strstr(json, "\"complete\": false") != NULL, "the job says it is complete");
    snprintf(spp, sizeof spp, "%d", (int)got);
    ref[7] = spp;
    one = one_process(f, ref, "one.exr");
    many = read_image(&p, f, "many.exr");
    EXPECT(&p, same_image(&one, &many), "the time-limited image is not the %s-spp image", spp);
    free(json);
    rs_free(one.rgb);
    rs_free(many.rgb);
    proc_free(&p);
}

static void test_ctrl_c_stops_every_rank(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", "64", "--height",
                                       "64", "--spp", "100000", "-q", "-o", "many.exr", NULL};
    const char *argv[MAX_ARGS + 1];
    proc p;
    char path[256];
    int k = 0, i;
    argv[k++] = "-n";
    argv[k++] = "2";
    argv[k++] = "--oversubscribe";
    if (geteuid() == 0)
        argv[k++] = "--allow-run-as-root";
    argv[k++] = RS_BINARY;
    for (i = 0; args[i]; ++i)
        argv[k++] = args[i];
    argv[k] = NULL;
    proc_start_prog(&p, f->dir, "mpirun", argv);
    while (rs_now_s() - p.start < 3.0)
        proc_pump(&p, 50);
    kill(p.pid, SIGINT);
    proc_finish(&p, 30.0);
    EXPECT(&p, !p.timed_out, "Ctrl-C did not end the job");
    EXPECT(&p, !exited_with(&p, 0), "an interrupted job exited 0");
    path_in(f, "many.exr", path, sizeof path);
    if (file_exists(path)) {
        image im = read_image(&p, f, "many.exr");
        EXPECT(&p, im.w == 64 && im.h == 64, "a broken partial image");
        rs_free(im.rgb);
    }
    proc_free(&p);
}

/* An adaptive job with --checkpoint whose rank dies without mpirun's recovery: mpirun stops
 * the others (SIGTERM) within a round whose dead rank's passes are missing; the checkpoint keeps
 * the last one written (said once) and the partial image is written without a failure (issue
 * 39: rank 0 then failed renaming the checkpoint it had never written: "cannot put the finished
 * file in place", "the run failed; some outputs were already replaced"). */
static void test_adaptive_stop_keeps_checkpoint(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                       SIZE, "--spp", "64", "--adaptive", "0.05", "--mpi-pass",
                                       "1", "--mpi-timeout", "2", "-q", "-o", "many.exr",
                                       "--checkpoint", "many.ckpt", NULL};
    proc p;
    char path[256];
    setenv("RS_MPI_FAULT", "die:2:2", 1);
    mpirun(&p, f, 3, 0, args);
    setenv("RS_MPI_FAULT", "", 1);
    EXPECT(&p, !p.timed_out, "the job did not end");
    printf("  %s\n", strstr(p.err.data, "not updated") ? "stopped within a round: checkpoint kept"
                                                       : "stopped between rounds");
    EXPECT(&p, strstr(p.err.data, "the run failed") == NULL &&
                   strstr(p.err.data, "cannot put the finished file") == NULL,
           "a stopped adaptive job with --checkpoint failed its outputs: %s", p.err.data);
    path_in(f, "many.exr", path, sizeof path);
    EXPECT(&p, file_exists(path), "no partial image");
    proc_free(&p);
}

/* Channel `ch` of `a` and of `b` (files in f's folder) the same, bit for bit. */
static void expect_same_channel(const proc *p, const fixture *f, const char *a, const char *b,
                                const char *ch)
{
    char pa[256], pb[256];
    float *da = NULL, *db = NULL;
    uint32_t wa = 0, ha = 0, wb = 0, hb = 0;
    path_in(f, a, pa, sizeof pa);
    path_in(f, b, pb, sizeof pb);
    EXPECT(p, rs_image_read_channel(pa, ch, &wa, &ha, &da) == RS_OK, "%s has no channel %s", a,
           ch);
    EXPECT(p, rs_image_read_channel(pb, ch, &wb, &hb, &db) == RS_OK, "%s has no channel %s", b,
           ch);
    EXPECT(p, wa == wb && ha == hb && memcmp(da, db, (size_t)wa * ha * sizeof(float)) == 0,
           "channel %s of %s is not the one-process render's", ch, b);
    rs_free(da);
    rs_free(db);
}

static void test_aov_denoise_same_image(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const chans[] = {"R",        "G",        "B",        "albedo.R",
                                        "albedo.G", "albedo.B", "normal.X", "normal.Y",
                                        "normal.Z", "depth.Z",  "samples.Y", "noisy.R",
                                        "noisy.G",  "noisy.B"};
    static const char *const with[] = {"render", "builtin:cornell", "--width", SIZE, "--height",
                                       SIZE, "--spp", "8", "--aov", "all", "--denoise", "-q",
                                       NULL};
    static const char *const without[] = {"render", "builtin:cornell", "--width", SIZE,
                                          "--height", SIZE, "--spp", "8", "--aov", "all", "-q",
                                          NULL};
    const char *const *args = with;
    const char *argv[MAX_ARGS + 1];
    size_t n_chans = sizeof chans / sizeof chans[0], k;
    int i;
    proc p;
    for (i = 0; with[i]; ++i)
        argv[i] = with[i];
    argv[i++] = "-o";
    argv[i++] = "one.exr";
    argv[i] = NULL;
    run(&p, f->dir, TIMEOUT_S, argv);
    if (exited_with(&p, 1) && strstr(p.err.data, "raystream: --denoise: ")) {
        printf("  no OIDN here (%.*s): --aov all alone\n", (int)strcspn(p.err.data, "\n"),
               p.err.data);
        args = without;
        n_chans -= 3; /* no raw layer beside a denoised beauty */
        rs_free(one_process(f, without, "one.exr").rgb);
    } else {
        EXPECT(&p, exited_with(&p, 0), "the one-process render with --aov all --denoise failed");
    }
    proc_free(&p);
    for (i = 0; args[i]; ++i)
        argv[i] = args[i];
    argv[i++] = "-o";
    argv[i++] = "many.exr";
    argv[i] = NULL;
    mpirun(&p, f, 2, 0, argv);
    EXPECT(&p, exited_with(&p, 0), "mpirun -n 2 with --aov all%s failed",
           args == with ? " --denoise" : "");
    for (k = 0; k < n_chans; ++k)
        expect_same_channel(&p, f, "one.exr", "many.exr", chans[k]);
    printf("  --aov all%s under 2 ranks: %zu channels the one-process render's\n",
           args == with ? " --denoise" : "", n_chans);
    proc_free(&p);
}

static void test_bad_fault(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const plain[] = {"render", "builtin:cornell", "-q", NULL};
    proc p;
    const char *s;
    int lines = 0;
    setenv("RS_MPI_FAULT", "die:0:x", 1);
    mpirun(&p, f, 2, 0, plain);
    setenv("RS_MPI_FAULT", "", 1);
    for (s = strstr(p.err.data, "raystream:"); s; s = strstr(s + 1, "raystream:"))
        ++lines;
    EXPECT(&p, !exited_with(&p, 0) && lines == 1 && strstr(p.err.data, "RS_MPI_FAULT"),
           "a bad RS_MPI_FAULT is not one line (%d lines)", lines);
    proc_free(&p);
}

/* --tev under mpirun: one warning (no live preview there), and the render goes on.  Lines are
 * counted by the program's prefix, as test_bad_fault does: a sanitizer build's ranks add their
 * own report to stderr as they exit. */
static void test_tev_warns(void **state)
{
    const fixture *f = (const fixture *)*state;
    static const char *const args[] = {
        "render", "builtin:cornell", "--width", "32", "--spp", "2", "--tev", "1", "-q",
        "-o",     "out.pfm",         NULL};
    proc p;
    const char *s;
    int lines = 0;
    mpirun(&p, f, 2, 0, args);
    for (s = strstr(p.err.data, "raystream:"); s; s = strstr(s + 1, "raystream:"))
        ++lines;
    EXPECT(&p,
           exited_with(&p, 0) && lines == 1 &&
               strstr(p.err.data, "raystream: warning: --tev: no live preview under mpirun"),
           "--tev under mpirun: one warning line, then the render (%d lines)", lines);
    proc_free(&p);
}

static void asan_full_unwind(void)
{
    const char *asan = getenv("ASAN_OPTIONS");
    char opts[512];
    snprintf(opts, sizeof opts, "%s%sfast_unwind_on_malloc=0", asan ? asan : "",
             asan && *asan ? ":" : "");
    setenv("ASAN_OPTIONS", opts, 1);
}

static int find_mpi(void)
{
    static const char *const version[] = {"--version", NULL};
    fixture f;
    proc p;
    strcpy(f.dir, "/tmp");
    run(&p, f.dir, TIMEOUT_S, version);
    if (!strstr(p.out.data, "MPI:         yes"))
        snprintf(g_skip, sizeof g_skip, "%s was built without MPI", RS_BINARY);
    proc_free(&p);
    if (!g_skip[0] && system("mpirun --version >/dev/null 2>&1") != 0)
        snprintf(g_skip, sizeof g_skip, "mpirun is not on PATH (apt-get install openmpi-bin)");
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_same_image_any_ranks, setup, teardown),
        cmocka_unit_test_setup_teardown(test_tev_warns, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive_same_image, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive_checkpoint_resume, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive_killed_rank, setup, teardown),
        cmocka_unit_test_setup_teardown(test_slow_rank_gets_fewer_passes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_killed_rank_recovered, setup, teardown),
        cmocka_unit_test_setup_teardown(test_killed_rank_does_not_hang, setup, teardown),
        cmocka_unit_test_setup_teardown(test_rank_dead_while_starting, setup, teardown),
        cmocka_unit_test_setup_teardown(test_checkpoint_with_gaps, setup, teardown),
        cmocka_unit_test_setup_teardown(test_periodic_checkpoints, setup, teardown),
        cmocka_unit_test_setup_teardown(test_time_limit_whole_passes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_ctrl_c_stops_every_rank, setup, teardown),
        cmocka_unit_test_setup_teardown(test_adaptive_stop_keeps_checkpoint, setup, teardown),
        cmocka_unit_test_setup_teardown(test_aov_denoise_same_image, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_fault, setup, teardown),
    };
    find_mpi();
    if (g_skip[0]) {
        printf("app_mpi_test: skipped: %s\n", g_skip);
        return 77;
    }
    setenv("RS_MPI_FAULT", "", 1);
    /* under AddressSanitizer the binary knows Open MPI's leaks (app/distributed.c); for them to
     * be traced to its libraries, allocations are unwound in full (ignored by other builds) */
    asan_full_unwind();
    return cmocka_run_group_tests(tests, group_setup, NULL);
}
