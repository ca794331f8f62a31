/* app/checkpoint.h — a render's film saved to a file (--checkpoint FILE) and read back
 * (--resume FILE), so that a render continued from it ends bit for bit as the uninterrupted one.
 * Version 7 below; versions 2 and 4, written before it, are read.
 *
 * Why that holds: each path's radiance depends only on its number (paths are numbered
 * sample-major, scheduler/render.h), on every device set, and the film's sums are exact integers
 * (shading/film.h), so they do not depend on the order samples are added in.  A checkpoint
 * stores the exact sums and counts and which paths they hold: ranges of the numbering, usually
 * one prefix [0, paths) (whole waves; whole samples for the megakernel), several where an MPI
 * job stopped with passes missing; the resumed render adds the paths between them.
 *
 * File format, version 2 (little-endian; a header of 92 bytes + the scene name):
 *   off  size  field
 *     0     8  magic "RSCKPT\r\n" (a text-mode transfer or a truncation shows)
 *     8     4  version (2; version 1 held double sums)
 *    12     4  header bytes (from offset 0 to the first sum)
 *    16     8  scene content hash (rs_checkpoint_scene_hash: geometry, materials, textures,
 *              lights, camera, background; a mesh or texture file's content is in it)
 *    24     8  seed
 *    32     8  paths on the film (the ranges' total)
 *    40     8  non-finite samples dropped so far
 *    48    40  width, height, spp, max depth, rr depth, sampling, sampler, sphere test,
 *              triangle test, box test (u32 each)
 *    88     4  scene name bytes n (< 4096), then the name as given on the command line
 *  92+n     4  ranges R (1..65536; 0 for an empty film), then the pixel and texture filters
 *              (u32: kind << 24 | 1 << 23 for trilinear textures | the width in thousandths
 *              of a pixel, kind and width 0 for a box of 1 pixel: files before raystream 0.9,
 *              a box and bilinear textures, hold 0 here)
 *  100+n 16*R  the paths held: R ranges [lo, hi) (u64 each), sorted, disjoint, not touching,
 *              each starting at a whole sample (lo a multiple of P)
 *  hdr   48*P  the sums, 3 signed 128-bit integers a pixel in film units (2^-40; P = width *
 *              height)
 *         4*P  the counts, u32 a pixel (must be the ranges' paths of that pixel)
 *           8  FNV-1a 64 of every byte before it
 * Version 4, an adaptive render (--adaptive), is version 2 with no ranges (R = 0; the counts
 * say what each pixel holds: its first samples, scheduler/adaptive.h) and, between the counts
 * and the checksum, the adaptive section:
 *           8  the threshold (f64)
 *          40  min spp, n, step, rounds (u32 each), the round's paths on the film (u64), samples
 *              taken (u64), pixels stopped (u32), 4 zero bytes (rs_adaptive_state)
 *        24*P  each pixel's sum of squared luminance (rs_film_sq: a 192-bit integer in units
 *              of 2^-64, three u64 from the lowest; version 3 had an f64 here and is refused)
 *           P  each pixel's running flag (0 or 1)
 * Version 7, what this raystream writes, is version 2 (or 4, adaptive) with, after the ranges,
 *           4  flags: 1 adaptive (the adaptive section follows the film), 2 passes
 *           4  settings bytes L (< 8192), then L bytes of the settings block: "NAME=VALUE\n" for
 *              every image-defining setting (app/image_settings.h), which a resumed render
 *              must match row for row (the fixed fields 24 and 48..87 and the filter word are
 *              still written, and read only in files of versions 2 and 4)
 *  and, with flag 2, between the counts and the adaptive section, the film's passes
 *  (shading/film.h: what --aov and --denoise read):
 *       160*P  the passes' sums, RS_FILM_PASSES signed 128-bit integers a pixel in film units
 *         4*P  the samples whose camera ray hit something, u32 a pixel
 * A render that writes passes resumes only from a file that holds them; one that does not
 * skips them.
 * Everything that decides the image is in the header; the devices, threads, chunk and wave
 * sizes, the BVH builder and the integrator are not (they do not change the image).  spp matters
 * only to the zsobol sampler (its point set depends on it) and to adaptive sampling (its last
 * round's size); with the others a checkpoint may be continued to more samples. */
