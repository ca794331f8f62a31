#!/usr/bin/env python3
"""scripts/cuda-occupancy.py — every CUDA kernel's registers, stack, spills and shared memory, its
theoretical occupancy on sm_90 (H100/H200), and the launch geometry of the megakernel and the
trace kernel for a 512x512 image, all without a GPU; checked against the recorded gpu/occupancy.txt.

  python3 scripts/cuda-occupancy.py [--baseline FILE] [--source-dir DIR] OBJECT|LOG...
  python3 scripts/cuda-occupancy.py --write-baseline [--baseline FILE] OBJECT|LOG...
  python3 scripts/cuda-occupancy.py --self-test [OBJECT|LOG...]

OBJECT is a .cu object of rs_gpu (build/CMakeFiles/rs_gpu.dir/gpu/*.cu.o); its numbers are read
from OBJECT.ptxas.txt, which the build writes beside it (rs_gpu is compiled with -Xptxas=-v
through scripts/ptxas-log.sh).  A LOG is any saved `nvcc -Xptxas -v` output.  Objects of C files
(no log, not .cu) are skipped.  cuobjdump --dump-resource-usage is not used: the toolkit on the
build machines has no cuobjdump, and only ptxas reports spill bytes.

The check fails (exit 1, one line per kernel saying what) when a kernel uses more registers, stack
or spill bytes than recorded, when a kernel of the build is not recorded, when a recorded kernel
is gone, and when a target the baseline marks `enforced` is missed.  Targets not enforced (issue
38: the hot wavefront kernels at most 64 registers without spills, the megakernel at most 96) are
printed as information.  Fewer registers than recorded pass with a note: record them with
--write-baseline, which rewrites the kernel lines and keeps the targets and the header.  Exit 77
(CTest: skipped) when the build has no sm_90 code.  CTest runs this as cuda_occupancy_check and
cuda_occupancy_self_test (tests/CMakeLists.txt); docs/gpu.md, "Occupancy without a GPU"."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile

ARCH = "sm_90"
SMS = 132  # an H200 (and an H100 SXM)

# ---- the occupancy rules of compute capability 9.0 ------------------------------------------
# From the CUDA toolkit's cuda_occupancy.h (cudaOccMaxActiveBlocksPerMultiprocessor), the code
# the runtime's occupancy API and Nsight Compute's "theoretical occupancy" follow.  For a block of
# B threads of a kernel with R registers per thread and S bytes of static shared memory:
#
#   warps per block     W = ceil(B / 32)
#   warp slots          by_warps = floor(64 / W)                    (2048 threads per SM)
#   block slots         by_blocks = 32
#   registers           per warp: Rw = roundup(R * 32, 256)        (allocated per warp, in units
#                       of 256); they are allocated in each of the SM's 4 sub-partitions of
#                       65536 / 4 = 16384: by_regs = floor(floor(16384 / Rw) * 4 / W), and 0 when
#                       Rw * roundup(W, 4) > 65536 (a block must fit) or R > 255
#   shared memory       per block: Sb = roundup(S + 1024, 128)     (1 KB reserved per block);
#                       by_smem = floor(228 KB / Sb), and 0 when S > 227 KB
#   barriers            by_bars = floor(2 * 32 / barriers used)     (none used: no limit)
#   blocks per SM       N = min(by_warps, by_blocks, by_regs, by_smem, by_bars)
#   occupancy           N * W / 64
#
# The per-sub-partition rounding matters: 96 registers give floor(16384 / 3072) * 4 = 20 warps,
# not floor(65536 / 3072) = 21.  The launches take their block size from
# cudaOccupancyMaxPotentialBlockSize under the kernel's __launch_bounds__ (gpu/cuda_device.cu,
# gpu/cuda_megakernel.cu), which tries B = bound, bound - 32, ..., 32 and keeps the first B with
# the most threads per SM (N * B); block_for() does the same.  Worked cases (--self-test checks
# them):
#   118 registers, B = 256: Rw = 3776 -> 3840, floor(16384 / 3840) = 4 -> 16 warps, N = 2 -> 25%
#     (Nsight Compute's figure for the trace kernel in issue 38); the API keeps 256.
#   146 registers, B = 256: Rw = 4672 -> 4864, floor(16384 / 4864) = 3 -> 12 warps, N = 1 -> 12.5%;
#     the API picks B = 192 (6 warps): N = 2 -> 12 warps = 18.75% (issue 38's megakernel figure).
#   64 registers, B = 256: Rw = 2048, 8 -> 32 warps, N = 4 -> 50%.
#   CUB's single-tile sort, 128 registers, 33856 B shared, B = 256: by_regs 2, Sb = 34944 ->
#     by_smem 6, N = 2 -> 25%.
WARP = 32
MAX_WARPS_SM = 64
MAX_BLOCKS_SM = 32
REGS_SM = 65536
REGS_BLOCK = 65536
REG_UNIT = 256
SUB_PARTITIONS = 4
MAX_REGS_THREAD = 255
SMEM_SM = 228 * 1024
SMEM_BLOCK = 227 * 1024
SMEM_RESERVED = 1024
SMEM_UNIT = 128
MAX_THREADS_BLOCK = 1024


def ceil_div(a, b):
    return (a + b - 1) // b


def round_up(a, b):
    return ceil_div(a, b) * b


def blocks_per_sm(regs, smem, barriers, block):
    """(blocks of `block` threads resident per SM, the limiting resource) on sm_90."""
    w = ceil_div(block, WARP)
    limits = {"warps": MAX_WARPS_SM // w, "blocks": MAX_BLOCKS_SM}
    rw = round_up(regs * WARP, REG_UNIT)
    if regs > MAX_REGS_THREAD or rw * round_up(w, SUB_PARTITIONS) > REGS_BLOCK:
        limits["registers"] = 0
    elif rw > 0:
        limits["registers"] = (REGS_SM // SUB_PARTITIONS // rw) * SUB_PARTITIONS // w
    if smem > SMEM_BLOCK:
        limits["shared"] = 0
    else:
        limits["shared"] = SMEM_SM // round_up(smem + SMEM_RESERVED, SMEM_UNIT)
    if barriers:
        limits["barriers"] = 2 * MAX_BLOCKS_SM // barriers
    n = min(limits.values())
    # the first limit that binds, in the order Nsight Compute names them
    why = next(k for k in ("registers", "shared", "warps", "blocks", "barriers")
               if limits.get(k) == n)
    return n, why


def occupancy(regs, smem, barriers, block):
    n, _ = blocks_per_sm(regs, smem, barriers, block)
    return n * ceil_div(block, WARP) / MAX_WARPS_SM


def block_for(regs, smem, barriers, bound):
    """The block size cudaOccupancyMaxPotentialBlockSize picks under `bound` threads."""
    limit = min(bound, MAX_THREADS_BLOCK)
    best, best_threads = 0, 0
    for b in range(round_up(limit, WARP), 0, -WARP):
        b = min(b, limit)
        threads = b * blocks_per_sm(regs, smem, barriers, b)[0]
        if threads > best_threads:
            best, best_threads = b, threads
        if best_threads == MAX_WARPS_SM * WARP:
            break
    return best


# ---- ptxas -v ------------------------------------------------------------------------------
class Kernel:
    def __init__(self, mangled, arch, origin):
        self.mangled, self.arch, self.origin = mangled, arch, origin
        self.name = mangled
        self.regs = self.frame = self.stack = self.spill_st = self.spill_ld = 0
        self.smem = self.barriers = 0
        self.bound = None  # (max threads, min blocks) from __launch_bounds__, or None

    @property
    def spill(self):
        return self.spill_st + self.spill_ld


RE_ENTRY = re.compile(r"^ptxas info\s*: Compiling entry function '([^']+)' for '(\w+)'")
RE_PROPS = re.compile(r"^ptxas info\s*: Function properties for (\S+)")
RE_FRAME = re.compile(r"^\s+(\d+) bytes stack frame, (\d+) bytes spill stores, "
                      r"(\d+) bytes spill loads")
RE_USED = re.compile(r"^ptxas info\s*: Used (\d+) registers")


def parse_ptxas(text, origin):
    """The entry functions (kernels) of one ptxas -v log, in order."""
    kernels, cur, props = [], None, None
    for line in text.splitlines():
        m = RE_ENTRY.match(line)
        if m:
            cur = Kernel(m.group(1), m.group(2), origin)
            kernels.append(cur)
            props = None
            continue
        m = RE_PROPS.match(line)
        if m:
            props = m.group(1)
            continue
        m = RE_FRAME.match(line)
        if m:
            if cur is not None and props == cur.mangled:
                cur.frame = int(m.group(1))
                cur.spill_st, cur.spill_ld = int(m.group(2)), int(m.group(3))
            props = None
            continue
        m = RE_USED.match(line)
        if m and cur is not None:
            cur.regs = int(m.group(1))
            for value, what in re.findall(r"(\d+) (bytes smem|barriers|bytes cumulative stack)",
                                          line.replace("used ", "")):
                if what == "bytes smem":
                    cur.smem = int(value)
                elif what == "barriers":
                    cur.barriers = int(value)
                else:
                    cur.stack = int(value)
    for k in kernels:
        k.stack = max(k.stack, k.frame)
    return kernels


def demangle(names):
    """Mangled -> demangled through c++filt (the mangled name itself where that fails)."""
    out = dict((n, n) for n in names)
    if names and shutil.which("c++filt"):
        r = subprocess.run(["c++filt"], input="\n".join(names) + "\n", capture_output=True,
                           text=True, check=False)
        lines = r.stdout.splitlines()
        if r.returncode == 0 and len(lines) == len(names):
            out = dict(zip(names, lines))
    return out


def strip_nested(s, open_c, close_c):
    out, depth = [], 0
    for c in s:
        if c == open_c:
            depth += 1
        elif c == close_c:
            depth -= 1
        elif depth == 0:
            out.append(c)
    return "".join(out)


def short_name(demangled, mangled):
    """The kernel's own name: no return type, scope, template arguments or parameters
    ("void cub::...::EmptyKernel<void>()" -> "EmptyKernel")."""
    s = demangled.strip()
    if s == mangled:  # not demangled: _Z<len><name>... of a plain function
        m = re.match(r"_Z(\d+)", s)
        return s[len(m.group(0)):len(m.group(0)) + int(m.group(1))] if m else s
    s = strip_nested(s.replace("(anonymous namespace)", "anon"), "<", ">")
    s = strip_nested(s, "(", ")")
    return s.split()[-1].split("::")[-1] if s.split() else demangled


def load_kernels(paths):
    """Kernels of every object's log (or log), named; (kernels, sources read)."""
    kernels, read = [], []
    for p in paths:
        if p.endswith(".ptxas.txt") or not re.search(r"\.(o|obj)$", p):
            log = p
        else:
            log = p + ".ptxas.txt"
            if not os.path.exists(log):
                if not re.search(r"\.cu\.(o|obj)$", p):
                    continue  # a C or C++ object of the library: no device code
                sys.exit(f"cuda-occupancy: {log}: no ptxas log beside {os.path.basename(p)} "
                         "(build rs_gpu: its CUDA compile writes it, scripts/ptxas-log.sh)")
            if os.path.exists(p) and os.path.getmtime(log) < os.path.getmtime(p):
                sys.exit(f"cuda-occupancy: {log} is older than its object (rebuild rs_gpu)")
        try:
            with open(log, encoding="utf-8", errors="replace") as f:
                kernels += parse_ptxas(f.read(), os.path.basename(log))
        except OSError as e:
            sys.exit(f"cuda-occupancy: {log}: {e.strerror}")
        read.append(log)
    dm = demangle(sorted(set(k.mangled for k in kernels)))
    for k in kernels:
        k.name = short_name(dm[k.mangled], k.mangled)
    seen = {}
    for k in sorted(kernels, key=lambda k: (k.name, k.mangled)):
        if k.arch != ARCH:
            continue
        seen[k.name] = seen.get(k.name, 0) + 1
        if seen[k.name] > 1:  # two instances of one template: number them
            k.name = f"{k.name}#{seen[k.name]}"
    return kernels, read


