/* core/status.h — error codes and the first-error message slot.
 *
 * Whatever can fail returns an rs_status and hands results out through out-parameters.  The
 * first function to fail records a one-line human message with rs_error_set(); callers further
 * up only pass the code along, so the message names the real cause.  The slot is per thread. */
#ifndef RS_CORE_STATUS_H
#define RS_CORE_STATUS_H

#include <stddef.h>

typedef enum rs_status {
    RS_OK = 0,
    RS_ERR_ARG,         /* bad argument or bad input data */
    RS_ERR_IO,          /* a file could not be read or written */
    RS_ERR_NOMEM,       /* out of memory */
    RS_ERR_CUDA,        /* a CUDA call failed */
    RS_ERR_DEVICE_LOST, /* a device failed or is unavailable */
    RS_ERR_CANCELLED    /* the user interrupted the work */
} rs_status;

#ifdef __cplusplus
extern "C" {
#endif
/* Records `fmt` as this thread's error message unless one is already recorded.  Returns `code`
 * so that `return rs_error_set(RS_ERR_IO, "...")` reads naturally. */
rs_status rs_error_set(rs_status code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* This thread's recorded message, or "" if none. */
const char *rs_error_message(void);
/* Forgets this thread's message. */
void rs_error_clear(void);
const char *rs_status_name(rs_status s);
/* A reason for the caller into why[n] (nothing when why is NULL or n is 0): the "0 with one line
 * in why" convention of the parsers and loaders that do not record an error. */
void rs_say(char *why, size_t n, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
#ifdef __cplusplus
}
#endif
#endif
