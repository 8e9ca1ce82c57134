#!/bin/sh
# tests/aarch64/count.sh "QEMU" BENCH DIR: guest instructions the frame path
# executes on AArch64, per 2448 x 2048 frame, full search and tracked
# (`make bench-aarch64`). Emulated time means nothing, and Debian's
# qemu-user ships no TCG plugins (libinsn.so), so the count comes from
# qemu's own logs: -d in_asm prints every translated block with its
# instructions, -d exec,nochain every block executed (nochain: each
# execution is logged, none chained past the log); the sum over executions
# of the block's instruction count is the guest instruction count. BENCH
# (tests/bench/bench_frame.c built for AArch64) reads DIR/frames.raw, which
# the host's bench-frame wrote; a run that only loads the frames is the
# baseline subtracted. One frame: the log is ~100 bytes per block executed,
# streamed through awk, never stored.
set -u
qemu=$1 bench=$2 dir=$3
[ -f "$dir/frames.raw" ] || { echo "count.sh: $dir/frames.raw missing (run make bench-frame first)" >&2; exit 2; }
tmp=$(mktemp -d) || exit 1
trap 'rm -rf "$tmp"' EXIT
count() { # mode -> total guest instructions
    mkfifo "$tmp/log"
    awk '
        /^IN:/ { inblk = 1; start = ""; next }
        inblk && /^0x[0-9a-f]+:/ {
            a = substr($1, 3, length($1) - 3); sub(/^0+/, "", a)
            if (start == "") { start = a; size[start] = 0 }
            size[start]++; next
        }
        inblk && !/^0x/ { inblk = 0 }
        /^Trace / {
            # Trace N: HOSTPTR [CPU/PC/FLAGS/CFLAGS] SYMBOL
            split($0, f, "/"); pc = f[2]; sub(/^0+/, "", pc)
            total += size[pc]
        }
        END { printf "%.0f\n", total }' "$tmp/log" >"$tmp/n" &
    # shellcheck disable=SC2086
    $qemu -d in_asm,exec,nochain -D "$tmp/log" "$bench" "$dir" "$1" 1 1 >/dev/null || { wait; rm -f "$tmp/log"; return 1; }
    wait
    rm -f "$tmp/log"
    cat "$tmp/n"
}
base=$(count load) && full=$(count full) && track=$(count track) || { echo "count.sh: qemu run failed" >&2; exit 1; }
echo "AArch64 (qemu-aarch64, guest instructions, one 2448 x 2048 frame; emulated time means nothing):"
echo "  full search: $((full - base)) instructions per frame"
echo "  tracked:     $((track - full)) instructions per frame (the tracked run minus the full search it takes its prior from)"
