/* scenes/sky.c — the Preetham daylight sky and sun as an environment image (see sky.h and
 * docs/sky.md).  Everything is computed in double and rounded to float once, per texel.
 *
 * Sources: A. J. Preetham, P. Shirley, B. Smits, "A Practical Analytic Model for Daylight",
 * SIGGRAPH 1999: the Perez coefficients, zenith luminance and chromaticity (Appendix A.2), the
 * sun's spectral radiance and its transmittances (Appendix A.3, after Iqbal, "An Introduction to
 * Solar Radiation", 1983); the CIE 1931 curves as C. Wyman, P.-P. Sloan, P. Shirley's multi-lobe
 * fit ("Simple Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013);
 * XYZ to linear sRGB by the IEC 61966-2-1 matrix (D65 white). */
#include "scenes/sky.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/try.h"
#include "scenes/scene.h"

#define PI 3.14159265358979323846

/* Perez coefficients A..E = a T + b for Y, x, y (Preetham et al. 1999, Appendix A.2). */
static const double perez_coef[3][5][2] = {
    {{0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}},
    {{-0.0193, -0.2592},
     {-0.0665, 0.0008},
     {-0.0004, 0.2125},
     {-0.0641, -0.8989},
     {-0.0033, 0.0452}},
    {{-0.0167, -0.2608},
     {-0.0950, 0.0092},
     {-0.0079, 0.2102},
     {-0.0441, -1.6537},
     {-0.0109, 0.0529}},
};

/* Zenith chromaticity: x_z = [T^2 T 1] M [ts^3 ts^2 ts 1]^T (Appendix A.2), rows for T^2, T, 1. */
static const double zenith_x[3][4] = {{0.00166, -0.00375, 0.00209, 0.0},
                                      {-0.02903, 0.06377, -0.03202, 0.00394},
                                      {0.11693, -0.21196, 0.06052, 0.25886}};
static const double zenith_y[3][4] = {{0.00275, -0.00610, 0.00317, 0.0},
                                      {-0.04214, 0.08970, -0.04153, 0.00516},
                                      {0.15346, -0.26756, 0.06670, 0.26688}};

/* The extraterrestrial sun's spectral radiance, W m^-2 sr^-1 nm^-1, 380..750 nm by 10 nm
 * (Preetham et al.'s table). */
#define SUN_L0 380.0
#define SUN_DL 10.0
#define SUN_N  38
static const double sun_spectrum[SUN_N] = {
    16559.0, 16233.7, 21127.5, 25888.2, 25829.1, 24232.3, 26760.5, 29658.3, 30545.4, 30057.5,
    30663.7, 28830.4, 28712.1, 27825.0, 27100.6, 27233.6, 26361.3, 25503.8, 25060.2, 25311.6,
    25355.9, 25134.2, 24631.5, 24173.2, 23685.3, 23212.1, 22827.7, 22339.8, 21970.2, 21526.7,
    21097.9, 20728.3, 20240.4, 19870.8, 19427.2, 19072.4, 18628.9, 18259.2};

/* Ozone absorption k_o (cm^-1) and water vapour absorption k_wa (cm^-1), as (nm, value) pairs
 * over 355..760 nm, linearly interpolated (Iqbal's tables as Preetham et al. give them).  The
 * mixed gases' band (759..771 nm) lies past the spectrum above and is left out. */
static const double ozone_k[][2] = {
    {355, 0.0},   {445, 0.003}, {450, 0.003}, {455, 0.004}, {460, 0.006}, {465, 0.008},
    {470, 0.009}, {475, 0.012}, {480, 0.014}, {485, 0.017}, {490, 0.021}, {495, 0.025},
    {500, 0.03},  {505, 0.035}, {510, 0.04},  {515, 0.045}, {520, 0.048}, {525, 0.057},
    {530, 0.063}, {535, 0.07},  {540, 0.075}, {545, 0.08},  {550, 0.085}, {555, 0.095},
    {560, 0.103}, {565, 0.110}, {570, 0.12},  {575, 0.122}, {580, 0.12},  {585, 0.118},
    {590, 0.115}, {595, 0.12},  {600, 0.125}, {605, 0.130}, {610, 0.12},  {620, 0.105},
    {630, 0.09},  {640, 0.079}, {650, 0.067}, {660, 0.057}, {670, 0.048}, {680, 0.036},
    {690, 0.028}, {700, 0.023}, {710, 0.018}, {720, 0.014}, {730, 0.011}, {740, 0.010},
    {750, 0.009}, {760, 0.007}};
