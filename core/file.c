/* core/file.c — see file.h. */
#include "core/file.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/alloc.h"

static rs_status say(char *msg, size_t n, rs_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static rs_status say(char *msg, size_t n, rs_status code, const char *fmt, ...)
{
    va_list ap;
    if (msg && n) {
        va_start(ap, fmt);
        vsnprintf(msg, n, fmt, ap);
        va_end(ap);
    }
    return code;
}

/* The kind and size of what stat() saw, as a refusal or RS_OK. */
static rs_status check_stat(const char *path, const struct stat *sb, uint64_t max_bytes,
                            char *msg, size_t n)
{
    if (S_ISDIR(sb->st_mode))
        return say(msg, n, RS_ERR_ARG, "%s: is a folder", path);
    if (!S_ISREG(sb->st_mode))
        return say(msg, n, RS_ERR_ARG, "%s: not a regular file", path);
    if (sb->st_size < 0 || (uint64_t)sb->st_size > max_bytes) {
        if (max_bytes >= ((uint64_t)1 << 30) && max_bytes % ((uint64_t)1 << 30) == 0)
            return say(msg, n, RS_ERR_ARG, "%s: larger than %llu GiB", path,
                       (unsigned long long)(max_bytes >> 30));
        return say(msg, n, RS_ERR_ARG, "%s: larger than %llu MiB", path,
                   (unsigned long long)(max_bytes >> 20));
    }
    return RS_OK;
}

rs_status rs_file_open_quiet(const char *path, uint64_t max_bytes, int *fd, uint64_t *size,
                             char *msg, size_t n)
{
    struct stat before, after;
    rs_status st;
    int d, flags;
    *fd = -1;
    if (size)
        *size = 0;
    if (!path || !*path)
        return say(msg, n, RS_ERR_ARG, "(empty file name): cannot open");
    /* stat() first: a FIFO, a device or a socket is refused without being opened (opening a
     * FIFO for reading blocks until a writer comes; a tape drive may rewind) */
    if (stat(path, &before) != 0)
        return say(msg, n, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    st = check_stat(path, &before, max_bytes, msg, n);
    if (st != RS_OK)
        return st;
    /* O_NONBLOCK: should the path have been replaced by a FIFO since, open() still returns */
    d = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
    if (d < 0)
        return say(msg, n, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (fstat(d, &after) != 0) {
        st = say(msg, n, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        close(d);
        return st;
    }
    st = check_stat(path, &after, max_bytes, msg, n);
    if (st == RS_OK && (after.st_dev != before.st_dev || after.st_ino != before.st_ino))
        st = say(msg, n, RS_ERR_IO, "%s: changed while being opened", path);
    flags = fcntl(d, F_GETFL);
    if (st == RS_OK && (flags < 0 || fcntl(d, F_SETFL, flags & ~O_NONBLOCK) != 0))
        st = say(msg, n, RS_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    if (st != RS_OK) {
        close(d);
        return st;
    }
    *fd = d;
    if (size)
        *size = (uint64_t)after.st_size;
    return RS_OK;
}

rs_status rs_file_open(const char *path, uint64_t max_bytes, FILE **f, uint64_t *size)
{
    char msg[1200];
    int fd;
    rs_status st = rs_file_open_quiet(path, max_bytes, &fd, size, msg, sizeof msg);
    *f = NULL;
    if (st != RS_OK)
        return rs_error_set(st, "%s", msg);
    *f = fdopen(fd, "rb");
    if (!*f) {
        int err = errno;
        close(fd);
        return rs_error_set(RS_ERR_IO, "%s: cannot open: %s", path, strerror(err));
    }
    return RS_OK;
}

rs_status rs_file_check(const char *path, uint64_t max_bytes, uint64_t *size)
{
    char msg[1200];
    int fd;
    rs_status st = rs_file_open_quiet(path, max_bytes, &fd, size, msg, sizeof msg);
    if (st != RS_OK)
        return rs_error_set(st, "%s", msg);
    close(fd);
    return RS_OK;
}

rs_status rs_file_read(const char *path, uint64_t max_bytes, char **text, size_t *len)
{
    FILE *f;
    uint64_t n;
    size_t got;
    char *buf;
    rs_status st = rs_file_open(path, max_bytes, &f, &n);
    *text = NULL;
    *len = 0;
    if (st != RS_OK)
        return st;
    if (n > (uint64_t)SIZE_MAX - 1 || !(buf = (char *)rs_alloc((size_t)n + 1, 1))) {
        fclose(f);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    }
    got = fread(buf, 1, (size_t)n, f);
    fclose(f);
    if (got != (size_t)n) {
        rs_free(buf);
        return rs_error_set(RS_ERR_IO, "%s: read error (the file shrank while being read?)", path);
    }
    buf[n] = '\0';
    *text = buf;
    *len = (size_t)n;
    return RS_OK;
}

int rs_file_temp_name(const char *path, char *buf, size_t n)
{
    int k = snprintf(buf, n, "%s.tmp-%ld", path, (long)getpid());
    return k > 0 && (size_t)k < n;
}
