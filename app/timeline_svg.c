/* app/timeline_svg.c — see timeline_svg.h.
 *
 * Layout (pixels, y downwards), SVG_W wide:
 *   title (y 24), summary line (y 44);
 *   the device lanes from PLOT_TOP, one every LANE_PITCH, each LANE_H high: name and busy % in the
 *   label column left of PLOT_X0, spans in the plot from PLOT_X0 to PLOT_X1;
 *   the wave row (WAVE_ROW high: sparse "wave N" labels over a thin band whose shade alternates
 *   at each new wave), then the render-thread lane;
 *   the time axis in seconds (its ticks also drawn as light grid lines through the lanes);
 *   the legend: one swatch per stage that occurs, then "idle".
 * Time runs from 0 (the timeline's start) to the last span's end.  Nothing is drawn from outside
 * the spans' own data, so the picture of a given timeline is always the same file. */
#include "app/timeline_svg.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

#define SVG_W          1200
#define PLOT_X0        210 /* the label column is left of this */
#define PLOT_X1        (SVG_W - 30)
#define PLOT_TOP       64
#define LANE_H         26
#define LANE_PITCH     34
#define WAVE_ROW       22
#define LEGEND_ROW     20
#define NAME_MAX_LEN   24  /* longer lane names are cut (the full name is the label's tooltip) */
#define MIN_RECT_W     1.0 /* a span shorter than a pixel still shows as a hairline */
#define WAVE_LABEL_GAP 10.0

#define LANE_BG     "#eceef2"
#define GRID_COLOR  "#d3d7de"
#define TEXT_COLOR  "#222222"
#define MUTED_COLOR "#666666"

/* Tableau 10: distinguishable, and readable next to each other; index RS_STAGE_COUNT is for a
 * stage value the enum does not know. */
static const char *const g_stage_color[RS_STAGE_COUNT + 1] = {
    "#4e79a7", /* raygen: blue */
    "#f28e2b", /* trace-closest: orange */
    "#59a14f", /* shade: green */
    "#b8312f", /* trace-shadow: dark red (darker than trace-closest, its neighbour on devices) */
    "#b07aa1", /* resolve-shadows: purple */
    "#edc948", /* compact: yellow */
    "#9c755f", /* film: brown */
    "#76b7b2", /* pass: teal */
    "#888888", /* unknown */
};

const char *rs_timeline_stage_color(rs_stage s)
{
    return g_stage_color[(unsigned)s < RS_STAGE_COUNT ? (unsigned)s : RS_STAGE_COUNT];
}

/* A span on a known lane, its stage clamped to 0 .. RS_STAGE_COUNT (unknown). */
typedef struct item {
    double t0, t1;
    uint32_t wave;
    uint16_t lane;
    uint8_t stage;
} item;

/* A dense lane's pixel column, per stage: the share of the column's time busy with the stage,
 * how many of its spans start in the column, and their waves. */
typedef struct bin {
    double busy;
    uint32_t count, wave_lo, wave_hi;
} bin;

#define N_STAGES (RS_STAGE_COUNT + 1)
#define N_COLS   (PLOT_X1 - PLOT_X0)

typedef struct wave_start {
    double t;
    uint32_t wave;
} wave_start;

static int cmp_lane_t0(const void *a, const void *b)
{
    const item *x = (const item *)a, *y = (const item *)b;
    if (x->lane != y->lane)
        return x->lane < y->lane ? -1 : 1;
    if (x->t0 != y->t0)
        return x->t0 < y->t0 ? -1 : 1;
    if (x->t1 != y->t1)
        return x->t1 < y->t1 ? -1 : 1;
    return (x->stage > y->stage) - (x->stage < y->stage);
}

static int cmp_wave_start(const void *a, const void *b)
{
    const wave_start *x = (const wave_start *)a, *y = (const wave_start *)b;
    if (x->t != y->t)
        return x->t < y->t ? -1 : 1;
    return (x->wave > y->wave) - (x->wave < y->wave);
}

