/* app/timeline_svg.h — `--timeline FILE.svg`: a render's timeline as a picture read at a glance.
 *
 * One horizontal lane per device (lane i = device i) and a last lane for the render thread;
 * busy spans are rectangles coloured by stage (a legend names each stage that occurs), idle time
 * shows as the lane's light background, new waves are marked above the render-thread lane, and
 * a time axis in seconds runs underneath.  The title and a one-line summary (total time, busy
 * percentage per lane) head the picture.  The SVG is self-contained: no scripts, no external
 * fonts or CSS. */
#ifndef RS_APP_TIMELINE_SVG_H
#define RS_APP_TIMELINE_SVG_H

#include "core/status.h"
#include "scheduler/timeline.h"

/* Each stage's fill colour in the SVG, "#rrggbb" (fixed, so pictures compare across runs). */
const char *rs_timeline_stage_color(rs_stage s);

/* Writes the timeline `t` to `path` as SVG.  lane_names[i] names lane i (n_lanes of them: the
 * devices, then the render thread, e.g. "shading (render thread)"); lane_names, or any one
 * name, may be NULL ("lane i" is used).  Spans on lanes >= n_lanes are left out (the summary says
 * how many).  title may be NULL.  Names are XML-escaped.  The file is written as `path.tmp` in the
 * same folder and renamed into place, so a failure leaves no partial file.  Each span is one
 * rectangle with a tooltip (stage, wave, t0-t1 ms), unless the timeline holds more than
 * RS_TIMELINE_SVG_MERGE_SPANS spans (about 130 bytes each): then each lane with more than
 * RS_TIMELINE_SVG_MERGE_SPANS / n_lanes spans is drawn binned, per pixel column a stack of its
 * stages' busy shares, neighbouring columns with the same stack merged into one rectangle per
 * stage (the tooltip gives the share, the span count and the waves), which keeps the file to a
 * few MB whatever the span count.  RS_ERR_ARG for a NULL path or timeline or n_lanes outside
 * 1 .. 65536, RS_ERR_IO when the file cannot be written, RS_ERR_NOMEM.  Safe to call while
 * other threads add spans (those added meanwhile are left out). */
rs_status rs_timeline_write_svg(const char *path, const rs_timeline *t,
                                const char *const *lane_names, int n_lanes, const char *title);

#define RS_TIMELINE_SVG_MERGE_SPANS 20000

#endif
