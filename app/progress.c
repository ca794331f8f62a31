/* app/progress.c — see progress.h. */
#include "app/progress.h"

#include <stdio.h>
#include <time.h>
#include <unistd.h>

void rs_progress_begin(rs_progress *p, int enabled)
{
    p->enabled = enabled;
    p->tty = isatty(STDERR_FILENO);
    p->start = rs_now_s();
    p->last_draw = 0.0;
    p->last_decile = 0;
    p->drawn = 0;
}

void rs_progress_update(void *progress, uint64_t done, uint64_t total)
{
    rs_progress *p = (rs_progress *)progress;
    double now = rs_now_s(), frac = total ? (double)done / (double)total : 1.0;
    double elapsed = now - p->start;
    if (!p->enabled)
        return;
    if (p->tty) {
        enum { WIDTH = 40 };
        char bar[WIDTH + 1];
        int i, fill = (int)(frac * WIDTH);
        if (now - p->last_draw < 0.1 && done < total)
            return;
        p->last_draw = now;
        for (i = 0; i < WIDTH; ++i)
            bar[i] = i < fill ? '=' : (i == fill ? '>' : ' ');
        bar[WIDTH] = '\0';
        if (frac > 0.0 && done < total)
            fprintf(stderr, "\r[%s] %5.1f%%  %6.1f s  eta %6.1f s ", bar, 100.0 * frac, elapsed,
                    elapsed / frac - elapsed);
        else
            fprintf(stderr, "\r[%s] %5.1f%%  %6.1f s              ", bar, 100.0 * frac, elapsed);
        fflush(stderr);
        p->drawn = 1;
    } else {
        int decile = (int)(frac * 10.0);
        if (decile <= p->last_decile)
            return;
        p->last_decile = decile;
        fprintf(stderr, "raystream: %3d%% after %.1f s\n", decile * 10, elapsed);
    }
}

void rs_progress_end(rs_progress *p)
{
    if (p->enabled && p->tty && p->drawn)
        fputc('\n', stderr);
    p->drawn = 0;
}
