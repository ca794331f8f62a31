#!/usr/bin/env python3
"""bench/peers/blender_compare.py — raystream's reading of glTF materials against Blender's
(issue 29): the same glTF file rendered by raystream and by Blender's Cycles (bpy), per-material
region means and a block z-test, so that a difference shows where our reading of a material
departs from Blender's.

Run with the Cycles venv's Python (sh scripts/install-peers.sh makes build/peers-venv-cycles):

    build/peers-venv-cycles/bin/python bench/peers/blender_compare.py \\
        [--raystream build/raystream] [--size 256] [--spp 256] [--quick] [--out DIR] [--md FILE]

The scene is scripts/make-gltf-samples.py's grid of nine spheres (plain, metal, the specular,
clearcoat, sheen, glass + volume, emissive-strength and unlit extensions, a grey reference)
under a uniform white environment of radiance 1 (raystream: --background 1; Blender: the
world's background colour 1, strength 1), seen by the file's camera.  Both render with a
1-pixel box filter, 64 bounces, no clamping, no denoising, no filter glossy, Standard view
(linear EXR).  Each sphere's region is the disc of 0.6 times its projected radius about its
projected centre.  Per region: both renderers' mean RGB, the ratio of the means' luminances, and
a z-score from 16 blocks of the region (the blocks' mean differences against their own spread:
|z| > 4 is a difference beyond noise).  Without bpy the script says so and exits 0.

--quick: 96 x 96 at 32 spp (the suite's smoke run, when a Cycles venv exists)."""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))


def luminance(c):
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]


def render_blender(gltf, out, size, spp, threads):
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=gltf)
    sc = bpy.context.scene
    cams = [o for o in sc.objects if o.type == "CAMERA"]
    if not cams:
        raise SystemExit("blender_compare: Blender imported no camera from %s" % gltf)
    sc.camera = cams[0]
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    bg = world.node_tree.nodes["Background"]
    bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bg.inputs["Strength"].default_value = 1.0
    sc.world = world
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = spp
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.max_bounces = 64
    cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 64
    cy.transparent_max_bounces = cy.volume_bounces = 64
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.seed = 1
    sc.render.threads_mode = "FIXED"
    sc.render.threads = threads
    sc.render.resolution_x = sc.render.resolution_y = size
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    sc.render.image_settings.color_mode = "RGB"
    sc.render.filepath = out
    t0 = time.time()
    bpy.ops.render.render(write_still=True)
    return time.time() - t0


def load_exr(path):
    """RGB rows top to bottom as a numpy array (h, w, 3)."""
    import bpy
    import numpy as np

    im = bpy.data.images.load(path, check_existing=False)
    w, h = im.size
    px = np.array(im.pixels[:], dtype=np.float64).reshape(h, w, 4)[::-1, :, :3]
    bpy.data.images.remove(im)
    return px


def regions(meta, size):
    """Per sphere: (name, boolean mask) of the disc of 0.6 x its projected radius."""
    import numpy as np

    cz = meta["camera"]["position"][2]
    t = math.tan(0.5 * meta["camera"]["yfov"])
    ys, xs = np.mgrid[0:size, 0:size]
    out = []
    for s in meta["spheres"]:
        x, y, z = s["center"]
        d = cz - z
        px = (x / (d * t) * 0.5 + 0.5) * size
        py = (0.5 - y / (d * t) * 0.5) * size
        pr = s["radius"] / math.sqrt(max(d * d - s["radius"] ** 2, 1e-9)) / t * 0.5 * size
        r = 0.6 * pr
        out.append((s["name"], (xs + 0.5 - px) ** 2 + (ys + 0.5 - py) ** 2 < r * r))
    return out


