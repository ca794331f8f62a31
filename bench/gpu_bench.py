#!/usr/bin/env python3
"""bench/gpu_bench.py -- the GPU bench of issue 38 (scripts/gpu-check.sh --bench runs it).

For the Cornell box at 512x512 and the living room (../shared/models/living-room, its textures
replaced by albedo 0.5, as in docs/gpu.md), prints samples/s and the time to an RMSE of 0.01
against a reference for each way raystream can render on a GPU machine:

  cpu        the stream engine on the CPU's threads (--devices cpu)
  gpu        the GPU's wavefront: paths run whole on the GPU (--devices gpu)
  cpu+gpu    both on one frame, the plan dealt by their rates (--devices cpu,gpu)
  gpu-host   the thesis's design: the GPU traces, the host shades (--devices gpu --shade-on host)
  megakernel the GPU megakernel (--integrator megakernel --devices gpu)
  megakernel-b2  the same built for two blocks per SM (RS_MEGAKERNEL_BOUNDS=2; at most 128
             registers), to time against the default (one block: ptxas's own choice)
  mitsuba-ld, mitsuba-ind
             Mitsuba 3 (cuda_ad_rgb: --mitsuba-variant) with its ldsampler and independent
             sampler, where --mitsuba-python imports mitsuba (scripts/gpu-check.sh unpacks the
             wheels it carries onto PYTHONPATH); each against its own reference (independent, at
             the same REF spp).  The scenes it gets are peers_bench's (--export): raystream's
             Cornell box, and the interior of bench/peers_bench (the living room's geometry,
             Lambertian 0.5, glass left out, a uniform sky of radiance 1, max depth 16) at
             960x540, which raystream's rows then render too (its scene.json)

Time to RMSE 0.01 is t * (rmse / 0.01)^2 from a render of t seconds (render time, from
--stats-json) at RMSE rmse against the reference (the wavefront at REF spp: its own noise is
included in rmse, 1/16 of the variance or less).  Each row is the median of --runs renders,
interleaved (run k of every row before run k + 1 of any).  Images are .pfm (every build writes
them), compared in Python (no numpy needed).  A 1-pixel box filter everywhere.

  gpu_bench.py --raystream BIN [--models DIR] [--out DIR] [--runs N] [--quick]
               [--rows cpu,gpu,cpu+gpu,gpu-host,megakernel]

--quick: small sizes, one run (the suite's smoke test on the GPU's host fallback).
"""
import argparse
import json
import math
import os
import platform
import re
import subprocess
import sys
import time

from array import array


def read_pfm(path):
    """The floats of an RGB .pfm (row order does not matter for an RMSE between two)."""
    with open(path, "rb") as f:
        if f.readline().strip() != b"PF":
            raise RuntimeError("%s: not an RGB .pfm" % path)
        f.readline()
        scale = float(f.readline())
        data = array("f")
        data.frombytes(f.read())
    if (scale < 0) != (sys.byteorder == "little"):
        data.byteswap()
    return data


def image_rmse(a, b):
    if len(a) != len(b):
        raise RuntimeError("images of different sizes")
    return math.sqrt(math.fsum((x - y) * (x - y) for x, y in zip(a, b)) / len(a))