static const double water_k[][2] = {{689, 0.0},    {690, 0.016}, {700, 0.024},
                                    {710, 0.0125}, {720, 1.0},   {730, 0.87},
                                    {740, 0.061},  {750, 0.001}, {760, 0.00001}};

#define OZONE_CM      0.35 /* ozone layer thickness, cm (NTP) */
#define WATER_CM      2.0  /* precipitable water vapour, cm */
#define AEROSOL_ALPHA 1.3

/* The model for one set of parameters. */
typedef struct sky_model {
    double perez[3][5]; /* A..E for Y, x, y */
    double zenith[3];   /* Y_z (kcd/m^2), x_z, y_z */
    double norm[3];     /* zenith / F(0, theta_s) */
    double theta_s;     /* the sun's zenith angle */
    double sun[3];      /* toward the sun */
    double scale;       /* RS_SKY_SCALE * intensity */
} sky_model;

static double table_lerp(const double (*t)[2], size_t n, double x)
{
    size_t k;
    if (x <= t[0][0])
        return t[0][1];
    for (k = 1; k < n; k++)
        if (x <= t[k][0])
            return t[k - 1][1] +
                   (t[k][1] - t[k - 1][1]) * (x - t[k - 1][0]) / (t[k][0] - t[k - 1][0]);
    return t[n - 1][1];
}

/* Wyman, Sloan, Shirley 2013, eq. 2: a Gaussian with different widths either side of mu. */
static double lobe(double l, double mu, double s1, double s2)
{
    double t = (l - mu) / (l < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

static void cie_xyz(double l, double xyz[3])
{
    xyz[0] = 1.056 * lobe(l, 599.8, 37.9, 31.0) + 0.362 * lobe(l, 442.0, 16.0, 26.7) -
             0.065 * lobe(l, 501.1, 20.4, 26.2);
    xyz[1] = 0.821 * lobe(l, 568.8, 46.9, 40.5) + 0.286 * lobe(l, 530.9, 16.3, 31.1);
    xyz[2] = 1.217 * lobe(l, 437.0, 11.8, 36.0) + 0.681 * lobe(l, 459.0, 26.0, 13.8);
}

/* Linear sRGB (Rec.709 primaries, D65) from XYZ; negative components (out of gamut) clamped. */
static void xyz_to_rgb(const double xyz[3], double s, double rgb[3])
{
    double r = 3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2];
    double g = -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2];
    double b = 0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2];
    rgb[0] = (r > 0 ? r : 0) * s;
    rgb[1] = (g > 0 ? g : 0) * s;
    rgb[2] = (b > 0 ? b : 0) * s;
}

/* Perez et al. 1993: F(theta, gamma) = (1 + A e^(B / cos theta)) (1 + C e^(D gamma) + E cos^2
 * gamma).  cos theta is kept above 1e-4: B < 0 for every allowed T, so the first factor goes
 * to 1 at the horizon, as the formula does in the limit. */
static double perez(const double *c, double cos_theta, double gamma, double cos_gamma)
{
    double ct = cos_theta > 1e-4 ? cos_theta : 1e-4;
    return (1.0 + c[0] * exp(c[1] / ct)) *
           (1.0 + c[2] * exp(c[3] * gamma) + c[4] * cos_gamma * cos_gamma);
}

