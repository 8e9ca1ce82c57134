#!/usr/bin/env bash
# tests/daemon/aravis_e2e.sh FAKECAM: cdspd's aravis source end to end with
# the fake GigE Vision camera (tests/fakecam: libaravis's ArvGvFakeCamera
# drawing pipes of known pose, fakecam_path.h) on 127.0.0.1:
#   1. poses of every frame within the tolerance of their sigmas against the
#      camera's ground truth, sequence numbers continuous;
#   2. the camera killed (SIGKILL) and started again: cdspd reports the
#      source down (status datagrams), reopens it and poses resume;
#   3. a camera that drops 2 of every 1000 GVSP packets (and never resends):
#      incomplete frames are counted and skipped, the others solved; then
#      Mono16 frames (the pixel format set by cdspd);
#   4. no such camera: exit status 3 after open_timeout.
# One fake camera per machine (GVCP has one port): the lock the fake
# camera's own test uses is held throughout.
# Speed (issue 9): the camera draws its $cycle poses before it says ready
# (--cycle, once: later starts read them from --cache), so it serves at the
# asked rate on any machine; every step waits for counts of poses, bad
# frames and statuses (wait_rx), never for a fixed time, so a slow or
# loaded machine waits longer and the assertions stay the same. The
# bounds on each wait only catch a hang.
. "$(dirname "$0")/lib.sh"
fakecam=${1:?usage: aravis_e2e.sh FAKECAM}
[ -x "$fakecam" ] || fail "'$fakecam' is not an executable"
cycle=10
cam_pid=""
mkdir -p "$work/poses"

# start_camera ARGS...: the fake camera, ready; its poses drawn (or read
# from $work/poses) before that, however long it takes (bounded: 600 s).
start_camera() {
    "$fakecam" -i 127.0.0.1 --duration 300 --cycle $cycle --cache "$work/poses" "$@" \
        >"$work/cam.out" 2>"$work/cam.err" &
    cam_pid=$!
    pids+=("$cam_pid")
    for _ in $(seq 6000); do
        grep -q '^cdsp_fakecam: ready' "$work/cam.out" && { cat "$work/cam.out"; return 0; }
        kill -0 "$cam_pid" 2>/dev/null || break
        sleep 0.1
    done
    fail "cdsp_fakecam did not start"
}
stop_camera() {
    kill -"${1:-TERM}" "$cam_pid" 2>/dev/null
    wait_for "$cam_pid" 10 >/dev/null 2>&1
}

exec 8>/tmp/cdsp-fakecam-gvcp.lock
flock -w 300 8 || fail "the fake camera's lock is held by another test for 300 s"

arv=(--source aravis:127.0.0.1 --calib "$CALIB" --radius 10 --set retry_min=0.5 --set retry_max=2
     --set aravis.frame_timeout=2 --set stats_interval=0 --set status_interval=0.25)

# Poses before the camera is killed, and in all (after it came back).
before=30 total=60

echo "--- 1+2. poses against the camera's truth; camera killed and restarted"
start_camera --formats Mono8,Mono16   # Mono16 for step 3b
# --resume-within: the camera is away for at least its restart here; the
# bound (from the first source-down to the next pose) only catches a
# daemon that never reopens.
start_rx rx --truth fakecam --cycle $cycle --calib "$CALIB" --duration 900 --idle 30 \
    --min-poses $total --expect-status source-down --min-reconnects 1 --resume-within 300
start_cdspd d "${arv[@]}" --dest 127.0.0.1:$RX_PORT
wait_log "$work/d.log" "aravis:127.0.0.1: open" 60 || fail "cdspd did not open the camera"
wait_rx rx poses $before 300
stop_camera KILL
wait_log "$work/d.log" "lost: " 60 || fail "cdspd did not notice the camera's loss"
grep -m1 "lost: " "$work/d.log"
# the camera stays away until status datagrams have said source-down
wait_rx rx source-down 2 120
start_camera
wait_log "$work/d.log" "aravis:127.0.0.1: reopened" 120 || fail "cdspd did not reopen the camera"
wait_rx rx poses $total 300
kill -TERM "$d_pid"
wait_for "$d_pid" 30 || fail "cdspd exit status $? after SIGTERM"
kill -TERM "$rx_pid"   # the daemon has stopped: nothing more comes
wait_for "$rx_pid" 60 || fail "receiver"
cat "$work/rx.out"
stop_camera

echo "--- 3. GVSP packet loss"
start_camera -r 2
start_rx rx2 --truth fakecam --cycle $cycle --calib "$CALIB" --duration 900 --idle 30 --min-poses 20 \
    --min-bad 3
start_cdspd d2 "${arv[@]}" --dest 127.0.0.1:$RX_PORT
wait_log "$work/d2.log" "aravis:127.0.0.1: open" 60 || fail "cdspd did not open the lossy camera"
wait_rx rx2 poses 20 300
wait_rx rx2 bad 3 300
kill -TERM "$d2_pid"
wait_for "$d2_pid" 30 || fail "cdspd exit status $? after SIGTERM (lossy camera)"
kill -TERM "$rx2_pid"   # the daemon has stopped: nothing more comes
wait_for "$rx2_pid" 60 || fail "receiver (lossy camera)"
cat "$work/rx2.out"
grep -m1 "frame skipped" "$work/d2.log" || fail "no message about incomplete frames"
stop_camera

echo "--- 3b. Mono16 (set by cdspd)"
start_camera --formats Mono8,Mono16
start_rx rx3 --truth fakecam --cycle $cycle --calib "$CALIB" --duration 900 --idle 30 --min-poses 15
start_cdspd d3 "${arv[@]}" --set aravis.pixel_format=Mono16 --dest 127.0.0.1:$RX_PORT
wait_log "$work/d3.log" "aravis:127.0.0.1: open" 60 || fail "cdspd did not open the camera in Mono16"
grep -q "16 bit" "$work/d3.log" || fail "the camera is not in Mono16"
wait_rx rx3 poses 15 300
kill -TERM "$d3_pid"
wait_for "$d3_pid" 30 || fail "cdspd exit status $? after SIGTERM (Mono16)"
kill -TERM "$rx3_pid"   # the daemon has stopped: nothing more comes
wait_for "$rx3_pid" 60 || fail "receiver (Mono16)"
cat "$work/rx3.out"
stop_camera

echo "--- 4. no such camera"
expect_rc 3 nocam "$CDSPD" --source aravis:cdspd-no-such-camera --calib "$CALIB" --radius 10 \
    --dest 127.0.0.1:9 --set open_timeout=2
expect_msg nocam "no camera 'cdspd-no-such-camera'"
grep "cannot open the source" "$work/nocam.err"
echo "PASS: aravis source with the fake GigE Vision camera"
