#!/usr/bin/env bash
# tests/fakecam/check.sh FAKECAM PROBE: the fake GigE Vision camera end to end
# on loopback (docs/testing-hardware.md). cdsp_fakecam serves frames drawn by
# libcdsp's renderer; arv_probe, an Aravis client, discovers it, streams and
# compares every frame pixel for pixel with the renderer's output:
#   1. 640x480 Mono8, the camera's default format, poses checked against the
#      camera's --truth file;
#   2. 320x240 Mono16, set by the client;
#   3. 320x240 Mono8 at 100 fps, long enough to cross the 16-bit frame id wrap;
#   4. a new camera dropping 20 of every 1000 GVSP packets: incomplete frames
#      must appear, and every complete one must still be exact.
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
    "$fakecam" -i 127.0.0.1 --duration 120 "$@" >"$work/cam.out" 2>"$work/cam.err" &
    cam_pid=$!
    for _ in $(seq 100); do
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

start_camera --truth "$work/truth.txt" || exit 1
step "640x480 Mono8 with ground truth" -n 15 --truth "$work/truth.txt" --timeout 30
step "320x240 Mono16" -n 20 --size 320x240 --pixel-format Mono16 --rate 50 --timeout 30
step "16-bit frame id wrap" -n 120 --size 320x240 --rate 100 --expect-wrap --timeout 40
stop_camera

start_camera -r 20 --size 320x240 || exit 1
step "GVSP loss 20/1000" -n 10 --min-incomplete 3 --rate 50 --timeout 30
stop_camera
grep -v '^cdsp_fakecam: drawing' "$work/cam.err" >&2
echo "PASS: fake GigE Vision camera on 127.0.0.1: frames pixel-exact in every step"