# ---- the sources: __launch_bounds__ and the constants of the launch sizes --------------------
def c_defines(paths):
    defs = {}
    for p in paths:
        try:
            with open(p, encoding="utf-8", errors="replace") as f:
                text = f.read()
        except OSError:
            continue
        for m in re.finditer(r"^[ \t]*#[ \t]*define[ \t]+(\w+)[ \t]+([^\n]*)", text, re.M):
            defs.setdefault(m.group(1), re.sub(r"/\*.*?(\*/|$)", "", m.group(2)).strip())
    return defs


def c_value(expr, defs, depth=0):
    """The integer value of a constant C expression of literals, defines, ( ) << * + -; None."""
    if depth > 8:
        return None
    out = []
    for tok in re.findall(r"\w+|<<|>>|[()*+\-/]|\S", expr):
        if re.fullmatch(r"\d+[uUlL]*", tok):
            out.append(tok.rstrip("uUlL"))
        elif re.fullmatch(r"[A-Za-z_]\w*", tok):
            v = c_value(defs[tok], defs, depth + 1) if tok in defs else None
            if v is None:
                return None
            out.append(str(v))
        elif tok in ("(", ")", "<<", ">>", "*", "+", "-"):
            out.append(tok)
        elif tok == "/":
            out.append("//")
        else:
            return None
    try:
        return int(eval(" ".join(out), {"__builtins__": {}}))  # only digits and operators
    except (SyntaxError, ValueError, TypeError, ZeroDivisionError):
        return None


