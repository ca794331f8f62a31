/* core/srgb.h — the sRGB transfer curve (IEC 61966-2-1), both ways (core/srgb.c).  Apart from
 * core/image_io.h so that the views (core/view.c) use it without the image files' header, which
 * includes theirs. */
#ifndef RS_CORE_SRGB_H
#define RS_CORE_SRGB_H

#ifdef __cplusplus
extern "C" {
#endif
/* The sRGB encoding of a linear value, clamped to [0, 1]. */
float rs_srgb_encode(float linear);

/* The linear value of an sRGB-encoded one in [0, 1]. */
float rs_srgb_decode(float encoded);
#ifdef __cplusplus
}
#endif

#endif
