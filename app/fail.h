/* app/fail.h — the lines app/ prints for the user, and the one line every failure prints
 * (internal to app/).
 *
 * Every line goes through rs_app_print: to stderr, as the raystream command prints it, or, where
 * the calling thread has set a sink (the C API, api/raystream.c), to that sink instead, so that
 * a program using the library never sees app/'s lines on its stderr. */
#ifndef RS_APP_FAIL_H
#define RS_APP_FAIL_H

#include <stdarg.h>
#include <stdio.h>

#if defined(__GNUC__)
#  define RS_APP_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#  define RS_APP_PRINTF(f, a)
#endif

/* Where this thread's lines go: line(user, text) with one whole line, its newline included.
 * NULL: stderr (the default).  Thread-local. */
typedef void (*rs_app_sink_fn)(void *user, const char *line);
void rs_app_set_sink(rs_app_sink_fn line, void *user);
/* Whether this thread has a sink (the library, not the command, is running). */
int rs_app_has_sink(void);

/* Prints to this thread's sink or stderr.  A sink gets each line whole: text is gathered up to
 * its newline. */
void rs_app_print(const char *fmt, ...) RS_APP_PRINTF(1, 2);
void rs_app_vprint(const char *fmt, va_list ap);

/* The stream loaders' notes go to (a scene file's warnings): stderr without a sink, NULL with
 * one, or NULL when `quiet`. */
FILE *rs_app_log(int quiet);

/* Prints "raystream: WHAT: <the first error's message>" and returns `code`. */
int rs_app_fail(int code, const char *what);

#endif