def source_files(root, folder, exts):
    d = os.path.join(root, folder)
    try:
        return [os.path.join(d, f) for f in sorted(os.listdir(d)) if f.endswith(exts)]
    except OSError:
        return []


def launch_bounds(root):
    """kernel name -> (max threads, min blocks) from the __launch_bounds__ in gpu/."""
    files = source_files(root, "gpu", (".cu", ".h"))
    defs = c_defines(files)
    bounds = {}
    for p in files:
        with open(p, encoding="utf-8", errors="replace") as f:
            text = f.read()
        for m in re.finditer(r"__launch_bounds__\s*\(([^()]*)\)\s*(\w+)\s*\(", text):
            args = [a.strip() for a in m.group(1).split(",")]
            mx = c_value(args[0], defs)
            mn = c_value(args[1], defs) if len(args) > 1 else 0
            if mx:
                bounds[m.group(2)] = (mx, mn or 0)
    return bounds


# ---- the baseline --------------------------------------------------------------------------
TARGET = re.compile(r"(regs|stack|spill)<=(\d+)$")


class Record:
    def __init__(self, name, regs, stack, spill, target, enforced, line):
        self.name, self.regs, self.stack, self.spill = name, regs, stack, spill
        self.target, self.enforced, self.line = target, enforced, line


