#!/usr/bin/env python3
"""compare.py HOST.out MCU.out: does the firmware test's output on a
Cortex-M target (fw.c under QEMU) agree with the same program on the host,
and does each result match its ground truth?

Exit status: 0 all agree, 1 a disagreement (each one printed with the
numbers), 2 an input file is missing or malformed (named, with the line).

Tolerances, MCU versus host (same precision: M4F and M3 against the host
float build, M7 against the host double build). u is the unit roundoff,
2^-24 (float) or 2^-53 (double).

Both sides compute in IEEE-754 binary32/binary64 with round-to-nearest:
x86-64 SSE and the Cortex-M FPUs evaluate in the type itself
(FLT_EVAL_METHOD 0), libgcc's soft float (M3) rounds correctly, and
-std=c99 turns floating-point contraction off (no FMA on either side), so
+ - * / and sqrt give the same bits from the same operands. The inputs are
the same bits (gen.c writes float-exact literals). The one source of
difference is libm: newlib's and glibc's atan2, sin, cos, log, exp may
differ by up to E = 4 ulps (each is within 1-2 ulps of the true value).

Where libm enters (lib/, points and frame paths alike):
  - thresholds cos(normal_tol), cos(max_contour_angle) and RANSAC's
    iteration count log(1-conf)/log(1-w^2): discrete decisions, identical
    unless a value sits within a few ulps of the threshold. So statuses,
    flags, n_edges and inlier counts must be EQUAL; a flip is a finding.
  - the closed form: alpha = atan2(.) differs by <= E ulps (<= 2E u
    relative); d = r / sin(alpha/2): sin's own 2E u, alpha's carried with
    factor (alpha/2) cot(alpha/2) <= 1, the division 2u: <= (4E + 2) u;
    P_C = d * unit vector (identical bits): + 2u. So the pose moves by at
    most 20 u relative; the direction (cross product of identical normals,
    no libm) not at all. The visible segment is P_C + s v with s from
    dot products of P_C: the same 20 u of the larger of |P_C|, |segment|.
  - the uncertainty: sigma_x^2 = sum_k F_xk^2 over 4 line parameters, F
    in closed form from the normals (identical bits), P_C and d (lib/pair.c,
    axis_change: no libm but sqrt); F is linear in P_C and d to first
    order, so it carries their 20 u relative: |d sigma_x| <= 20 u sigma_x
    plus the few u of its own rounding, far under 40 u |x|.
Tolerance used: K u times the scale, K = 32 (the 20 u bound to the next
power of two) for the pose, 2 K for the sigmas; the scale is |P_C| for
point and sigma_point, max(|P_C|, |endpoint|) for the segment, d for
distance and sigma_distance, alpha for alpha, 1 for the direction and its
sigma, the value itself for rms.

Ground truth (each side, results with status ok): the generator's exact
pose. Point sets: every component of P_C and of the direction (sign-free)
within 6 sigma of the library's own first-order uncertainty plus the K u
rounding floor. Frames: distance of P_C and angle of the direction within
the bound gen.c derived (pose change when a contour moves by 0.5 px).
"""
import math
import sys

K_POSE = 32.0
K_SIGMA = 64.0
N_SIGMA = 6.0
U = {"float": 2.0 ** -24, "double": 2.0 ** -53}
INT_FIELDS = ("status", "expect", "flags", "n_edges", "inliers", "entry")


class Malformed(Exception):
    pass


def parse(path):
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().splitlines()
    except OSError as e:
        raise Malformed(f"{path}: cannot read: {e.strerror}")
    head, results, end, goldens = None, [], None, []
    for no, line in enumerate(lines, 1):
        words = line.split()
        if not words or words[0] not in ("fw", "result", "end", "golden"):
            continue  # other output (QEMU, semihosting) is not ours
        rec = {}
        for w in words[1:]:
            if "=" not in w:
                raise Malformed(f"{path}:{no}: '{w}' is not key=value")
            k, v = w.split("=", 1)
            rec[k] = v
        if words[0] == "fw":
            head = rec
        elif words[0] == "golden":
            try:
                goldens.append((int(rec["n"]), int(rec["start"]), no))
            except (KeyError, ValueError):
                raise Malformed(f"{path}:{no}: golden record without integer n= and start=")
        elif words[0] == "end":
            end = rec
        else:
            if "name" not in rec:
                raise Malformed(f"{path}:{no}: result without a name")
            rec["_line"] = no
            results.append(rec)
    if head is None or head.get("real") not in U:
        raise Malformed(f"{path}: no 'fw ... real=float|double' header (did the program start?)")
    if end is None:
        raise Malformed(f"{path}: no 'end' line: output truncated (crash, fault or timeout?)")
    if str(len(results)) != end.get("results"):
        raise Malformed(f"{path}: {len(results)} result lines, 'end' says {end.get('results')}")
    if str(len(goldens)) != end.get("goldens"):
        raise Malformed(f"{path}: {len(goldens)} golden lines, 'end' says {end.get('goldens')}")
    head["_goldens"] = goldens
    return head, results


