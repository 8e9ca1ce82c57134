#!/usr/bin/env bash
# tests/daemon/list_cameras.sh [FAKECAM]: cdspd --list-cameras, run by ux.sh
# inside a network namespace of its own (unshare -n: only loopback, so
# Aravis's discovery broadcast reaches nothing else):
#   1. no camera: a comment line per source kind, exit status 0;
#   2. with the fake GigE Vision camera on 127.0.0.1 (its lock held): a line
#      "aravis:ID ..." whose first word, pasted into --source, opens it.
. "$(dirname "$0")/lib.sh"
fakecam=${1:-}
ip link set lo up || fail "ip link set lo up"

echo "--- no camera"
expect_rc 0 none timeout -k 5 60 "$CDSPD" --list-cameras
cat "$work/none.out"
for k in aravis v4l2 libcamera; do
    grep -q "^# $k: " "$work/none.out" || fail "--list-cameras says nothing about $k"
done
grep -v '^#' "$work/none.out" | grep -q . && fail "--list-cameras lists a camera where there is none"
if "$CDSPD" --version | grep -q '^sources:.* aravis'; then
    grep -q "^# aravis: no camera found" "$work/none.out" || fail "aravis: not 'no camera found'"
fi

echo "--- the fake GigE Vision camera"
if [ -z "$fakecam" ]; then
    echo "SKIP: no fake camera (Aravis not built in)"
    exit 0
fi
exec 8>/tmp/cdsp-fakecam-gvcp.lock
flock -w 300 8 || fail "the fake camera's lock is held by another test for 300 s"
"$fakecam" -i 127.0.0.1 --duration 60 --serial LIST01 >"$work/cam.out" 2>"$work/cam.err" &
pids+=("$!")
wait_log "$work/cam.out" '^cdsp_fakecam: ready' 600 || fail "cdsp_fakecam did not start"
expect_rc 0 list timeout -k 5 60 "$CDSPD" --list-cameras
cat "$work/list.out"
line=$(grep '^aravis:' "$work/list.out" | head -1)
[ -n "$line" ] || fail "--list-cameras does not list the fake camera"
echo "$line" | grep -q "LIST01" || fail "the listed camera is not the fake one (serial LIST01)"
src=${line%% *}
start_cdspd d --source "$src" --calib "$CALIB" --radius 10 --dest 127.0.0.1:9 --duration 1 \
    --set stats_interval=0 --set aravis.packet_socket=off
wait_for "$d_pid" 60 || fail "cdspd --source $src: exit status $?"
grep -F "$src: open" "$work/d.log" || fail "--source $src (pasted from --list-cameras) did not open"
echo "PASS: --list-cameras"