#ifndef RS_APP_CHECKPOINT_H
#define RS_APP_CHECKPOINT_H

#include <stdint.h>

#include "app/image_settings.h"
#include "scenes/scene.h"
#include "scheduler/adaptive.h"
#include "scheduler/plan.h"
#include "shading/film.h"
#include "shading/filter.h"

#define RS_CHECKPOINT_VERSION          7u /* what is written: flags and the settings block */
#define RS_CHECKPOINT_VERSION_PLAIN    2u /* read: a render over every pixel */
#define RS_CHECKPOINT_VERSION_ADAPTIVE 4u /* read: --adaptive, version 2 and an adaptive
                                             section (3 had inexact squared-luminance sums) */

/* The paths a film holds (scheduler/plan.h): at most this many ranges in a file. */
#define RS_CHECKPOINT_MAX_RANGES RS_PATH_RANGES_MAX

/* What decides the image, as the checkpoint records it: the scene's content and the image
 * settings (img.spp 0 when reading: the file's). */
typedef struct rs_checkpoint_key {
    uint64_t scene_hash;
    rs_image_settings img;
    const char *scene; /* the scene's name on the command line (messages only) */
} rs_checkpoint_key;

/* The pixel filter and the texture filter as the header holds them: kind << 24 | trilinear << 23
 * | width in thousandths of a pixel (at most 16000: 14 bits), kind and width 0 for box:1 (so 0
 * is box:1 with bilinear textures: every checkpoint before raystream 0.9).  The same word
 * carries RS_CHECKPOINT_LIGHT_BVH for --light-sampler bvh (a render with it is a different
 * image). */
uint32_t rs_checkpoint_filter_code(const rs_filter *f, int trilinear);
#define RS_CHECKPOINT_LIGHT_BVH (1u << 22)

/* FNV-1a 64 over every array and setting of a finalized scene that shading reads. */
uint64_t rs_checkpoint_scene_hash(const rs_scene *s);

/* Writes `key` and the film, which holds the paths `held`, to `staged` (flushed to disk) and,
 * if `rename_now`, renames it to `path` (else the caller does, with the other outputs).  A
 * reader never sees a partial file at `path`; on failure `staged` is removed and `path` left as
 * it was.  Returns 1, or 0 after printing one line naming `path`. */
int rs_checkpoint_write(const char *path, const char *staged, int rename_now,
                        const rs_checkpoint_key *key, const rs_film *film,
                        const rs_path_ranges *held);
/* The same for an adaptive render (key->img.adaptive > 0): `held` is not used (the film's
 * counts say what it holds), *ad and the film's squared-luminance sums are saved with it. */
int rs_checkpoint_write_adaptive(const char *path, const char *staged, int rename_now,
                                 const rs_checkpoint_key *key, const rs_film *film,
                                 const rs_adaptive_state *ad);

/* Reads checkpoint `path` for a render with settings `want` into `film` (want's size, fresh):
 * *held (empty) gets the paths it holds.  want->img.spp == 0 takes the file's spp into it.
 * Returns 0 (RS_EXIT_OK); RS_EXIT_USAGE after one line naming the file when it is missing, not a
 * regular file or was made with other settings (the line names the field, its value in the
 * file and the one asked for); RS_EXIT_RUNTIME after one line when it is truncated or corrupt. */
int rs_checkpoint_read(const char *path, rs_checkpoint_key *want, rs_film *film,
                       rs_path_ranges *held);
/* The same for an adaptive render (want->img.adaptive > 0): the file must be an adaptive
 * checkpoint with the same threshold and min spp; *ad (zeroed) gets its state, the film its
 * squared-luminance sums.  A file of the other kind is refused with one line. */
int rs_checkpoint_read_adaptive(const char *path, rs_checkpoint_key *want, rs_film *film,
                                rs_adaptive_state *ad);

#endif
