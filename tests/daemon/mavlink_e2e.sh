#!/usr/bin/env bash
# tests/daemon/mavlink_e2e.sh: cdspd's MAVLink output (docs/mavlink.md)
# end to end, cdspd on its simulated camera sending MAVLink and JSON at once
# to the test receiver (mavlink_rx), which decodes every MAVLink frame and
# checks crc, ids, sequence, the heartbeat's content and rate, and that each
# LANDING_TARGET / DEBUG_VECT equals the JSON pose of its frame transformed
# by the mount:
#   1. udpout://, the default mount (forward camera at the origin);
#   2. udpout://, a preset mount with an offset (down-right, [50, -20, 100]
#      mm), other system/component ids, mavlink_rate 10 (of 25 fps);
#   3. udpout://, a mount of arbitrary angles, mavlink_position false
#      (angles only, position fields zero);
#   4. serial:// through a pseudo-terminal: the same checks, and the device
#      vanishes for 2 s (closed and removed) then comes back: cdspd keeps
#      running, reopens it with back-off, poses come again;
#   5. configuration errors of the new keys name the file and line, and
#      --check-config's dump of them reads back.
# Needs MAVLINK_RX (daemon/daemon.mk sets it). Exit status 0 when all pass.
. "$(dirname "$0")/lib.sh"
[ -x "${MAVLINK_RX:-}" ] || { echo "$0: \$MAVLINK_RX must name the built program" >&2; exit 2; }

# 8 frames rendered at start (a quarter of them with the pipe out of view:
# frames without a pipe must send no LANDING_TARGET); the start may take
# long on a loaded machine or under a sanitizer: the waits below are long,
# the receiver stops 3 s after the last datagram.
common=(--calib "$CALIB" --radius 10 --format json --set sim.rate=25 --set sim.frames=8
        --set sim.away=0.25 --set stats_interval=0)

# start_mrx NAME ARGS...: mavlink_rx in the background (lib.sh's start_rx;
# its port file holds "MAVPORT JSONPORT"); sets MAV_PORT, JSON_PORT and
# NAME_pid.
start_mrx() {
    CDSPD_RX=$MAVLINK_RX start_rx "$@"
    read -r MAV_PORT JSON_PORT <<<"$RX_PORT"
}

# finish NAME DAEMON: wait for both, then every pose of the JSON stream must
# have had its LANDING_TARGET unless cdspd reports it replaced by a newer
# one before sending (latest wins) or held back by mavlink_rate (the counts
# it logs at the end).
finish() {
    local rx=$1 d=$2 rc
    wait_for "$(eval echo \$${d}_pid)" 300; rc=$?
    [ $rc -eq 0 ] || fail "cdspd ($d) exit status $rc, expected 0 after --duration"
    wait_for "$(eval echo \$${rx}_pid)" 30 || fail "mavlink_rx ($rx)"
    cat "$work/$rx.out"
    local missing replaced limited
    missing=$(sed -n 's/^poses without a LANDING_TARGET: \([0-9-]*\)$/\1/p' "$work/$rx.out")
    replaced=$(sed -n 's/.*poses: [0-9]* sent, \([0-9]*\) replaced.*/\1/p' "$work/$d.log")
    limited=$(sed -n 's/.*poses: .*, \([0-9]*\) over mavlink_rate.*/\1/p' "$work/$d.log")
    [ -n "$missing" ] && [ -n "$replaced" ] && [ -n "$limited" ] || fail "$rx/$d: no pose counts"
    [ "$missing" -ge 0 ] && [ "$missing" -le $((replaced + limited)) ] ||
        fail "$missing poses without a LANDING_TARGET, cdspd replaced $replaced, held back $limited"
}

# Runs 1-3 stop after 100 processed frames (4 s at 25 fps on an idle
# machine, longer on a loaded one, never fewer frames); --duration only
# bounds a hang.
echo "--- 1. udpout, default mount"
start_mrx r1 --min-targets 10
start_cdspd d1 "${common[@]}" --mavlink udpout://127.0.0.1:$MAV_PORT --dest 127.0.0.1:$JSON_PORT \
    --frames 100 --duration 120
finish r1 d1
grep -q "sending MAVLink (system 1, component 191) to udpout://127.0.0.1:$MAV_PORT" "$work/d1.log" ||
    fail "no log line naming the link"

