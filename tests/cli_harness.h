/* tests/cli_harness.h — running the real `raystream` binary from a cmocka test: fork/execv (no
 * shell) inside a fresh temporary folder per test, stdout and stderr captured, killed and failed
 * past a time limit; reading its images back.  Included by app_cli_test.c and app_mpi_test.c
 * (each defines RS_BINARY, and may define RS_HARNESS_NAME for messages). */
#ifndef RS_TESTS_CLI_HARNESS_H
#define RS_TESTS_CLI_HARNESS_H

/* a test uses some of these helpers only */
#pragma GCC diagnostic ignored "-Wunused-function"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "core/image_io.h"

#ifndef RS_BINARY
#  error "RS_BINARY must name the raystream executable"
#endif
#ifndef RS_HARNESS_NAME
#  define RS_HARNESS_NAME "app_cli_test.c"
#endif

#define MAX_ARGS          32
#define DEFAULT_TIMEOUT_S 120.0
/* how long a run that must stop before rendering may take (its --spp would take minutes) */
#define EARLY_FAIL_LIMIT_S  5.0
#define SIGINT_EXIT_LIMIT_S 30.0

/* ---- running the binary ---------------------------------------------------------------------- */

/* A growable, NUL-terminated byte buffer fed from one pipe. */
typedef struct buf {
    char *data;
    size_t len, cap;
} buf;

/* One run of the binary.  `status` is waitpid's; `timed_out` means it was killed by us. */
typedef struct proc {
    char cmd[1024]; /* the arguments joined by spaces, for messages */
    pid_t pid;
    int out_fd, err_fd;
    buf out, err;
    int status;
    int reaped;
    int timed_out;
    double start, seconds;
} proc;

static void sleep_s(double s)
{
    struct timespec ts;
    ts.tv_sec = (time_t)s;
    ts.tv_nsec = (long)((s - (double)ts.tv_sec) * 1e9);
    while (nanosleep(&ts, &ts) != 0 && errno == EINTR)
        ;
}

static void buf_append(buf *b, const char *p, size_t n)
{
    if (b->len + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        char *d;
        while (b->len + n + 1 > cap)
            cap *= 2;
        d = (char *)realloc(b->data, cap);
        assert_non_null(d);
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->len, p, n);
    b->len += n;
    b->data[b->len] = '\0';
}

static void set_cloexec(int fd) { fcntl(fd, F_SETFD, fcntl(fd, F_GETFD) | FD_CLOEXEC); }

/* Starts program `prog` (RS_BINARY: argv[0] = "raystream") with the NULL-terminated `args` in
 * folder `cwd`, stdin from /dev/null, stdout and stderr into pipes, every signal unblocked. */
static void proc_start_prog(proc *p, const char *cwd, const char *prog, const char *const *args)
{
    int out_pipe[2], err_pipe[2], i;
    char *argv[MAX_ARGS + 2];
    size_t used = 0;

    memset(p, 0, sizeof *p);
    argv[0] = strcmp(prog, RS_BINARY) == 0 ? (char *)"raystream" : (char *)prog;
    for (i = 0; args[i]; ++i) {
        assert_true(i < MAX_ARGS);
        argv[i + 1] = (char *)args[i];
        used += (size_t)snprintf(p->cmd + used, used < sizeof p->cmd ? sizeof p->cmd - used : 0,
                                 "%s%s", i ? " " : "", args[i]);
        if (used >= sizeof p->cmd)
            used = sizeof p->cmd - 1;
    }
    argv[i + 1] = NULL;
    buf_append(&p->out, "", 0);
    buf_append(&p->err, "", 0);

    assert_int_equal(pipe(out_pipe), 0);
    assert_int_equal(pipe(err_pipe), 0);
    for (i = 0; i < 2; ++i) {
        set_cloexec(out_pipe[i]);
        set_cloexec(err_pipe[i]);
    }
    p->start = rs_now_s();
    p->pid = fork();
    assert_true(p->pid >= 0);
    if (p->pid == 0) {
        /* the child: only async-signal-safe calls until execv */
        sigset_t none;
        int devnull = open("/dev/null", O_RDONLY);
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        signal(SIGHUP, SIG_DFL);
        signal(SIGPIPE, SIG_DFL);
        if (devnull < 0 || dup2(devnull, STDIN_FILENO) < 0 ||
            dup2(out_pipe[1], STDOUT_FILENO) < 0 || dup2(err_pipe[1], STDERR_FILENO) < 0 ||
            chdir(cwd) != 0)
            _exit(126);
        if (strchr(prog, '/'))
            execv(prog, argv);
        else
            execvp(prog, argv);
        _exit(127);
    }
    close(out_pipe[1]);
    close(err_pipe[1]);
    p->out_fd = out_pipe[0];
    p->err_fd = err_pipe[0];
}

