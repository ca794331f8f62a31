/* accel/morton.h — 30-bit Morton codes of points, the key the LBVH builder sorts by.  RS_HD: the
 * host builder (accel/bvh_lbvh.c) and the GPU sort (gpu/cuda_lbvh.cu) compute the same codes
 * from the same frame, bit for bit (a subtraction and a product per axis: nothing nvcc can
 * contract into an FMA). */
#ifndef RS_ACCEL_MORTON_H
#define RS_ACCEL_MORTON_H

#include <stdint.h>

#include "core/vec3.h"

/* Spreads the low 10 bits of v so that two zero bits separate each (Karras 2012's blog post,
 * "Thinking parallel, part III"). */
RS_HD uint32_t rs_morton_expand_bits(uint32_t v)
{
    v = (v * 0x00010001u) & 0xFF0000FFu;
    v = (v * 0x00000101u) & 0x0F00F00Fu;
    v = (v * 0x00000011u) & 0xC30C30C3u;
    v = (v * 0x00000005u) & 0x49249249u;
    return v;
}

/* x in [lo, lo + 1024/scale] to 0..1023; NaN to 0. */
RS_HD uint32_t rs_morton_quantise(float x, float lo, float scale)
{
    float f = (x - lo) * scale;
    return f > 0.0f ? (f < 1023.0f ? (uint32_t)f : 1023u) : 0u;
}

/* The code of p in the frame (lo, scale): x, y, z interleaved from the top. */
RS_HD uint32_t rs_morton3(rs_vec3 p, const float lo[3], const float scale[3])
{
    return (rs_morton_expand_bits(rs_morton_quantise(p.x, lo[0], scale[0])) << 2) |
           (rs_morton_expand_bits(rs_morton_quantise(p.y, lo[1], scale[1])) << 1) |
           rs_morton_expand_bits(rs_morton_quantise(p.z, lo[2], scale[2]));
}

#endif
