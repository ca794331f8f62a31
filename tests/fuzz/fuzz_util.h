/* tests/fuzz/fuzz_util.h — what the libFuzzer harnesses share (fuzz_util.c): a private
 * temporary folder, a report channel that survives -close_fd_mask, and the check that a refused
 * input got the one clear line the README promises.  Fuzz-only helper.
 *
 * A harness must never crash, hang, leak or trip a sanitizer on any input; refusing the input is
 * fine.  A broken promise is reported with fz_broken() (a line, then abort()), which libFuzzer
 * records as a finding. */
#ifndef RS_TESTS_FUZZ_UTIL_H
#define RS_TESTS_FUZZ_UTIL_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

/* libFuzzer's hooks, defined by each harness (TestOneInput) and by fuzz_util.c (Initialize). */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerInitialize(int *argc, char ***argv);

/* A folder of our own under $TMPDIR (or /tmp), made at start-up, removed at exit. */
const char *fz_tmpdir(void);
/* Writes data[size] to `path` (truncating); a failure is the harness's, and aborts. */
void fz_write_file(const char *path, const uint8_t *data, size_t size);
/* Prints "fuzz: " and the message on the stderr the process started with (libFuzzer's
 * -close_fd_mask=2 closes fd 2 after start-up), then aborts. */
void fz_broken(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2), noreturn))
#endif
    ;
/* The file descriptors this process has open (from /proc/self/fd). */
int fz_open_fds(void);
/* A refused input: the first-error slot must hold one non-empty line that names `label`. */
void fz_check_refusal(rs_status st, const char *label);

#endif
