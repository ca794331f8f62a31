/* shading/camera.h — the thin-lens camera of "Ray Tracing in One Weekend" (v4): vertical field
 * of view, look-at frame, optional defocus.  Pixel (0, 0) is the top-left; a ray through pixel
 * (px, py) at offsets (jx, jy) in [0, 1)^2 samples a box filter over the pixel. */
#ifndef RS_SHADING_CAMERA_H
#define RS_SHADING_CAMERA_H

#include "core/ray.h"
#include "core/sampling.h"

typedef struct rs_camera {
    rs_vec3 origin;
    rs_vec3 corner;         /* top-left corner of the image on the focus plane, relative to
                               origin (so that directions keep their precision far from the
                               world's origin) */
    rs_vec3 du, dv;         /* one pixel to the right / one pixel down, on the focus plane */
    rs_vec3 lens_u, lens_v; /* lens-plane axes scaled by the lens radius */
    float lens_radius;
} rs_camera;

/* from/at/up: look-at frame; vfov in degrees; aperture = lens diameter (0: pinhole);
 * focus_dist <= 0 means |at - from|. */
RS_HD rs_camera rs_camera_make(rs_vec3 from, rs_vec3 at, rs_vec3 up, float vfov_deg, float aperture,
                               float focus_dist, uint32_t width, uint32_t height)
{
    rs_camera c;
    float theta = vfov_deg * (RS_PI / 180.0f);
    float fd = focus_dist > 0.0f ? focus_dist : rs_v3_length(rs_v3_sub(from, at));
    float vh = 2.0f * rs_tanf(0.5f * theta) * fd;
    float vw = vh * ((float)width / (float)height);
    rs_vec3 w = rs_v3_normalize(rs_v3_sub(from, at));
    rs_vec3 u = rs_v3_normalize(rs_v3_cross(up, w));
    rs_vec3 v = rs_v3_cross(w, u);
    rs_vec3 vu = rs_v3_scale(u, vw), vv = rs_v3_scale(v, -vh);
    c.origin = from;
    c.du = rs_v3_scale(vu, 1.0f / (float)width);
    c.dv = rs_v3_scale(vv, 1.0f / (float)height);
    c.corner = rs_v3_sub(rs_v3_sub(rs_v3_scale(w, -fd), rs_v3_scale(vu, 0.5f)),
                         rs_v3_scale(vv, 0.5f));
    c.lens_radius = 0.5f * aperture;
    c.lens_u = rs_v3_scale(u, c.lens_radius);
    c.lens_v = rs_v3_scale(v, c.lens_radius);
    return c;
}

/* A unit-direction primary ray; (l1, l2) in [0, 1)^2 pick the point on the lens. */
RS_HD rs_ray rs_camera_ray(const rs_camera *c, uint32_t px, uint32_t py, float jx, float jy,
                           float l1, float l2)
{
    rs_ray r;
    rs_vec3 target = rs_v3_add(rs_v3_add(c->corner, rs_v3_scale(c->du, (float)px + jx)),
                               rs_v3_scale(c->dv, (float)py + jy));
    rs_vec3 lens = rs_v3_splat(0.0f);
    if (c->lens_radius > 0.0f) {
        /* uniform point on the unit disk by polar mapping */
        float rr = sqrtf(l1), s, co;
        rs_sincosf(2.0f * RS_PI * l2, &s, &co);
        lens = rs_v3_add(rs_v3_scale(c->lens_u, rr * co), rs_v3_scale(c->lens_v, rr * s));
    }
    /* the direction from camera-relative points: the origin's size never rounds it */
    r.o = rs_v3_add(c->origin, lens);
    r.d = rs_v3_normalize(rs_v3_sub(target, lens));
    r.tmin = 0.0f;
    r.time = 0.0f; /* the caller picks the time in the shutter interval */
    r.tmax = 3.402823466e38f;
    return r;
}

#endif
