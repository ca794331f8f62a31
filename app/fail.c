/* app/fail.c — see fail.h.  A file of its own at the bottom of app/: every step and command
 * reports through it, so it calls up into none of them. */
#include "app/fail.h"

#include <stdio.h>

#include "core/status.h"

int rs_app_fail(int code, const char *what)
{
    const char *msg = rs_error_message();
    fprintf(stderr, "raystream: %s%s%s\n", what ? what : "", what && *msg ? ": " : "", msg);
    return code;
}
