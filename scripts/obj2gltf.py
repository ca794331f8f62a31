#!/usr/bin/env python3
"""Converts a triangulated OBJ with one texture (v, vt, f v/vt) to a glTF 2.0 file: the buffer
embedded as a data URI, the texture copied next to the output as the base colour.  Used to make the
README's glTF gallery image from the shared Spot model (nothing it writes goes into the repo):

    python3 scripts/obj2gltf.py ../shared/models/spot/spot_triangulated.obj \
        ../shared/models/spot/spot_texture.png /tmp/spot/spot.gltf [roughness [metallic [yaw]]]

yaw turns the model about +y (degrees, a node rotation); with it, a grey floor under the model and
a camera in front of it are added too (a small scene for the gallery).
"""
import math
import base64
import json
import os
import shutil
import struct
import sys


def main(obj, png, out, roughness=0.5, metallic=0.0, yaw=None):
    vs, vts, verts, index, seen = [], [], [], [], {}
    with open(obj) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] == "v":
                vs.append(tuple(map(float, w[1:4])))
            elif w[0] == "vt":
                vts.append(tuple(map(float, w[1:3])))
            elif w[0] == "f":
                if len(w) != 4:
                    sys.exit("%s: only triangles" % obj)
                for c in w[1:]:
                    if c not in seen:
                        p = c.split("/")
                        uv = vts[int(p[1]) - 1] if len(p) > 1 and p[1] else (0.0, 0.0)
                        seen[c] = len(verts)
                        verts.append((vs[int(p[0]) - 1], (uv[0], 1.0 - uv[1])))  # glTF: v down
                    index.append(seen[c])
    pos = b"".join(struct.pack("<3f", *v) for v, _ in verts)
    uvs = b"".join(struct.pack("<2f", *t) for _, t in verts)
    idx = b"".join(struct.pack("<I", i) for i in index)
    buf = pos + uvs + idx
    lo = [min(v[k] for v, _ in verts) for k in range(3)]
    hi = [max(v[k] for v, _ in verts) for k in range(3)]
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    tex = os.path.basename(png)
    shutil.copyfile(png, os.path.join(os.path.dirname(os.path.abspath(out)), tex))
    g = {
        "asset": {"version": "2.0", "generator": "raystream scripts/obj2gltf.py"},
        "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"name": os.path.splitext(os.path.basename(obj))[0], "mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "indices": 2, "material": 0}]}],
        "materials": [{"name": "skin", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": metallic,
            "roughnessFactor": roughness}}],
        "textures": [{"source": 0}], "images": [{"uri": tex}],
        "buffers": [{"byteLength": len(buf),
                     "uri": "data:application/octet-stream;base64," +
                            base64.b64encode(buf).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos)},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(uvs)},
                        {"buffer": 0, "byteOffset": len(pos) + len(uvs), "byteLength": len(idx)}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3",
             "min": lo, "max": hi},
            {"bufferView": 1, "componentType": 5126, "count": len(verts), "type": "VEC2"},
            {"bufferView": 2, "componentType": 5125, "count": len(index), "type": "SCALAR"}],
    }
    if yaw is not None:
        a = math.radians(yaw) / 2
        g["nodes"][0]["rotation"] = [0.0, math.sin(a), 0.0, math.cos(a)]
        r = 3.0 * max(hi[k] - lo[k] for k in range(3))
        fl = struct.pack("<12f", -r, lo[1], -r, r, lo[1], -r, r, lo[1], r, -r, lo[1], r)
        fi = struct.pack("<6I", 0, 2, 1, 0, 3, 2)
        off = len(buf)
        buf += fl + fi
        g["buffers"][0] = {"byteLength": len(buf), "uri": "data:application/octet-stream;base64,"
                           + base64.b64encode(buf).decode()}
        g["bufferViews"] += [{"buffer": 0, "byteOffset": off, "byteLength": 48},
                             {"buffer": 0, "byteOffset": off + 48, "byteLength": 24}]
        g["accessors"] += [{"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3",
                            "min": [-r, lo[1], -r], "max": [r, lo[1], r]},
                           {"bufferView": 4, "componentType": 5125, "count": 6,
                            "type": "SCALAR"}]
        g["meshes"].append({"primitives": [{"attributes": {"POSITION": 3}, "indices": 4,
                                            "material": 1}]})
        g["materials"].append({"name": "floor", "pbrMetallicRoughness": {
            "baseColorFactor": [0.55, 0.55, 0.55, 1], "metallicFactor": 0,
            "roughnessFactor": 0.8}})
        size = max(hi[k] - lo[k] for k in range(3))
        c = [(lo[k] + hi[k]) / 2 for k in range(3)]
        eye = [c[0] + 0.55 * size, c[1] + 0.35 * size, c[2] + 1.9 * size]
        # look at the model's centre: the camera looks down its -z
        d = [c[k] - eye[k] for k in range(3)]
        yaw_c = math.atan2(-d[0], -d[2])
        pitch = math.atan2(d[1], math.hypot(d[0], d[2]))
        qy = [0.0, math.sin(yaw_c / 2), 0.0, math.cos(yaw_c / 2)]
        qx = [math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2)]
        # q = qy * qx
        q = [qy[3] * qx[0] + qy[0] * qx[3] + qy[1] * qx[2] - qy[2] * qx[1],
             qy[3] * qx[1] - qy[0] * qx[2] + qy[1] * qx[3] + qy[2] * qx[0],
             qy[3] * qx[2] + qy[0] * qx[1] - qy[1] * qx[0] + qy[2] * qx[3],
             qy[3] * qx[3] - qy[0] * qx[0] - qy[1] * qx[1] - qy[2] * qx[2]]
        g["nodes"] += [{"name": "floor", "mesh": 1},
                       {"name": "camera", "camera": 0, "translation": eye, "rotation": q}]
        g["scenes"][0]["nodes"] += [1, 2]
        g["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.62, "aspectRatio": 1.5,
                                                                 "znear": 0.01}}]
    with open(out, "w") as f:
        json.dump(g, f)


if __name__ == "__main__":
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2], sys.argv[3], *map(float, sys.argv[4:7]))