def golden_problems(path, goldens):
    """lines.c's stride start must be floor(618034 n / 10^6) exactly, for every
    size printed (on a 32-bit target a naive n * 618034 wraps past 6949)."""
    out = []
    for n, start, no in goldens:
        want = n * 618034 // 1000000
        if start != want:
            out.append(f"{path}:{no}: golden start for n={n} is {start}, exact value {want}")
    return out


def reals(path, rec, key, n):
    try:
        v = [float(x) for x in rec[key].split(",")]
    except (KeyError, ValueError):
        raise Malformed(f"{path}:{rec['_line']}: field {key} missing or not numbers")
    if len(v) != n:
        raise Malformed(f"{path}:{rec['_line']}: field {key} has {len(v)} values, expected {n}")
    return v


def norm(v):
    return math.sqrt(sum(x * x for x in v))


def fields(path, rec):
    f = {k: reals(path, rec, k, n) for k, n in (
        ("point", 3), ("direction", 3), ("distance", 1), ("alpha", 1), ("segment", 6),
        ("sigma_point", 3), ("sigma_direction", 3), ("sigma_distance", 1), ("rms", 2),
        ("truth_point", 3), ("truth_direction", 3), ("truth_tol", 2))}
    return f


def tolerances(f, u):
    """Per-component tolerance of every compared field (see the docstring)."""
    p = norm(f["point"])
    seg = max(p, norm(f["segment"][:3]), norm(f["segment"][3:]))
    d = f["distance"][0]
    return {
        "point": [K_POSE * u * p] * 3,
        "direction": [K_POSE * u] * 3,
        "distance": [K_POSE * u * d],
        "alpha": [K_POSE * u * f["alpha"][0]],
        "segment": [K_POSE * u * seg] * 6,
        "sigma_point": [K_SIGMA * u * p] * 3,
        "sigma_direction": [K_SIGMA * u] * 3,
        "sigma_distance": [K_SIGMA * u * d],
        "rms": [K_POSE * u * abs(x) for x in f["rms"]],
    }


def truth_problems(f, u):
    """Ground-truth check of one ok result; returns (messages, the worst
    error / bound of its components)."""
    out = []
    worst = 0.0
    tp, tv, tol = f["truth_point"], f["truth_direction"], f["truth_tol"]
    p, v = f["point"], f["direction"]
    sgn = 1.0 if sum(a * b for a, b in zip(v, tv)) >= 0 else -1.0
    vv = [sgn * x for x in v]
    if tol[0] > 0:  # frame: geometric bound from gen.c
        dp = norm([a - b for a, b in zip(p, tp)])
        c = min(1.0, abs(sum(a * b for a, b in zip(v, tv))) / (norm(v) * norm(tv)))
        ang = math.acos(c)
        worst = max(dp / tol[0], ang / tol[1])
        if not dp <= tol[0]:
            out.append(f"P_C is {dp:.4g} from the truth, bound {tol[0]:.4g}")
        if not ang <= tol[1]:
            out.append(f"direction is {ang:.4g} rad from the truth, bound {tol[1]:.4g}")
        return out, worst
    floor = K_POSE * u * norm(tp)
    for i in range(3):
        lim = N_SIGMA * f["sigma_point"][i] + floor
        worst = max(worst, abs(p[i] - tp[i]) / lim)
        if not abs(p[i] - tp[i]) <= lim:
            out.append(f"point[{i}] {p[i]:.9g} vs truth {tp[i]:.9g}: off by "
                       f"{abs(p[i] - tp[i]):.3g} > {N_SIGMA:g} sigma + floor = {lim:.3g}")
        lim = N_SIGMA * f["sigma_direction"][i] + K_POSE * u
        worst = max(worst, abs(vv[i] - tv[i]) / lim)
        if not abs(vv[i] - tv[i]) <= lim:
            out.append(f"direction[{i}] {vv[i]:.9g} vs truth {tv[i]:.9g}: off by "
                       f"{abs(vv[i] - tv[i]):.3g} > {N_SIGMA:g} sigma + floor = {lim:.3g}")
    return out, worst


