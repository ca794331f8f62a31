#!/usr/bin/env python3
"""Writes shading/sheen_table.h: the directional albedo E(cos_o, r) of glTF's sheen BRDF
(KHR_materials_sheen: the "Charlie" distribution and visibility of Conty and Kulla 2017, colour
1, no Fresnel), which its albedo-scaling layering subtracts from the base:

    E(mu, r) = integral over the hemisphere of D(h) V(o, i) cos_i d(omega_i),
    D = (2 + 1/a) sin(h)^(1/a) / (2 pi),  V = 1 / ((1 + L(cos_o) + L(cos_i)) 4 cos_o cos_i),
    a = max(r, 0.07) (the spec's alphaG is the roughness itself)

on a 32 x 32 grid: mu = max(k / 31, 1e-3), r = j / 31.  Midpoint quadrature in (theta_i, phi_i),
1024 x 2048 cells, in double.  Usage: python3 scripts/make-sheen-table.py > shading/sheen_table.h
(numpy).  tests/shading_bsdf_test.c checks the table against the C BRDF."""
import numpy as np

N = 32


def lam_l(x, a):
    t = (1.0 - a) ** 2
    A = 21.5473 + (25.3245 - 21.5473) * t
    B = 3.82987 + (3.32435 - 3.82987) * t
    C = 0.19823 + (0.16801 - 0.19823) * t
    D = -1.97760 + (-1.27393 + 1.97760) * t
    E = -4.32054 + (-4.85967 + 4.32054) * t
    return A / (1.0 + B * np.power(x, C)) + D * x + E


def lam(c, a):
    c = np.abs(c)
    return np.where(c < 0.5, np.exp(lam_l(c, a)), np.exp(2.0 * lam_l(0.5, a) - lam_l(1.0 - c, a)))


def albedo(mu, r, nt=1024, nphi=2048):
    a = max(r, 0.07)
    th = (np.arange(nt) + 0.5) * (0.5 * np.pi / nt)
    ph = (np.arange(nphi) + 0.5) * (2.0 * np.pi / nphi)
    T, P = np.meshgrid(th, ph, indexing="ij")
    ci = np.cos(T)
    wi = np.stack([np.sin(T) * np.cos(P), np.sin(T) * np.sin(P), ci], -1)
    so = np.sqrt(max(0.0, 1.0 - mu * mu))
    wo = np.array([so, 0.0, mu])
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    ch = h[..., 2]
    s2h = np.maximum(0.0, 1.0 - ch * ch)
    Dd = (2.0 + 1.0 / a) * np.power(s2h, 0.5 / a) / (2.0 * np.pi)
    V = 1.0 / ((1.0 + lam(mu, a) + lam(ci, a)) * 4.0 * mu * ci)
    f = Dd * V * ci * np.sin(T)
    return f.sum() * (0.5 * np.pi / nt) * (2.0 * np.pi / nphi)


rows = []
for j in range(N):
    r = j / (N - 1)
    rows.append([albedo(max(k / (N - 1), 1e-3), r) for k in range(N)])

print("/* shading/sheen_table.h — written by scripts/make-sheen-table.py (see there): the directional")
print(" * albedo E[j][k] of glTF's sheen BRDF at roughness j / 31 and cos_o = max(k / 31, 1e-3).")
print(" * One copy for the host, one in device memory for CUDA (rs_sheen_table_at picks). */")
print("#ifndef RS_SHADING_SHEEN_TABLE_H")
print("#define RS_SHADING_SHEEN_TABLE_H")
print()
print('#include "core/hd.h"')
print()
print("#define RS_SHEEN_TABLE_N %d" % N)
print("/* clang-format off */")
print("#define RS_SHEEN_TABLE_DATA { \\")
for row in rows:
    vals = ["%.7ef" % v for v in row]
    lines = []
    for i in range(0, N, 6):
        lines.append("     " + ", ".join(vals[i:i + 6]))
    print("    {" + (", \\\n").join(lines).lstrip() + "}, \\")
print("}")
print("/* clang-format on */")
print()
print("static const float rs_sheen_albedo_table[RS_SHEEN_TABLE_N][RS_SHEEN_TABLE_N] = RS_SHEEN_TABLE_DATA;")
print("#if defined(__CUDACC__)")
print("static __device__ const float rs_sheen_albedo_table_dev[RS_SHEEN_TABLE_N][RS_SHEEN_TABLE_N] =")
print("    RS_SHEEN_TABLE_DATA;")
print("#endif")
print()
print("/* Entry [j][k]: the device's copy in device code, the host's elsewhere. */")
print("RS_HD float rs_sheen_table_at(int j, int k)")
print("{")
print("#if defined(__CUDA_ARCH__)")
print("    return rs_sheen_albedo_table_dev[j][k];")
print("#else")
print("    return rs_sheen_albedo_table[j][k];")
print("#endif")
print("}")
print()
print("#endif")
