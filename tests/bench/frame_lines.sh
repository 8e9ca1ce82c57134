#!/bin/sh
# frame_lines.sh BENCH_FRAME DIR - `make bench-frame-lines` (issue 17): the
# bytes of the frame the frame path actually reads, as distinct 64-byte
# cache lines, into DIR/lines.txt ("full N", "track N"), which
# `bench_frame DIR` then prints and divides by the bandwidth.
# Counted by callgrind's cache model with a last level of 16 MiB, larger
# than the frame and everything else the solve touches (bench_frame.c's
# LINES_LL_BYTES, which must agree): bench_frame's
# lines-full / lines-track modes warm the workspace on one copy of the
# frame and solve a second copy nothing has read (bench_frame.c, "lines
# modes"), so the measured call's last-level data read misses (DLmr) are
# the frame's distinct lines read, each once. Without valgrind, or if a
# count fails, lines.txt says "none" and bench_frame keeps its whole-row
# upper bound. Exit status 0 either way (a figure, not a check).
set -u
bin=$1
dir=$2
out="$dir/lines.txt"
if ! command -v valgrind >/dev/null 2>&1; then
    echo "frame_lines.sh: valgrind not found: the frame's lines are not counted (apt-get install valgrind)" >&2
    echo none > "$out"
    exit 0
fi
tmp=$(mktemp -d) || exit 0
trap 'rm -rf "$tmp"' EXIT
: > "$tmp/lines"
for m in full track; do
    if ! valgrind --tool=callgrind --cache-sim=yes --LL=16777216,16,64 --dump-instr=no \
            --toggle-collect="measured_$m" --callgrind-out-file="$tmp/cg.$m" \
            "$bin" "$dir" "lines-$m" > "$tmp/log.$m" 2>&1; then
        echo "frame_lines.sh: valgrind failed on lines-$m (log below): the lines are not counted" >&2
        cat "$tmp/log.$m" >&2
        echo none > "$out"
        exit 0
    fi
    # the events line names the columns of the summary line
    n=$(awk '/^events:/ { for (i = 2; i <= NF; i++) if ($i == "DLmr") c = i - 1 }
             /^summary:/ { if (c) print $(c + 1) }' "$tmp/cg.$m")
    case $n in
    '' | *[!0-9]*)
        echo "frame_lines.sh: no DLmr count in callgrind's output for lines-$m" >&2
        echo none > "$out"
        exit 0 ;;
    esac
    echo "$m $((n * 64))" >> "$tmp/lines"
    echo "frame path, $m: $n distinct 64-byte lines of the frame read ($((n * 64)) bytes)"
done
mv "$tmp/lines" "$out"
