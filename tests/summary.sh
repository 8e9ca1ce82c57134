#!/usr/bin/env bash
# Sum the step results of `make check` and print the closing line.
# A step that never recorded a result (build failure) is caught by the
# caller's exit status: make -k returns non-zero, and so do we.
set -u
results=$1
make_rc=${2:-0}
p=0 f=0
if [ -f "$results" ]; then
    echo
    echo "== make check =="
    # The seconds show where make check's time goes (wall clock: an upper
    # bound on a shared machine, for planning, never asserted).
    while read -r name np nf secs; do
        printf '  %-40s %4d passed %4d failed %6ss\n' "$name" "$np" "$nf" "${secs:-?}"
        p=$((p + np)); f=$((f + nf))
    done <"$results"
fi
if [ "$make_rc" -ne 0 ]; then
    echo "  (a build or check step failed before recording a result: see above)"
    f=$((f + 1))
fi
echo "check: $p passed, $f failed"
[ "$f" -eq 0 ] && [ "$p" -gt 0 ]