echo "--- 2. udpout, mount down-right with an offset, system 7 component 42, mavlink_rate 10"
start_mrx r2 --min-targets 5 --mount 0,-90,90,50,-20,100 --sysid 7 --compid 42 --max-rate 10
# a host name in the URL; mavlink_rx listens on 127.0.0.1 only, so the name
# is "localhost" where that resolves to 127.0.0.1 first (not where /etc/hosts
# puts ::1 first)
mhost=localhost
getent ahosts localhost 2>/dev/null | head -n1 | grep -q '^127\.0\.0\.1 ' || mhost=127.0.0.1
start_cdspd d2 "${common[@]}" --mavlink udpout://$mhost:$MAV_PORT --dest 127.0.0.1:$JSON_PORT \
    --set "mount=[down-right, 50, -20, 100]" --set mavlink_system_id=7 \
    --set mavlink_component_id=42 --set mavlink_rate=10 --frames 100 --duration 120
finish r2 d2

echo "--- 3. udpout, mount [10, -60, 30, 5, 0, -40], angles only (mavlink_position false)"
start_mrx r3 --min-targets 10 --mount 10,-60,30,5,0,-40 --no-position
start_cdspd d3 "${common[@]}" --mavlink udpout://127.0.0.1:$MAV_PORT --dest 127.0.0.1:$JSON_PORT \
    --set "mount=[10, -60, 30, 5, 0, -40]" --set mavlink_position=false --frames 100 --duration 120
finish r3 d3

echo "--- 4. serial through a pseudo-terminal that vanishes and comes back"
tty=$(cd "$work" && pwd)/ttyMAV   # serial:// takes an absolute path
start_mrx r4 --pty "$tty" --min-targets 10 --vanish-after 2 --vanish-for 2 --min-after-reopen 5
start_cdspd d4 "${common[@]}" --mavlink "serial://$tty:115200" --dest 127.0.0.1:$JSON_PORT \
    --set retry_min=0.2 --set retry_max=1 --duration 9
finish r4 d4
grep -q "serial://$tty:115200: write: " "$work/d4.log" || fail "cdspd did not notice the device vanish"
grep -q "serial://$tty:115200: reopened" "$work/d4.log" || fail "cdspd did not reopen the device"
grep "serial://" "$work/d4.log" | head -4

echo "--- 5. configuration errors and the dump"
cat >"$work/bad1.yaml" <<EOF
calib: $CALIB
radius: 10
mavlink: ["udpout://127.0.0.1"]
EOF
expect_rc 2 bad1 "$CDSPD" --config "$work/bad1.yaml" --check-config
expect_msg bad1 "bad1.yaml:3:1: key 'mavlink': 'udpout://127.0.0.1': expected udpout://HOST:PORT"
cat >"$work/bad2.yaml" <<EOF
calib: $CALIB
radius: 10
dest: 127.0.0.1:9
mount: [sideways, 0, 0, 0]
EOF
expect_rc 2 bad2 "$CDSPD" --config "$work/bad2.yaml" --check-config
expect_msg bad2 "bad2.yaml:4:1: key 'mount': unknown preset 'sideways'"
expect_rc 2 bad3 "$CDSPD" --calib "$CALIB" --radius 10 --mavlink serial:///dev/ttyS0:12345 --check-config
expect_msg bad3 "baud rate '12345'"
expect_rc 2 bad4 "$CDSPD" --calib "$CALIB" --radius 10 --check-config
expect_msg bad4 "or a MAVLink link (--mavlink)"
expect_rc 2 bad5 "$CDSPD" --calib "$CALIB" --radius 10 --mavlink udpout://127.0.0.1:9 \
    --set mavlink_component_id=0 --check-config
expect_msg bad5 "key 'mavlink_component_id': expected an integer in [1, 255], got '0'"
expect_rc 0 dump "$CDSPD" --calib "$CALIB" --radius 10 --mavlink udpout://127.0.0.1:14550 \
    --mavlink serial_flowcontrol:///dev/ttyAMA0:921600 --set mount=down --check-config
grep -q '^mavlink: \["udpout://127.0.0.1:14550", "serial_flowcontrol:///dev/ttyAMA0:921600"\]$' \
    "$work/dump.out" || fail "dump: mavlink"
grep -q '^mount: \[0, -90, 0, 0, 0, 0\]$' "$work/dump.out" || fail "dump: mount"
grep -v '^#' "$work/dump.out" >"$work/dump.yaml"
expect_rc 0 dump2 "$CDSPD" --config "$work/dump.yaml" --check-config
cmp -s <(grep -v '^#' "$work/dump2.out") "$work/dump.yaml" || fail "the dump does not read back"
echo "PASS: cdspd -> MAVLink (UDP, serial pty with reopen): frames, heartbeat, targets = JSON pose through the mount"
