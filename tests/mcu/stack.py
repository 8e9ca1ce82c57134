#!/usr/bin/env python3
"""stack.py - worst-case stack depth of libcdsp's entry points on a Cortex-M
target, and its check against the depth measured under QEMU.

  stack.py --target T --elf PROBE.elf [--objdump TOOL] FILE.ci...
      Prints the table: for each public function of the library, the
      deepest call path below it and its bytes (the sum of the frames on
      that path, i.e. what the call needs below the caller's stack pointer).
  stack.py --check-measured FW.out STACK.txt
      Fails if a depth measured by the firmware test (stack= fields, the
      painted-stack high-water mark under QEMU) exceeds the static bound of
      its entry point: that would mean the analysis misses a frame.

Frames: the library's from the compiler (-fstack-usage, carried in the
-fcallgraph-info=su .ci files); functions the library calls outside itself
(libm, libgcc's soft-float and 64-bit helpers, libc's memcpy) from the
disassembly of PROBE.elf (push/vpush/stmdb/sub sp/str-with-writeback in the
function, summed: an upper bound). Calls: the .ci edges, plus every bl/b.w
to another function in the disassembly (this adds the libcalls gcc emits
after the call graph is built, e.g. __aeabi_* and memcpy). Calls to
functions that were inlined cost nothing extra (their frames are part of
the caller's); the walk still follows them, which can only overestimate.
Recursion or an indirect call makes a bound unknowable: reported, and the
bound is printed as such.

Exit status: 0, 1 (check failed / no bound), 2 (missing or malformed input,
named in the message).
"""
import argparse
import bisect
import os
import re
import subprocess
import sys

TARGET_NAMES = {"m4f": "Cortex-M4F, float", "m7": "Cortex-M7, double",
                "m3": "Cortex-M3, float (soft)"}
# The rows docs/mcu.md shows first; every other public function follows.
KEY_ENTRIES = ["cdsp_points_solve", "cdsp_frame_solve", "cdsp_axis_solve",
               "cdsp_edges_detect", "cdsp_camera_undistort_edges", "cdsp_line_fit",
               "cdsp_svd3"]


def die(msg):
    print(f"stack.py: {msg}", file=sys.stderr)
    sys.exit(2)


# ---------------------------------------------------------------- .ci files
NODE_RE = re.compile(r'^node: \{ title: "([^"]*)" label: "([^"]*)"')
EDGE_RE = re.compile(r'^edge: \{ sourcename: "([^"]*)" targetname: "([^"]*)"')
BYTES_RE = re.compile(r'\\n(\d+) bytes \(([a-z,]+)\)')


def read_ci(paths):
    nodes = {}   # title -> {name, unit, frame, qual}
    edges = {}   # title -> set(target titles)
    for path in paths:
        try:
            with open(path, encoding="utf-8") as f:
                text = f.read().splitlines()
        except OSError as e:
            die(f"{path}: cannot read: {e.strerror}")
        if not text or not text[0].startswith("graph: { title:"):
            die(f"{path}: not a -fcallgraph-info file (no 'graph: {{ title:' line)")
        unit = path
        for line in text:
            m = NODE_RE.match(line)
            if m:
                title, label = m.groups()
                b = BYTES_RE.search(label)
                if b:  # defined here, with its frame
                    nodes[title] = {"name": label.split("\\n")[0], "unit": unit,
                                    "frame": int(b.group(1)), "qual": b.group(2)}
                continue
            m = EDGE_RE.match(line)
            if m:
                edges.setdefault(m.group(1), set()).add(m.group(2))
    if not nodes:
        die("no function frames in the .ci files (built without -fcallgraph-info=su?)")
    return nodes, edges


# ---------------------------------------------------------- disassembly
FUNC_RE = re.compile(r"^([0-9a-f]+) <([^>]+)>:$")
INSN_RE = re.compile(r"^\s+[0-9a-f]+:\s+(\S+)\s*(.*)$")
TARGET_RE = re.compile(r"^([0-9a-f]+) <")
COND = r"(?:eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?"
BL_RE = re.compile(rf"^bl{COND}(?:\.w)?$")
BLX_RE = re.compile(rf"^blx{COND}$")
B_RE = re.compile(rf"^b{COND}(?:\.w|\.n)?$")


def reglist_bytes(ops):
    m = re.search(r"\{([^}]*)\}", ops)
    if not m:
        return 0
    total = 0
    for tok in m.group(1).split(","):
        tok = tok.strip()
        r = re.match(r"([a-z]+)(\d+)-[a-z]*(\d+)$", tok)
        size = 8 if tok.startswith("d") else 4
        if r:
            total += size * (int(r.group(3)) - int(r.group(2)) + 1)
        elif tok:
            total += size
    return total


