#!/usr/bin/env bash
# tests/daemon/firewall.sh WORKDIR: run by faults.sh in a network namespace
# of its own (unshare -n: only lo, and a ruleset nobody else sees). cdspd
# streams to a receiver on 127.0.0.1 while nftables
#   1. drops the datagrams on input (a firewall in the path: sendto
#      succeeds, nothing arrives) for 2 s;
#   2. drops them on output (the host's own firewall: sendto fails with
#      EPERM) for 2 s: counted as send errors, logged at most once per 10 s;
#   3. lets them through again: "sending works again" is logged.
# The receiver sees two gaps in seq and otherwise valid datagrams.
. "$(dirname "$0")/lib.sh"
ip link set lo up || fail "ip link set lo up"
cp "$(dirname "$0")/cam320.yaml" "$work/cam.yaml"
start_rx rx --validate --allow-seq-gaps --duration 120 --idle 6 --min-poses 40 --truth sim \
    --calib "$work/cam.yaml" --set radius=10 --set sim.frames=4 --set sim.away=0 --set sim.rate=50
port=$RX_PORT
start_cdspd d --calib "$work/cam.yaml" --radius 10 --set sim.frames=4 --set sim.away=0 \
    --set sim.rate=50 --set stats_interval=0 --dest 127.0.0.1:$port
wait_log "$work/d.log" "sim: open" 60 || fail "cdspd did not start"
sleep 1
nft add table inet cdsp_test &&
nft add chain inet cdsp_test in '{ type filter hook input priority 0; }' &&
nft add rule inet cdsp_test in udp dport $port drop || fail "nft: cannot add the input rule"
sleep 2
nft flush chain inet cdsp_test in
nft add chain inet cdsp_test out '{ type filter hook output priority 0; }' &&
nft add rule inet cdsp_test out udp dport $port drop || fail "nft: cannot add the output rule"
sleep 2
nft delete table inet cdsp_test
wait_log "$work/d.log" "sending works again" 10 || fail "no message when sending worked again"
sleep 1
kill -TERM "$d_pid"
wait_for "$d_pid" 10 || fail "cdspd exit status $? (firewalled receiver)"
wait_for "$rx_pid" 10 || fail "receiver (firewalled)"
cat "$work/rx.out"
grep -E "cannot send|works again" "$work/d.log"
grep -q "127.0.0.1:$port: cannot send: Operation not permitted" "$work/d.log" ||
    fail "no warning when the output firewall rejected the datagrams"
[ "$(grep -c "cannot send" "$work/d.log")" -eq 1 ] || fail "send errors not rate-limited"
gaps=$(sed -n 's/.*seq gaps \([0-9]*\),.*/\1/p' "$work/rx.out")
[ "${gaps:-0}" -ge 100 ] || fail "only ${gaps:-0} datagrams missing over 4 s firewalled at 50/s"
grep -q "seq out of order 0" "$work/rx.out" || fail "seq out of order"
echo "PASS: firewalled receiver: dropped on input, rejected on output, back"