def block_z(a, b, mask, blocks=16):
    """z of the mean luminance difference a - b over the region, from `blocks` blocks."""
    import numpy as np

    la = (a * [0.2126, 0.7152, 0.0722]).sum(-1)[mask]
    lb = (b * [0.2126, 0.7152, 0.0722]).sum(-1)[mask]
    d = la - lb
    n = len(d) // blocks * blocks
    if n < blocks * 2:
        return float("nan")
    m = d[:n].reshape(blocks, -1).mean(1)
    se = m.std(ddof=1) / math.sqrt(blocks)
    return float(m.mean() / se) if se > 0 else float("inf") if m.mean() else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--raystream", default=os.path.join(ROOT, "build", "raystream"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--out", default=None, help="keep the images and the scene here")
    ap.add_argument("--md", default=None, help="also write the table as Markdown to this file")
    o = ap.parse_args()
    if o.quick:
        o.size, o.spp = 96, 32
    try:
        import bpy  # noqa: F401
        import numpy as np  # noqa: F401
    except ImportError as e:
        print("blender_compare: skipped: %s (run it with the Cycles venv's python: "
              "sh scripts/install-peers.sh, then build/peers-venv-cycles/bin/python)" % e)
        return 0
    import bpy

    out = o.out or tempfile.mkdtemp(prefix="blender_compare.")
    os.makedirs(out, exist_ok=True)
    subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "make-gltf-samples.py"), out],
                   check=True, stdout=subprocess.DEVNULL)
    gltf = os.path.join(out, "extensions.gltf")
    with open(os.path.join(out, "extensions.json")) as f:
        meta = json.load(f)
    rs_exr = os.path.join(out, "raystream.exr")
    bl_exr = os.path.join(out, "blender.exr")
    t0 = time.time()
    subprocess.run([o.raystream, "render", gltf, "--background", "1", "--filter", "box",
                    "--spp", str(o.spp), "--width", str(o.size), "--height", str(o.size),
                    "--max-depth", "64", "--threads", str(o.threads), "-q", "-o", rs_exr],
                   check=True)
    t_rs = time.time() - t0
    t_bl = render_blender(gltf, bl_exr, o.size, o.spp, o.threads)
    a = load_exr(rs_exr)
    b = load_exr(bl_exr)
    if a.shape != b.shape:
        raise SystemExit("blender_compare: the images differ in size: %s, %s" % (a.shape, b.shape))
    rows = []
    for name, mask in regions(meta, o.size):
        ma = a[mask].mean(0)
        mb = b[mask].mean(0)
        la, lb = luminance(ma), luminance(mb)
        rows.append((name, int(mask.sum()), ma, mb, la / lb if lb > 0 else float("nan"),
                     block_z(a, b, mask)))
    head = ("blender_compare: %s, %dx%d, %d spp, box filter 1 px, white environment; raystream "
            "%.1f s, Blender %s Cycles %.1f s (%d threads)" %
            (os.path.basename(gltf), o.size, o.size, o.spp, t_rs, bpy.app.version_string, t_bl,
             o.threads))
    print(head)
    fmt = "%-10s %6s  %-24s %-24s %7s %7s"
    print(fmt % ("material", "pixels", "raystream mean RGB", "Blender mean RGB", "Y ratio", "z"))
    lines = ["| material | pixels | raystream mean RGB | Blender (Cycles) mean RGB | luminance "
             "ratio | z (16 blocks) |", "| --- | ---: | --- | --- | ---: | ---: |"]
    for name, n, ma, mb, ratio, z in rows:
        ra = "%.3f %.3f %.3f" % tuple(ma)
        rb = "%.3f %.3f %.3f" % tuple(mb)
        zs = "exact" if math.isinf(z) or (z == 0.0 and (ma == mb).all()) else "%.1f" % z
        print(fmt % (name, n, ra, rb, "%.3f" % ratio, zs))
        lines.append("| %s | %d | %s | %s | %.3f | %s |" % (name, n, ra, rb, ratio, zs))
    if o.md:
        with open(o.md, "w") as f:
            f.write(head + "\n\n" + "\n".join(lines) + "\n")
    if not o.out:
        print("(images in %s)" % out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
