/* scenes/sky.h — a daylight sky with a sun, as an equirectangular environment image.
 *
 * The sky is Preetham, Shirley and Smits, "A Practical Analytic Model for Daylight" (SIGGRAPH
 * 1999): the Perez distribution of luminance Y and chromaticities x, y, scaled by the paper's
 * zenith values, turned from xyY into XYZ and then into linear Rec.709 / sRGB primaries.  The sun
 * is a disc of angular radius RS_SKY_SUN_RADIUS_DEG whose radiance is the paper's Appendix: the
 * extraterrestrial solar spectrum attenuated by Rayleigh, aerosol (Angstrom, from turbidity),
 * ozone and water vapour transmittances, integrated against the CIE 1931 curves.  Below the
 * horizon the image shows a grey ground of albedo RS_SKY_GROUND_ALBEDO lit by that sky and sun
 * (uniform radiance albedo * E / pi, E the horizontal irradiance).  docs/sky.md has the formulas,
 * their sources and the limitations.
 *
 * Frame: +y is up (the zenith); the sun at azimuth 0 lies toward -z (the middle of the image in
 * shading/envmap.h's mapping), at azimuth +90 toward +x:
 *   sun = (cos(el) sin(az), sin(el), -cos(el) cos(az)).
 * Units: radiance = luminance in kcd/m^2 times RS_SKY_SCALE times `intensity` (per RGB channel,
 * the channel's share of it), chosen so that a white diffuse plane facing up under the default
 * sky and sun (45 degrees) reflects about 1.0.
 *
 * The image carries the sun's power exactly: each texel the disc touches gets the sun's radiance
 * times the fraction of its solid angle the disc covers, the fractions scaled so that their sum
 * times the texels' solid angles equals the disc's solid angle (the part above the horizon), so
 * the irradiance from the sun is right although the disc drawn is blocky.
 *
 * Parameters must lie in the ranges below: rs_sky_image checks them, the other functions assume
 * them.  Host only; every function is thread-safe (no state). */
#ifndef RS_SCENES_SKY_H
#define RS_SCENES_SKY_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/vec3.h"

/* renderer radiance per kcd/m^2 of luminance (intensity 1) */
#define RS_SKY_SCALE 0.0365f
/* the mean solar angular radius, degrees */
#define RS_SKY_SUN_RADIUS_DEG 0.2666
/* the ground below the horizon: a grey Lambertian reflector lit by the sky and the sun */
#define RS_SKY_GROUND_ALBEDO 0.1
/* the image size meant for rendering: 0.176 degrees a texel, the sun ~3 texels across; 24 MiB */
#define RS_SKY_WIDTH  2048u
#define RS_SKY_HEIGHT 1024u

typedef struct rs_sky_params {
    float elevation_deg; /* the sun above the horizon, degrees, 0..90, default 45 */
    float azimuth_deg;   /* the sun's compass direction, degrees, -360..360, default 0: toward -z
                            (the map's centre); +90: toward +x */
    float turbidity;     /* Preetham's T, 2..10, default 3 (clear); larger is hazier */
    float intensity;     /* multiplier of everything (sky, sun, ground), 0..1e6, default 1 */
    int sun;             /* 1: the sun disc is drawn (default), 0: sky only (the ground is still
                            lit by the sun) */
} rs_sky_params;

#ifdef __cplusplus
extern "C" {
#endif
void rs_sky_defaults(rs_sky_params *p);

/* Parses what follows "sky" in "sky" or "sky:elevation=30,azimuth=120,turbidity=4,intensity=2,
 * sun=0": "" (the defaults) or ":k=v,..." (the defaults with those keys changed; a key may repeat,
 * the last wins).  1 with *p set, or 0 with *p unchanged and one line in why[n] (NUL-terminated,
 * cut to fit; why may be NULL) naming the bad key or value and the allowed range. */
int rs_sky_parse(const char *spec, rs_sky_params *p, char *why, size_t n);

/* The w x h equirectangular image (3 floats a texel, rows from the top, rs_alloc'ed: free with
 * rs_free) in shading/envmap.h's mapping with identity rotation: texel (i, j) holds the radiance
 * toward its centre direction, plus the sun's share as above.  RS_ERR_ARG for parameters out of
 * range or w < 2, h < 2, or a size past RS_IMAGE_MAX_SIDE-like limits (each side at most 65536);
 * RS_ERR_NOMEM. */
rs_status rs_sky_image(const rs_sky_params *p, uint32_t w, uint32_t h, float **rgb);

/* The sky's radiance toward direction d (unit; world = map frame) without the sun disc: the
 * Preetham sky above the horizon (d.y >= 0), the lit ground below it. */
rs_vec3 rs_sky_radiance(const rs_sky_params *p, rs_vec3 d);

/* The unit direction toward the sun's centre. */
rs_vec3 rs_sky_sun_direction(const rs_sky_params *p);

struct rs_scene;
/* Lights scene `s` with the sky: its RS_SKY_WIDTH x RS_SKY_HEIGHT image as the environment map
 * (importance-sampled with MIS like any map, shading/envmap.h), in place of the background.
 * The caller finalizes the scene. */
rs_status rs_scene_set_sky(struct rs_scene *s, const rs_sky_params *p);

/* The default sky of a scene whose file says nothing of its lighting (a glTF file): the defaults
 * (45 degrees, turbidity 3) with the sun behind a camera looking from `from` to `at`, 30 degrees
 * to its left (a key light over the left shoulder); a camera looking straight up or down takes
 * azimuth 0. */
void rs_sky_default_for_camera(rs_vec3 from, rs_vec3 at, rs_sky_params *p);

/* The sun disc's radiance (RGB, renderer units, intensity included) whether or not p->sun. */
rs_vec3 rs_sky_sun_radiance(const rs_sky_params *p);

/* The ground's radiance (RGB, renderer units): RS_SKY_GROUND_ALBEDO / pi times the horizontal
 * irradiance from the sky and the sun's visible part. */
rs_vec3 rs_sky_ground_radiance(const rs_sky_params *p);
#ifdef __cplusplus
}
#endif
#endif