/* Writes s with &, <, >, " and ' escaped; at most max_bytes bytes of it (cut at a UTF-8
 * character boundary, then "..."), or all of it when max_bytes is 0. */
static void put_xml(FILE *f, const char *s, size_t max_bytes)
{
    size_t n = strlen(s), i, cut = n;
    if (max_bytes && n > max_bytes) {
        cut = max_bytes;
        while (cut > 0 && ((unsigned char)s[cut] & 0xC0) == 0x80)
            --cut;
    }
    for (i = 0; i < cut; ++i) {
        switch (s[i]) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        case '\'': fputs("&apos;", f); break;
        default: fputc(s[i], f); break;
        }
    }
    if (cut < n)
        fputs("...", f);
}

/* The lane's name for the summary line: up to " (" ("cuda:0 (NVIDIA H100)" -> "cuda:0"). */
static void put_short_name(FILE *f, const char *s)
{
    const char *p = strstr(s, " (");
    size_t n = p && p != s ? (size_t)(p - s) : strlen(s);
    char buf[64];
    if (n >= sizeof buf)
        n = sizeof buf - 1;
    memcpy(buf, s, n);
    buf[n] = '\0';
    put_xml(f, buf, 0);
}

/* 1, 2 or 5 times a power of ten, giving about `target` ticks over `range`. */
static double nice_step(double range, int target)
{
    double raw = range / target, mag = pow(10.0, floor(log10(raw))), r = raw / mag;
    return (r < 1.5 ? 1.0 : r < 3.5 ? 2.0 : r < 7.5 ? 5.0 : 10.0) * mag;
}

typedef struct layout {
    double end;   /* the last span's end, seconds (0: no spans) */
    double total; /* seconds the plot spans (end, or 1 ms for no spans) */
    double scale; /* pixels per second */
    int n_lanes;
    int render_y; /* top of the render-thread lane */
    int axis_y;
    int legend_y;
    int height;
} layout;

static double x_of(const layout *L, double t) { return PLOT_X0 + t * L->scale; }

static int lane_y(const layout *L, int lane)
{
    return lane == L->n_lanes - 1 ? L->render_y : PLOT_TOP + lane * LANE_PITCH;
}

static const char *lane_name(const char *const *names, int lane, char *buf, size_t size)
{
    if (names && names[lane])
        return names[lane];
    snprintf(buf, size, "lane %d", lane);
    return buf;
}

/* Legend entries' widths, so the rows (and the picture's height) are known before writing. */
static double legend_item_w(const char *name) { return 12 + 6 + 7.0 * (double)strlen(name) + 22; }

static int legend_rows(const int *used)
{
    int rows = 1, s;
    double x = PLOT_X0;
    for (s = 0; s <= RS_STAGE_COUNT + 1; ++s) {
        const char *name;
        if (s < RS_STAGE_COUNT + 1 && !used[s])
            continue;
        name = s == RS_STAGE_COUNT + 1 ? "idle"
               : s == RS_STAGE_COUNT   ? "unknown"
                                       : rs_stage_name((rs_stage)s);
        if (x + legend_item_w(name) > SVG_W - 10 && x > PLOT_X0) {
            ++rows;
            x = PLOT_X0;
        }
        x += legend_item_w(name);
    }
    return rows;
}