def read_baseline(path):
    """(header lines, {name: Record}); exits on a malformed line."""
    header, recs = [], {}
    with open(path, encoding="utf-8") as f:
        lines = f.read().splitlines()
    for n, line in enumerate(lines, 1):
        words = line.split("#", 1)[0].split()
        if not words:
            if not recs:
                header.append(line)
            continue
        bad = f"cuda-occupancy: {path}:{n}: expected `KERNEL REGS STACK SPILL [TARGET [enforced]]`"
        if len(words) < 4 or len(words) > 6 or not all(w.isdigit() for w in words[1:4]):
            sys.exit(bad)
        target = [] if len(words) < 5 or words[4] == "-" else words[4].split(",")
        if any(not TARGET.match(t) for t in target) or (len(words) == 6 and words[5] != "enforced"):
            sys.exit(bad + f" (TARGET: '-' or e.g. regs<=64,spill<=0)")
        if words[0] in recs:
            sys.exit(f"cuda-occupancy: {path}:{n}: {words[0]} is recorded twice")
        recs[words[0]] = Record(words[0], int(words[1]), int(words[2]), int(words[3]), target,
                                len(words) == 6, n)
    return header, recs


def write_baseline(path, header, recs, kernels):
    rows = [("# kernel", "regs", "stack", "spill", "target")]
    for k in kernels:
        r = recs.get(k.name)
        t = ",".join(r.target) if r and r.target else "-"
        rows.append((k.name, str(k.regs), str(k.stack), str(k.spill),
                     t + (" enforced" if r and r.enforced else "")))
    w = [max(len(r[i]) for r in rows) for i in range(4)]
    body = [f"{r[0]:<{w[0]}}  {r[1]:>{w[1]}}  {r[2]:>{w[2]}}  {r[3]:>{w[3]}}  {r[4]}".rstrip()
            for r in rows]
    head = [h for h in header if not h.startswith("# kernel ")]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(head + body) + "\n")


def target_values(k):
    return {"regs": k.regs, "stack": k.stack, "spill": k.spill}


def check(kernels, recs, base_name):
    """(failure lines, note lines, target lines)."""
    fails, notes, targets = [], [], []
    units = {"regs": "registers", "stack": "B stack", "spill": "B spills"}
    names = set()
    for k in kernels:
        names.add(k.name)
        r = recs.get(k.name)
        if r is None:
            fails.append(f"{k.name}: in the build but not in {base_name} (record it: {k.regs} "
                         f"registers, {k.stack} B stack, {k.spill} B spills; --write-baseline)")
            continue
        got, bad, better = target_values(k), [], []
        for key, rec in (("regs", r.regs), ("stack", r.stack), ("spill", r.spill)):
            if got[key] > rec:
                bad.append(f"{got[key]} {units[key]} > {rec} recorded")
            elif got[key] < rec:
                better.append(f"{got[key]} {units[key]} < {rec}")
        missed = {}  # target -> the value that misses it
        for t in r.target:
            key, most = TARGET.match(t).groups()
            if got[key] > int(most):
                missed[t] = got[key]
        if r.enforced and missed:
            bad.append("enforced target " + ", ".join(f"{t} missed ({v})"
                                                      for t, v in missed.items()))
        if bad:
            fails.append(f"{k.name}: " + ", ".join(bad))
        if better:
            notes.append(f"{k.name}: {', '.join(better)} recorded: better; record it "
                         "(--write-baseline)")
        if r.target:
            parts = [f"{t} missed ({missed[t]})" if t in missed else f"{t} met"
                     for t in r.target]
            targets.append(f"{k.name}: {', '.join(parts)}"
                           + (" [enforced]" if r.enforced else ""))
    for name, r in sorted(recs.items(), key=lambda kv: kv[1].line):
        if name not in names:
            fails.append(f"{name}: recorded in {base_name} but not in the build")
    return fails, notes, targets


