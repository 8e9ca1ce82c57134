#!/usr/bin/env python3
"""size.py - flash and RAM of libcdsp's paths on a Cortex-M target, from the
linker map files of the size probes (tests/mcu/probe.c around example.c).

  size.py --target T [--stack STACK.txt] [--budget NAME=BYTES]... [--enforce]
          points.map frame.map both.map [all.map]

Every byte the linker placed is attributed by its input file: libcdsp.a,
libm, libgcc (soft-float and 64-bit helpers), libc (memcpy, memset) or the
application (example.c, probe.c: the firmware's own code and its static
buffers). flash = text + rodata + the initial values of .data; RAM = .data +
.bss. The application's static buffers are split into the library's
workspace (cdsp_points_ws, cdsp_frame_ws), the edge-point input buffer and
the rest of the caller's state (params, results, rng, camera).

With --stack (stack.py's table) the worst-case stack of the entry point is
added to RAM. --budget evaluates the points path (cdsp_points_solve, the
probe's default capacities) against a limit: flash (the library path),
ram (data + bss + workspace + point buffer + static worst-case stack) or
stack (static worst case); the limits are given by tests/mcu/mcu.mk
(MCU_BUDGET_*, issue 6's, docs/mcu.md), not kept here. ram and stack need
--stack.

Exit status 0 (printed: a report, budgets met or not), 1 with --enforce when
a budget is exceeded (a FAIL line names the budget, its limit and the
measured figure), 2 when a map file is missing or not a GNU ld map, or an
argument is malformed (named in the message).
"""
import argparse
import re
import sys

TARGET_NAMES = {"m4f": "Cortex-M4F, float, -mfpu=fpv4-sp-d16",
                "m7": "Cortex-M7, double, -mfpu=fpv5-d16",
                "m3": "Cortex-M3, float, soft float"}
CATS = ("libcdsp", "libm", "libgcc", "libc", "app")
FLASH_OUT = (".text", ".preinit_array", ".init_array", ".fini_array", ".ARM.extab",
             ".ARM.exidx")
ENTRY = {"points": "cdsp_points_solve", "frame": "cdsp_frame_solve",
         "both": "cdsp_frame_solve"}
BUDGETS = {"flash": "library path",
           "ram": "data + bss + workspace + point buffer + stack",
           "stack": "cdsp_points_solve, static worst case"}


def die(msg):
    print(f"size.py: {msg}", file=sys.stderr)
    sys.exit(2)


def category(path):
    if "libcdsp.a(" in path:
        return "libcdsp"
    if "/libm.a(" in path:
        return "libm"
    if "libgcc.a(" in path:
        return "libgcc"
    if re.search(r"/lib(c|c_nano|g|g_nano|nosys|rdimon)\.a\(", path):
        return "libc"
    return "app"