static void sun_dir(const rs_sky_params *p, double s[3])
{
    double el = p->elevation_deg * (PI / 180.0), az = p->azimuth_deg * (PI / 180.0);
    s[0] = cos(el) * sin(az);
    s[1] = sin(el);
    s[2] = -cos(el) * cos(az);
}

static void model_init(const rs_sky_params *p, sky_model *m)
{
    double T = p->turbidity, ts, chi, tv[4];
    int c, k;
    sun_dir(p, m->sun);
    m->theta_s = ts = (90.0 - p->elevation_deg) * (PI / 180.0);
    for (c = 0; c < 3; c++)
        for (k = 0; k < 5; k++)
            m->perez[c][k] = perez_coef[c][k][0] * T + perez_coef[c][k][1];
    /* zenith luminance, kcd/m^2 (Appendix A.2) */
    chi = (4.0 / 9.0 - T / 120.0) * (PI - 2.0 * ts);
    m->zenith[0] = (4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192;
    tv[0] = ts * ts * ts;
    tv[1] = ts * ts;
    tv[2] = ts;
    tv[3] = 1.0;
    m->zenith[1] = m->zenith[2] = 0.0;
    for (k = 0; k < 4; k++) {
        m->zenith[1] += (T * T * zenith_x[0][k] + T * zenith_x[1][k] + zenith_x[2][k]) * tv[k];
        m->zenith[2] += (T * T * zenith_y[0][k] + T * zenith_y[1][k] + zenith_y[2][k]) * tv[k];
    }
    /* Y(theta, gamma) = Y_z F(theta, gamma) / F(0, theta_s), likewise x and y */
    for (c = 0; c < 3; c++)
        m->norm[c] = m->zenith[c] / perez(m->perez[c], 1.0, ts, cos(ts));
    m->scale = (double)RS_SKY_SCALE * p->intensity;
}

/* The sky's radiance (RGB, renderer units) toward unit d; directions below the horizon get the
 * horizon's value (callers put the ground there). */
static void sky_rgb(const sky_model *m, const double d[3], double rgb[3])
{
    double ct = d[1] > 0.0 ? d[1] : 0.0;
    double cg = d[0] * m->sun[0] + d[1] * m->sun[1] + d[2] * m->sun[2], g, Y, x, y, xyz[3];
    cg = cg > 1.0 ? 1.0 : cg < -1.0 ? -1.0 : cg;
    g = acos(cg);
    Y = m->norm[0] * perez(m->perez[0], ct, g, cg);
    x = m->norm[1] * perez(m->perez[1], ct, g, cg);
    y = m->norm[2] * perez(m->perez[2], ct, g, cg);
    if (!(Y > 0.0) || !(y > 0.0)) {
        rgb[0] = rgb[1] = rgb[2] = 0.0;
        return;
    }
    xyz[0] = x / y * Y;
    xyz[1] = Y;
    xyz[2] = (1.0 - x - y) / y * Y;
    xyz_to_rgb(xyz, m->scale, rgb);
}

/* The sun disc's radiance (RGB, renderer units) at zenith angle theta_s (Appendix A.3). */
static void sun_rgb(const sky_model *m, double turbidity, double rgb[3])
{
    double ts_deg = m->theta_s * (180.0 / PI), xyz[3] = {0, 0, 0};
    /* relative optical mass (Kasten 1966), finite down to the horizon */
    double mass = 1.0 / (cos(m->theta_s) + 0.15 * pow(93.885 - ts_deg, -1.253));
    double beta = 0.04608365822050 * turbidity - 0.04586025928522; /* Angstrom's beta */
    int i;
    for (i = 0; i < SUN_N; i++) {
        double l = SUN_L0 + SUN_DL * i, um = l / 1000.0, cmf[3];
        double tau_r = exp(-mass * 0.008735 * pow(um, -4.08));
        double tau_a = exp(-mass * beta * pow(um, -AEROSOL_ALPHA));
        double tau_o =
            exp(-mass * OZONE_CM * table_lerp(ozone_k, sizeof ozone_k / sizeof *ozone_k, l));
        double kw = table_lerp(water_k, sizeof water_k / sizeof *water_k, l) * WATER_CM * mass;
        double tau_w = exp(-0.2385 * kw / pow(1.0 + 20.07 * kw, 0.45));
        double L = sun_spectrum[i] * tau_r * tau_a * tau_o * tau_w;
        cie_xyz(l, cmf);
        xyz[0] += L * cmf[0] * SUN_DL;
        xyz[1] += L * cmf[1] * SUN_DL;
        xyz[2] += L * cmf[2] * SUN_DL;
    }
    /* W m^-2 sr^-1 -> cd m^-2 (683 lm/W) -> kcd m^-2 */
    for (i = 0; i < 3; i++)
        xyz[i] *= 683.0 / 1000.0;
    xyz_to_rgb(xyz, m->scale, rgb);
}

static double sun_solid_angle(void)
{
    return 2.0 * PI * (1.0 - cos(RS_SKY_SUN_RADIUS_DEG * PI / 180.0));
}

/* The ground's radiance: albedo / pi times the horizontal irradiance from the sky (midpoint
 * quadrature, 96 x 192 cells over the upper hemisphere: the sky is smooth) and the sun. */
static void ground_rgb(const sky_model *m, const rs_sky_params *p, double rgb[3])
{
    enum { NT = 96, NP = 192 };
    double e[3] = {0, 0, 0}, sun[3], dp = 2.0 * PI / NP;
    int j, i, c;
    for (j = 0; j < NT; j++) {
        double t0 = 0.5 * PI * j / NT, t1 = 0.5 * PI * (j + 1) / NT, t = 0.5 * (t0 + t1);
        double w = dp * (cos(t0) - cos(t1)) * cos(t), st = sin(t);
        for (i = 0; i < NP; i++) {
            double ph = (i + 0.5) * dp, d[3] = {st * sin(ph), cos(t), -st * cos(ph)}, L[3];
            sky_rgb(m, d, L);
            for (c = 0; c < 3; c++)
                e[c] += L[c] * w;
        }
    }
    sun_rgb(m, p->turbidity, sun);
    for (c = 0; c < 3; c++)
        rgb[c] = RS_SKY_GROUND_ALBEDO / PI * (e[c] + sun[c] * sun_solid_angle() * cos(m->theta_s));
}

void rs_sky_defaults(rs_sky_params *p)
{
    p->elevation_deg = 45.0f;
    p->azimuth_deg = 0.0f;
    p->turbidity = 3.0f;
    p->intensity = 1.0f;
    p->sun = 1;
}

static int params_ok(const rs_sky_params *p)
{
    return p && p->elevation_deg >= 0.0f && p->elevation_deg <= 90.0f &&
           p->azimuth_deg >= -360.0f && p->azimuth_deg <= 360.0f && p->turbidity >= 2.0f &&
           p->turbidity <= 10.0f && p->intensity >= 0.0f && p->intensity <= 1e6f &&
           (p->sun == 0 || p->sun == 1);
}

rs_vec3 rs_sky_sun_direction(const rs_sky_params *p)
{
    double s[3];
    sun_dir(p, s);
    return rs_v3((float)s[0], (float)s[1], (float)s[2]);
}

rs_vec3 rs_sky_sun_radiance(const rs_sky_params *p)
{
    sky_model m;
    double rgb[3];
    model_init(p, &m);
    sun_rgb(&m, p->turbidity, rgb);
    return rs_v3((float)rgb[0], (float)rgb[1], (float)rgb[2]);
}

rs_vec3 rs_sky_ground_radiance(const rs_sky_params *p)
{
    sky_model m;
    double rgb[3];
    model_init(p, &m);
    ground_rgb(&m, p, rgb);
    return rs_v3((float)rgb[0], (float)rgb[1], (float)rgb[2]);
}

rs_vec3 rs_sky_radiance(const rs_sky_params *p, rs_vec3 dv)
{
    sky_model m;
    double d[3] = {dv.x, dv.y, dv.z}, rgb[3];
    model_init(p, &m);
    if (d[1] < 0.0)
        ground_rgb(&m, p, rgb);
    else
        sky_rgb(&m, d, rgb);
    return rs_v3((float)rgb[0], (float)rgb[1], (float)rgb[2]);
}

/* The direction of (phi, theta) in envmap.h's mapping: phi = atan2(x, -z), theta from +y. */
static void map_dir(double phi, double theta, double d[3])
{
    double st = sin(theta);
    d[0] = st * sin(phi);
    d[1] = cos(theta);
    d[2] = -st * cos(phi);
}

/* Adds the sun disc to the image: texel (i, j) gets L_sun * k * (its solid angle inside the disc
 * and above the horizon) / (its solid angle), the inside part measured on S x S sub-cells, and
 * k = (the disc's solid angle) / (the sub-cells' total inside the disc, above the horizon or
 * not), so that the image's sun power is L_sun times the disc's visible solid angle, up to the
 * sub-cells' resolution of the horizon only.  Pass 0 measures, pass 1 adds. */
static void add_sun(const sky_model *m, const double L[3], uint32_t w, uint32_t h, float *rgb)
{
    double r = RS_SKY_SUN_RADIUS_DEG * PI / 180.0, cr = cos(r), dt = PI / h, dp = 2.0 * PI / w;
    double total = 0.0, k = 0.0;
    long j0 = (long)floor((m->theta_s - r) / dt) - 1, j1 = (long)floor((m->theta_s + r) / dt) + 1;
    long half, ic, di, j, pass;
    int S = (int)ceil(8.0 * dt / r);
    double phi_s = atan2(m->sun[0], -m->sun[2]);
    S = S < 16 ? 16 : S > 256 ? 256 : S;
    j0 = j0 < 0 ? 0 : j0;
    j1 = j1 > (long)h - 1 ? (long)h - 1 : j1;
    /* columns: all near a pole, else the disc's half-width in phi plus two texels */
    if (m->theta_s - r <= 2.0 * dt || m->theta_s + r >= PI - 2.0 * dt)
        half = (long)w;
    else
        half = (long)ceil(asin(fmin(1.0, sin(r) / sin(m->theta_s - r))) / dp) + 2;
    ic = (long)floor((0.5 + phi_s / (2.0 * PI)) * w);
    if (2 * half + 1 >= (long)w) {
        ic = 0;
        half = (long)w; /* every column once: di in [0, w) below */
    }
    for (pass = 0; pass < 2; pass++) {
        for (j = j0; j <= j1; j++) {
            double ta = j * dt, tb = (j + 1) * dt, texel = dp * (cos(ta) - cos(tb));
            long lo = half == (long)w ? 0 : -half, hi = half == (long)w ? (long)w - 1 : half;
            for (di = lo; di <= hi; di++) {
                long i = ((ic + di) % (long)w + (long)w) % (long)w;
                double in = 0.0, vis = 0.0;
                int a, b;
                for (b = 0; b < S; b++) {
                    double t0 = ta + dt * b / S, t1 = ta + dt * (b + 1) / S;
                    double t = 0.5 * (t0 + t1), sub = dp / S * (cos(t0) - cos(t1));
                    for (a = 0; a < S; a++) {
                        double ph = -PI + dp * (i + (a + 0.5) / S), d[3];
                        map_dir(ph, t, d);
                        if (d[0] * m->sun[0] + d[1] * m->sun[1] + d[2] * m->sun[2] >= cr) {
                            in += sub;
                            if (d[1] >= 0.0)
                                vis += sub;
                        }
                    }
                }
                if (pass == 0) {
                    total += in;
                } else if (vis > 0.0) {
                    float *t = &rgb[3 * ((size_t)j * w + (size_t)i)];
                    double f = k * vis / texel;
                    t[0] += (float)(L[0] * f);
                    t[1] += (float)(L[1] * f);
                    t[2] += (float)(L[2] * f);
                }
            }
        }
        if (pass == 0) {
            if (total > 0.0) {
                k = sun_solid_angle() / total;
            } else if (m->sun[1] >= 0.0) {
                /* no sub-cell centre fell in the disc (cannot happen with S >= 8 dt / r): the
                 * whole power into the texel of the sun's direction */
                double v = m->theta_s / PI, u = 0.5 + phi_s / (2.0 * PI);
                size_t jj = v * h >= h ? h - 1 : (size_t)(v * h);
                size_t ii = u * w >= w ? w - 1 : (size_t)(u * w);
                double texel = dp * (cos(jj * dt) - cos((jj + 1) * dt));
                float *t = &rgb[3 * (jj * w + ii)];
                t[0] += (float)(L[0] * sun_solid_angle() / texel);
                t[1] += (float)(L[1] * sun_solid_angle() / texel);
                t[2] += (float)(L[2] * sun_solid_angle() / texel);
                return;
            } else {
                return;
            }
        }
    }
}

rs_status rs_sky_image(const rs_sky_params *p, uint32_t w, uint32_t h, float **rgb)
{
    sky_model m;
    double ground[3], sun[3];
    size_t n;
    float *im;
    uint32_t i, j;
    if (!rgb)
        return rs_error_set(RS_ERR_ARG, "sky: no output pointer");
    *rgb = NULL;
    if (!params_ok(p))
        return rs_error_set(RS_ERR_ARG, "sky: parameters out of range (elevation 0..90, azimuth "
                                        "-360..360, turbidity 2..10, intensity 0..1e6, sun 0/1)");
    if (w < 2 || h < 2 || w > 65536 || h > 65536)
        return rs_error_set(RS_ERR_ARG, "sky: image size %ux%u (each side 2..65536)", w, h);
    if (!rs_mul_size((size_t)w * h, 3, &n) || !(im = rs_alloc(n, sizeof *im)))
        return rs_error_set(RS_ERR_NOMEM, "sky: no memory for a %ux%u image", w, h);
    model_init(p, &m);
    ground_rgb(&m, p, ground);
    for (j = 0; j < h; j++) {
        double theta = (j + 0.5) * PI / h;
        for (i = 0; i < w; i++) {
            double d[3], c[3];
            float *t = &im[3 * ((size_t)j * w + i)];
            map_dir(((i + 0.5) / w - 0.5) * 2.0 * PI, theta, d);
            if (d[1] < 0.0)
                memcpy(c, ground, sizeof c);
            else
                sky_rgb(&m, d, c);
            t[0] = (float)c[0];
            t[1] = (float)c[1];
            t[2] = (float)c[2];
        }
    }
    if (p->sun) {
        sun_rgb(&m, p->turbidity, sun);
        add_sun(&m, sun, w, h, im);
    }
    *rgb = im;
    return RS_OK;
}

/* ---- parsing ---- */


typedef struct sky_key {
    const char *name;
    double lo, hi;
    const char *range;
} sky_key;

static const sky_key sky_keys[] = {{"elevation", 0.0, 90.0, "0..90 degrees"},
                                   {"azimuth", -360.0, 360.0, "-360..360 degrees"},
                                   {"turbidity", 2.0, 10.0, "2..10"},
                                   {"intensity", 0.0, 1e6, "0..1e6"},
                                   {"sun", 0.0, 1.0, "0 or 1"}};

int rs_sky_parse(const char *spec, rs_sky_params *out, char *why, size_t n)
{
    rs_sky_params p;
    const char *s;
    if (why && n)
        why[0] = '\0';
    if (!spec || !out) {
        rs_say(why, n, "sky: no specification");
        return 0;
    }
    rs_sky_defaults(&p);
    if (spec[0] == '\0') {
        *out = p;
        return 1;
    }
    if (spec[0] != ':') {
        rs_say(why, n, "sky: expected ':key=value,...' after 'sky', got '%.40s'", spec);
        return 0;
    }
    s = spec + 1;
    for (;;) {
        const char *end = strchr(s, ','), *eq;
        size_t len = end ? (size_t)(end - s) : strlen(s), kl, vl, k;
        char val[64], *vend;
        double v;
        if (len == 0) {
            rs_say(why, n,
                "sky: empty item in '%.60s' (keys: elevation, azimuth, turbidity, "
                "intensity, sun)",
                spec);
            return 0;
        }
        eq = memchr(s, '=', len);
        if (!eq) {
            rs_say(why, n, "sky: '%.*s' is not key=value", (int)(len > 40 ? 40 : len), s);
            return 0;
        }
        kl = (size_t)(eq - s);
        vl = len - kl - 1;
        for (k = 0; k < sizeof sky_keys / sizeof *sky_keys; k++)
            if (strlen(sky_keys[k].name) == kl && memcmp(sky_keys[k].name, s, kl) == 0)
                break;
        if (k == sizeof sky_keys / sizeof *sky_keys) {
            rs_say(why, n,
                "sky: unknown key '%.*s' (keys: elevation, azimuth, turbidity, intensity, "
                "sun)",
                (int)(kl > 40 ? 40 : kl), s);
            return 0;
        }
        if (vl == 0 || vl >= sizeof val) {
            rs_say(why, n, "sky: %s needs a value in %s", sky_keys[k].name, sky_keys[k].range);
            return 0;
        }
        memcpy(val, eq + 1, vl);
        val[vl] = '\0';
        v = strtod(val, &vend);
        if (vend == val || *vend != '\0' || !isfinite(v)) {
            rs_say(why, n, "sky: %s='%s' is not a number (%s)", sky_keys[k].name, val,
                sky_keys[k].range);
            return 0;
        }
        if (v < sky_keys[k].lo || v > sky_keys[k].hi || (k == 4 && v != 0.0 && v != 1.0)) {
            rs_say(why, n, "sky: %s=%s is out of range (%s)", sky_keys[k].name, val,
                sky_keys[k].range);
            return 0;
        }
        switch (k) {
        case 0: p.elevation_deg = (float)v; break;
        case 1: p.azimuth_deg = (float)v; break;
        case 2: p.turbidity = (float)v; break;
        case 3: p.intensity = (float)v; break;
        default: p.sun = (int)v; break;
        }
        if (!end)
            break;
        s = end + 1;
    }
    *out = p;
    return 1;
}

rs_status rs_scene_set_sky(struct rs_scene *s, const rs_sky_params *p)
{
    float *rgb = NULL;
    uint32_t id;
    rs_status st;
    RS_TRY(rs_sky_image(p, RS_SKY_WIDTH, RS_SKY_HEIGHT, &rgb));
    st = rs_scene_add_image(s, RS_SKY_WIDTH, RS_SKY_HEIGHT, rgb, &id);
    rs_free(rgb);
    if (st == RS_OK)
        st = rs_scene_set_environment(s, id, rs_v3_splat(1.0f), NULL);
    return st;
}

void rs_sky_default_for_camera(rs_vec3 from, rs_vec3 at, rs_sky_params *p)
{
    /* behind the camera: -forward, turned 30 degrees toward the camera's left (about +y,
     * counter-clockwise seen from above) */
    double bx = -(double)(at.x - from.x), bz = -(double)(at.z - from.z), len = sqrt(bx * bx + bz * bz);
    const double turn = 30.0 * 3.14159265358979323846 / 180.0;
    rs_sky_defaults(p);
    if (len > 0.0) {
        double c = cos(turn), sn = sin(turn);
        /* looking along f, the camera's left is f turned +90 degrees about +y; behind it and to
         * the left, -f turned by -turn toward that side */
        double hx = (bx * c - bz * sn) / len, hz = (bx * sn + bz * c) / len;
        p->azimuth_deg = (float)(atan2(hx, -hz) * 180.0 / 3.14159265358979323846);
    }
}
