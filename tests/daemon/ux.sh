#!/usr/bin/env bash
# tests/daemon/ux.sh: what a new user relies on (issue 15, the daemon side):
#   1. a file: replay at file.rate=0 processes every frame, in order (the
#      capture thread waits for the solver; only live cameras drop);
#   2. frames that are not the calibration's size (larger or smaller) give
#      bad-frame datagrams in their place, not silence;
#   3. --check-config refuses a file: glob that matches nothing (exit 2);
#   4. two `cdsp_tool listen` on one port: the second fails with exit 2;
#   (per-destination counters: tests/daemon/netns.sh, which needs root)
#   6. the sim's ground truth in JSON datagrams (sim.truth), and --record
#      saving the calibration so a replay needs no --calib.
# Needs CDSP_TOOL (cdsp_tool) besides lib.sh's variables.
. "$(dirname "$0")/lib.sh"
[ -x "${CDSP_TOOL:-}" ] || { echo "$0: \$CDSP_TOOL must name cdsp_tool" >&2; exit 2; }

# A free UDP port on loopback: bind port 0 with the test receiver, read the
# port it got, stop it. (Another program could take it in between; the
# tests that use it would then fail loudly, not pass wrongly.)
free_port() {
    start_rx probe --duration 30
    kill -TERM "$probe_pid"; wait "$probe_pid" 2>/dev/null
    echo "$RX_PORT"
}

# listen_json NAME PORT SECONDS: cdsp_tool listen --json in the background,
# output NAME.out; sets NAME_pid once it is listening.
listen_json() {
    local name=$1 port=$2 secs=$3
    "$CDSP_TOOL" listen "127.0.0.1:$port" --json --duration "$secs" >"$work/$name.out" \
        2>"$work/$name.err" &
    eval "${name}_pid=$!"
    pids+=("$!")
    sleep 0.3 # bind happens first thing; a datagram sent before would be lost, not wrong
}

echo "--- 1. file: replay at file.rate=0: every frame, in order"
frames=$work/frames
timeout -k 5 120 "$CDSP_TOOL" sim --calib "$CALIB" -n 50 --out "$frames" -p 0,0,400 \
    -d 0.1,1,0.05 -r 10 --move 1,0,0 --seed 3 >"$work/sim.out" 2>&1 || fail "cdsp_tool sim"
[ "$(ls "$frames"/*.pgm | wc -l)" -eq 50 ] || fail "cdsp_tool sim did not write 50 frames"
port=$(free_port)
listen_json l1 "$port" 60
start_cdspd r1 --calib "$frames/camera.yaml" --radius 10 --source "file:$frames/*.pgm" \
    --set file.rate=0 --dest "127.0.0.1:$port" --format json --set stats_interval=0
wait_for "$r1_pid" 60 || fail "cdspd replay: exit status $?, expected 0 at the end of the files"
sleep 0.3; kill -TERM "$l1_pid"; wait "$l1_pid" 2>/dev/null
grep -F "final: " "$work/r1.log"
grep -qF "frames in 50 " "$work/r1.log" && grep -qF "processed 50 " "$work/r1.log" &&
    grep -qF "dropped 0," "$work/r1.log" || fail "replay: not 50 in, 50 processed, 0 dropped"
got=$(grep '"kind":"frame"' "$work/l1.out" | grep -o '"frame":[0-9]*' | cut -d: -f2 | tr '\n' ' ')
[ "$got" = "$(seq -s ' ' 0 49) " ] || fail "replay: frames received out of order or missing: $got"
[ "$(grep -c '"status":"ok"' "$work/l1.out")" -eq 50 ] || fail "replay: not 50 poses"

echo "--- 2. frames not of the calibration's size: bad-frame datagrams"
mixed=$work/mixed
mkdir -p "$mixed"
for i in $(seq 0 9); do cp "$frames/frame_000$i.pgm" "$mixed/"; done
{ printf 'P5\n800 600\n255\n'; head -c $((800 * 600)) /dev/zero; } >"$mixed/frame_0003b.pgm"
{ printf 'P5\n320 240\n255\n'; head -c $((320 * 240)) /dev/zero; } >"$mixed/frame_0007b.pgm"
port=$(free_port)
listen_json l2 "$port" 60
start_cdspd r2 --calib "$frames/camera.yaml" --radius 10 --source "file:$mixed/*.pgm" \
    --set file.rate=0 --dest "127.0.0.1:$port" --format json --set stats_interval=0
wait_for "$r2_pid" 60 || fail "cdspd mixed replay: exit status $?"
sleep 0.3; kill -TERM "$l2_pid"; wait "$l2_pid" 2>/dev/null
# name order: frame_0003.pgm, frame_0003b.pgm, ...: the bad ones are frames 4 and 9
bad=$(grep '"error":"bad-frame"' "$work/l2.out" | grep -o '"frame":[0-9]*' | cut -d: -f2 | tr '\n' ' ')
[ "$bad" = "4 9 " ] || fail "bad-frame datagrams for frames '$bad', expected '4 9 '"
[ "$(grep -c '"status":"ok"' "$work/l2.out")" -eq 10 ] || fail "mixed replay: not 10 poses"
grep -qF "bad 2," "$work/r2.log" || fail "mixed replay: the statistics do not count 2 bad frames"

echo "--- 3. --check-config: a file: glob that matches nothing"
expect_rc 2 emptyglob "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 \
    --source "file:$work/none/*.pgm" --check-config
expect_msg emptyglob "no file matches '$work/none/*.pgm'"
expect_rc 0 fullglob "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 \
    --source "file:$frames/*.pgm" --check-config

echo "--- 4. two cdsp_tool listen on one port: the second fails (exit 2)"
port=$(free_port)
listen_json l3 "$port" 30
kill -0 "$l3_pid" 2>/dev/null || fail "the first listener did not start"
expect_rc 2 listen2 "$CDSP_TOOL" listen "127.0.0.1:$port" --duration 1
expect_msg listen2 "cannot listen on 127.0.0.1:$port: Address already in use"
expect_msg listen2 "a unicast port has one listener"
kill -0 "$l3_pid" 2>/dev/null || fail "the first listener died"
kill -TERM "$l3_pid"; wait "$l3_pid" 2>/dev/null

echo "PASS: new-user behaviour of cdspd"
