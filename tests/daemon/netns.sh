#!/usr/bin/env bash
# tests/daemon/netns.sh WORKDIR: run by errors.sh inside its own network
# and mount namespaces (unshare -n -m), where only a loopback interface
# exists (so any other address is unreachable: sendto fails at once) and a
# tiny tmpfs can be mounted:
#   1. one unreachable and one reachable destination: the daemon warns about
#      the first, keeps sending to the second, counts each apart (SIGUSR1's
#      and the final statistics), exits 0;
#   2. broadcast (127.255.255.255) and multicast (239.255.77.1, routed via lo);
#   3. --record into a 1 MiB tmpfs: the disk fills, recording stops with a
#      message, the datagrams go on.
. "$(dirname "$0")/lib.sh"
ip link set lo up || fail "ip link set lo up"
ip link set lo multicast on || fail "no multicast on lo"
ip route add 224.0.0.0/4 dev lo || fail "no multicast route"
sim=(--calib "$CALIB" --radius 10 --set sim.frames=8 --set sim.rate=50 --set sim.away=0
     --set stats_interval=0)

echo "--- unreachable destination"
start_rx rx1 --duration 30 --idle 2
start_cdspd d1 "${sim[@]}" --dest 10.77.0.1:5000 --dest 127.0.0.1:$RX_PORT --duration 2
wait_log "$work/d1.log" "sim: open" 20 || fail "cdspd (unreachable) did not start"
sleep 0.5
kill -USR1 "$d1_pid"
wait_for "$d1_pid" 30; rc=$?
[ $rc -eq 0 ] || fail "cdspd with an unreachable destination: exit status $rc"
grep -F "10.77.0.1:5000: cannot send: Network is unreachable" "$work/d1.log" | head -1
grep -qF "10.77.0.1:5000: cannot send: Network is unreachable" "$work/d1.log" || fail "no warning"
[ "$(grep -c "cannot send" "$work/d1.log")" -le 2 ] || fail "send errors are not rate-limited"
grep -q "send errors [1-9]" "$work/d1.log" || fail "send errors not counted"
# counted per destination, in SIGUSR1's report and the final one
for why in "SIGUSR1: " "final: "; do
    grep -F "${why}destination " "$work/d1.log"
    grep -qE "${why}destination 10\.77\.0\.1:5000: sent 0, send errors [1-9]" "$work/d1.log" ||
        fail "$why: the unreachable destination's errors are not its own"
    grep -qE "${why}destination 127\.0\.0\.1:$RX_PORT: sent [1-9][0-9]*, send errors 0 " \
        "$work/d1.log" || fail "$why: the reachable destination's datagrams are not counted as sent"
done
wait_for "$rx1_pid" 10 || fail "the reachable destination lost datagrams"
cat "$work/rx1.out"

echo "--- broadcast and multicast"
start_rx rx2 --bind 0.0.0.0:0 --duration 30 --idle 2 --min-poses 20
# 75 frames (1.5 s at 50 fps idle; never fewer on a loaded machine)
start_cdspd d2 "${sim[@]}" --dest 127.255.255.255:$RX_PORT --frames 75 --duration 60
wait_for "$d2_pid" 90 || fail "cdspd (broadcast) exit status $?"
wait_for "$rx2_pid" 10 || fail "broadcast"
cat "$work/rx2.out"
port=$(( 40000 + RANDOM % 20000 ))
start_rx rx3 --bind 239.255.77.1:$port --duration 30 --idle 2
start_cdspd d3 "${sim[@]}" --dest 239.255.77.1:$port --set net.multicast_interface=127.0.0.1 --duration 1.5
wait_for "$d3_pid" 30 || fail "cdspd (multicast) exit status $?"
wait_for "$rx3_pid" 10 || fail "multicast"
cat "$work/rx3.out"

echo "--- a full disk under --record"
mkdir -p "$work/small" && mount -t tmpfs -o size=1m tmpfs "$work/small" || fail "cannot mount a tmpfs"
start_rx rx4 --duration 30 --idle 2
start_cdspd d4 "${sim[@]}" --dest 127.0.0.1:$RX_PORT --duration 2 --record "$work/small" \
    --set record_every=1
wait_for "$d4_pid" 30; rc=$?
umount "$work/small"
[ $rc -eq 0 ] || fail "cdspd with a full disk: exit status $rc"
grep -F "recording stopped" "$work/d4.log" || fail "no message when the disk filled"
wait_for "$rx4_pid" 10 || fail "datagrams stopped with the disk full"
cat "$work/rx4.out"
echo "PASS: namespaces"