static void write_legend(FILE *f, const layout *L, const int *used)
{
    int s, row = 0;
    double x = PLOT_X0;
    fputs("<g id=\"legend\">\n", f);
    for (s = 0; s <= RS_STAGE_COUNT + 1; ++s) {
        const char *name, *color;
        int y;
        if (s < RS_STAGE_COUNT + 1 && !used[s])
            continue;
        name = s == RS_STAGE_COUNT + 1 ? "idle"
               : s == RS_STAGE_COUNT   ? "unknown"
                                       : rs_stage_name((rs_stage)s);
        color = s == RS_STAGE_COUNT + 1 ? LANE_BG : g_stage_color[s];
        if (x + legend_item_w(name) > SVG_W - 10 && x > PLOT_X0) {
            ++row;
            x = PLOT_X0;
        }
        y = L->legend_y + row * LEGEND_ROW;
        fprintf(f, "<rect x=\"%.0f\" y=\"%d\" width=\"12\" height=\"12\" fill=\"%s\"%s/>", x, y,
                color, s == RS_STAGE_COUNT + 1 ? " stroke=\"#b8bec8\"" : "");
        fprintf(f, "<text x=\"%.0f\" y=\"%d\">%s</text>\n", x + 18, y + 10, name);
        x += legend_item_w(name);
    }
    fputs("</g>\n", f);
}

static void write_axis(FILE *f, const layout *L)
{
    double step = nice_step(L->total, 8), t;
    int decimals = step >= 1.0 ? 0 : (int)ceil(-log10(step) - 1e-9), k;
    fprintf(f, "<g stroke=\"#444444\"><line x1=\"%d\" y1=\"%d\" x2=\"%d\" y2=\"%d\"/>", PLOT_X0,
            L->axis_y, PLOT_X1, L->axis_y);
    for (k = 0; (t = k * step) <= L->total * (1.0 + 1e-9); ++k)
        fprintf(f, "<line x1=\"%.2f\" y1=\"%d\" x2=\"%.2f\" y2=\"%d\"/>", x_of(L, t), L->axis_y,
                x_of(L, t), L->axis_y + 5);
    fputs("</g>\n<g text-anchor=\"middle\" font-size=\"11\">", f);
    for (k = 0; (t = k * step) <= L->total * (1.0 + 1e-9); ++k)
        fprintf(f, "<text x=\"%.2f\" y=\"%d\">%.*f s</text>", x_of(L, t), L->axis_y + 18, decimals,
                t);
    fputs("</g>\n", f);
}

static void write_grid(FILE *f, const layout *L)
{
    double step = nice_step(L->total, 8), t;
    int k;
    fprintf(f, "<g stroke=\"%s\">", GRID_COLOR);
    for (k = 1; (t = k * step) <= L->total * (1.0 + 1e-9); ++k)
        fprintf(f, "<line x1=\"%.2f\" y1=\"%d\" x2=\"%.2f\" y2=\"%d\"/>", x_of(L, t), PLOT_TOP,
                x_of(L, t), L->render_y + LANE_H);
    fputs("</g>\n", f);
}

/* The wave row above the render-thread lane: a band whose shade changes at each new wave (waves
 * starting less than a pixel after the previous band's start join it), and a "wave N" label
 * where there is room since the last one. */
static void write_waves(FILE *f, const layout *L, const wave_start *ws, uint32_t n_ws, double end)
{
    uint32_t i, j;
    int parity = 0;
    double label_end = -1e9;
    int band_y = L->render_y - 7, text_y = L->render_y - 10;
    fputs("<g id=\"waves\">\n", f);
    for (i = 0; i < n_ws; i = j) {
        double x0 = x_of(L, ws[i].t), x1;
        /* the band runs to the next start at least a pixel away */
        for (j = i + 1; j < n_ws && x_of(L, ws[j].t) - x0 < 1.0; ++j)
            ;
        x1 = j < n_ws ? x_of(L, ws[j].t) : x_of(L, end);
        if (x1 - x0 < 1.0)
            x1 = x0 + 1.0;
        fprintf(f, "<rect x=\"%.2f\" y=\"%d\" width=\"%.2f\" height=\"5\" fill=\"%s\">", x0, band_y,
                x1 - x0, parity ? "#c3c9d2" : "#7d8796");
        if (j - i > 1)
            fprintf(f, "<title>waves %u-%u</title></rect>\n", (unsigned)ws[i].wave,
                    (unsigned)ws[j - 1].wave);
        else
            fprintf(f, "<title>wave %u</title></rect>\n", (unsigned)ws[i].wave);
        parity ^= 1;
        if (x0 >= label_end + WAVE_LABEL_GAP) {
            char label[32];
            double w;
            snprintf(label, sizeof label, "wave %u", (unsigned)ws[i].wave);
            w = 5.6 * (double)strlen(label);
            if (x0 + w <= SVG_W - 2) {
                /* the label's tick runs down through the band to the lane */
                fprintf(f, "<rect x=\"%.2f\" y=\"%d\" width=\"1\" height=\"%d\" fill=\"%s\"/>", x0,
                        text_y - 8, L->render_y - text_y + 8, MUTED_COLOR);
                fprintf(f, "<text x=\"%.2f\" y=\"%d\" font-size=\"10\" fill=\"%s\">%s</text>\n",
                        x0 + 3, text_y, MUTED_COLOR, label);
                label_end = x0 + w;
            }
        }
    }
    fputs("</g>\n", f);
}

