/* app/fail.c — see fail.h.  A file of its own at the bottom of app/: every step and command
 * reports through it, so it calls up into none of them. */
#include "app/fail.h"

#include <stdarg.h>
#include <string.h>

#include "core/status.h"

typedef struct app_sink {
    rs_app_sink_fn line;
    void *user;
    char pending[2048]; /* text up to its newline */
    size_t n;
} app_sink;

static _Thread_local app_sink g_sink;

void rs_app_set_sink(rs_app_sink_fn line, void *user)
{
    g_sink.line = line;
    g_sink.user = user;
    g_sink.n = 0;
}

int rs_app_has_sink(void) { return g_sink.line != NULL; }

/* Hands the sink every whole line gathered; a line longer than the buffer goes in parts. */
static void sink_add(const char *text)
{
    app_sink *s = &g_sink;
    for (; *text; ++text) {
        s->pending[s->n++] = *text;
        if (*text == '\n' || s->n == sizeof s->pending - 2) {
            if (*text != '\n')
                s->pending[s->n++] = '\n';
            s->pending[s->n] = '\0';
            s->line(s->user, s->pending);
            s->n = 0;
        }
    }
}

void rs_app_vprint(const char *fmt, va_list ap)
{
    char buf[4096];
    if (!g_sink.line) {
        vfprintf(stderr, fmt, ap);
        return;
    }
    vsnprintf(buf, sizeof buf, fmt, ap);
    sink_add(buf);
}

void rs_app_print(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    rs_app_vprint(fmt, ap);
    va_end(ap);
}

FILE *rs_app_log(int quiet) { return quiet || g_sink.line ? NULL : stderr; }

int rs_app_fail(int code, const char *what)
{
    const char *msg = rs_error_message();
    rs_app_print("raystream: %s%s%s\n", what ? what : "", what && *msg ? ": " : "", msg);
    return code;
}