OUT_RE = re.compile(r"^(\.\S+)(?:\s+0x[0-9a-f]+\s+0x[0-9a-f]+.*)?$")
IN_ONE_RE = re.compile(r"^ (\.\S+|COMMON)\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
IN_NAME_RE = re.compile(r"^ (\.\S+|COMMON)\s*$")
IN_REST_RE = re.compile(r"^\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)\s+(\S.*)$")
FILL_RE = re.compile(r"^ \*fill\*\s+0x([0-9a-f]+)\s+0x([0-9a-f]+)")


def parse_map(path):
    """Input sections: list of (output section, input section, size, file)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except OSError as e:
        die(f"{path}: cannot read: {e.strerror}")
    try:
        start = lines.index("Linker script and memory map")
    except ValueError:
        die(f"{path}: not a GNU ld map file (no 'Linker script and memory map')")
    out, pending, secs = None, None, []
    for line in lines[start + 1:]:
        if line.startswith("."):
            m = OUT_RE.match(line)
            out = m.group(1) if m else None
            pending = None
            continue
        if out is None or out.startswith((".debug", ".comment", ".ARM.attributes")):
            continue
        m = IN_ONE_RE.match(line)
        if m:
            secs.append((out, m.group(1), int(m.group(3), 16), m.group(4)))
            pending = None
            continue
        m = IN_NAME_RE.match(line)
        if m:
            pending = m.group(1)
            continue
        m = IN_REST_RE.match(line)
        if m and pending:
            secs.append((out, pending, int(m.group(2), 16), m.group(3)))
            pending = None
            continue
        m = FILL_RE.match(line)
        if m:
            secs.append((out, "*fill*", int(m.group(2), 16), "(alignment)"))
    if not secs:
        die(f"{path}: no input sections found")
    return secs


def summarize(secs):
    s = {c: {"flash": 0, "ram": 0} for c in CATS}
    s["app"].update({"ws": 0, "edges": 0, "state": 0})
    funcs = {}
    for out, name, size, path in secs:
        cat = "app" if path == "(alignment)" else category(path)
        if out in FLASH_OUT or out == ".data":
            s[cat]["flash"] += size
        if out in (".data", ".bss"):
            s[cat]["ram"] += size
            if cat == "app":
                key = "ws" if name.endswith("_ws") else "edges" if name.endswith(".edges") \
                    else "state"
                s["app"][key] += size
        if out == ".text" and cat in ("libcdsp", "libm", "libgcc", "libc") and size:
            member = re.search(r"\((?:lib_a-)?([^()]*?)(?:\.o)?\)$", path)
            member = member.group(1) if member else path
            if cat == "libcdsp" and re.match(r"^\.text\.", name):
                fn = name[len(".text."):]          # one function per section
            elif cat == "libcdsp":
                fn = member + " constants"         # .rodata: tables, strings
            else:
                fn = member                        # libm etc.: one object per function
            key = (cat, fn)
            funcs[key] = funcs.get(key, 0) + size
    return s, funcs


def read_stack(path):
    out = {}
    if not path:
        return out
    try:
        with open(path, encoding="utf-8") as f:
            for line in f:
                m = re.match(r"^  (cdsp_\w+)\s+(\d+)\s", line)
                if m:
                    out[m.group(1)] = int(m.group(2))
    except OSError as e:
        die(f"{path}: cannot read: {e.strerror}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--target", required=True)
    ap.add_argument("--stack")
    ap.add_argument("--budget", action="append", default=[], metavar="NAME=BYTES")
    ap.add_argument("--enforce", action="store_true")
    ap.add_argument("maps", nargs="+")
    args = ap.parse_args()
    budget = {}
    for b in args.budget:
        m = re.match(r"^(\w+)=(\d+)$", b)
        if not m or m.group(1) not in BUDGETS:
            die(f"--budget {b}: expected NAME=BYTES, NAME one of {', '.join(BUDGETS)}")
        budget[m.group(1)] = int(m.group(2))
    if not args.stack and ("ram" in budget or "stack" in budget):
        die("--budget ram/stack needs --stack (the worst-case stack is part of them)")
    kinds = {}
    for m in args.maps:
        k = re.search(r"probe-(points|frame|both|all)\.elf\.map$", m)
        if not k:
            die(f"{m}: expected a probe-<points|frame|both|all>.elf.map file")
        kinds[k.group(1)] = summarize(parse_map(m))
    for need in ("points", "frame", "both"):
        if need not in kinds:
            die(f"no probe-{need}.elf.map given")
    stack = read_stack(args.stack)

    print(f"Size, {args.target} ({TARGET_NAMES.get(args.target, args.target)}), bytes; "
          "-Os, --gc-sections, newlib-nano; default capacities")
    print(f"  {'':<34}{'points path':>16}{'frame path':>16}{'points + frame':>18}")
    print(f"  {'':<34}{'flash':>8}{'RAM':>8}{'flash':>8}{'RAM':>8}{'flash':>9}{'RAM':>9}")

    def row(label, get):
        vals = [get(kinds[k][0]) for k in ("points", "frame", "both")]
        print(f"  {label:<34}{vals[0][0]:>8}{vals[0][1]:>8}{vals[1][0]:>8}{vals[1][1]:>8}"
              f"{vals[2][0]:>9}{vals[2][1]:>9}")
        return vals

    for c, label in (("libcdsp", "libcdsp.a"), ("libm", "libm"),
                     ("libgcc", "libgcc (soft-float, 64-bit)"), ("libc", "libc (memcpy, memset)")):
        row(label, lambda s, c=c: (s[c]["flash"], s[c]["ram"]))
    lib = row("= library path", lambda s: (sum(s[c]["flash"] for c in CATS[:4]),
                                           sum(s[c]["ram"] for c in CATS[:4])))
    row("workspace (cdsp_*_ws, static)", lambda s: (0, s["app"]["ws"]))
    row("edge-point buffer (2048 points)", lambda s: (0, s["app"]["edges"]))
    row("caller state (params, results..)", lambda s: (0, s["app"]["state"]))
    row("application code (example.c)", lambda s: (s["app"]["flash"], 0))
    tot = row("= firmware (probe) total", lambda s: (sum(s[c]["flash"] for c in CATS),
                                                     sum(s[c]["ram"] for c in CATS)))
    if stack:
        st = [stack.get(ENTRY[k], 0) for k in ("points", "frame", "both")]
        print(f"  {'worst-case stack (make stack)':<34}{'':>8}{st[0]:>8}{'':>8}{st[1]:>8}"
              f"{'':>9}{st[2]:>9}")
        print(f"  {'= RAM with stack':<34}{'':>8}{tot[0][1] + st[0]:>8}{'':>8}"
              f"{tot[1][1] + st[1]:>8}{'':>9}{tot[2][1] + st[2]:>9}")
    print(f"  frame path adds to the points path: flash {lib[2][0] - lib[0][0]:+d} B (library), "
          f"RAM {tot[2][1] - tot[0][1]:+d} B (its workspace)")
    funcs = kinds["points"][1]
    top = sorted(funcs.items(), key=lambda kv: -kv[1])[:10]
    print("  largest pieces of the points path: " +
          ", ".join(f"{fn} {n}" + ("" if cat == "libcdsp" else f" [{cat}]")
                    for (cat, fn), n in top))
    rc = 0
    if budget:
        if args.stack and "cdsp_points_solve" not in stack:
            die(f"{args.stack}: no cdsp_points_solve row (or no bound for it)")
        measured = {"flash": lib[0][0],
                    "ram": tot[0][1] + stack.get("cdsp_points_solve", 0),
                    "stack": stack.get("cdsp_points_solve", 0)}
        print("  budget, points path at 2048 points (issue 6; tests/mcu/mcu.mk MCU_BUDGET_*):")
        for what in BUDGETS:
            if what not in budget:
                continue
            val, lim = measured[what], budget[what]
            print(f"    {what:<6} {val:>6} B of {lim:>6} B: "
                  f"{'met' if val <= lim else 'NOT MET'} ({BUDGETS[what]})")
        for what in BUDGETS:
            if args.enforce and what in budget and measured[what] > budget[what]:
                rc = 1
                print(f"FAIL budget {what} ({args.target}, points path, {BUDGETS[what]}): "
                      f"measured {measured[what]} B > limit {budget[what]} B")
    return rc


if __name__ == "__main__":
    sys.exit(main())