def untextured_living_room(models, out_dir):
    """The living room with every textured material made Lambertian 0.5 (a PFM-only build reads
    no PNG), paths made absolute: the JSON written to out_dir."""
    src = os.path.join(models, "living-room", "living-room.raystream.json")
    if not os.path.exists(src):
        return None
    base = os.path.dirname(os.path.abspath(src))
    with open(src) as f:
        scene = json.load(f)
    scene.pop("textures", None)
    for m in scene["materials"].values():
        if "texture" in m:
            del m["texture"]
            m["albedo"] = [0.5, 0.5, 0.5]
    for o in scene["objects"]:
        if "file" in o:
            o["file"] = os.path.join(base, o["file"])
    bg = scene.get("background", {})
    if "map" in bg:
        bg["map"] = os.path.join(base, bg["map"])
    path = os.path.join(out_dir, "living-room-untextured.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    return path


ROWS = {
    "cpu": ["--devices", "cpu"],
    "gpu": ["--devices", "gpu"],
    "cpu+gpu": ["--devices", "cpu,gpu"],
    "gpu-host": ["--devices", "gpu", "--shade-on", "host"],
    "megakernel": ["--integrator", "megakernel", "--devices", "gpu"],
    "megakernel-b2": ["--integrator", "megakernel", "--devices", "gpu"],
}
# rows that differ by the environment only: the megakernel built for two blocks per SM
ENV = {"megakernel-b2": {"RS_MEGAKERNEL_BOUNDS": "2"}}


def render(args, binary, scene, spp, row, out, extra):
    img = os.path.join(out, "img.pfm")
    js = os.path.join(out, "stats.json")
    cmd = [binary, "render"] + scene + ["--spp", str(spp), "--filter", "box", "-q", "-o", img,
                                        "--stats-json", js] + ROWS[row] + extra
    env = dict(os.environ, **ENV.get(row, {}))
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout, env=env)
    if r.returncode != 0:
        raise RuntimeError("%s: exit %d: %s" % (" ".join(cmd), r.returncode, r.stderr.strip()))
    if "CPU fallback" in r.stderr and row != "cpu" and not args.quick:
        raise RuntimeError("%s ran on the CPU fallback: %s" % (row, r.stderr.strip()))
    with open(js) as f:
        st = json.load(f)
    return st["seconds"], st["samples"], read_pfm(img)


