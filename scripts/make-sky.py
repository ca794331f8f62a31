#!/usr/bin/env python3
"""Writes scenes/examples/sky.pfm: a small procedural equirectangular sky (64 x 32, linear RGB)
with a warm sun, for the environment-lit example.  Our own data: no third-party assets.

Rows run from the zenith (top) to the nadir; the middle column looks down -z (shading/envmap.h).
"""
import math
import struct
import sys

W, H = 64, 32
SUN_THETA, SUN_PHI = math.radians(35.0), math.radians(-40.0)  # from the zenith; 0 = -z


def texel(i, j):
    theta = (j + 0.5) / H * math.pi
    phi = ((i + 0.5) / W - 0.5) * 2 * math.pi
    d = (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))
    s = (math.sin(SUN_THETA) * math.sin(SUN_PHI), math.cos(SUN_THETA),
         -math.sin(SUN_THETA) * math.cos(SUN_PHI))
    if d[1] >= 0:
        h = d[1]
        sky = (0.35 + 0.35 * (1 - h), 0.55 + 0.25 * (1 - h), 1.0)
    else:
        sky = (0.12, 0.10, 0.08)  # the ground
    c = sum(a * b for a, b in zip(d, s))
    glow = 40.0 * max(0.0, c) ** 400 + 0.4 * max(0.0, c) ** 8
    return tuple(k + glow * w for k, w in zip(sky, (1.0, 0.85, 0.6)))


def main(path):
    with open(path, "wb") as f:
        f.write(b"PF\n%d %d\n-1.0\n" % (W, H))
        for j in reversed(range(H)):  # PFM stores the bottom row first
            for i in range(W):
                f.write(struct.pack("<3f", *texel(i, j)))


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scenes/examples/sky.pfm")
