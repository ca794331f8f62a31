#!/usr/bin/env python3
"""bench/peers/mitsuba_peer.py -- Mitsuba 3's side of bench/peers_bench.

Renders a Mitsuba scene file (written by peers_bench from raystream's own scene) at each of
several sample counts and prints one line per render, "SPP SECONDS", where SECONDS is the time
of mi.render alone (scene loading and, for the JIT variants, a warm-up render that compiles the
kernels at that sample count are not counted).  Writes OUT_SPP.exr (linear RGB float).

  mitsuba_peer.py SCENE.xml VARIANT SAMPLER THREADS SEED OUT SPP[,SPP...] [--no-warmup]
"""
import faulthandler
import sys
import time


def main(argv):
    # a hung render must not hang the benchmark
    faulthandler.dump_traceback_later(3600, exit=True)
    if len(argv) not in (8, 9):
        sys.stderr.write(__doc__)
        return 2
    scene_path, variant, sampler, threads, seed, out, spps = argv[1:8]
    warmup = len(argv) == 8
    import drjit as dr
    # before the variant loads: Dr.Jit's thread pool is sized once
    dr.set_thread_count(int(threads))
    import mitsuba as mi
    mi.set_variant(variant)
    scene = mi.load_file(scene_path, sampler=sampler)
    for spp in (int(s) for s in spps.split(",")):
        if warmup and variant.startswith(("llvm", "cuda")):
            img = mi.render(scene, spp=spp, seed=int(seed) + 7919)
            dr.eval(img)
            dr.sync_thread()
        t0 = time.perf_counter()
        img = mi.render(scene, spp=spp, seed=int(seed))
        dr.eval(img)
        dr.sync_thread()
        secs = time.perf_counter() - t0
        # raw float32 RGB rows from the top (mi.Bitmap.write deadlocks with one thread)
        import numpy as np
        np.asarray(img, dtype=np.float32)[:, :, :3].tofile("%s_%d.f32" % (out, spp))
        print("%d %.6f" % (spp, secs), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
