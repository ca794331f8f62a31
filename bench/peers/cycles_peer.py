#!/usr/bin/env python3
"""bench/peers/cycles_peer.py -- Blender Cycles' side of bench/peers_bench (bpy from PyPI).

Reads peers.json (camera, image size, depth, background and one OBJ file per material, written by
peers_bench from raystream's own scene), builds the same scene in Cycles without any axis
conversion (our coordinates are used as they are; the camera is placed by its look-at frame) and
renders it on the CPU at each of several sample counts, printing one line per render, "SPP
SECONDS", SECONDS being the time of the samples alone: the wall time of the render call less
what a render costs besides its samples (syncing the scene, building its BVH, the film), measured
by one-sample renders; neither is counted, as for the other peers.  Writes OUT_SPP.f32: raw float32 linear RGB, rows from the top.

Settings: path tracing, a 1-pixel box filter, no adaptive sampling, no denoising, no clamping,
caustics on, the Standard view transform (the pixels are read back linear), Cycles' default
sampler (Tabulated Sobol) and its Russian roulette; max bounces = our max depth - 1 (Cycles
counts bounces, we count segments).

  cycles_peer.py PEERS.json DEVICE SAMPLER THREADS SEED OUT SPP[,SPP...]
  DEVICE: CPU; SAMPLER: default (Cycles' own), SOBOL_BURLEY or TABULATED_SOBOL
"""
import faulthandler
import json
import math
import os
import sys
import tempfile
import time
import warnings

# Blender 5.2 deprecates `use_nodes` (gone in 6.0) but still needs it set: keep its warnings off
# the benchmark's output
warnings.filterwarnings("ignore", category=DeprecationWarning)


def read_obj(path):
    verts, tris = [], []
    with open(path) as f:
        for line in f:
            p = line.split()
            if not p:
                continue
            if p[0] == "v":
                verts.append(tuple(float(x) for x in p[1:4]))
            elif p[0] == "f":
                tris.append(tuple(int(x) - 1 for x in p[1:4]))
    return verts, tris


def look_at(frm, at, up):
    """Blender's camera looks down its local -Z with +Y up: the world matrix's columns are
    right, up', -forward and the position."""
    def sub(a, b):
        return [a[i] - b[i] for i in range(3)]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]

    def norm(a):
        n = math.sqrt(sum(x * x for x in a))
        return [x / n for x in a]

    f = norm(sub(at, frm))
    r = norm(cross(f, up))
    u = cross(r, f)
    return [[r[0], u[0], -f[0], frm[0]],
            [r[1], u[1], -f[1], frm[1]],
            [r[2], u[2], -f[2], frm[2]],
            [0.0, 0.0, 0.0, 1.0]]


def diffuse_material(bpy, name, rgb):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return m