static void write_span(FILE *f, const layout *L, const item *it)
{
    double x0 = x_of(L, it->t0), w = (it->t1 - it->t0) * L->scale;
    const char *name = it->stage < RS_STAGE_COUNT ? rs_stage_name((rs_stage)it->stage) : "unknown";
    if (w < MIN_RECT_W)
        w = MIN_RECT_W;
    fprintf(f, "<rect x=\"%.2f\" y=\"%d\" width=\"%.2f\" height=\"%d\" fill=\"%s\"><title>", x0,
            lane_y(L, it->lane) + 1, w, LANE_H - 2, g_stage_color[it->stage]);
    fprintf(f, "%s, wave %u, %.3f-%.3f ms</title></rect>\n", name, (unsigned)it->wave, 1e3 * it->t0,
            1e3 * it->t1);
}

/* Stage s's segment heights in column c: the column's stages stacked in enum order from the
 * lane's bottom, the cumulative share rounded to whole pixels (so the column's total height is
 * its busy share of the lane's height). */
static void column_heights(const bin *col, int *h)
{
    double cum = 0.0;
    int s, prev = 0, y;
    for (s = 0; s < N_STAGES; ++s) {
        cum += col[s].busy;
        y = (int)floor((cum < 1.0 ? cum : 1.0) * (LANE_H - 2) + 0.5);
        h[s] = y - prev;
        prev = y;
    }
}

static void flush_run(FILE *f, const layout *L, int lane, int c0, int c1, const int *h,
                      const bin *run)
{
    int s, below = 0, y_bottom = lane_y(L, lane) + LANE_H - 1;
    for (s = 0; s < N_STAGES; ++s) {
        if (h[s] > 0) {
            below += h[s];
            fprintf(f,
                    "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"%s\"><title>"
                    "%s: %.0f%% busy over %.3f-%.3f ms, %u spans, waves %u-%u</title></rect>\n",
                    PLOT_X0 + c0, y_bottom - below, c1 - c0, h[s], g_stage_color[s],
                    s < RS_STAGE_COUNT ? rs_stage_name((rs_stage)s) : "unknown",
                    100.0 * run[s].busy / (c1 - c0), 1e3 * c0 / L->scale, 1e3 * c1 / L->scale,
                    (unsigned)run[s].count, (unsigned)run[s].wave_lo, (unsigned)run[s].wave_hi);
        }
    }
}

/* A lane with very many spans, drawn at the plot's resolution: per pixel column a stack of the
 * stages' busy shares (a full-height column is a column busy all the time), columns with the
 * same stack drawn as one rectangle per stage.  At most N_COLS * N_STAGES rectangles, whatever
 * the span count.  `bins` has N_COLS * N_STAGES entries. */
