/* app/signals.h — the stop signals (SIGINT, SIGTERM, SIGHUP) and the load watchdog.  Internal
 * to app/. */
#ifndef RS_APP_SIGNALS_H
#define RS_APP_SIGNALS_H

#include <stdatomic.h>

/* Catches the stop signals (a signal the caller ignores stays ignored).  The first asks for a
 * clean stop: the flag rs_signals_cancel() points to is set; a second removes the tracked
 * outputs (app/outputs.h) and dies of the signal.  They stay caught until the program ends. */
void rs_signals_install(void);
/* The flag the render polls; set by the first stop signal. */
const atomic_int *rs_signals_cancel(void);
/* The first stop signal's number, or 0. */
int rs_signals_caught(void);
/* "SIGINT", "SIGTERM", "SIGHUP" or "a signal". */
const char *rs_signal_name(int sig);

/* Runs load(arg) and returns what it returns; should it take longer than a bound far above
 * any real load, prints one line naming `what` and ends the process with RS_EXIT_RUNTIME
 * (unwatched if the watch cannot be started). */
int rs_load_watch_run(const char *what, int (*load)(void *arg), void *arg);
/* Runs fn(arg) and returns what it returns; should it take longer than limit_s seconds, prints
 * `line` and ends the process with RS_EXIT_RUNTIME (unwatched if the watch cannot be
 * started). */
int rs_watch_run(double limit_s, const char *line, int (*fn)(void *arg), void *arg);

#endif
