/* app/fail.h — the one line every app/ failure prints (internal to app/). */
#ifndef RS_APP_FAIL_H
#define RS_APP_FAIL_H

/* Prints "raystream: WHAT: <the first error's message>" and returns `code`. */
int rs_app_fail(int code, const char *what);

#endif