static void write_binned_lane(FILE *f, const layout *L, int lane, const item *items, uint32_t n,
                              bin *bins)
{
    int c, s, c0 = -1, h[N_STAGES], run_h[N_STAGES];
    bin run[N_STAGES];
    uint32_t i;
    for (c = 0; c < N_COLS * N_STAGES; ++c) {
        bins[c].busy = 0.0;
        bins[c].count = 0;
        bins[c].wave_lo = UINT32_MAX;
        bins[c].wave_hi = 0;
    }
    for (i = 0; i < n; ++i) {
        double x0 = items[i].t0 * L->scale, x1 = items[i].t1 * L->scale;
        int first = (int)floor(x0), last = (int)ceil(x1) - 1;
        if (first < 0)
            first = 0;
        if (last >= N_COLS)
            last = N_COLS - 1;
        if (last < first)
            last = first; /* an empty span still counts in its column */
        for (c = first; c <= last; ++c) {
            bin *b = &bins[c * N_STAGES + items[i].stage];
            double lo = x0 > c ? x0 : c, hi = x1 < c + 1 ? x1 : c + 1;
            if (hi > lo)
                b->busy += hi - lo;
            if (c == first)
                ++b->count;
            if (items[i].wave < b->wave_lo)
                b->wave_lo = items[i].wave;
            if (items[i].wave > b->wave_hi)
                b->wave_hi = items[i].wave;
        }
    }
    fprintf(f, "<g id=\"lane%d\" shape-rendering=\"crispEdges\">\n", lane);
    for (c = 0; c <= N_COLS; ++c) {
        int same = c0 >= 0 && c < N_COLS, empty = 1;
        if (c < N_COLS) {
            column_heights(&bins[c * N_STAGES], h);
            for (s = 0; s < N_STAGES; ++s) {
                empty &= h[s] == 0;
                if (c0 >= 0 && h[s] != run_h[s])
                    same = 0;
            }
        }
        if (same) {
            for (s = 0; s < N_STAGES; ++s) {
                const bin *b = &bins[c * N_STAGES + s];
                run[s].busy += b->busy;
                run[s].count += b->count;
                if (b->wave_lo < run[s].wave_lo)
                    run[s].wave_lo = b->wave_lo;
                if (b->wave_hi > run[s].wave_hi)
                    run[s].wave_hi = b->wave_hi;
            }
            continue;
        }
        if (c0 >= 0)
            flush_run(f, L, lane, c0, c, run_h, run);
        c0 = -1;
        if (c < N_COLS && !empty) {
            c0 = c;
            memcpy(run_h, h, sizeof h);
            memcpy(run, &bins[c * N_STAGES], sizeof run);
        }
    }
    fputs("</g>\n", f);
}

/* Everything the picture is drawn from. */
typedef struct picture {
    layout L;
    item *items;          /* sorted by lane, then t0 */
    uint32_t *lane_first; /* lane l's spans: items[lane_first[l] ..][.. lane_n[l]] */
    uint32_t *lane_n;
    double *busy; /* seconds lane l was busy (the union of its spans) */
    int used[N_STAGES];
    wave_start *ws; /* new waves, by time */
    uint32_t n_ws;
    double wave_end;
    uint32_t dense; /* lanes with more spans than this are drawn binned */
    bin *bins;      /* N_COLS * N_STAGES, when a lane is binned */
    uint32_t n_spans, off_lane;
    uint64_t dropped;
} picture;

/* The picture's head: the <svg> element, its background, the title and the summary line (total
 * time, each lane's busy share, the log's size). */
