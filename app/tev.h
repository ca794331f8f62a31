/* app/tev.h — --tev [HOST:]PORT: the image sent to a running tev viewer as it converges, over
 * tev's TCP protocol (github.com/Tom94/tev, its scripts/ipc.py: little-endian packets of a
 * uint32 length, a type byte, then the fields; CreateImage = 4, UpdateImage = 6 with per-channel
 * offsets and strides).  Internal to app/.
 *
 * The render thread only resolves the film into a buffer (rs_tev_film: at most 4 times a second,
 * only when the last update has gone out, and so that an update's cost, the resolve and the send,
 * is at most 1/100 of the time between two); a thread of the preview's own sends it, in tiles of
 * 128 x 128, so a slow or stalled viewer never holds the render up.  A viewer that is not
 * there, or goes away, costs one warning line and the render goes on. */
#ifndef RS_APP_TEV_H
#define RS_APP_TEV_H

#include <stdint.h>

#include "shading/film.h"

#define RS_TEV_DEFAULT_PORT 14158
#define RS_TEV_TILE         128
#define RS_TEV_INTERVAL_S   0.25 /* the shortest time between two updates */
#define RS_TEV_COST_SHARE   100  /* an update costs at most 1/100 of the time between two */

typedef struct rs_tev rs_tev;

/* Checks "[HOST:]PORT" (HOST a name or an IPv4/IPv6 address, default 127.0.0.1; PORT 1..65535).
 * Returns 1, or 0 with why in `why`. */
int rs_tev_parse(const char *spec, char *host, size_t host_n, int *port, char *why, size_t why_n);

/* Connects to the viewer and creates the image `name` (width x height, channels R, G, B).  NULL
 * after one warning line (rs_app_print) when it cannot. */
rs_tev *rs_tev_open(const char *spec, const char *name, uint32_t width, uint32_t height);

/* Offers the film as it is now (the caller may read it: a film_ready hook).  `final`: always sent,
 * and waited for; otherwise skipped when the last update is under way or was sent less than
 * RS_TEV_INTERVAL_S ago.  NULL tev: nothing. */
void rs_tev_film(rs_tev *t, const rs_film *film, int final);

/* Waits for the last update, closes the connection, frees everything.  NULL: nothing. */
void rs_tev_close(rs_tev *t);

#endif
