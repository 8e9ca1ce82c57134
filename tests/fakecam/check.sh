#!/usr/bin/env bash
# tests/fakecam/check.sh FAKECAM PROBE: the fake GigE Vision camera end to end
# on loopback (docs/testing-hardware.md). cdsp_fakecam serves frames drawn by
# libcdsp's renderer; arv_probe, an Aravis client, discovers it, streams and
# compares every frame pixel for pixel with the renderer's output:
#   1. 640x480 Mono8, the camera's default format, poses checked against the
#      camera's --truth file;
#   2. 320x240 Mono16, set by the client;
#   3. 320x240 Mono8 at 100 fps with --cycle 10 (10 poses drawn once, then
#      served from memory), long enough to cross the 16-bit frame id wrap;
#   4. a new camera dropping 20 of every 1000 GVSP packets: incomplete frames
#      must appear, and every complete one must still be exact.
# Incomplete frames are tolerated in steps 1-3: on a loaded machine the
# receiving thread can fall behind and the socket buffer overflow (GVSP is
# UDP, and the fake camera never resends); each step still needs its count
# of exact frames.
# Speed (issue 9): every step counts frames; a slow machine only takes
# longer. Every camera draws its 10 poses before it says ready (--cycle,
# at the size and in the formats the probe sets), so it serves the asked
# rate however slow the drawing: a camera drawing each frame as it is sent
# stops answering GVCP while it draws, and on a loaded machine (3 s a
# 640x480 frame was seen) the client's heartbeat then expires and the
# camera stops streaming. The time-outs (300 s a step, 600 s for a camera
# to start) only catch a hang.
# Only 127.0.0.1 is used. GVCP has one fixed port (3956) and lo has one
# address here, so one fake camera at a time per machine: every test that
# runs one holds the lock /tmp/cdsp-fakecam-gvcp.lock (flock) while it does.
# Exit status: 0 all passed, 1 a step failed, 2 usage error.
set -u
[ $# -eq 2 ] || { echo "usage: tests/fakecam/check.sh FAKECAM PROBE" >&2; exit 2; }
fakecam=$1 probe=$2
for p in "$fakecam" "$probe"; do
    [ -x "$p" ] || { echo "tests/fakecam/check.sh: '$p' is not an executable" >&2; exit 2; }
done

lock=/tmp/cdsp-fakecam-gvcp.lock
work=$(mktemp -d "${TMPDIR:-/tmp}/cdsp-fakecam.XXXXXX") || exit 1
cam_pid=""

stop_camera() {
    if [ -n "$cam_pid" ]; then
        kill -TERM "$cam_pid" 2>/dev/null
        # it stops within 0.1 s plus a frame; SIGKILL if it hangs
        for _ in $(seq 50); do kill -0 "$cam_pid" 2>/dev/null || break; sleep 0.1; done
        kill -KILL "$cam_pid" 2>/dev/null
        wait "$cam_pid" 2>/dev/null
        cam_pid=""
    fi
}
cleanup() { stop_camera; rm -rf "$work"; }
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

# Another test's camera may be running (make -j): wait for it, bounded.
exec 8>"$lock"
flock -w 300 8 || { echo "FAIL: $lock held by another fake-camera test for 300 s" >&2; exit 1; }

# start_camera ARGS...: start cdsp_fakecam on 127.0.0.1 and wait until it
# answers. --duration bounds its life even if this script is killed -9.
start_camera() {
    "$fakecam" -i 127.0.0.1 --duration 600 "$@" >"$work/cam.out" 2>"$work/cam.err" &
    cam_pid=$!
    for _ in $(seq 6000); do
        grep -q '^cdsp_fakecam: ready' "$work/cam.out" && { cat "$work/cam.out"; return 0; }
        kill -0 "$cam_pid" 2>/dev/null || break
        sleep 0.1
    done
    echo "FAIL: cdsp_fakecam did not start:" >&2
    cat "$work/cam.out" "$work/cam.err" >&2
    stop_camera
    return 1
}

step() {
    local name=$1; shift
    echo "--- $name"
    if ! "$probe" -a 127.0.0.1 "$@"; then
        echo "FAIL: $name" >&2
        echo "cdsp_fakecam said:" >&2; cat "$work/cam.err" >&2
        exit 1
    fi
}

start_camera --cycle 10 --truth "$work/truth.txt" || exit 1
step "640x480 Mono8 with ground truth" -n 10 --cycle 10 --truth "$work/truth.txt" --timeout 300
stop_camera

start_camera --cycle 10 --size 320x240 --formats Mono8,Mono16 || exit 1
step "320x240 Mono16" -n 20 --cycle 10 --size 320x240 --pixel-format Mono16 --rate 50 --timeout 300
stop_camera

start_camera --cycle 10 --size 320x240 || exit 1
step "16-bit frame id wrap, --cycle 10" -n 150 --cycle 10 --size 320x240 --rate 100 \
    --expect-wrap --timeout 300
stop_camera

start_camera -r 20 --size 320x240 --cycle 10 || exit 1
# A 320x240 Mono8 frame is about 57 packets: 0.98^57 = 32 % arrive whole.
# 20 whole frames with fewer than 5 incomplete ones: probability 0.32^20 *
# sum_{k<5} C(19+k,k) 0.68^k < 1e-6 if the loss works.
step "GVSP loss 20/1000" -n 20 --cycle 10 --min-incomplete 5 --rate 50 --timeout 300
stop_camera
grep -v '^cdsp_fakecam: drawing' "$work/cam.err" >&2
echo "PASS: fake GigE Vision camera on 127.0.0.1: frames pixel-exact in every step"