def main(argv):
    if len(argv) != 3:
        print("usage: compare.py HOST.out MCU.out", file=sys.stderr)
        return 2
    hpath, mpath = argv[1], argv[2]
    try:
        hhead, hres = parse(hpath)
        mhead, mres = parse(mpath)
        if hhead["real"] != mhead["real"]:
            raise Malformed(f"{mpath}: real={mhead['real']} but {hpath} has real={hhead['real']}")
        hnames = [r["name"] for r in hres]
        mnames = [r["name"] for r in mres]
        if hnames != mnames:
            raise Malformed(f"{mpath}: cases {mnames} differ from {hpath}'s {hnames}")
        hf = [fields(hpath, r) for r in hres]
        mf = [fields(mpath, r) for r in mres]
    except Malformed as e:
        print(f"compare.py: {e}", file=sys.stderr)
        return 2

    gold = golden_problems(hpath, hhead["_goldens"]) + golden_problems(mpath, mhead["_goldens"])
    if [g[:2] for g in hhead["_goldens"]] != [g[:2] for g in mhead["_goldens"]] and not gold:
        gold.append(f"{mpath}: golden records differ from {hpath}'s")
    for msg in gold:
        print(f"  DISAGREE golden: {msg}")

    real = mhead["real"]
    u = U[real]
    target = mhead.get("target", "?")
    print(f"{target} vs host, {real}: u = {u:.3g}, pose tolerance {K_POSE:g} u x scale, "
          f"sigma {K_SIGMA:g} u x scale")
    print(f"  {'case':<12} {'status':<11} {'inliers':<11} {'max |mcu-host|/tol':>19}  "
          f"{'worst field':<16} {'stack B':>7} {'truth err/tol':>13}")
    bad = 0
    for h, m, a, b in zip(hres, mres, hf, mf):
        name = h["name"]
        problems = []
        for k in INT_FIELDS:
            if h.get(k) != m.get(k):
                problems.append(f"{k}: host {h.get(k)}, mcu {m.get(k)}")
        if m.get("status") != m.get("expect"):
            problems.append(f"status {m.get('status')}, expected {m.get('expect')}")
        worst, wfield, tworst = 0.0, "-", 0.0
        if m.get("status") == "ok" and h.get("status") == "ok":
            tol = tolerances(a, u)
            for k, tl in tol.items():
                for i, t in enumerate(tl):
                    diff = abs(a[k][i] - b[k][i])
                    r = diff / t if t > 0 else (0.0 if diff == 0 else math.inf)
                    if r > worst:
                        worst, wfield = r, f"{k}[{i}]"
                    if not diff <= t:
                        problems.append(f"{k}[{i}]: host {a[k][i]!r}, mcu {b[k][i]!r}, "
                                        f"|diff| {diff:.3g} > tol {t:.3g}")
            for side, res in (("mcu", b), ("host", a)):
                msgs, tw = truth_problems(res, u)
                tworst = max(tworst, tw)
                problems += [f"truth ({side}): {msg}" for msg in msgs]
        print(f"  {name:<12} {m.get('status', '?'):<11} {m.get('inliers', '?'):<11} "
              f"{worst:>19.3g}  {wfield:<16} {m.get('stack', '?'):>7} {tworst:>13.3g}")
        for p in problems:
            print(f"    DISAGREE {name}: {p}")
        bad += len(problems)
    bad += len(gold)
    if bad:
        print(f"compare.py: {bad} disagreement(s) between {hpath} and {mpath}")
        return 1
    print(f"compare.py: {len(mres)} results agree ({mpath} vs {hpath})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
