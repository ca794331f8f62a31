/* app/signals.c — the stop signals and the load watchdog; see signals.h. */
#include "app/signals.h"

#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "app/options.h"
#include "app/outputs.h"

/* The first stop signal sets g_cancel, which the render loop polls, and g_signal, its number,
 * for the exit status (128 + it).  A second one stops at once: the files being written
 * (app/outputs.h, tracked before the first is created) are removed and the program dies of that
 * signal, as it would without a handler.  The handler may run on any thread; it touches only
 * lock-free atomics and calls only async-signal-safe functions (unlink, signal, raise). */
static atomic_int g_cancel;
static atomic_int g_signal;

static void on_stop_signal(int sig)
{
    int none = 0, saved_errno = errno; /* unlink may set it under the interrupted code's feet */
    if (atomic_compare_exchange_strong(&g_signal, &none, sig)) {
        atomic_store(&g_cancel, 1);
        return;
    }
    rs_outputs_remove_tracked();
    signal(sig, SIG_DFL);
    raise(sig); /* pending until the handler returns (the signal is blocked in it), then fatal */
    errno = saved_errno;
}

static const int k_stop_signals[] = {SIGINT, SIGTERM, SIGHUP};

void rs_signals_install(void)
{
    struct sigaction sa, old;
    size_t i;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    for (i = 0; i < sizeof k_stop_signals / sizeof k_stop_signals[0]; ++i)
        sigaddset(&sa.sa_mask, k_stop_signals[i]); /* one handler at a time */
    sa.sa_flags = SA_RESTART;
    for (i = 0; i < sizeof k_stop_signals / sizeof k_stop_signals[0]; ++i)
        if (sigaction(k_stop_signals[i], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(k_stop_signals[i], &sa, NULL);
}

const atomic_int *rs_signals_cancel(void) { return &g_cancel; }

int rs_signals_caught(void) { return atomic_load(&g_signal); }

const char *rs_signal_name(int sig)
{
    switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
    }
}

/* A last bound on reading the inputs.  Every file is checked before it is opened (core/file.h)
 * and the one known spin of a library (Assimp on a cut PLY header) is caught before the file is
 * handed over, but a parser of some other format may still spin on a malformed file.  Should
 * loading take longer than this, the run ends with one line naming the input and exit status 1
 * instead of hanging; nothing has been written yet.  Far above any real load (the 100k-triangle
 * dragon loads in about a second here). */
#define LOAD_LIMIT_S 600

typedef struct load_watch {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int done;
    double limit_s;
    char line[512];
} load_watch;

static void *load_watch_main(void *arg)
{
    load_watch *w = (load_watch *)arg;
    struct timespec until;
    clock_gettime(CLOCK_MONOTONIC, &until);
    until.tv_sec += (time_t)w->limit_s;
    until.tv_nsec += (long)((w->limit_s - (double)(time_t)w->limit_s) * 1e9);
    if (until.tv_nsec >= 1000000000L) {
        until.tv_sec++;
        until.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&w->mu);
    while (!w->done)
        if (pthread_cond_timedwait(&w->cv, &w->mu, &until) == ETIMEDOUT && !w->done) {
            fputs(w->line, stderr);
            _exit(RS_EXIT_RUNTIME); /* the watched code may hold any lock: no exit handlers */
        }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

int rs_watch_run(double limit_s, const char *line, int (*fn)(void *arg), void *arg)
{
    load_watch w;
    pthread_condattr_t ca;
    pthread_t t;
    int code, watching;
    memset(&w, 0, sizeof w);
    w.limit_s = limit_s;
    snprintf(w.line, sizeof w.line, "%s", line);
    pthread_mutex_init(&w.mu, NULL);
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&w.cv, &ca);
    pthread_condattr_destroy(&ca);
    watching = pthread_create(&t, NULL, load_watch_main, &w) == 0;
    code = fn(arg);
    if (watching) {
        pthread_mutex_lock(&w.mu);
        w.done = 1;
        pthread_cond_signal(&w.cv);
        pthread_mutex_unlock(&w.mu);
        pthread_join(t, NULL);
    }
    pthread_cond_destroy(&w.cv);
    pthread_mutex_destroy(&w.mu);
    return code;
}

int rs_load_watch_run(const char *what, int (*load)(void *arg), void *arg)
{
    char line[512];
    snprintf(line, sizeof line,
             "raystream: %s: still reading after %d s, giving up (a malformed file?)\n", what,
             LOAD_LIMIT_S);
    return rs_watch_run(LOAD_LIMIT_S, line, load, arg);
}
