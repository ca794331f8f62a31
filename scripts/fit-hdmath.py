#!/usr/bin/env python3
"""scripts/fit-hdmath.py — where the constants of core/hdmath.h come from.

Prints, as C, the minimax polynomials of core/hdmath.h, its split constants, the bits of 2/pi its
large-argument sine and cosine reduce with, and how near a float comes to a multiple of pi/2.
Needs mpmath (pip install mpmath); runs in under a minute:

    python3 scripts/fit-hdmath.py

Each polynomial is a Remez exchange (weighted so that the error is relative to the function's
value) in mpmath at 50 digits, for
    sin(r) = r + r^3 S(r^2)              |r| <= pi/4 (a little over: see R_MAX)
    cos(r) = 1 - r^2/2 + r^4 C(r^2)      |r| <= pi/4
    exp(r) = 1 + r + r^2 E(r)            |r| <= ln 2 / 2
    atan(u) = u + u^3 A(u^2)             |u| <= tan(pi/8)
    asin(x) = x + x^3 B(x^2)             |x| <= 1/2
then rounded to float (the header's constants are these floats, printed with 9 digits, which
read back as the same float).  The fit error of the rounded polynomial is printed next to each,
in units of 2^-24 (about one float ulp relative to the function's value): the rest of the
error budget is the float arithmetic's rounding, which tests/core_hdmath_test.c measures.
"""
import struct

import mpmath as mp

mp.mp.dps = 50


def to_float(x):
    """x rounded to the nearest IEEE single (through double: exact enough at 2^-53)."""
    return struct.unpack("f", struct.pack("f", float(x)))[0]


def remez(g, w, a, b, n, iters=12, grid=2000):
    """Coefficients c0..cn of the polynomial P minimising max |w(z) (g(z) - P(z))| on [a, b]
    (grid points at half steps: none at a, b or the middle, where w may vanish)."""
    ref = [(a + b) / 2 - (b - a) / 2 * mp.cos(mp.pi * (i + 0.5) / (n + 2)) for i in range(n + 2)]
    pts = [a + (b - a) * (mp.mpf(i) + mp.mpf(0.5)) / grid for i in range(grid)]
    c = None
    for _ in range(iters):
        A = mp.matrix(n + 2, n + 2)
        rhs = mp.matrix(n + 2, 1)
        for i, z in enumerate(ref):
            for j in range(n + 1):
                A[i, j] = z**j
            A[i, n + 1] = (-1) ** i / w(z)
            rhs[i] = g(z)
        sol = mp.lu_solve(A, rhs)
        c = [sol[j] for j in range(n + 1)]

        def err(z):
            return w(z) * (g(z) - sum(cj * z**j for j, cj in enumerate(c)))

        e = [err(z) for z in pts]
        # the extrema of alternating sign, the largest of each run of one sign
        ext = []
        for i, z in enumerate(pts):
            if ext and mp.sign(e[i]) == mp.sign(ext[-1][1]):
                if abs(e[i]) > abs(ext[-1][1]):
                    ext[-1] = (z, e[i])
            else:
                ext.append((z, e[i]))
        while len(ext) > n + 2:  # drop the smaller end
            if abs(ext[0][1]) < abs(ext[-1][1]):
                ext.pop(0)
            else:
                ext.pop()
        if len(ext) < n + 2:
            break
        ref = [z for z, _ in ext]
    return c


def max_rel_err(f, approx, a, b, grid=20000):
    m = mp.mpf(0)
    for i in range(1, grid + 1):
        x = a + (b - a) * (mp.mpf(i) - mp.mpf(0.5)) / grid
        fx = f(x)
        if fx != 0:
            m = max(m, abs((approx(x) - fx) / fx))
    return m


def poly(c, z):
    return sum(mp.mpf(cj) * z**j for j, cj in enumerate(c))


def show(name, c, f, approx, a, b):
    cf = [to_float(x) for x in c]
    e = max_rel_err(f, lambda x: approx(cf, x), a, b)
    print("/* %s: fit error %.3f x 2^-24 relative */" % (name, float(e * 2**24)))
    for j, x in enumerate(cf):
        print("#define RS_HDM_%s%d %.9ef" % (name, j, x))
    print()


def tiny(b):
    return b * mp.mpf("1e-12")


R_MAX = mp.pi / 4 * mp.mpf("1.0001")  # the fast reduction's k can be one off at a half-way point

# sin: S(z) = (sin r - r) / r^3, error relative to sin r
z1 = R_MAX**2
c = remez(lambda z: (mp.sin(mp.sqrt(z)) - mp.sqrt(z)) / mp.sqrt(z) ** 3,
          lambda z: mp.sqrt(z) ** 3 / mp.sin(mp.sqrt(z)), tiny(z1), z1, 2)
