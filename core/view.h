/* core/view.h — view transforms: scene-linear radiance to the display-encoded values an 8-bit
 * file stores (docs/view.md).
 *
 * A view is an exposure (a gain of 2^EV on linear radiance) followed by one curve:
 *   standard     clamp to [0, 1], then the sRGB curve: rs_srgb_encode, bit for bit, which is
 *                what every 8-bit output used before views existed (the default)
 *   filmic       (alias agx) Troy Sobotka's AgX base as Blender ships it: inset matrix, log2
 *                encoding over [-12.47393, +4.026069] EV, the published 6th-order polynomial fit
 *                of its sigmoid, outset matrix, 2.2 power, then the sRGB curve
 *   pbr-neutral  the Khronos PBR Neutral tone mapper (its reference GLSL), then the sRGB curve
 *   OCIO         a view of the default display of the OpenColorIO config named by $OCIO,
 *                applied through OpenImageIO (its input: the config's scene_linear role)
 * Scene-linear outputs (.exr, .hdr, .pfm) never go through a view.
 *
 * Built-in names are matched first and exactly (lower case); any other name is looked up in the
 * $OCIO config.  Thread safety: rs_view_apply may run on any number of threads at once; the
 * OCIO config is loaded once, on first use, under a lock. */
#ifndef RS_CORE_VIEW_H
#define RS_CORE_VIEW_H

#include <stddef.h>

#include "core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rs_view_kind {
    RS_VIEW_STANDARD = 0,
    RS_VIEW_FILMIC,
    RS_VIEW_PBR_NEUTRAL,
    RS_VIEW_OCIO
} rs_view_kind;

typedef struct rs_view {
    rs_view_kind kind;
    float exposure; /* EV: linear radiance is multiplied by 2^exposure before the curve */
    char name[64];  /* the canonical built-in name ("filmic" for "agx"), or the OCIO view */
} rs_view;

/* The view called `name` (NULL: standard) with `exposure_ev` stops of exposure: 1 and *out
 * filled, or 0 with a one-line reason in why[n] (no "raystream:" prefix) for an unknown name or
 * an exposure that is not finite or outside [-64, 64]. */
int rs_view_from_name(const char *name, float exposure_ev, rs_view *out, char *why, size_t n);

/* Display-encoded values in [0, 1] (what an 8-bit file stores, / 255) from linear RGB: npix
 * pixels of 3 floats each, in and out (display_rgb may be linear_rgb: in place).  NaN and
 * negative inputs count as 0.  RS_OK, or RS_ERR_ARG (and the first-error message) when the OCIO
 * view cannot be applied. */
rs_status rs_view_apply(const rs_view *v, const float *linear_rgb, size_t npix, float *display_rgb);

/* 1 when `v` is the standard view at 0 EV: what every output looked like before views. */
int rs_view_is_default(const rs_view *v);

/* The built-in names, for messages: "standard, filmic (or agx), pbr-neutral". */
const char *rs_view_builtin_names(void);

/* One curve on one grey or colour, for tests and documentation: linear in (exposure already
 * applied), display-encoded out.  Not for OCIO views. */
void rs_view_filmic_rgb(const float in[3], float out[3]);
void rs_view_pbr_neutral_rgb(const float in[3], float out[3]);

/* The OpenColorIO half (core/view_ocio.cpp with OpenImageIO, core/view_ocio_none.c without).
 * rs_view_ocio_available: 1 when this build's OpenImageIO has OpenColorIO.
 * rs_view_ocio_find: 1 when $OCIO is set, its config loads and its default display has the
 * view `name`, whose processor can be made (its LUTs read); else 0 with the reason in why[n],
 * which lists the config's views when it loaded, or -1 when the view is there but cannot be
 * made (why[n]: OpenColorIO's reason, on one line).
 * rs_view_ocio_apply: the display transform in place on npix RGB pixels (already exposed). */
int rs_view_ocio_available(void);
int rs_view_ocio_find(const char *name, char *why, size_t n);
rs_status rs_view_ocio_apply(const char *name, float *rgb, size_t npix);

#ifdef __cplusplus
}
#endif
#endif
