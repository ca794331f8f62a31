/* tests/fuzz/fuzz_util.c — see fuzz_util.h. */
#include "fuzz_util.h"

#include <dirent.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char g_dir[512];
static FILE *g_report;

static void remove_dir(void)
{
    if (g_dir[0])
        rmdir(g_dir);
}

/* Runs before libFuzzer parses its flags and closes stdout/stderr. */
int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    const char *t = getenv("TMPDIR");
    int fd = dup(2);
    (void)argc, (void)argv;
    g_report = fd >= 0 ? fdopen(fd, "w") : NULL;
    snprintf(g_dir, sizeof g_dir, "%s/rs-fuzz-XXXXXX", t && *t ? t : "/tmp");
    if (!mkdtemp(g_dir))
        fz_broken("cannot make a folder in %s", t && *t ? t : "/tmp");
    atexit(remove_dir);
    return 0;
}

const char *fz_tmpdir(void) { return g_dir; }

void fz_broken(const char *fmt, ...)
{
    FILE *out = g_report ? g_report : stderr;
    va_list ap;
    va_start(ap, fmt);
    fputs("fuzz: ", out);
    vfprintf(out, fmt, ap);
    fputc('\n', out);
    fflush(out);
    va_end(ap);
    abort();
}

void fz_write_file(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        fz_broken("cannot write %s", path);
}

void fz_check_refusal(rs_status st, const char *label)
{
    const char *msg = rs_error_message();
    if (st != RS_OK && (!*msg || strchr(msg, '\n') || !strstr(msg, label)))
        fz_broken("refusal (%s) without one line naming %s: '%s'", rs_status_name(st), label, msg);
}

int fz_open_fds(void)
{
    DIR *d = opendir("/proc/self/fd");
    struct dirent *e;
    int n = 0;
    if (!d)
        fz_broken("cannot list /proc/self/fd");
    while ((e = readdir(d)) != NULL)
        n += e->d_name[0] != '.';
    closedir(d);
    return n;
}