# ---- printing ------------------------------------------------------------------------------
def table(kernels):
    rows = [("kernel", "regs", "frame", "stack", "spill st/ld", "smem", "bound", "block",
             "blk/SM", "warps", "occupancy", "at bound", "limit")]
    for k in kernels:
        if k.bound:
            b = block_for(k.regs, k.smem, k.barriers, k.bound[0])
            n, why = blocks_per_sm(k.regs, k.smem, k.barriers, b)
            rows.append((k.name, str(k.regs), str(k.frame), str(k.stack),
                         f"{k.spill_st}/{k.spill_ld}", str(k.smem), f"{k.bound[0]},{k.bound[1]}",
                         str(b), str(n), str(n * ceil_div(b, WARP)),
                         pct(occupancy(k.regs, k.smem, k.barriers, b)),
                         pct(occupancy(k.regs, k.smem, k.barriers, k.bound[0])), why))
        else:
            rows.append((k.name, str(k.regs), str(k.frame), str(k.stack),
                         f"{k.spill_st}/{k.spill_ld}", str(k.smem), "-", "-", "-", "-", "-", "-",
                         "-"))
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return ["  ".join(c.ljust(w[i]) if i in (0, 12) else c.rjust(w[i]) for i, c in enumerate(r))
            .rstrip() for r in rows]


def pct(x):
    return f"{100.0 * x:.2f}%".replace(".00%", "%")


def geometry(kernels, root, width=512, height=512, spps=(1, 64)):
    """Lines on the launches of the megakernel and the trace kernel for a WxH image."""
    by = dict((k.name, k) for k in kernels)
    defs = c_defines(source_files(root, "scheduler", ".h") + source_files(root, "gpu", ".h"))
    const = dict((n, c_value(defs.get(n, ""), defs)) for n in (
        "RS_RENDER_DEFAULT_WAVE", "RS_SCHED_FIRST_GPU", "RS_SCHED_MAX_CHUNK", "RS_GPU_MIN_PIECE",
        "RS_GPU_LAUNCH_SAMPLES", "RS_CUDA_WF_WAVE"))
    npix, million = width * height, 1 << 20
    rows = [("kernel", "spp", "launch", "paths", "launches", "block", "grid", "wave", "waves",
             ">=1M", "whole")]

    def row(k, spp, what, paths, launches):
        b = block_for(k.regs, k.smem, k.barriers, k.bound[0])
        if k is by.get("rs_megakernel_kernel"):
            b -= b % WARP  # gpu/cuda_megakernel.cu: whole warps for the counters' shuffles
        n, _ = blocks_per_sm(k.regs, k.smem, k.barriers, b)
        grid, per_wave = ceil_div(paths, b), n * SMS
        waves = grid / per_wave if per_wave else float("inf")
        rows.append((k.name, str(spp), what, f"{paths:,}", f"{launches:,}", str(b), f"{grid:,}",
                     f"{per_wave * b:,}", f"{waves:.2f}", "yes" if paths >= million else "no",
                     "yes" if per_wave and grid % per_wave == 0 else "no"))

    mk, tr = by.get("rs_megakernel_kernel"), by.get("rs_trace_kernel")
    if mk and mk.bound and const["RS_GPU_LAUNCH_SAMPLES"]:
        for spp in spps:
            per = min(spp, const["RS_GPU_LAUNCH_SAMPLES"])
            row(mk, spp, f"{per} sample{'s' if per > 1 else ''}", npix * per, ceil_div(spp, per))
    busy = [by[n] for n in ("rs_wf_trace_kernel", "rs_wf_shade_kernel", "rs_wf_trace_flat_kernel")
            if n in by and by[n].bound]
    if const["RS_CUDA_WF_WAVE"] and busy:
        # gpu/cuda_wavefront.cu wf_make: a wave is a whole number of the busiest kernel's
        # resident threads
        def resident(k):
            b = block_for(k.regs, k.smem, k.barriers, k.bound[0])
            b -= b % WARP
            return blocks_per_sm(k.regs, k.smem, k.barriers, b)[0] * SMS * b
        most = max(resident(k) for k in busy)
        cap = const["RS_CUDA_WF_WAVE"]
        cap -= cap % most if cap >= most else 0
        for name in ("rs_wf_trace_flat_kernel", "rs_wf_shade_kernel"):
            k = by.get(name)
            for spp in spps if k and k.bound else ():
                wave = min(cap, npix * spp)
                row(k, spp, "a wave, bounce 1", wave, ceil_div(npix * spp, wave))
    waves = []
    if tr and tr.bound and None not in const.values():
        for spp in spps:
            # scheduler/stream_engine.c resolve_settings: with a GPU, RS_RENDER_DEFAULT_WAVE
            # paths in flight in 2 waves, a wave at most the render's paths
            wave = min(ceil_div(const["RS_RENDER_DEFAULT_WAVE"], 2), npix * spp)
            waves.append(f"{spp} spp: {min(2, ceil_div(npix * spp, wave))} x {wave:,}")
            # scheduler/sched.c: a GPU's first chunk RS_SCHED_FIRST_GPU, then its rays/s times
            # 20 ms, at most RS_SCHED_MAX_CHUNK and what is left of the wave's batch
            first = min(const["RS_SCHED_FIRST_GPU"], wave)
            most = min(const["RS_SCHED_MAX_CHUNK"], wave)
            for what, chunk in (("first chunk", first), ("largest chunk", most)):
                piece = piece_size(chunk, const["RS_GPU_MIN_PIECE"])
                row(tr, spp, f"{what} {chunk:,}", piece, ceil_div(chunk, piece))
    w = [max(len(r[i]) for r in rows) for i in range(len(rows[0]))]
    return [f"launch geometry on an H200 ({SMS} SMs), {width}x{height}:"] + [
        "  " + "  ".join(c.ljust(w[i]) if i in (0, 2) else c.rjust(w[i]) for i, c in enumerate(r))
        .rstrip() for r in rows] + [
        f"  (wave: threads resident at once, blocks/SM x {SMS} x block; waves: grid / (blocks/SM"
        f" x {SMS});",
        "   >=1M: a million paths or more per launch; whole: no partial last wave.  Megakernel: "
        "every pixel",
        f"   {const['RS_GPU_LAUNCH_SAMPLES'] or '?'} times per launch, grid = ceil(pixels x "
        "samples / block) (gpu/cuda_megakernel.cu).",
        f"   Wavefront: waves of up to {const['RS_CUDA_WF_WAVE'] or 0:,} paths, cut to a whole "
        "number of the busiest",
        "   kernel's resident threads (gpu/cuda_wavefront.cu; later bounces: the paths still alive).  Trace kernel (--shade-on host): the stream engine's waves in "
        "flight (scheduler/stream_engine.c",
        f"   resolve_settings: {'; '.join(waves)} paths) are traced in chunks",
        "   (scheduler/sched.c), each cut into rs_gpu_piece_size pieces (gpu/gpu_device.h), a "
        "launch each",
        "   over 2 streams (gpu/cuda_device.cu launch_piece); launches: per chunk.  Block: the "
        "API's.)"]