static void proc_start(proc *p, const char *cwd, const char *const *args)
{
    proc_start_prog(p, cwd, RS_BINARY, args);
}

/* Reads whatever the pipes have for up to `wait_ms`; closes a pipe at end of file. */
static void proc_pump(proc *p, int wait_ms)
{
    struct pollfd fds[2];
    int nfds = 0, i;
    char chunk[4096];
    if (p->out_fd >= 0)
        fds[nfds++] = (struct pollfd){p->out_fd, POLLIN, 0};
    if (p->err_fd >= 0)
        fds[nfds++] = (struct pollfd){p->err_fd, POLLIN, 0};
    if (nfds == 0) {
        if (wait_ms > 0)
            sleep_s(wait_ms / 1000.0);
        return;
    }
    if (poll(fds, (nfds_t)nfds, wait_ms) <= 0)
        return;
    for (i = 0; i < nfds; ++i) {
        int *fd = fds[i].fd == p->out_fd ? &p->out_fd : &p->err_fd;
        buf *b = fds[i].fd == p->out_fd ? &p->out : &p->err;
        ssize_t n;
        if (!(fds[i].revents & (POLLIN | POLLHUP | POLLERR)))
            continue;
        n = read(*fd, chunk, sizeof chunk);
        if (n > 0) {
            buf_append(b, chunk, (size_t)n);
        } else if (n == 0 || errno != EINTR) {
            close(*fd);
            *fd = -1;
        }
    }
}

/* Drains the pipes and reaps the child; past `timeout_s` from the start, kills it (SIGKILL) and
 * sets timed_out. */
static void proc_finish(proc *p, double timeout_s)
{
    double deadline = p->start + timeout_s;
    while (!p->reaped) {
        pid_t r;
        proc_pump(p, 20);
        r = waitpid(p->pid, &p->status, WNOHANG);
        if (r == p->pid) {
            p->reaped = 1;
        } else if (rs_now_s() > deadline) {
            kill(p->pid, SIGKILL);
            waitpid(p->pid, &p->status, 0);
            p->reaped = 1;
            p->timed_out = 1;
        }
    }
    p->seconds = rs_now_s() - p->start;
    /* the child is gone: what is left in the pipes ends in end of file */
    while (p->out_fd >= 0 || p->err_fd >= 0)
        proc_pump(p, 1000);
}

static void proc_free(proc *p)
{
    free(p->out.data);
    free(p->err.data);
    p->out.data = p->err.data = NULL;
}

/* Runs `args` to completion in `cwd` (at most `timeout_s`). */
static void run(proc *p, const char *cwd, double timeout_s, const char *const *args)
{
    proc_start(p, cwd, args);
    proc_finish(p, timeout_s);
}

static void describe_status(const proc *p, char *s, size_t n)
{
    if (p->timed_out)
        snprintf(s, n, "still running after %.1f s (killed)", p->seconds);
    else if (WIFEXITED(p->status))
        snprintf(s, n, "exit status %d after %.2f s", WEXITSTATUS(p->status), p->seconds);
    else if (WIFSIGNALED(p->status))
        snprintf(s, n, "killed by signal %d after %.2f s", WTERMSIG(p->status), p->seconds);
    else
        snprintf(s, n, "wait status 0x%x", (unsigned)p->status);
}

/* Prints what the run did and fails the test; `line` is the caller's. */
static void report(const proc *p, int line, const char *cond, const char *fmt, ...)
{
    char msg[512], st[96];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    describe_status(p, st, sizeof st);
    print_error(RS_HARNESS_NAME ":%d: %s\n  (%s does not hold)\n  command: raystream %s\n"
                "  result:  %s\n  stderr:  \"%.3000s\"\n  stdout:  \"%.1000s\"\n",
                line, msg, cond, p->cmd, st, p->err.data ? p->err.data : "",
                p->out.data ? p->out.data : "");
    _fail(__FILE__, line);
}

/* Checks `cond` about run `p`; on failure shows the command, its status and its output. */
#define EXPECT(p, cond, ...)                                                                       \
  do {                                                                                             \
    if (!(cond))                                                                                   \
      report((p), __LINE__, #cond, __VA_ARGS__);                                                   \
  } while (0)

static int exited_with(const proc *p, int code)
{
    return !p->timed_out && WIFEXITED(p->status) && WEXITSTATUS(p->status) == code;
}

/* Exactly one line: text that ends in the only newline. */
static int one_line(const buf *b)
{
    const char *nl = b->len ? strchr(b->data, '\n') : NULL;
    return nl && nl == b->data + b->len - 1 && nl != b->data;
}

static int contains_ci(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; ++hay) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            ++i;
        if (i == n)
            return 1;
    }
    return n == 0;
}

/* ---- the temporary folder -------------------------------------------------------------------- */

typedef struct fixture {
    char dir[64];
} fixture;

