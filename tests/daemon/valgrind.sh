#!/usr/bin/env bash
# tests/daemon/valgrind.sh: cdspd (the plain build) under valgrind memcheck:
# the sim source at 20 frames/s on a small camera (320 x 240: valgrind runs
# the solver some 30 times slower), a hundred frames solved, each datagram
# checked by cdspd_rx (--validate, poses against the simulated truth), then
# SIGTERM. Passes when valgrind reports no error (invalid read or write,
# use of uninitialised values, bad free, fd misuse) and no block definitely,
# indirectly or possibly lost at exit (tests/daemon/valgrind.supp lists the
# one library thread that is not cdspd's, and why). Still-reachable blocks
# are GLib's type registrations from its library constructors (kept by
# design until the process ends): counted and printed, not errors.
. "$(dirname "$0")/lib.sh"
command -v valgrind >/dev/null || { echo "SKIP: valgrind is not installed"; exit 0; }
cp "$(dirname "$0")/cam320.yaml" "$work/cam.yaml"
# 100 frames: enough for every path of a frame to have run many times.
# sim.rate 20, not 0: valgrind runs one thread at a time, and a capture
# thread producing frames as fast as it can starved the solver (29 frames in
# 300 s on a loaded machine). The wait below is a hang bound only.
frames=100
# status_interval 60: no status datagram while valgrind renders the frames
sim=(--set sim.frames=4 --set sim.away=0)
start_rx rx --validate --truth sim --calib "$work/cam.yaml" --set radius=10 "${sim[@]}" \
    --count $frames --duration 1200 --min-poses $((frames - 5))
# --track-fds: descriptors left open at exit are listed too (stdio only)
valgrind --error-exitcode=99 --leak-check=full --show-leak-kinds=all \
    --errors-for-leak-kinds=definite,indirect,possible --track-fds=yes \
    --suppressions="$(dirname "$0")/valgrind.supp" \
    "$CDSPD" --calib "$work/cam.yaml" --radius 10 "${sim[@]}" --set sim.rate=20 --set sim.threads=1 \
    --set stats_interval=0 --set status_interval=60 --dest 127.0.0.1:$RX_PORT >"$work/d.out" 2>"$work/d.log" &
d_pid=$!; pids+=("$d_pid")
for _ in $(seq 12000); do
    kill -0 "$rx_pid" 2>/dev/null || break
    kill -0 "$d_pid" 2>/dev/null || fail "cdspd under valgrind stopped early"
    sleep 0.1
done
wait_for "$rx_pid" 1 || fail "the receiver (cdspd under valgrind): exit status $?"
kill -TERM "$d_pid"
wait_for "$d_pid" 120; rc=$?
cat "$work/rx.out"
grep -E "ERROR SUMMARY|definitely lost|indirectly lost|possibly lost|still reachable|FILE DESCRIPTORS" "$work/d.log"
[ $rc -eq 0 ] || fail "cdspd under valgrind: exit status $rc (99: valgrind found errors)"
grep -q "ERROR SUMMARY: 0 errors" "$work/d.log" || fail "valgrind reports errors"
grep -q "stopped (exit status 0)" "$work/d.log" || fail "cdspd did not stop cleanly on SIGTERM"
# the leak summary: nothing lost of any kind
for kind in "definitely lost" "indirectly lost" "possibly lost"; do
    grep -q "$kind: 0 bytes" "$work/d.log" || grep -q "All heap blocks were freed" "$work/d.log" ||
        fail "valgrind: $kind is not 0 bytes"
done
# descriptors cdspd opened and left open at exit (inherited ones and
# stdio aside): none
n_fd=$(awk '/Open (file|AF_[A-Z0-9]* socket) descriptor [0-9]+/ { fd = $0; getline; 
        if ($0 !~ /inherited from parent/ && fd !~ /descriptor [012]:/) n++ } END { print n + 0 }' "$work/d.log")
[ "$n_fd" -eq 0 ] || fail "$n_fd descriptors opened by cdspd are still open at exit"
echo "PASS: cdspd under valgrind: $frames datagrams, 0 errors, nothing lost, no descriptor left open"