static void write_head(FILE *f, const picture *P, const char *const *lane_names, const char *title)
{
    const layout *L = &P->L;
    int l;
    char buf[32];
    fprintf(f,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
            "viewBox=\"0 0 %d %d\" font-family=\"sans-serif\" font-size=\"12\" fill=\"%s\">\n",
            SVG_W, L->height, SVG_W, L->height, TEXT_COLOR);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#ffffff\"/>\n", SVG_W, L->height);
    fputs("<text x=\"12\" y=\"24\" font-size=\"16\" font-weight=\"bold\">", f);
    put_xml(f, title ? title : "raystream timeline", 0);
    fputs("</text>\n", f);

    fprintf(f, "<text x=\"12\" y=\"44\">total %.3f s &#183; busy:", L->end);
    for (l = 0; l < L->n_lanes; ++l) {
        fputs(l ? ", " : " ", f);
        put_short_name(f, lane_name(lane_names, l, buf, sizeof buf));
        fprintf(f, " %.0f%%", 100.0 * P->busy[l] / L->total);
    }
    fprintf(f, " &#183; %u spans", (unsigned)P->n_spans);
    if (P->n_ws)
        fprintf(f, ", %u waves", (unsigned)P->n_ws);
    if (P->dropped || P->off_lane) {
        fputs(" &#183; <tspan fill=\"#c0392b\">", f);
        if (P->dropped)
            fprintf(f, "%llu dropped (log full)%s", (unsigned long long)P->dropped,
                    P->off_lane ? ", " : "");
        if (P->off_lane)
            fprintf(f, "%u on unknown lanes left out", (unsigned)P->off_lane);
        fputs("</tspan>", f);
    }
    fputs("</text>\n", f);
}

/* Each lane's frame: its label (cut to NAME_MAX_LEN, the full name as tooltip), its busy share
 * and its background (idle shows through it). */
static void write_lane_frames(FILE *f, const picture *P, const char *const *lane_names)
{
    const layout *L = &P->L;
    int l;
    char buf[32];
    for (l = 0; l < L->n_lanes; ++l) {
        const char *name = lane_name(lane_names, l, buf, sizeof buf);
        int y = lane_y(L, l);
        fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"end\">", PLOT_X0 - 10, y + 12);
        if (strlen(name) > NAME_MAX_LEN) {
            fputs("<title>", f);
            put_xml(f, name, 0);
            fputs("</title>", f);
        }
        put_xml(f, name, NAME_MAX_LEN);
        fprintf(f,
                "</text>\n<text x=\"%d\" y=\"%d\" text-anchor=\"end\" font-size=\"10\" "
                "fill=\"%s\">busy %.1f%%%s</text>\n",
                PLOT_X0 - 10, y + 24, MUTED_COLOR, 100.0 * P->busy[l] / L->total,
                P->lane_n[l] > P->dense ? " (binned)" : "");
        fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"%s\"/>\n", PLOT_X0, y,
                PLOT_X1 - PLOT_X0, LANE_H, LANE_BG);
    }
}

/* Each lane's spans: one rectangle per span, or binned where the lane is dense. */
static void write_lane_spans(FILE *f, const picture *P)
{
    const layout *L = &P->L;
    int l;
    uint32_t i;
    for (l = 0; l < L->n_lanes; ++l) {
        const item *a = P->items + P->lane_first[l];
        if (P->lane_n[l] > P->dense) {
            write_binned_lane(f, L, l, a, P->lane_n[l], P->bins);
            continue;
        }
        /* crisp edges: anti-aliased seams between touching spans would read as idle gaps */
        fprintf(f, "<g id=\"lane%d\" shape-rendering=\"crispEdges\">\n", l);
        for (i = 0; i < P->lane_n[l]; ++i)
            write_span(f, L, &a[i]);
        fputs("</g>\n", f);
    }
}

/* The whole picture; a failed write shows in ferror(f). */
static void write_svg(FILE *f, const picture *P, const char *const *lane_names, const char *title)
{
    write_head(f, P, lane_names, title);
    write_lane_frames(f, P, lane_names);
    write_grid(f, &P->L);
    if (P->n_ws)
        write_waves(f, &P->L, P->ws, P->n_ws, P->wave_end);
    write_lane_spans(f, P);
    write_axis(f, &P->L);
    write_legend(f, &P->L, P->used);
    fputs("</svg>\n", f);
}

/* The new waves: where the render thread first works on a wave newer than any before it (waves
 * overlap when they are pipelined); from the devices' spans if the render thread has none. */
