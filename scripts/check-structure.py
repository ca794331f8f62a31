#!/usr/bin/env python3
"""scripts/check-structure.py — the code's shape as issue 41 set it (docs/architecture.md):

  1. calls between .c files run one way: no circle of calls (file A calls a function that file B
     defines, and B, through any chain, calls back into A), but for the documented pair
     accel/bvh.c <-> accel/bvh_grid.c;
  2. no function in app/, scheduler/ or scenes/ is over 80 lines (from its signature to its
     closing brace);
  3. only core/hd.h names the CUDA compiler's macros (__CUDACC__, __CUDA_ARCH__): everything else
     asks core/hd.h (RS_CUDA_SOURCE, RS_DEVICE_PASS, RS_ATOMIC_ADD_*).

    python3 scripts/check-structure.py [SOURCE_ROOT]   check the tree (default: this checkout)
    python3 scripts/check-structure.py --self-test     check the checker on planted faults

A problem prints one line naming the files (and function) and the script exits 1; a clean tree
prints one summary line and exits 0.  Run by CTest as structure_check and structure_self_test.
The call graph is read from the text (a function defined at the start of a line, not static; a
call: its name followed by '('), which is what the house style writes; comments are skipped. """
import os
import re
import sys
import tempfile

FOLDERS = ["core", "streams", "accel", "scenes", "shading", "scheduler", "cpu", "gpu", "app"]
SHORT_FOLDERS = ["app", "scheduler", "scenes"]
MAX_LINES = 80
ALLOWED_CIRCLES = [{"accel/bvh.c", "accel/bvh_grid.c"}]
CUDA_HOME = "core/hd.h"

DEF_RE = re.compile(r"^(?!static\b)[A-Za-z_][\w \*]*?\b(rs_\w+)\s*\([^;{]*\)\s*\{", re.M)
CALL_RE = re.compile(r"\b(rs_\w+)\s*\(")


def strip_comments(text):
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def sources(root, exts):
    for d in FOLDERS:
        top = os.path.join(root, d)
        if not os.path.isdir(top):
            continue
        for name in sorted(os.listdir(top)):
            if name.endswith(exts):
                yield d + "/" + name


def circles(root):
    files = [f for f in sources(root, (".c", ".cpp", ".cu")) if not f.endswith("_none.c")]
    text = {}
    defs = {}
    for f in files:
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            text[f] = strip_comments(fh.read())
        for m in DEF_RE.finditer(text[f]):
            defs.setdefault(m.group(1), set()).add(f)
    edges = {f: set() for f in files}
    for f in files:
        for name in set(CALL_RE.findall(text[f])):
            edges[f] |= {g for g in defs.get(name, ()) if g != f}
    # Tarjan's strongly connected components, iteratively
    index, low, on, stack, comps, counter = {}, {}, set(), [], [], [0]
    for start in files:
        if start in index:
            continue
        work = [(start, iter(sorted(edges[start])))]
        index[start] = low[start] = counter[0]
        counter[0] += 1
        stack.append(start)
        on.add(start)
        while work:
            v, it = work[-1]
            w = next(it, None)
            if w is not None:
                if w not in index:
                    index[w] = low[w] = counter[0]
                    counter[0] += 1
                    stack.append(w)
                    on.add(w)
                    work.append((w, iter(sorted(edges[w]))))
                elif w in on:
                    low[v] = min(low[v], index[w])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[v])
            if low[v] == index[v]:
                comp = set()
                while True:
                    w = stack.pop()
                    on.discard(w)
                    comp.add(w)
                    if w == v:
                        break
                if len(comp) > 1:
                    comps.append(comp)
    problems = []
    for comp in comps:
        if comp in ALLOWED_CIRCLES:
            continue
        arrows = []
        for a in sorted(comp):
            for b in sorted(edges[a] & comp):
                called = sorted(n for n in set(CALL_RE.findall(text[a])) if b in defs.get(n, ()))
                arrows.append("%s -> %s (%s)" % (a, b, ", ".join(called[:3])))
        problems.append("a circle of calls among %s: %s" % (", ".join(sorted(comp)),
                                                          "; ".join(arrows)))
    return problems, len(files)