show("SIN", c, mp.sin, lambda cf, r: r + r**3 * poly(cf, r * r), tiny(R_MAX), R_MAX)

# cos: C(z) = (cos r - 1 + z/2) / z^2, error relative to cos r
c = remez(lambda z: (mp.cos(mp.sqrt(z)) - 1 + z / 2) / z**2, lambda z: z**2 / mp.cos(mp.sqrt(z)),
          tiny(z1), z1, 2)
show("COS", c, mp.cos, lambda cf, r: 1 - r * r / 2 + r**4 * poly(cf, r * r), tiny(R_MAX), R_MAX)

# exp: E(r) = (e^r - 1 - r) / r^2 on [-ln2/2, ln2/2], error relative to e^r
h = mp.log(2) / 2 * mp.mpf("1.0001")
c = remez(lambda r: (mp.exp(r) - 1 - r) / r**2, lambda r: r**2 / mp.exp(r), -h, h, 4)
show("EXP", c, mp.exp, lambda cf, r: 1 + r + r * r * poly(cf, r), -h, h)

# atan: A(z) = (atan u - u) / u^3 for u <= tan(pi/8), error relative to atan u
u1 = mp.tan(mp.pi / 8) * mp.mpf("1.0001")
c = remez(lambda z: (mp.atan(mp.sqrt(z)) - mp.sqrt(z)) / mp.sqrt(z) ** 3,
          lambda z: mp.sqrt(z) ** 3 / mp.atan(mp.sqrt(z)), tiny(u1 * u1), u1 * u1, 4)
show("ATAN", c, mp.atan, lambda cf, u: u + u**3 * poly(cf, u * u), tiny(u1), u1)

# asin: B(z) = (asin x - x) / x^3 for x <= 1/2, error relative to asin x
c = remez(lambda z: (mp.asin(mp.sqrt(z)) - mp.sqrt(z)) / mp.sqrt(z) ** 3,
          lambda z: mp.sqrt(z) ** 3 / mp.asin(mp.sqrt(z)), tiny(mp.mpf(0.25)), mp.mpf(0.25), 4)
show("ASIN", c, mp.asin, lambda cf, x: x + x**3 * poly(cf, x * x), tiny(mp.mpf(0.5)),
     mp.mpf(0.5))

# 2/pi in 32-bit words, most significant first, after 32 zero bits (the table's word 0 is the
# integer part's word, 0): word i holds the bits of weight 2^-(32 (i - 1) + 1) .. 2^-(32 i)
mp.mp.dps = 120
v = 2 / mp.pi
words = [0]
for _ in range(8):
    v *= 2**32
    w = int(mp.floor(v))
    words.append(w)
    v -= w
print("/* 2/pi: word i (i >= 1) holds its bits 32 (i - 1) + 1 .. 32 i after the binary point */")
print("#define RS_HDM_TWO_OVER_PI_WORDS {" + ", ".join("0x%08xu" % w for w in words) + "}")

# Split constants (Cody and Waite): c = hi + mid + lo with hi (and mid) cut to a few significant
# bits, so that k hi (and k mid) is exact for the k the reductions make.
mp.mp.dps = 60


def trunc_bits(v, bits):
    """v (> 0) cut (towards zero) to `bits` significant bits."""
    e = int(mp.floor(mp.log(v, 2)))
    q = mp.mpf(2) ** (e - bits + 1)
    return mp.floor(v / q) * q


def split(name, v, bits, parts, fmt="f"):
    out = []
    for i in range(parts - 1):
        h = trunc_bits(v, bits[i])
        out.append(h)
        v -= h
    out.append(v)
    for i, h in enumerate(out):
        if fmt == "f":
            print("#define RS_HDM_%s_%d %.9ef" % (name, i, to_float(h)))
        else:
            print("#define RS_HDM_%s_%d %.17e" % (name, i, float(h)))


print("/* pi/2 for the small-argument reduction: 20 + 20 bits and a float */")
split("PIO2", mp.pi / 2, [20, 20], 3)
print("/* ln 2 for expf: 16 bits and a float */")
split("LN2", mp.log(2), [16], 2)
print("/* pi/4 in 21 bits and a float (m pi/4, m <= 4, exact in the first) */")
split("PIO4", mp.pi / 4, [21], 2)
print("/* pi/2 and pi as float + float */")
split("PIO2F", mp.pi / 2, [24], 2)
split("PIF", mp.pi, [24], 2)
print("/* ln 2 for the double log and exp: 32 bits and a double */")
split("LN2D", mp.log(2), [32], 2, fmt="d")
print("#define RS_HDM_PIO2_2M94 %.17e /* pi/2 * 2^-94, double */" % float(mp.pi / 2 * mp.mpf(2) ** -94))

