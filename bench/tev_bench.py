#!/usr/bin/env python3
"""bench/tev_bench.py -- what --tev costs a render (issue 42: at most 2%).

Runs `raystream render` with and without `--tev 127.0.0.1:PORT`, interleaved (round k of both
before round k + 1), against a fake tev in this script: a thread that accepts the connection and
reads every byte (as tev would, without drawing), counting the packets.  Prints the machine, the
settings, each row's render times (--stats-json "seconds") and median, and the ratio of the
medians; the images of both rows must be the same file, bit for bit.

  tev_bench.py --raystream BIN [--quick] [--runs N] [--scene S] [--width W] [--spp N]
               [--threads T]

--quick: a small render, one run (the suite's smoke test, tev_bench_quick).
"""
import argparse
import json
import os
import platform
import socket
import statistics
import subprocess
import sys
import tempfile
import threading


class FakeTev:
    """Accepts connections on a loopback port and reads them to the end."""

    def __init__(self):
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(4)
        self.port = self.sock.getsockname()[1]
        self.bytes = 0
        self.packets = 0
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        while True:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            buf = bytearray(1 << 20)
            head = b""  # the next packet's length field, as far as it came
            skip = 0    # bytes of the current packet still to come
            with conn:
                while True:
                    n = conn.recv_into(buf)
                    if not n:
                        break
                    self.bytes += n
                    i = 0
                    while i < n:  # packet boundaries only: a uint32 length, then the rest
                        if skip:
                            k = min(skip, n - i)
                            skip -= k
                            i += k
                            continue
                        take = min(4 - len(head), n - i)
                        head += bytes(buf[i:i + take])
                        i += take
                        if len(head) == 4:
                            skip = int.from_bytes(head, "little") - 4
                            head = b""
                            self.packets += 1


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def render(args, out, stats, tev_port):
    cmd = [args.raystream, "render", args.scene, "--width", str(args.width), "--spp",
           str(args.spp), "--threads", str(args.threads), "--filter", "box:1", "-q", "-o", out,
           "--stats-json", stats]
    if tev_port:
        cmd += ["--tev", "127.0.0.1:%d" % tev_port]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0 or r.stderr:
        sys.exit("tev_bench: %s: exit %d: %s" % (" ".join(cmd), r.returncode, r.stderr.strip()))
    with open(stats) as f:
        return json.load(f)["seconds"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--raystream", required=True)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--scene", default="builtin:cornell")
    ap.add_argument("--width", type=int, default=600)
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--threads", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    if args.quick:
        args.width, args.spp, args.runs = 96, 4, 1
    tev = FakeTev()
    times = {"plain": [], "tev": []}
    with tempfile.TemporaryDirectory() as tmp:
        for k in range(args.runs):
            for row in ("plain", "tev"):
                out = os.path.join(tmp, row + ".pfm")
                times[row].append(render(args, out, os.path.join(tmp, row + ".json"),
                                         tev.port if row == "tev" else 0))
            with open(os.path.join(tmp, "plain.pfm"), "rb") as a, \
                    open(os.path.join(tmp, "tev.pfm"), "rb") as b:
                if a.read() != b.read():
                    sys.exit("tev_bench: the image with --tev differs from the one without")
    print("machine: %s, %d CPUs, %s" % (cpu_model(), os.cpu_count() or 0, platform.platform()))
    print("settings: %s --width %d --spp %d --threads %d --filter box:1, %d interleaved runs"
          % (args.scene, args.width, args.spp, args.threads, args.runs))
    med = {}
    for row in ("plain", "tev"):
        med[row] = statistics.median(times[row])
        print("%-6s %s  median %.3f s" % (row, " ".join("%.3f" % t for t in times[row]),
                                          med[row]))
    print("tev / plain: %.3f (the fake tev took %d packets, %.1f MB)"
          % (med["tev"] / med["plain"], tev.packets, tev.bytes / 1e6))
    print("images: the same, bit for bit")


if __name__ == "__main__":
    main()