def light_material(bpy, name, rgb):
    """Emits radiance rgb on the front side only (as raystream's one-sided lights) and reflects
    nothing: emission mixed with black by the Backfacing output."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    em.inputs["Strength"].default_value = 1.0
    holdout = nt.nodes.new("ShaderNodeEmission")
    holdout.inputs["Strength"].default_value = 0.0
    geo = nt.nodes.new("ShaderNodeNewGeometry")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(geo.outputs["Backfacing"], mix.inputs["Fac"])
    nt.links.new(em.outputs["Emission"], mix.inputs[1])
    nt.links.new(holdout.outputs["Emission"], mix.inputs[2])
    nt.links.new(mix.outputs["Shader"], out.inputs["Surface"])
    m.cycles.emission_sampling = "FRONT"
    return m


def main(argv):
    faulthandler.dump_traceback_later(3600, exit=True)
    if len(argv) != 8:
        sys.stderr.write(__doc__)
        return 2
    desc_path, device, sampler, threads, seed, out, spps = argv[1:8]
    import bpy
    import numpy as np
    with open(desc_path) as f:
        d = json.load(f)
    folder = os.path.dirname(os.path.abspath(desc_path))
    w, h = d["width"], d["height"]

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    for i, m in enumerate(d["meshes"]):
        verts, tris = read_obj(os.path.join(folder, m["obj"]))
        mesh = bpy.data.meshes.new("mesh%d" % i)
        mesh.from_pydata(verts, [], tris)
        mesh.update()
        mat = (light_material if m["kind"] == "light" else diffuse_material)(
            bpy, "mat%d" % i, m["rgb"])
        mesh.materials.append(mat)
        obj = bpy.data.objects.new("obj%d" % i, mesh)
        scene.collection.objects.link(obj)

    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    rgb = d.get("background", [0.0, 0.0, 0.0])
    bg.inputs["Color"].default_value = (rgb[0], rgb[1], rgb[2], 1.0)
    bg.inputs["Strength"].default_value = 1.0
    scene.world = world

    cam_data = bpy.data.cameras.new("camera")
    cam_data.sensor_fit = "VERTICAL"
    cam_data.angle_y = math.radians(d["vfov"])
    # Blender clips camera rays at 0.1 and 100 units by default; the Cornell box is 556 units
    # across and seen from 800 away: no clipping (raystream and the other peers have none)
    cam_data.clip_start = 1e-6
    cam_data.clip_end = 1e9
    cam = bpy.data.objects.new("camera", cam_data)
    scene.collection.objects.link(cam)
    import mathutils
    cam.matrix_world = mathutils.Matrix(look_at(d["from"], d["at"], d["up"]))
    scene.camera = cam

    r = scene.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, 100
    r.threads_mode = "FIXED"
    r.threads = int(threads)
    # no persistent data: with it, the first render after a change of the sample count
    # renders the old count (seen here with bpy 5.2.3: 16 spp in the time of 1)
    r.use_persistent_data = False
    r.image_settings.file_format = "OPEN_EXR"
    r.image_settings.color_depth = "32"
    r.image_settings.exr_codec = "NONE"
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    c = scene.cycles
    c.device = device
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.use_preview_denoising = False
    c.seed = int(seed) % 2147483647
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    c.blur_glossy = 0.0
    bounces = max(d["max_depth"] - 1, 0)
    c.max_bounces = c.diffuse_bounces = c.glossy_bounces = bounces
    c.transmission_bounces = c.volume_bounces = c.transparent_max_bounces = bounces
    c.use_light_tree = True
    if sampler != "default":
        c.sampling_pattern = sampler
    c.use_auto_tile = False

    tmp = tempfile.mkdtemp(prefix="cycles_peer.")
    path = os.path.join(tmp, "render.exr")
    r.filepath = path

    def render(spp):
        c.samples = spp
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        return time.perf_counter() - t0

    # Blender prints a line per step to file descriptor 1: ours goes to a copy of it, its to
    # /dev/null, so that nothing of its reaches the bench
    ours = os.fdopen(os.dup(1), "w")
    devnull = os.open(os.devnull, os.O_WRONLY)
    sys.stdout.flush()
    os.dup2(devnull, 1)
    # what every render costs besides its samples (sync, BVH, film, file): t1 = fixed + one
    # sample's work, the median of three one-sample renders after a warm-up
    render(1)
    t1 = sorted(render(1) for _ in range(3))[1]
    for spp in (int(s) for s in spps.split(",")):
        raw = render(spp)
        # raw = fixed + spp * w and t1 = fixed + w, so spp * w = (raw - t1) * spp / (spp - 1)
        secs = max(raw - t1, 0.0) * spp / (spp - 1) if spp > 1 else raw
        img = bpy.data.images.load(path)
        px = np.array(img.pixels[:], dtype=np.float32).reshape(h, w, 4)
        bpy.data.images.remove(img)
        # Blender's rows run from the bottom
        np.ascontiguousarray(px[::-1, :, :3]).tofile("%s_%d.f32" % (out, spp))
        ours.write("%d %.6f\n" % (spp, secs))
        ours.flush()
    os.remove(path)
    os.rmdir(tmp)
    return 0


if __name__ == "__main__":
    rc = main(sys.argv)
    sys.stdout.flush()
    os._exit(rc)
