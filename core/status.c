/* core/status.c — the per-thread first-error message. */
#include "core/status.h"

#include <stdarg.h>
#include <stdio.h>

static _Thread_local char g_message[512];
static _Thread_local int g_has_message;

rs_status rs_error_set(rs_status code, const char *fmt, ...)
{
    if (!g_has_message) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(g_message, sizeof g_message, fmt, ap);
        va_end(ap);
        g_has_message = 1;
    }
    return code;
}

const char *rs_error_message(void) { return g_has_message ? g_message : ""; }

void rs_error_clear(void)
{
    g_has_message = 0;
    g_message[0] = '\0';
}

const char *rs_status_name(rs_status s)
{
    switch (s) {
    case RS_OK: return "ok";
    case RS_ERR_ARG: return "invalid argument";
    case RS_ERR_IO: return "I/O error";
    case RS_ERR_NOMEM: return "out of memory";
    case RS_ERR_CUDA: return "CUDA error";
    case RS_ERR_DEVICE_LOST: return "device lost";
    case RS_ERR_CANCELLED: return "cancelled";
    }
    return "unknown error";
}

void rs_say(char *why, size_t n, const char *fmt, ...)
{
    va_list ap;
    if (!why || n == 0)
        return;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
}
