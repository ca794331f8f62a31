/* app/outputs.c — see outputs.h. */
#include "app/outputs.h"
#include "app/fail.h"

#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/options.h"
#include "core/file.h"

#define TRACK_MAX 8

/* The names a signal handler removes.  A slot is written before the count that publishes it
 * (release), and the handler reads the count first (acquire); lock-free atomics are
 * async-signal-safe. */
static char g_tracked[TRACK_MAX][RS_OUTPUT_PATH_MAX];
static atomic_int g_n_tracked;

void rs_outputs_track(const char *path)
{
    int n = atomic_load(&g_n_tracked);
    size_t len = strlen(path);
    if (n >= TRACK_MAX || len >= RS_OUTPUT_PATH_MAX)
        return;
    memcpy(g_tracked[n], path, len + 1);
    atomic_store_explicit(&g_n_tracked, n + 1, memory_order_release);
}

void rs_outputs_untrack(void) { atomic_store(&g_n_tracked, 0); }

void rs_outputs_remove_tracked(void)
{
    int i, n = atomic_load_explicit(&g_n_tracked, memory_order_acquire);
    for (i = 0; i < n && i < TRACK_MAX; ++i)
        unlink(g_tracked[i]);
}

/* One line "raystream: OPTION PATH: what" and RS_EXIT_USAGE. */
static int refuse(const rs_output *o, const char *what, const char *detail)
{
    rs_app_print("raystream: %s %s: %s%s%s%s\n", o->option, o->path, what, detail ? " (" : "",
                 detail ? detail : "", detail ? ")" : "");
    return RS_EXIT_USAGE;
}

static int same_file(const char *a, const char *b)
{
    struct stat sa, sb;
    if (strcmp(a, b) == 0)
        return 1;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev &&
           sa.st_ino == sb.st_ino;
}

/* The target itself: a regular file that may be replaced, a special file written in place, or
 * nothing yet.  Returns RS_EXIT_OK or RS_EXIT_USAGE after one line. */
static int check_target(rs_output *o)
{
    struct stat sb;
    o->in_place = 0;
    if (stat(o->path, &sb) != 0) {
        if (errno == ENOENT || errno == ENOTDIR)
            return RS_EXIT_OK; /* the folder check says what is missing */
        return refuse(o, "cannot be reached", strerror(errno));
    }
    if (S_ISDIR(sb.st_mode))
        return refuse(o, "is a folder", NULL);
    if (!S_ISREG(sb.st_mode) && !o->may_be_special)
        return refuse(o, "is not a regular file", NULL);
    /* replacing a read-only file by a rename would work; refusing keeps what the user protected */
    if (access(o->path, W_OK) != 0)
        return refuse(o, "the file is not writable", strerror(errno));
    o->in_place = !S_ISREG(sb.st_mode);
    return RS_EXIT_OK;
}

/* The folder the staged file goes into: it exists and takes a new file. */
static int check_folder(rs_output *o)
{
    char dir[RS_OUTPUT_PATH_MAX];
    const char *slash = strrchr(o->path, '/');
    struct stat sb;
    int fd;
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - o->path) : 1,
             slash ? (slash == o->path ? "/" : o->path) : ".");
    if (stat(dir, &sb) != 0) {
        char what[RS_OUTPUT_PATH_MAX + 32];
        snprintf(what, sizeof what, "the folder %s does not exist", dir);
        return refuse(o, what, errno == ENOENT ? NULL : strerror(errno));
    }
    if (!S_ISDIR(sb.st_mode)) {
        char what[RS_OUTPUT_PATH_MAX + 32];
        snprintf(what, sizeof what, "%s is not a folder", dir);
        return refuse(o, what, NULL);
    }
    fd = open(o->staged, O_WRONLY | O_CREAT | O_TRUNC, 0666);
    if (fd < 0) {
        char what[RS_OUTPUT_PATH_MAX + 32];
        snprintf(what, sizeof what, "the folder %s is not writable", dir);
        return refuse(o, what, strerror(errno));
    }
    close(fd);
    unlink(o->staged);
    return RS_EXIT_OK;
}

int rs_outputs_check(rs_output *out, int n, const char *const *inputs, int n_inputs)
{
    int i, j, rc;
    for (i = 0; i < n; ++i) {
        rs_output *o = &out[i];
        if (!rs_file_temp_name(o->path, o->staged, sizeof o->staged))
            return refuse(o, "the name is too long", NULL);
        for (j = 0; j < i; ++j)
            if (same_file(o->path, out[j].path)) {
                char what[96];
                snprintf(what, sizeof what, "%s writes the same file", out[j].option);
                return refuse(o, what, NULL);
            }
        for (j = 0; j < n_inputs; ++j)
            if (inputs[j] && same_file(o->path, inputs[j]) &&
                !(o->may_replace && same_file(o->may_replace, inputs[j])))
                return refuse(o, "would replace an input file", NULL);
        if ((rc = check_target(o)) != RS_EXIT_OK)
            return rc;
        if (!o->in_place && (rc = check_folder(o)) != RS_EXIT_OK)
            return rc;
    }
    return RS_EXIT_OK;
}

int rs_output_commit(const rs_output *o)
{
    if (rename(o->staged, o->path) == 0)
        return 1;
    rs_app_print("raystream: %s: cannot put the finished file in place (%s)\n", o->path,
                 strerror(errno));
    return 0;
}