static void find_waves(picture *P, uint32_t n)
{
    int render = P->L.n_lanes - 1, from_render = P->lane_n[render] > 0;
    int64_t newest = -1;
    uint32_t i, n_cand = 0;
    for (i = 0; i < n; ++i) {
        if (from_render && P->items[i].lane != render)
            continue;
        P->ws[n_cand].t = P->items[i].t0;
        P->ws[n_cand++].wave = P->items[i].wave;
        if (P->items[i].t1 > P->wave_end)
            P->wave_end = P->items[i].t1;
    }
    qsort(P->ws, n_cand, sizeof *P->ws, cmp_wave_start);
    P->n_ws = 0;
    for (i = 0; i < n_cand; ++i)
        if ((int64_t)P->ws[i].wave > newest) {
            newest = P->ws[i].wave;
            P->ws[P->n_ws++] = P->ws[i];
        }
}

/* Allocates P's arrays for P->n_spans spans over n_lanes lanes and *tmp, the name "`path`.tmp"
 * (every allocation tried, in this order, even after one fails).  RS_ERR_NOMEM with a message
 * when one failed; free_picture and rs_free(*tmp) release what was made either way. */
static rs_status alloc_picture(picture *P, const char *path, int n_lanes, char **tmp)
{
    size_t plen = strlen(path);
    *tmp = (char *)rs_alloc(plen + 5, 1);
    P->items = (item *)rs_alloc(P->n_spans, sizeof *P->items);
    P->ws = (wave_start *)rs_alloc(P->n_spans, sizeof *P->ws);
    P->lane_first = (uint32_t *)rs_calloc((size_t)n_lanes, sizeof *P->lane_first);
    P->lane_n = (uint32_t *)rs_calloc((size_t)n_lanes, sizeof *P->lane_n);
    P->busy = (double *)rs_calloc((size_t)n_lanes, sizeof *P->busy);
    if (!*tmp || !P->items || !P->ws || !P->lane_first || !P->lane_n || !P->busy)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory for the timeline", path);
    memcpy(*tmp, path, plen);
    memcpy(*tmp + plen, ".tmp", 5);
    return RS_OK;
}

static void free_picture(picture *P)
{
    rs_free(P->items);
    rs_free(P->ws);
    rs_free(P->lane_first);
    rs_free(P->lane_n);
    rs_free(P->busy);
    rs_free(P->bins);
}

/* The spans on known lanes (lanes < n_lanes; the others counted in P->off_lane) into P->items,
 * sorted by lane then start, with each lane's range and the stages used.  Returns how many;
 * *tmax is the latest end (0 for none). */
static uint32_t collect_items(picture *P, const rs_span *spans, int n_lanes, double *tmax)
{
    uint32_t n = 0, i;
    *tmax = 0.0;
    for (i = 0; i < P->n_spans; ++i) {
        const rs_span *s = &spans[i];
        item *it;
        if (s->lane >= n_lanes) {
            ++P->off_lane;
            continue;
        }
        it = &P->items[n++];
        it->t0 = s->t0;
        it->t1 = s->t1;
        it->wave = s->wave;
        it->lane = s->lane;
        it->stage = s->stage < RS_STAGE_COUNT ? s->stage : RS_STAGE_COUNT;
        P->used[it->stage] = 1;
        if (s->t1 > *tmax)
            *tmax = s->t1;
    }
    qsort(P->items, n, sizeof *P->items, cmp_lane_t0);
    for (i = 0; i < n; ++i)
        if (P->lane_n[P->items[i].lane]++ == 0)
            P->lane_first[P->items[i].lane] = i;
    return n;
}

/* The time scale and the rows' positions (see the layout at the top of the file). */
static void lay_out(layout *L, double tmax, int n_lanes, const int *used)
{
    L->end = tmax;
    L->total = tmax > 0.0 ? tmax : 1e-3;
    L->scale = N_COLS / L->total;
    L->n_lanes = n_lanes;
    L->render_y = PLOT_TOP + (n_lanes - 1) * LANE_PITCH + WAVE_ROW;
    L->axis_y = L->render_y + LANE_H + 8;
    L->legend_y = L->axis_y + 34;
    L->height = L->legend_y + legend_rows(used) * LEGEND_ROW + 6;
}