# The nearest approach of a float to a multiple of pi/2 (k pi/2 for k < 2^15, that is |x| below
# about 51000): how many bits the reductions must keep of x - k pi/2.  Only the float nearest
# each k pi/2 can be nearest.
mp.mp.dps = 40
best = None
for k in range(1, 1 << 15):
    v = k * mp.pi / 2
    e = int(mp.floor(mp.log(v, 2)))
    ulp = mp.mpf(2) ** (e - 23)
    d = abs(mp.nint(v / ulp) * ulp - v)
    if best is None or d < best[0]:
        best = (d, k)
    if k == 10:
        print("/* below 16: nearest approach 2^%.1f (k = %d) */" % (float(mp.log(best[0], 2)), best[1]))
print("/* below 51000: nearest approach 2^%.1f (k = %d) */" % (float(mp.log(best[0], 2)), best[1]))

# rs_powf's and rs_logf's double-precision log2 and exp2 (table-driven, as glibc's powf):
#   log2 x = k + log2 c_i + log2(1 + r), r = z / c_i - 1, z = x 2^-k in [OFF, 2 OFF) (as bits),
#   the 32 subintervals of z by its bits; c_i near each one's middle (c = 1 for the one holding 1,
#   so that log2 x is exact relative to itself near 1); log2(1 + r) = r L(r)
#   2^t = 2^(j/32) 2^(k) 2^r, |r| <= 1/64: 2^r = 1 + r X(r)
mp.mp.dps = 50
OFF = 0x3F330000


def bits_to_float(b):
    return struct.unpack("f", struct.pack("I", b))[0]


invc, logc, rmin, rmax = [], [], 0, 0
for i in range(32):
    lo = mp.mpf(bits_to_float(OFF + (i << 18)))
    hi = mp.mpf(bits_to_float(OFF + ((i + 1) << 18)))
    if lo <= 1 < hi:
        ic = mp.mpf(1)
    else:
        ic = mp.mpf(float(2 / (lo + hi)))  # 1/c rounded to double
    invc.append(float(ic))
    lc = -mp.log(mp.mpf(float(ic)), 2)
    logc.append(float(lc))
    rmin = min(rmin, lo * mp.mpf(float(ic)) - 1)
    rmax = max(rmax, hi * mp.mpf(float(ic)) - 1)
print("/* log2: r in [%.6f, %.6f] */" % (float(rmin), float(rmax)))
print("#define RS_HDM_LOG2_INVC {" + ", ".join(v.hex() for v in invc) + "}")
print("#define RS_HDM_LOG2_LOGC {" + ", ".join(v.hex() for v in logc) + "}")
for deg in (6,):
    c = remez(lambda r: mp.log(1 + r, 2) / r, lambda r: r / mp.log(1 + r, 2), rmin, rmax, deg - 1)
    cd = [float(x) for x in c]
    e = max_rel_err(lambda r: mp.log(1 + r, 2),
                    lambda r: r * sum(mp.mpf(cj) * r**j for j, cj in enumerate(cd)), rmin, rmax, 4000)
    print("/* log2(1 + r) = r L(r), degree %d: relative error 2^%.1f */" % (deg, float(mp.log(e, 2))))
    print("#define RS_HDM_LOG2_POLY {" + ", ".join(v.hex() for v in cd) + "}")
print("#define RS_HDM_EXP2_TAB {" + ", ".join(float(mp.mpf(2) ** (mp.mpf(j) / 32)).hex() for j in range(32)) + "}")
h = mp.mpf(1) / 64 * mp.mpf("1.0001")
for deg in (5,):
    # weighted by 1 / 2^r, not r / 2^r: the relative error of X, |r| times that of 2^r
    c = remez(lambda r: (mp.mpf(2) ** r - 1) / r, lambda r: 1 / mp.mpf(2) ** r, -h, h, deg - 1)
    cd = [float(x) for x in c]
    e = max_rel_err(lambda r: mp.mpf(2) ** r,
                    lambda r: 1 + r * sum(mp.mpf(cj) * r**j for j, cj in enumerate(cd)), -h, h, 4000)
    print("/* 2^r = 1 + r X(r), degree %d: relative error 2^%.1f */" % (deg, float(mp.log(e, 2))))
    print("#define RS_HDM_EXP2_POLY {" + ", ".join(v.hex() for v in cd) + "}")
