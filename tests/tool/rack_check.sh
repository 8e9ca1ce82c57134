#!/bin/sh
# check-rack (issue 13): the paper's real experiment rendered, one frame per
# group (cdsp_tool bench --rack --rack-frames 1, 10 frames of 2448 x 2048):
# both pipes found in every frame and no gap between them reported as a
# pipe, in any of the bench's solves. The coarse pass's bands once lost
# pipes here (9 of 10, 2 gaps) while every unit test passed.
# Usage: rack_check.sh CDSP_TOOL OUTDIR
tool=$1 out=$2
log=$out/rack.log
mkdir -p "$out" || exit 1
"$tool" bench --rack --rack-frames 1 --out "$out" >"$log" 2>&1 || {
    echo "rack_check: cdsp_tool bench --rack failed (exit $?); $log:"; cat "$log"; exit 1; }
found=$(sed -n 's/^rack detection: both pipes found in \([0-9]*\) of \([0-9]*\) frames.*/\1 \2/p' "$log")
gaps=$(sed -n 's/.*a gap taken for a pipe), all solves: \([0-9]*\).*/\1/p' "$log")
set -- $found
if [ -z "$1" ] || [ -z "$gaps" ]; then
    echo "rack_check: no rack detection lines in $log"; cat "$log"; exit 1
fi
echo "rack_check: both pipes found in $1 of $2 frames, gaps reported as pipes: $gaps"
[ "$1" -eq "$2" ] && [ "$2" -gt 0 ] && [ "$gaps" -eq 0 ]
