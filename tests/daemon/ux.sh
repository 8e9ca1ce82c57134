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
#      saving the calibration so a replay needs no --calib;
#   7. --list-cameras, with no camera and with the fake GigE camera
#      (tests/daemon/list_cameras.sh, in a network namespace; FAKECAM names
#      the fake camera when Aravis is built in).
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

echo "--- 3b. one vocabulary: -o is the output directory, polarity in words"
expect_rc 0 vocab "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 -o "$work/out" \
    -k solver.polarity=dark -o sim.rate=5 --check-config
grep -qx "record: \"$work/out\"" "$work/vocab.out" || fail "-o DIR is not --record DIR"
grep -qx "  polarity: dark" "$work/vocab.out" || fail "-k solver.polarity=dark not applied"
grep -qx "  rate: 5" "$work/vocab.out" || fail "the deprecated -o KEY=VALUE was not applied"
expect_msg vocab "-o sim.rate=5: -o is --record DIR now"
expect_rc 2 badpol "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 \
    --set solver.polarity=up --check-config
expect_msg badpol "expected any, bright or dark (or 0, 1, -1), got 'up'"

echo "--- 4. two cdsp_tool listen on one port: the second fails (exit 2)"
port=$(free_port)
listen_json l3 "$port" 30
kill -0 "$l3_pid" 2>/dev/null || fail "the first listener did not start"
expect_rc 2 listen2 "$CDSP_TOOL" listen "127.0.0.1:$port" --duration 1
expect_msg listen2 "cannot listen on 127.0.0.1:$port: Address already in use"
expect_msg listen2 "a unicast port has one listener"
kill -0 "$l3_pid" 2>/dev/null || fail "the first listener died"
kill -TERM "$l3_pid"; wait "$l3_pid" 2>/dev/null

echo "--- 5. sim.truth: the ground truth in JSON datagrams"
# Flat light (sim.ambient=1): the detector's shading bias is 0, so a pose
# lies within 6 of its own sigmas of the truth (cdspd_rx's derivation with
# delta = 0; measured here: at most 2.8 sigma, 0.65 mm). Neighbouring
# frames of a 16-frame path are about 12 mm apart, so the truth of the
# wrong frame fails the same bound: the check sees the plumbing.
port=$(free_port)
listen_json l4 "$port" 60
start_cdspd t1 --calib "$CALIB" --radius 10 --set sim.truth=true --set sim.frames=16 \
    --set sim.rate=50 --set sim.ambient=1 --dest "127.0.0.1:$port" --format json --duration 1 \
    --set stats_interval=0
wait_for "$t1_pid" 90 || fail "cdspd sim.truth: exit status $?"
sleep 0.3; kill -TERM "$l4_pid"; wait "$l4_pid" 2>/dev/null
frames_json='select(.kind == "frame")'
[ "$(jq -c "$frames_json" "$work/l4.out" | wc -l)" -ge 40 ] || fail "sim.truth: too few frames"
[ "$(jq -c "$frames_json | select(.truth == null)" "$work/l4.out" | wc -l)" -eq 0 ] ||
    fail "sim.truth: a frame datagram without truth"
[ "$(jq -c "$frames_json | select((.status == \"ok\") != .truth.in_view)" "$work/l4.out" | wc -l)" -eq 0 ] ||
    fail "sim.truth: a pose where the truth says out of view, or none where in view"
# ratio |P_C - truth| / (6 |sigma_point|), per pose: its own truth, and the next frame's
ratios='def err(a; b): [a, b] | transpose | map((.[0] - .[1]) * (.[0] - .[1])) | add | sqrt;
        def six_sigma: .sigma.point | map(. * .) | add | sqrt * 6;'
own=$(jq -s "$ratios [.[] | select(.kind == \"frame\" and .status == \"ok\") |
        err(.point; .truth.point) / six_sigma] | max" "$work/l4.out")
wrong=$(jq -s "$ratios [.[] | select(.kind == \"frame\")] as \$f |
        [range(0; (\$f | length) - 1) | select(\$f[.].status == \"ok\" and \$f[. + 1].truth.in_view) |
         (err(\$f[.].point; \$f[. + 1].truth.point) / (\$f[.] | six_sigma))] | min" "$work/l4.out")
echo "worst pose / (6 sigma) against its own truth: $own; best against the next frame's: $wrong"
awk -v r="$own" 'BEGIN { exit !(r <= 1) }' || fail "sim.truth: a pose beyond 6 sigma of its truth"
awk -v r="$wrong" 'BEGIN { exit !(r > 1) }' || fail "sim.truth: the next frame's truth fits as well"
expect_rc 0 truthbin "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 --set sim.truth=true \
    --check-config
grep -q '^  truth: true' "$work/truthbin.out" || fail "--check-config does not show sim.truth"

echo "--- 6. --record saves the calibration: the replay needs no --calib"
rec=$work/rec
port=$(free_port)
start_cdspd rec1 --calib "$frames/camera.yaml" --radius 10 --source "file:$frames/*.pgm" \
    --set file.rate=0 --dest "127.0.0.1:$port" --record "$rec" --set record_every=5 \
    --set stats_interval=0
wait_for "$rec1_pid" 60 || fail "cdspd --record: exit status $?"
run=$(basename "$(ls "$rec"/*.jsonl)" .jsonl)
[ -s "$rec/$run.yaml" ] || fail "--record did not save $run.yaml"
n_rec=$(ls "$rec"/*.pgm | wc -l)
[ "$n_rec" -eq 10 ] || fail "--record every 5th of 50 frames saved $n_rec" # a replay never skips
# the saved calibration is the one recorded with: frame k of the replay gives
# line k's result (within 6 of its sigmas: the replay tracks from frame k-1
# of the recording, 5 frames back, the recording from the frame before)
start_rx rx6 --compare-jsonl "$rec/$run.jsonl" --duration 60 --idle 2 --max-dropped 0 --min-poses 0
start_cdspd rep --radius 10 --source "file:$rec/$run-*.pgm" --set file.rate=0 \
    --dest "127.0.0.1:$RX_PORT" --set stats_interval=0
wait_for "$rep_pid" 60 || fail "replay without --calib: exit status $?"
grep -F "calibration $rec/$run.yaml" "$work/rep.log" | head -1
grep -qF "processed 10 " "$work/rep.log" || fail "replay without --calib: not 10 frames processed"
wait_for "$rx6_pid" 10 || fail "the replay with the saved calibration differs from the recording"
cat "$work/rx6.out"
expect_rc 2 nocalib "$CDSPD" --radius 10 --dest 127.0.0.1:9 --source "file:$frames/*.none"
expect_msg nocalib "none beside the frames either"

echo "--- 7. --list-cameras (in a network namespace: discovery broadcasts)"
if [ "$(id -u)" -ne 0 ] || ! unshare -n true 2>/dev/null; then
    echo "SKIP: a network namespace needs root (unshare -n)"
else
    unshare -n -- bash "$(dirname "$0")/list_cameras.sh" "${FAKECAM:-}" || fail "--list-cameras"
fi

echo "PASS: new-user behaviour of cdspd"