/* Busy time per lane: the union of its spans (a device may run chunks side by side). */
static void lane_busy(picture *P)
{
    int l;
    uint32_t i;
    for (l = 0; l < P->L.n_lanes; ++l) {
        const item *a = P->items + P->lane_first[l];
        double end = -1.0, sum = 0.0;
        for (i = 0; i < P->lane_n[l]; ++i) {
            double t0 = a[i].t0 > end ? a[i].t0 : end;
            if (a[i].t1 > t0)
                sum += a[i].t1 - t0;
            if (a[i].t1 > end)
                end = a[i].t1;
        }
        P->busy[l] = sum;
    }
}

/* Too many spans (n of them) for one rectangle each: the lanes holding most of them are binned,
 * so at most RS_TIMELINE_SVG_MERGE_SPANS spans are drawn one by one.  Sets P->dense and
 * allocates P->bins where needed; RS_ERR_NOMEM with a message. */
static rs_status choose_binning(picture *P, uint32_t n, const char *path)
{
    P->dense = UINT32_MAX;
    if (n > RS_TIMELINE_SVG_MERGE_SPANS) {
        P->dense = RS_TIMELINE_SVG_MERGE_SPANS / (uint32_t)P->L.n_lanes;
        P->bins = (bin *)rs_alloc(N_COLS * N_STAGES, sizeof *P->bins);
        if (!P->bins)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory for the timeline", path);
    }
    return RS_OK;
}

/* Writes the picture to `tmp` and renames it to `path`; on failure removes `tmp` and reports
 * RS_ERR_IO. */
static rs_status write_file(const char *path, const char *tmp, const picture *P,
                            const char *const *lane_names, const char *title)
{
    FILE *f = fopen(tmp, "wb");
    int ok;
    if (!f)
        return rs_error_set(RS_ERR_IO, "%s: cannot write the timeline (%s)", path, strerror(errno));
    setvbuf(f, NULL, _IOFBF, 1 << 16);
    write_svg(f, P, lane_names, title);
    ok = !ferror(f);
    if (fclose(f) != 0)
        ok = 0;
    if (!ok) {
        rs_status st =
            rs_error_set(RS_ERR_IO, "%s: cannot write the timeline (%s)", path, strerror(errno));
        remove(tmp);
        return st;
    }
    if (rename(tmp, path) != 0) {
        rs_status st = rs_error_set(RS_ERR_IO, "%s: cannot write the timeline (rename: %s)", path,
                                    strerror(errno));
        remove(tmp);
        return st;
    }
    return RS_OK;
}

rs_status rs_timeline_write_svg(const char *path, const rs_timeline *t,
                                const char *const *lane_names, int n_lanes, const char *title)
{
    const rs_span *spans;
    uint32_t n;
    double tmax;
    picture P;
    char *tmp = NULL;
    rs_status st;

    if (!path || !t)
        return rs_error_set(RS_ERR_ARG, "rs_timeline_write_svg: no %s", path ? "timeline" : "path");
    if (n_lanes < 1 || n_lanes > 65536)
        return rs_error_set(RS_ERR_ARG, "%s: %d timeline lanes (1 .. 65536)", path, n_lanes);
    memset(&P, 0, sizeof P);
    spans = rs_timeline_spans(t, &P.n_spans, &P.dropped);

    /* everything is allocated before the file is opened */
    st = alloc_picture(&P, path, n_lanes, &tmp);
    if (st == RS_OK) {
        n = collect_items(&P, spans, n_lanes, &tmax);
        lay_out(&P.L, tmax, n_lanes, P.used);
        lane_busy(&P);
        find_waves(&P, n);
        st = choose_binning(&P, n, path);
    }
    if (st == RS_OK)
        st = write_file(path, tmp, &P, lane_names, title);
    rs_free(tmp);
    free_picture(&P);
    return st;
}
