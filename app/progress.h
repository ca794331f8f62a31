/* app/progress.h — the progress display on stderr: a redrawn bar on a terminal, a line every
 * 10% otherwise (logs stay short).  Updates are throttled; calls come from the render thread. */
#ifndef RS_APP_PROGRESS_H
#define RS_APP_PROGRESS_H

#include <stdint.h>

#include "core/clock.h"

typedef struct rs_progress {
    int enabled;
    int tty;
    double start, last_draw;
    int last_decile;
    int drawn; /* a bar is on screen and needs a newline before other output */
} rs_progress;

void rs_progress_begin(rs_progress *p, int enabled);
void rs_progress_update(void *progress, uint64_t done, uint64_t total);
/* Ends the bar's line (if any). */
void rs_progress_end(rs_progress *p);

#endif
