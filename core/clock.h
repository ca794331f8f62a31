/* core/clock.h — the one clock every part of raystream times itself with. */
#ifndef RS_CORE_CLOCK_H
#define RS_CORE_CLOCK_H

/* Seconds on the monotonic clock (CLOCK_MONOTONIC) since an arbitrary start: only differences
 * mean anything. */
double rs_now_s(void);

#endif