def read_disassembly(objdump, elf):
    try:
        out = subprocess.run([objdump, "-d", "--no-show-raw-insn", elf], check=True,
                             capture_output=True, text=True).stdout
    except FileNotFoundError:
        die(f"{objdump}: not found")
    except subprocess.CalledProcessError as e:
        die(f"{elf}: {objdump} failed: {e.stderr.strip()}")
    funcs = {}   # name -> list of {frame, calls, indirect, dynamic}
    starts = []  # (address, record): branch targets are resolved by address,
    raw = []     # since objdump may label an address with any symbol there
    cur = None
    for line in out.splitlines():
        m = FUNC_RE.match(line)
        if m:
            cur = {"name": m.group(2), "frame": 0, "targets": set(), "indirect": False,
                   "dynamic": False}
            funcs.setdefault(cur["name"], []).append(cur)
            starts.append((int(m.group(1), 16), cur))
            continue
        m = INSN_RE.match(line)
        if not m or cur is None:
            continue
        mn, ops = m.group(1), m.group(2).split("@")[0].strip()
        if mn in ("push", "push.w", "vpush") or \
                (mn.startswith(("stmdb", "stmfd", "vstmdb")) and ops.startswith("sp!")):
            cur["frame"] += reglist_bytes(ops)
        elif mn in ("sub", "sub.w", "subw", "subs") and re.match(r"sp, (sp, )?#", ops):
            cur["frame"] += int(re.search(r"#(\d+)", ops).group(1))
        elif mn in ("sub", "sub.w") and re.match(r"sp, (sp, )?r", ops):
            cur["dynamic"] = True
        elif mn.startswith(("str", "vstr")) and re.search(r"\[sp, #-(\d+)\]!", ops):
            cur["frame"] += int(re.search(r"\[sp, #-(\d+)\]!", ops).group(1))
        elif BL_RE.match(mn) or BLX_RE.match(mn) or B_RE.match(mn):
            t = TARGET_RE.match(ops)
            if t:
                cur["targets"].add(int(t.group(1), 16))
            elif BLX_RE.match(mn):
                cur["indirect"] = True
    starts.sort(key=lambda x: x[0])
    addrs = [a for a, _ in starts]
    # Aliases: objdump labels an address with one of its names
    # (__addsf3 for __aeabi_fadd); the symbol table has them all.
    try:
        syms = subprocess.run([objdump, "-t", elf], check=True, capture_output=True,
                              text=True).stdout
    except subprocess.CalledProcessError as e:
        die(f"{elf}: {objdump} -t failed: {e.stderr.strip()}")
    at = {a: rec for a, rec in starts}
    for line in syms.splitlines():
        m = re.match(r"^([0-9a-f]+)\s.*\sF\s+\S+\s+[0-9a-f]+\s+(?:\.hidden\s+)?(\S+)$", line)
        if m:
            rec = at.get(int(m.group(1), 16) & ~1)
            if rec is not None and m.group(2) not in funcs:
                funcs[m.group(2)] = [rec]
    for a, rec in starts:
        rec["calls"] = set()
        for t in rec.pop("targets"):
            i = bisect.bisect_right(addrs, t) - 1
            if i >= 0 and starts[i][1] is not rec:
                rec["calls"].add(starts[i][1]["name"])  # a call or a tail call
    return funcs


# ---------------------------------------------------------- the walk
class Graph:
    def __init__(self, nodes, edges, dis):
        self.nodes, self.edges, self.dis = nodes, edges, dis
        self.memo = {}
        self.problems = []
        self.by_name = {}
        for title, n in nodes.items():
            self.by_name.setdefault(n["name"], []).append(title)
        self.mismatch, self.compared = [], 0
        for title, n in nodes.items():  # sanity of the disassembly estimate
            d = dis.get(n["name"])
            if d and len(d) == 1 and len(self.by_name[n["name"]]) == 1:
                self.compared += 1
                if d[0]["frame"] != n["frame"]:
                    self.mismatch.append((n["name"], n["frame"], d[0]["frame"]))

    def resolve(self, name, unit):
        """Key of a callee: the library node (a static of the same unit, or
        a global), else ('ext', name)."""
        if name in self.nodes:
            return name
        base = name.split(":")[-1]
        for title in self.by_name.get(base, []):
            if self.nodes[title]["unit"] == unit:
                return title
        if base in self.nodes:
            return base
        return ("ext", base)

    def info(self, key):
        """frame, callee keys, label, origin for one function."""
        if isinstance(key, tuple):
            name = key[1]
            d = self.dis.get(name)
            if not d:
                return None, [], name, "?"
            calls = set().union(*(x["calls"] for x in d))
            if any(x["indirect"] for x in d):
                self.problems.append(f"{name}: indirect call (no bound)")
            if any(x["dynamic"] for x in d):
                self.problems.append(f"{name}: variable-size frame (no bound)")
            return max(x["frame"] for x in d), [self.resolve(c, None) for c in sorted(calls)], \
                name, "disasm"
        n = self.nodes[key]
        if n["qual"] != "static":
            self.problems.append(f"{n['name']}: frame is {n['qual']} (-fstack-usage)")
        calls = set(self.edges.get(key, ()))
        for d in self.dis.get(n["name"], []):
            calls |= d["calls"]
        return n["frame"], [self.resolve(c, n["unit"]) for c in sorted(calls)], n["name"], "su"

    def worst(self, key, stack=()):
        """(bytes, path) of the deepest chain from key; bytes None if unknown."""
        if key in self.memo:
            return self.memo[key]
        if key in stack:
            names = [self.info(k)[2] for k in stack[stack.index(key):]] + [self.info(key)[2]]
            self.problems.append("recursion: " + " > ".join(names))
            return None, []
        frame, callees, label, origin = self.info(key)
        if frame is None:
            self.problems.append(f"{label}: called but not in the disassembly (no frame)")
            res = (None, [(label, "?")])
        else:
            best, bpath = 0, []
            unknown = False
            for c in callees:
                b, p = self.worst(c, stack + (key,))
                if b is None:
                    unknown = True
                    bpath = p
                elif b > best and not unknown:
                    best, bpath = b, p
            res = (None if unknown else frame + best, [(label, frame)] + bpath)
        self.memo[key] = res
        return res


