#!/usr/bin/env bash
# tests/summary.sh RESULTS [MAKE_RC [T0 [T1]]]: sum the step results of `make
# check` (tests/run.sh's lines, in the order the steps finished) and print
# the closing line. A step that never recorded a result (build failure) is
# caught by the caller's exit status: make -k returns non-zero, and so do we.
# T0 (date +%s when make check began): the wall clock is printed beside the
# steps' own seconds; with steps running side by side (the Makefile's
# check-run) the wall clock is the smaller. T1: when the builds (the
# Makefile's first make) ended and the steps began.
set -u
results=$1
make_rc=${2:-0}
t0=${3:-}
t1=${4:-}
p=0 f=0 s=0
if [ -f "$results" ]; then
    echo
    echo "== make check =="
    # The seconds show where make check's time goes (wall clock: an upper
    # bound on a shared machine, for planning, never asserted).
    while read -r name np nf secs; do
        printf '  %-40s %4d passed %4d failed %6ss\n' "$name" "$np" "$nf" "${secs:-?}"
        p=$((p + np)); f=$((f + nf)); s=$((s + ${secs:-0}))
    done <"$results"
fi
if [ "$make_rc" -ne 0 ]; then
    echo "  (a build or check step failed before recording a result: see above)"
    f=$((f + 1))
fi
if [ -n "$t0" ]; then
    now=$(date +%s)
    echo "check: ${s} s in the steps, $((now - t0)) s wall clock${t1:+ ($((t1 - t0)) s building, $((now - t1)) s running the steps)}"
fi
echo "check: $p passed, $f failed"
[ "$f" -eq 0 ] && [ "$p" -gt 0 ]