static void path_in(const fixture *f, const char *name, char *out, size_t n)
{
    snprintf(out, n, "%s/%s", f->dir, name);
}

/* Removes a folder and what is under it; folders are made writable first, so a read-only
 * folder a test created (or one the binary should not have written into) goes too. */
static void rm_tree(const char *path)
{
    struct stat sb;
    if (lstat(path, &sb) != 0)
        return;
    if (S_ISDIR(sb.st_mode)) {
        DIR *d;
        struct dirent *e;
        chmod(path, 0700);
        d = opendir(path);
        if (d) {
            while ((e = readdir(d)) != NULL) {
                char sub[1024];
                if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                    continue;
                snprintf(sub, sizeof sub, "%s/%s", path, e->d_name);
                rm_tree(sub);
            }
            closedir(d);
        }
        rmdir(path);
    } else {
        unlink(path);
    }
}

/* The names in folder `dir` (not . and ..), joined by spaces into `names`; returns the count. */
static int list_dir(const char *dir, char *names, size_t n)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    int count = 0;
    size_t used = 0;
    if (n)
        names[0] = '\0';
    if (!d)
        return -1;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
            continue;
        if (used < n)
            used += (size_t)snprintf(names + used, n - used, "%s%s", count ? " " : "", e->d_name);
        ++count;
    }
    closedir(d);
    return count;
}

static int file_exists(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0;
}

static int setup(void **state)
{
    fixture *f = (fixture *)calloc(1, sizeof *f);
    if (!f)
        return -1;
    strcpy(f->dir, "/tmp/raystream-cli-XXXXXX");
    if (!mkdtemp(f->dir)) {
        perror("mkdtemp");
        free(f);
        return -1;
    }
    *state = f;
    return 0;
}

static int teardown(void **state)
{
    fixture *f = (fixture *)*state;
    rm_tree(f->dir);
    free(f);
    return 0;
}

static int group_setup(void **state)
{
    (void)state;
    if (access(RS_BINARY, X_OK) != 0) {
        fprintf(stderr, RS_HARNESS_NAME ": %s is not an executable: %s\n", RS_BINARY, strerror(errno));
        return -1;
    }
    return 0;
}

/* Runs `args` in the test folder and expects exit status `code`. */
static void run_expect(const fixture *f, const char *const *args, int code, proc *p)
{
    run(p, f->dir, DEFAULT_TIMEOUT_S, args);
    EXPECT(p, exited_with(p, code), "expected exit status %d", code);
}

/* Writes `text` to file `name` in the test folder. */
static void write_in(const fixture *f, const char *name, const char *text)
{
    char path[512];
    FILE *fp;
    path_in(f, name, path, sizeof path);
    fp = fopen(path, "w");
    assert_non_null(fp);
    fputs(text, fp);
    fclose(fp);
}

/* ---- reading images back --------------------------------------------------------------------- */

typedef struct image {
    uint32_t w, h;
    float *rgb;
} image;

/* Reads `name` from the test folder; fails the test (showing run `p`) if it cannot. */
static image read_image(const proc *p, const fixture *f, const char *name)
{
    image im = {0, 0, NULL};
    char path[256];
    rs_status st;
    path_in(f, name, path, sizeof path);
    st = rs_image_read(path, &im.w, &im.h, &im.rgb);
    EXPECT(p, st == RS_OK, "cannot read back %s: %s", name, rs_error_message());
    return im;
}

/* 1 if a and b have the same size and the same pixels bit for bit. */
static int same_image(const image *a, const image *b)
{
    return a->w == b->w && a->h == b->h && a->rgb && b->rgb &&
           memcmp(a->rgb, b->rgb, (size_t)a->w * a->h * 3 * sizeof(float)) == 0;
}

static double image_mean(const image *im)
{
    size_t i, n = (size_t)im->w * im->h * 3;
    double sum = 0.0;
    for (i = 0; i < n; ++i)
        sum += im->rgb[i];
    return n ? sum / (double)n : 0.0;
}

/* The index of the first value that is not finite or is negative, or -1. */
static long first_bad_value(const image *im)
{
    size_t i, n = (size_t)im->w * im->h * 3;
    for (i = 0; i < n; ++i)
        if (!isfinite(im->rgb[i]) || im->rgb[i] < 0.0f)
            return (long)i;
    return -1;
}

/* The whole content of a file (malloc'd) or NULL. */
static char *read_bytes(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    char *data = NULL;
    long n;
    if (!fp)
        return NULL;
    if (fseek(fp, 0, SEEK_END) == 0 && (n = ftell(fp)) >= 0 && fseek(fp, 0, SEEK_SET) == 0) {
        data = (char *)malloc((size_t)n + 1);
        if (data && fread(data, 1, (size_t)n, fp) != (size_t)n) {
            free(data);
            data = NULL;
        }
        *len = (size_t)n;
    }
    fclose(fp);
    return data;
}

#endif