def piece_size(n, min_piece):
    """gpu/gpu_device.h rs_gpu_piece_size: a quarter of the chunk, at least min_piece rays."""
    piece = n // 4 + (n % 4 != 0)
    if piece < min_piece:
        piece = n if n < min_piece else min_piece
    return piece


def run(args):
    kernels, logs = load_kernels(args.inputs)
    if not logs:
        sys.exit("cuda-occupancy: no ptxas log among the inputs")
    ours = [k for k in kernels if k.arch == ARCH]
    if not ours:
        archs = sorted(set(k.arch for k in kernels)) or ["none"]
        print(f"cuda-occupancy: no {ARCH} code in {len(logs)} logs (archs: {', '.join(archs)}): "
              f"add 90 to CMAKE_CUDA_ARCHITECTURES to measure it; skipped")
        return 77
    bounds = launch_bounds(args.source_dir)
    for k in ours:
        k.bound = bounds.get(k.name)
    base_name = os.path.relpath(args.baseline, args.source_dir)
    try:
        header, recs = read_baseline(args.baseline)
    except FileNotFoundError:
        if not args.write_baseline:
            sys.exit(f"cuda-occupancy: {args.baseline}: no such file (--write-baseline makes it)")
        header, recs = [], {}
    ours.sort(key=lambda k: (k.name not in recs, recs[k.name].line if k.name in recs else 0,
                             k.name))
    if args.write_baseline:
        write_baseline(args.baseline, header, recs, ours)
        print(f"cuda-occupancy: wrote {len(ours)} kernels to {args.baseline}")
        return 0
    print(f"cuda-occupancy: {len(ours)} kernels of {len(logs)} objects, {ARCH}: {SMS} SMs, 64K "
          "registers, 64 warps, 32 blocks, 228 KB shared per SM")
    for line in table(ours):
        print("  " + line)
    print("  (stack: bytes per thread, with callees; bound: __launch_bounds__ (max threads, min "
          "blocks) in gpu/;\n   block: what cudaOccupancyMaxPotentialBlockSize picks under it, "
          "as the launches do; at bound: the\n   occupancy of blocks of the bound; limit: the "
          "resource that binds)")
    for line in geometry(ours, args.source_dir):
        print(line)
    fails, notes, targets = check(ours, recs, base_name)
    if targets:
        print("targets (issue 38; information unless enforced):")
        for line in targets:
            print("  " + line)
    for line in notes:
        print("note: " + line)
    for line in fails:
        print("FAIL " + line)
    print(f"cuda-occupancy: {len(ours)} kernels against {base_name}: "
          + (f"{len(fails)} failed" if fails else "ok"))
    return 1 if fails else 0


# ---- self-test -----------------------------------------------------------------------------
def fixture_log(kernels):
    """A ptxas -v log of (mangled, regs, frame, stack, spill st, spill ld, smem) entries."""
    out = ["ptxas info    : 4096 bytes gmem"]
    for m, regs, frame, stack, st, ld, smem in kernels:
        out += [f"ptxas info    : Compiling entry function '{m}' for 'sm_90'",
                f"ptxas info    : Function properties for {m}",
                f"    {frame} bytes stack frame, {st} bytes spill stores, {ld} bytes spill loads",
                f"ptxas info    : Used {regs} registers, used {1 if smem else 0} barriers"
                + (f", {smem} bytes smem" if smem else "")
                + (f", {stack} bytes cumulative stack size" if stack else ""),
                "ptxas info    : Compile time = 1.000 ms"]
    out += ["ptxas info    : Function properties for _ZN12_GLOBAL__N_14leafEv",
            "    48 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads"]
    return "\n".join(out) + "\n"