def table(args):
    nodes, edges = read_ci(args.ci)
    if not os.path.exists(args.elf):
        die(f"{args.elf}: no such file")
    dis = read_disassembly(args.objdump, args.elf)
    g = Graph(nodes, edges, dis)
    public = sorted(t for t, n in nodes.items() if t == n["name"] and
                    n["name"].startswith("cdsp_") and not n["name"].startswith("cdsp__"))
    order = [e for e in KEY_ENTRIES if e in public] + [e for e in public if e not in KEY_ENTRIES]
    print(f"Worst-case stack, {args.target} ({TARGET_NAMES.get(args.target, args.target)}): "
          "bytes below the caller's stack pointer")
    print(f"  frames: lib/ from -fstack-usage; libm/libgcc/libc from {args.elf}'s disassembly")
    print(f"  {'entry point':<30} {'bytes':>6}  worst path: function(frame bytes)")
    rc = 0
    for e in order:
        b, path = g.worst(e)
        shown = " > ".join(f"{n}({f})" for n, f in path)
        print(f"  {e:<30} {b if b is not None else 'none':>6}  {shown}")
        if b is None:
            rc = 1
    print(f"  self-check: the disassembly estimate equals -fstack-usage for "
          f"{g.compared - len(g.mismatch)} of {g.compared} library functions")
    if g.mismatch:
        print("  note: it differs for: " +
              ", ".join(f"{n} ({s} vs {d})" for n, s, d in g.mismatch))
    for p in sorted(set(g.problems)):
        print(f"  NO BOUND: {p}")
    return rc


def check_measured(fw_out, stack_txt):
    meas = {}
    try:
        with open(fw_out, encoding="utf-8", errors="replace") as f:
            for line in f:
                if line.startswith("result "):
                    kv = dict(w.split("=", 1) for w in line.split()[1:] if "=" in w)
                    if "entry" not in kv or not kv.get("stack", "").isdigit():
                        die(f"{fw_out}: result line without entry= or stack=")
                    e = kv["entry"]
                    meas[e] = max(meas.get(e, 0), int(kv["stack"]))
    except OSError as ex:
        die(f"{fw_out}: cannot read: {ex.strerror}")
    bound = {}
    try:
        with open(stack_txt, encoding="utf-8") as f:
            for line in f:
                m = re.match(r"^  (cdsp_\w+)\s+(\d+|none)\s", line)
                if m:
                    bound[m.group(1)] = None if m.group(2) == "none" else int(m.group(2))
    except OSError as ex:
        die(f"{stack_txt}: cannot read: {ex.strerror}")
    if not meas:
        die(f"{fw_out}: no results with a measured stack")
    rc = 0
    for e, m in sorted(meas.items()):
        b = bound.get(e)
        if b is None:
            print(f"FAIL {e}: measured {m} B, no static bound in {stack_txt}")
            rc = 1
        elif m > b:
            print(f"FAIL {e}: measured {m} B under QEMU > static bound {b} B: "
                  "the analysis misses a frame")
            rc = 1
        else:
            print(f"ok   {e}: measured {m} B <= static bound {b} B ({100 * m // b}% of it)")
    return rc


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--target")
    ap.add_argument("--elf")
    ap.add_argument("--objdump", default="arm-none-eabi-objdump")
    ap.add_argument("--check-measured", nargs=2, metavar=("FW_OUT", "STACK_TXT"))
    ap.add_argument("ci", nargs="*")
    args = ap.parse_args()
    if args.check_measured:
        return check_measured(*args.check_measured)
    if not args.target or not args.elf or not args.ci:
        ap.error("--target, --elf and .ci files are required")
    return table(args)


if __name__ == "__main__":
    sys.exit(main())
