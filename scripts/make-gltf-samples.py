#!/usr/bin/env python3
"""Writes glTF 2.0 sample files that exercise the material extensions raystream reads (issue 29),
for bench/peers/blender_compare.py and by hand: no third-party assets, no packages beyond the
standard library.

    python3 scripts/make-gltf-samples.py OUTDIR

OUTDIR/extensions.gltf (+ extensions.bin): a 3 x 3 grid of UV spheres, one material each, seen
by a perspective camera from the front; no lights (raystream's --background, Blender's world,
light it).  The materials, in reading order (left to right, top to bottom):

    plain        pbr dielectric, base (0.8, 0.3, 0.2), roughness 0.5
    metal        pbr metal, base (0.9, 0.8, 0.5), roughness 0.3
    specular     KHR_materials_specular 0.5, colour (1, 0.5, 0.2), KHR_materials_ior 1.8
    clearcoat    KHR_materials_clearcoat 1, roughness 0.1, over a rough blue base
    sheen        KHR_materials_sheen colour (1, 0.8, 0.6), roughness 0.4, on dark red
    glass        KHR_materials_transmission 1, KHR_materials_ior 1.5, KHR_materials_volume:
                 attenuation colour (0.8, 0.4, 0.2) over 1 unit (the sphere's radius is 0.4)
    emissive     emissive (1, 0.5, 0.25) x KHR_materials_emissive_strength 3
    unlit        KHR_materials_unlit, base (0.2, 0.6, 0.9)
    grey         pbr dielectric, base 0.5, roughness 1 (a reference the two should agree on)

OUTDIR/extensions.json: the spheres' centres, radius, names and the camera, for the bench's
region masks.
"""
import json
import math
import os
import struct
import sys

MATERIALS = [
    ("plain", {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 1], "metallicFactor": 0,
                                        "roughnessFactor": 0.5}}),
    ("metal", {"pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.8, 0.5, 1], "metallicFactor": 1,
                                        "roughnessFactor": 0.3}}),
    ("specular", {"pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.5, 0.3, 1],
                                           "metallicFactor": 0, "roughnessFactor": 0.3},
                  "extensions": {"KHR_materials_specular": {"specularFactor": 0.5,
                                                            "specularColorFactor": [1, 0.5, 0.2]},
                                 "KHR_materials_ior": {"ior": 1.8}}}),
    ("clearcoat", {"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.6, 1],
                                            "metallicFactor": 0, "roughnessFactor": 0.8},
                   "extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1,
                                                              "clearcoatRoughnessFactor": 0.1}}}),
    ("sheen", {"pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.05, 0.05, 1],
                                        "metallicFactor": 0, "roughnessFactor": 0.9},
               "extensions": {"KHR_materials_sheen": {"sheenColorFactor": [1, 0.8, 0.6],
                                                      "sheenRoughnessFactor": 0.4}}}),
    ("glass", {"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0,
                                        "roughnessFactor": 0},
               "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                              "KHR_materials_ior": {"ior": 1.5},
                              "KHR_materials_volume": {"thicknessFactor": 0.8,
                                                       "attenuationDistance": 1.0,
                                                       "attenuationColor": [0.8, 0.4, 0.2]}}}),
    ("emissive", {"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.1, 0.1, 1],
                                           "metallicFactor": 0, "roughnessFactor": 1},
                  "emissiveFactor": [1, 0.5, 0.25],
                  "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 3}}}),
    ("unlit", {"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.6, 0.9, 1]},
               "extensions": {"KHR_materials_unlit": {}}}),
    ("grey", {"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0,
                                       "roughnessFactor": 1}}),
]

RADIUS = 0.4
SPACING = 1.0
CAMERA_Z = 6.0
YFOV = 0.55


def uv_sphere(radius, nu=48, nv=24):
    """Positions, normals and triangle indices of a UV sphere about the origin."""
    pos, nrm, idx = [], [], []
    for j in range(nv + 1):
        th = math.pi * j / nv
        for i in range(nu + 1):
            ph = 2 * math.pi * i / nu
            n = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            nrm.append(n)
            pos.append(tuple(radius * c for c in n))
    for j in range(nv):
        for i in range(nu):
            a = j * (nu + 1) + i
            b = a + nu + 1
            if j != 0:
                idx += [a, a + 1, b]
            if j != nv - 1:
                idx += [a + 1, b + 1, b]
    return pos, nrm, idx


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: make-gltf-samples.py OUTDIR")
    out = sys.argv[1]
    os.makedirs(out, exist_ok=True)
    pos, nrm, idx = uv_sphere(RADIUS)
    blob = b"".join(struct.pack("<3f", *p) for p in pos)
    off_n = len(blob)
    blob += b"".join(struct.pack("<3f", *n) for n in nrm)
    off_i = len(blob)
    blob += b"".join(struct.pack("<I", k) for k in idx)
    with open(os.path.join(out, "extensions.bin"), "wb") as f:
        f.write(blob)
    used = sorted({e for _, m in MATERIALS for e in m.get("extensions", {})})
    nodes, meshes, spheres = [], [], []
    for k, (name, _) in enumerate(MATERIALS):
        x = (k % 3 - 1) * SPACING
        y = (1 - k // 3) * SPACING
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
                                                     "indices": 2, "material": k}]})
        nodes.append({"name": name, "mesh": k, "translation": [x, y, 0]})
        spheres.append({"name": name, "center": [x, y, 0], "radius": RADIUS})
    nodes.append({"name": "camera", "camera": 0, "translation": [0, 0, CAMERA_Z]})
    doc = {
        "asset": {"version": "2.0", "generator": "raystream scripts/make-gltf-samples.py"},
        "extensionsUsed": used,
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "meshes": meshes,
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": YFOV, "aspectRatio": 1.0, "znear": 0.1}}],
        "materials": [dict(m, name=n) for n, m in MATERIALS],
        "buffers": [{"uri": "extensions.bin", "byteLength": len(blob)}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": off_n, "target": 34962},
            {"buffer": 0, "byteOffset": off_n, "byteLength": off_i - off_n, "target": 34962},
            {"buffer": 0, "byteOffset": off_i, "byteLength": len(blob) - off_i, "target": 34963},
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3",
             "min": [-RADIUS] * 3, "max": [RADIUS] * 3},
            {"bufferView": 1, "componentType": 5126, "count": len(nrm), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": len(idx), "type": "SCALAR"},
        ],
    }
    with open(os.path.join(out, "extensions.gltf"), "w") as f:
        json.dump(doc, f, indent=1)
    with open(os.path.join(out, "extensions.json"), "w") as f:
        json.dump({"spheres": spheres, "camera": {"position": [0, 0, CAMERA_Z], "yfov": YFOV}}, f,
                  indent=1)
    print("wrote %s/extensions.gltf (%d spheres, %d triangles each; extensions: %s)" %
          (out, len(MATERIALS), len(idx) // 3, ", ".join(used)))


if __name__ == "__main__":
    main()