TRACE = "_Z15rs_trace_kernel11rs_bvh_view7rs_geom14rs_trace_batch"
MEGA = "_Z20rs_megakernel_kernel16rs_render_consts14rs_path_tracerjP7rs_vec3P17rs_cuda_mk_counts"
EMPTY = "_ZN3cub17CUB_300001_SM_9006detail11EmptyKernelIvEEvv"
CLEAN = [(TRACE, 118, 736, 736, 0, 0, 0), (MEGA, 146, 3120, 3120, 0, 0, 0),
         (EMPTY, 4, 0, 0, 0, 0, 0)]
BASELINE = """# kernel  regs stack spill target
rs_trace_kernel      118  736  0  regs<=64,spill<=0
rs_megakernel_kernel 146 3120  0  regs<=96
EmptyKernel            4    0  0  -
"""
SOURCE = """#define RS_T_MAX 256 /* threads */
#define RS_M_MAX (RS_T_MAX)
__global__ void __launch_bounds__(RS_T_MAX, 1)
    rs_trace_kernel(int x) {}
__global__ void __launch_bounds__(RS_M_MAX, 1) rs_megakernel_kernel(int x) {}
"""


def self_test(script, inputs):
    passed, failed = [0], [0]

    def ok(cond, what, detail=""):
        if cond:
            print(f"ok - {what}")
            passed[0] += 1
        else:
            print(f"FAIL - {what}" + (f": {detail}" if detail else ""))
            failed[0] += 1

    # the formula against the worked cases and issue 38's Nsight Compute figures
    ok(occupancy(118, 0, 0, 256) == 0.25, "118 registers, 256 threads: 25%")
    ok(block_for(118, 0, 0, 256) == 256, "118 registers: the API keeps 256 threads")
    ok(occupancy(146, 0, 0, 256) == 0.125, "146 registers, 256 threads: 12.5%")
    ok(block_for(146, 0, 0, 256) == 192 and occupancy(146, 0, 0, 192) == 0.1875,
       "146 registers: the API picks 192 threads, 18.75%")
    ok(occupancy(162, 0, 0, 192) == 0.1875, "162 registers, 192 threads: 18.75%")
    ok(occupancy(64, 0, 0, 256) == 0.5, "64 registers, 256 threads: 50%")
    ok(blocks_per_sm(96, 0, 0, 32) == (20, "registers"),
       "96 registers: 20 warps (per sub-partition), not 21")
    ok(blocks_per_sm(128, 33856, 1, 256) == (2, "registers") and
       blocks_per_sm(32, 33856, 1, 256)[0] == 6, "33856 B shared: 6 blocks of 34944 B")
    ok(blocks_per_sm(16, 0, 0, 1024) == (2, "warps") and occupancy(16, 0, 0, 64) == 1.0,
       "few registers: the warp and block slots bind")
    ok(occupancy(255, 0, 0, 256) == 0.125 and blocks_per_sm(255, 0, 0, 512)[0] == 0,
       "255 registers: one block of 256, none of 512")
    ok(piece_size(65536, 32768) == 32768 and piece_size(1 << 20, 32768) == 262144 and
       piece_size(1000, 32768) == 1000, "rs_gpu_piece_size's cases")
    ok(c_value("(1u << 20)", {}) == 1 << 20 and c_value("(A * 2)", {"A": "3u"}) == 6 and
       c_value("sizeof(x)", {}) is None, "C constants")
    ok(short_name("void cub::CUB_300001_SM_900::detail::EmptyKernel<void>()", EMPTY) ==
       "EmptyKernel" and short_name(TRACE, TRACE) == "rs_trace_kernel",
       "kernel names without scope, templates and parameters")

    tmp = tempfile.mkdtemp(prefix="cuda-occupancy.")
    try:
        os.makedirs(os.path.join(tmp, "gpu"))
        with open(os.path.join(tmp, "gpu", "k.cu"), "w") as f:
            f.write(SOURCE)
        ok(launch_bounds(tmp) == {"rs_trace_kernel": (256, 1), "rs_megakernel_kernel": (256, 1)},
           "__launch_bounds__ read through #defines", str(launch_bounds(tmp)))

        def case(name, log_kernels, baseline, want_rc, want_lines=(), unwanted=()):
            d = os.path.join(tmp, name)
            os.makedirs(d)
            obj = os.path.join(d, "k.cu.o")
            open(obj, "w").close()
            with open(obj + ".ptxas.txt", "w") as f:
                f.write(fixture_log(log_kernels) if isinstance(log_kernels, list) else log_kernels)
            base = os.path.join(d, "occupancy.txt")
            with open(base, "w") as f:
                f.write(baseline)
            r = subprocess.run([sys.executable, script, "--baseline", base, "--source-dir", tmp,
                                obj, os.path.join(d, "fallback.c.o")],
                               capture_output=True, text=True, check=False)
            out = r.stdout + r.stderr
            lines = out.splitlines()
            good = r.returncode == want_rc and all(w in lines for w in want_lines) and \
                not any(u in out for u in unwanted)
            ok(good, f"{name}: exit {want_rc}" + (f", '{want_lines[0]}'" if want_lines else ""),
               f"exit {r.returncode}, output:\n{out}")

        case("clean", CLEAN, BASELINE, 0,
             ["cuda-occupancy: 3 kernels against clean/occupancy.txt: ok",
              "  rs_trace_kernel: regs<=64 missed (118), spill<=0 met"], ["FAIL"])
        case("registers", [(TRACE, 130, 736, 736, 0, 0, 0)] + CLEAN[1:], BASELINE, 1,
             ["FAIL rs_trace_kernel: 130 registers > 118 recorded"])
        case("stack_spill", CLEAN[:1] + [(MEGA, 146, 3200, 3200, 16, 24, 0), CLEAN[2]], BASELINE,
             1, ["FAIL rs_megakernel_kernel: 3200 B stack > 3120 recorded, 40 B spills > 0 "
                 "recorded"])
        case("new_kernel", CLEAN + [("_Z8rs_k_newv", 40, 0, 0, 0, 0, 0)], BASELINE, 1,
             ["FAIL rs_k_new: in the build but not in new_kernel/occupancy.txt (record it: 40 "
              "registers, 0 B stack, 0 B spills; --write-baseline)"])
        case("gone", CLEAN[:2], BASELINE, 1,
             ["FAIL EmptyKernel: recorded in gone/occupancy.txt but not in the build"])
        case("enforced", CLEAN, BASELINE.replace("regs<=96", "regs<=96 enforced"), 1,
             ["FAIL rs_megakernel_kernel: enforced target regs<=96 missed (146)"])
        case("better", [(TRACE, 100, 736, 736, 0, 0, 0)] + CLEAN[1:], BASELINE, 0,
             ["note: rs_trace_kernel: 100 registers < 118 recorded: better; record it "
              "(--write-baseline)"], ["FAIL"])
        case("other_arch", fixture_log(CLEAN).replace("'sm_90'", "'sm_80'"), BASELINE, 77)
        case("bad_line", CLEAN, BASELINE + "rs_x 12 abc 0\n", 1, unwanted=["Traceback"])

        # the build's own logs against a baseline one register below each kernel: every kernel
        # must fail, one line each
        logs = [p for p in inputs if os.path.exists(p + ".ptxas.txt") or p.endswith(".ptxas.txt")]
        if logs:
            real, _ = load_kernels(logs)
            real = [k for k in real if k.arch == ARCH]
            base = os.path.join(tmp, "planted.txt")
            with open(base, "w") as f:
                f.write("".join(f"{k.name} {k.regs - 1} {k.stack} {k.spill}\n" for k in real))
            r = subprocess.run([sys.executable, script, "--baseline", base, "--source-dir",
                                os.path.dirname(os.path.dirname(os.path.abspath(script)))] + logs,
                               capture_output=True, text=True, check=False)
            nfail = sum(1 for line in r.stdout.splitlines() if re.match(
                r"FAIL \S+: \d+ registers > \d+ recorded$", line))
            ok(r.returncode == 1 and nfail == len(real) > 0,
               f"the build's {len(real)} kernels against a baseline one register lower: "
               f"{len(real)} failures", f"exit {r.returncode}, output:\n{r.stdout}{r.stderr}")
    finally:
        shutil.rmtree(tmp)
    print(f"{passed[0]} passed, {failed[0]} failed")
    return 1 if failed[0] else 0


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    root = os.path.dirname(here)
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("inputs", nargs="*", help="rs_gpu objects (OBJ.ptxas.txt beside) or ptxas logs")
    p.add_argument("--baseline", default=os.path.join(root, "gpu", "occupancy.txt"))
    p.add_argument("--source-dir", default=root, help="the checkout (gpu/, scheduler/)")
    p.add_argument("--write-baseline", action="store_true",
                   help="record the measured numbers (keeps targets and the header)")
    p.add_argument("--self-test", action="store_true",
                   help="check the formula and the check on planted fixtures (and, given the "
                        "build's objects, a baseline planted one register low)")
    args = p.parse_args()
    if args.self_test:
        return self_test(os.path.abspath(__file__), args.inputs)
    if not args.inputs:
        p.error("no objects or logs given")
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