def long_functions(root):
    problems, n = [], 0
    for f in sources(root, (".c", ".cpp", ".cu")):
        if f.split("/")[0] not in SHORT_FOLDERS:
            continue
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            lines = fh.read().split("\n")
        i = 0
        while i < len(lines):
            if lines[i].startswith("{") and i > 0:
                j = i - 1  # back to the signature's first line
                while j > 0 and lines[j - 1].strip() and not lines[j - 1].startswith(
                        ("}", "/*", " *", "#")) and not lines[j - 1].rstrip().endswith(";"):
                    j -= 1
                k = i
                while k < len(lines) and not lines[k].startswith("}"):
                    k += 1
                n += 1
                if k - j + 1 > MAX_LINES:
                    m = re.search(r"(\w+)\s*\(", " ".join(lines[j:i]))
                    problems.append("%s:%d: %s is %d lines (at most %d in %s)" % (
                        f, j + 1, m.group(1) if m else "a function", k - j + 1, MAX_LINES,
                        ", ".join(s + "/" for s in SHORT_FOLDERS)))
                i = k
            i += 1
    return problems, n


def cuda_macros(root):
    problems = []
    for f in sources(root, (".c", ".h", ".cpp")):
        if f == CUDA_HOME:
            continue
        with open(os.path.join(root, f), encoding="utf-8", errors="replace") as fh:
            for no, line in enumerate(fh, 1):
                if "__CUDA" in line:
                    problems.append("%s:%d: names the CUDA compiler's macros (only %s may: use "
                                    "RS_CUDA_SOURCE, RS_DEVICE_PASS)" % (f, no, CUDA_HOME))
    return problems


def check(root):
    if not any(os.path.isdir(os.path.join(root, d)) for d in FOLDERS):
        print("check-structure: %s: none of %s is there" % (root, " ".join(FOLDERS)),
              file=sys.stderr)
        return 2
    circ, n_files = circles(root)
    longf, n_funcs = long_functions(root)
    cuda = cuda_macros(root)
    for p in circ + longf + cuda:
        print("check-structure: " + p)
    if circ or longf or cuda:
        return 1
    print("check-structure: %d source files, calls one way (but %s); %d functions in %s all at "
          "most %d lines; __CUDA only in %s" % (
              n_files, " <-> ".join(sorted(ALLOWED_CIRCLES[0])), n_funcs,
              ", ".join(s + "/" for s in SHORT_FOLDERS), MAX_LINES, CUDA_HOME))
    return 0


def self_test():
    """A clean fixture passes; each planted fault is caught, by its own rule."""
    clean = {
        "core/hd.h": "#if defined(__CUDACC__)\n#endif\n",
        "app/a.c": "int rs_a(void)\n{\n    return rs_b();\n}\n",
        "scenes/b.c": "int rs_b(void)\n{\n    return 1;\n}\n",
    }
    faults = {
        "circle": {"scenes/b.c": "int rs_b(void)\n{\n    return rs_a();\n}\n"},
        "long": {"scenes/b.c": "int rs_b(void)\n{\n" + "    ;\n" * 80 + "    return 1;\n}\n"},
        "cuda": {"shading/c.h": "#ifdef __CUDA_ARCH__\n#endif\n"},
    }
    failures = 0
    for name, planted in [("clean", {})] + list(faults.items()):
        with tempfile.TemporaryDirectory(prefix="check-structure.") as tmp:
            for path, body in dict(clean, **planted).items():
                os.makedirs(os.path.join(tmp, os.path.dirname(path)), exist_ok=True)
                with open(os.path.join(tmp, path), "w", encoding="utf-8") as fh:
                    fh.write(body)
            circ, _ = circles(tmp)
            longf, _ = long_functions(tmp)
            cuda = cuda_macros(tmp)
            got = {"circle": bool(circ), "long": bool(longf), "cuda": bool(cuda)}
            want = {k: k == name for k in got}
            if got != want:
                print("check-structure self-test: %s fixture: found %s, expected %s" % (
                    name, got, want))
                failures += 1
    print("check-structure self-test: %s" % ("failed" if failures else
                                               "a clean tree passes, each planted fault is caught"))
    return 1 if failures else 0


def main(argv):
    if len(argv) > 1 and argv[1] == "--self-test":
        return self_test()
    root = argv[1] if len(argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(
        __file__)))
    return check(root)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