def export_peers(args, which, size, depth):
    """peers_bench --export: (scene.json, scene.xml) of `which` at SIZE ("WxH"), or None."""
    out = os.path.join(args.out, "peers-" + which)
    cmd = [args.peers_bench, "--export", out, "--scenes", which, "--size", size]
    if depth:
        cmd += ["--depth", str(depth)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    d = os.path.join(out, which)
    if r.returncode != 0 or not os.path.exists(os.path.join(d, "scene.xml")):
        print("gpu_bench: %s: not exported (%s)" % (which, (r.stdout + r.stderr).strip()[-300:]))
        return None
    return os.path.join(d, "scene.json"), os.path.join(d, "scene.xml")


def mitsuba_ready(args):
    """'' when --mitsuba-python imports mitsuba with --mitsuba-variant, else why not."""
    code = "import mitsuba, drjit; mitsuba.set_variant('%s'); print(mitsuba.__version__)" % \
        args.mitsuba_variant
    try:
        r = subprocess.run([args.mitsuba_python, "-c", code], capture_output=True, text=True,
                           timeout=args.timeout)
    except OSError as e:
        return str(e)
    if r.returncode != 0:
        return (r.stderr.strip().splitlines() or ["no output"])[-1]
    print("Mitsuba %s, %s (%s)" % (r.stdout.strip(), args.mitsuba_variant, args.mitsuba_python))
    return ""


def render_mitsuba(args, xml, spp, sampler, out):
    """(seconds, samples, image) of Mitsuba's render of `xml` (bench/peers/mitsuba_peer.py)."""
    here = os.path.dirname(os.path.abspath(__file__))
    prefix = os.path.join(out, "mi")
    cmd = [args.mitsuba_python, os.path.join(here, "peers", "mitsuba_peer.py"), xml,
           args.mitsuba_variant, sampler, str(os.cpu_count() or 1), "1", prefix, str(spp)]
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=args.timeout)
    if r.returncode != 0:
        raise RuntimeError("%s: exit %d: %s" % (" ".join(cmd), r.returncode, r.stderr.strip()))
    # the last "SPP SECONDS" line (Mitsuba's own log lines, with terminal colours, come too)
    plain = re.sub(r"\x1b\[[0-9;]*m", "", r.stdout)
    lines = [ln.split() for ln in plain.splitlines() if re.fullmatch(r"\d+ [0-9.]+", ln.strip())]
    if not lines:
        raise RuntimeError("%s: no 'SPP SECONDS' line in: %s" % (" ".join(cmd), r.stdout[-300:]))
    got, secs = lines[-1]
    img = array("f")
    with open("%s_%s.f32" % (prefix, got), "rb") as f:
        img.frombytes(f.read())
    return float(secs), spp * len(img) // 3, img


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    ap.add_argument("--raystream", required=True)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--models", default=os.path.join(here, "..", "..", "shared", "models"))
    ap.add_argument("--out", default="/tmp/gpu_bench")
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--rows", default="cpu,gpu,cpu+gpu,gpu-host,megakernel,megakernel-b2")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--timeout", type=float, default=240)
    ap.add_argument("--peers-bench", help="peers_bench, for the scenes Mitsuba gets (default: "
                    "bench/peers_bench beside --raystream)")
    ap.add_argument("--mitsuba-python", default=sys.executable)
    ap.add_argument("--mitsuba-variant", default="cuda_ad_rgb")
    ap.add_argument("--no-mitsuba", action="store_true")
    args = ap.parse_args()
    if not args.peers_bench:
        args.peers_bench = os.path.join(os.path.dirname(os.path.abspath(args.raystream)), "bench",
                                        "peers_bench")
    os.makedirs(args.out, exist_ok=True)
    rows = args.rows.split(",")
    q = args.quick
    # scene, reference spp, spp per row (about a second or two each on an H200 machine)
    scenes = [("cornell 512x512",
               ["builtin:cornell", "--width", "512", "--height", "512", "--max-depth", "50"]
               if not q else ["builtin:cornell", "--width", "64", "--height", "64"],
               4096 if not q else 64,
               {"cpu": 64, "gpu": 1024, "cpu+gpu": 1024, "gpu-host": 64, "megakernel": 256,
                "megakernel-b2": 256}
               if not q else {k: 4 for k in ROWS})]
    why = "--no-mitsuba" if args.no_mitsuba else mitsuba_ready(args)
    if why:
        print("gpu_bench: Mitsuba rows left out: %s" % why)
    xmls = {}
    peers = export_peers(args, "cornell", "512" if not q else "64", 0)
    if peers and not why:
        xmls["cornell 512x512"] = peers[1]
    peers = export_peers(args, "interior", "960x540" if not q else "48x27", 16 if not q else 4)
    if peers:
        ipx = (960, 540) if not q else (48, 27)
        name = "interior %dx%d (living room, Lambertian 0.5, uniform sky)" % ipx
        scenes.append((name, [peers[0], "--width", str(ipx[0]), "--height", str(ipx[1]),
                              "--max-depth", "16" if not q else "4"],
                       2048 if not q else 16,
                       {"cpu": 16, "gpu": 256, "cpu+gpu": 256, "gpu-host": 16, "megakernel": 64,
                        "megakernel-b2": 64} if not q else {k: 2 for k in ROWS}))
        if not why:
            xmls[name] = peers[1]
    lr = untextured_living_room(args.models, args.out) if not peers else None
    if lr:
        scenes.append(("living room 640x360 (untextured)",
                       [lr, "--width", "640", "--height", "360", "--max-depth", "16"]
                       if not q else [lr, "--width", "48", "--height", "27", "--max-depth", "4"],
                       2048 if not q else 16,
                       {"cpu": 16, "gpu": 256, "cpu+gpu": 256, "gpu-host": 16, "megakernel": 64,
                        "megakernel-b2": 64}
                       if not q else {k: 2 for k in ROWS}))
    elif not peers:
        print("gpu_bench: %s has no living-room/: that scene is left out" % args.models)
    print("machine: %s, %d cores; %s" % (platform.node(), os.cpu_count() or 0,
                                         subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version",
                                                         "--format=csv,noheader"],
                                                        capture_output=True, text=True).stdout.strip()
                                         if not q else "quick (GPU rows on whatever --devices gpu is)"))
    print("settings: box filter, sobol sampler, seed 1; time to RMSE 0.01 = t (rmse/0.01)^2 against "
          "the wavefront's reference; median of %d interleaved runs" % args.runs)
    results = []
    for name, scene, ref_spp, spps in scenes:
        t0 = time.time()
        _, _, ref = render(args, args.raystream, scene, ref_spp, "gpu", args.out, [])
        print("%s: reference %d spp in %.1f s" % (name, ref_spp, time.time() - t0), flush=True)
        mi_rows = ["mitsuba-ld", "mitsuba-ind"] if name in xmls else []
        if mi_rows:
            t0 = time.time()
            try: # a peer that fails is reported and left out, not the bench
                _, _, mi_ref = render_mitsuba(args, xmls[name], ref_spp, "independent", args.out)
                print("%s: Mitsuba's reference %d spp in %.1f s" % (name, ref_spp,
                                                                    time.time() - t0), flush=True)
            except (RuntimeError, OSError, subprocess.TimeoutExpired) as e:
                print("%s: Mitsuba rows left out: %s" % (name, str(e)[-400:]), flush=True)
                mi_rows = []
        got = {r: [] for r in rows + mi_rows}
        for k in range(args.runs):
            for r in rows:
                secs, samples, img = render(args, args.raystream, scene, spps[r], r, args.out, [])
                got[r].append((secs, samples, image_rmse(img, ref)))
            for r in mi_rows:
                spp = 4 # the ldsampler takes powers of 4 (it rounds others up)
                while spp < spps.get("gpu", 64):
                    spp *= 4
                secs, samples, img = render_mitsuba(args, xmls[name], spp,
                                                    "ldsampler" if r == "mitsuba-ld" else
                                                    "independent", args.out)
                got[r].append((secs, samples, image_rmse(img, mi_ref)))
        spps = dict(spps, **{r: spp for r in mi_rows})
        print("\n%s\n  %-13s %6s %9s %12s %9s %12s %8s" % (name, "row", "spp", "seconds", "Msamples/s",
                                                         "rmse", "t(0.01) s", "vs gpu"))
        med = {}
        for r in rows + mi_rows:
            runs = sorted(got[r])
            secs, samples, rmse = runs[len(runs) // 2]
            t01 = secs * (rmse / 0.01) ** 2
            med[r] = (secs, samples / secs / 1e6, rmse, t01)
        for r in rows + mi_rows:
            secs, rate, rmse, t01 = med[r]
            ratio = med["gpu"][1] and rate / med["gpu"][1] if "gpu" in med else 0
            print("  %-13s %6d %9.3f %12.1f %9.5f %12.4f %7.2fx" % (r, spps[r], secs, rate, rmse, t01,
                                                                ratio), flush=True)
        if "cpu+gpu" in med and "cpu" in med and "gpu" in med:
            s = med["cpu"][1] + med["gpu"][1]
            print("  cpu+gpu: %.1f Msamples/s = %.2f of cpu + gpu alone (%.1f)" %
                  (med["cpu+gpu"][1], med["cpu+gpu"][1] / s, s))
        for r in mi_rows:
            for ours in ("gpu", "megakernel"):
                if ours in med:
                    print("  %s reaches RMSE 0.01 %.2fx sooner than %s" %
                          (ours, med[r][3] / med[ours][3], r))
        results.append({"scene": name, "rows": {r: dict(zip(("seconds", "msamples_s", "rmse",
                                                              "t_rmse_0.01"), med[r]))
                                                for r in rows + mi_rows}})
    with open(os.path.join(args.out, "gpu_bench.json"), "w") as f:
        json.dump(results, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
