/* app/image_settings.h — what decides the image, made once from the options and read-only after
 * (as Cycles' Integrator and Film parameters stand apart from its SessionParams): the render's
 * image-defining settings, apart from how it runs (devices, threads, waves, the time limit:
 * scheduler/render.h's rs_render_settings takes both, app/render_steps.c fills it from this).
 *
 * Every output that records the settings reads them through one table (rs_image_setting): the
 * checkpoint's settings block (app/checkpoint.h: a resumed render must have the same value of
 * each, and a mismatch names its option), the EXR header ("raystream:NAME"), --stats-json's
 * "settings" object.  A new image-defining setting is a field here and a row in the table
 * (image_settings.c); tests/app_settings_test.c adds a dummy row and checks that the key, the
 * header and the report follow.
 *
 * The image size and spp are not rows: the checkpoint keeps them in fixed fields with rules of
 * their own (a render may be continued to more samples), and the EXR header reports the spp
 * every pixel has beside the spp asked for. */
#ifndef RS_APP_IMAGE_SETTINGS_H
#define RS_APP_IMAGE_SETTINGS_H

#include <stddef.h>
#include <stdint.h>

#include "shading/filter.h"
#include "shading/integrator.h"

typedef struct rs_image_settings {
    uint32_t width, height; /* the image (the scene's own size where no option gave one) */
    uint32_t spp;           /* samples per pixel asked for (adaptive: the most a pixel gets) */
    uint32_t max_depth;     /* most ray segments a path may have, camera ray included */
    uint32_t rr_depth;      /* Russian roulette from this segment on */
    uint64_t seed;
    rs_sampling sampling;
    rs_sampler sampler;
    rs_filter filter;        /* the pixel filter */
    uint32_t texture_filter; /* rs_texture_filter */
    uint32_t light_sampler;  /* rs_light_sampler */
    uint32_t isect_sphere, isect_tri, isect_aabb; /* the intersection tests (core/intersect.h) */
    double adaptive;           /* --adaptive's threshold; 0: every pixel gets spp */
    uint32_t adaptive_min_spp; /* with adaptive > 0 */
} rs_image_settings;

/* One row of the table: `name` is the setting's key everywhere (the checkpoint's block, the EXR
 * header's "raystream:NAME", the JSON's "settings"), `option` the command-line option that sets
 * it (for messages), `text` writes its value (at most RS_SETTING_TEXT bytes with the NUL). */
#define RS_SETTING_TEXT 64
typedef struct rs_setting_desc {
    const char *name, *option;
    void (*text)(const rs_image_settings *s, char *buf, size_t n);
} rs_setting_desc;

/* The rows: i in [0, rs_image_settings_count()). */
size_t rs_image_settings_count(void);
const rs_setting_desc *rs_image_setting(size_t i);
/* Tests only: one more row for the rest of the process (at most 4).  0 when full. */
int rs_image_settings_add_row(const rs_setting_desc *d);

/* The checkpoint's settings block: "NAME=VALUE\n" for every row, into buf (n bytes); returns the
 * length, or 0 when it does not fit. */
size_t rs_image_settings_block(const rs_image_settings *s, char *buf, size_t n);
/* A block read back from a checkpoint against s: 1 when every row has the same value; otherwise
 * 0 with the first that differs (or is missing on one side, or unknown to this build) described:
 * its option, the file's value and s's (either may be "(none)"). */
int rs_image_settings_match(const rs_image_settings *s, const char *block, size_t len,
                            char *option, size_t on, char *in_file, char *asked, size_t vn);

#endif
