#!/usr/bin/env bash
# tests/daemon/security.sh: what docs/security.md says, where it can be
# tested on a running cdspd:
#   1. it listens on nothing: no TCP, raw or packet socket; its only inet
#      sockets are the UDP senders, and their drop-all receive filter makes
#      the kernel drop every datagram sent to them (a burst of garbage at
#      the sender's port: the socket's drop counter grows by as many, its
#      receive queue stays empty, the datagrams going out stay valid);
#   2. it needs no privilege: as root, it runs as nobody with every
#      capability dropped and streams as usual;
#   3. systemd's sandbox: `systemd-analyze security` of daemon/cdspd.service
#      (offline: the unit need not be installed), its exposure printed;
#   4. hostile files are refused with status 2 and a message naming them:
#      a config or calibration that never ends (/dev/zero, /dev/urandom),
#      a calibration too large for any camera or with a non-finite focal
#      length, a recording directory that cannot be written.
. "$(dirname "$0")/lib.sh"
simd=(--calib "$CALIB" --radius 10 --set sim.frames=4 --set sim.away=0 --set sim.rate=50
      --set stats_interval=0)

echo "--- 1. sockets of a running cdspd"
start_rx rx --validate --duration 60 --idle 3 --min-poses 40 --truth sim --calib "$CALIB" \
    --set radius=10 --set sim.frames=4 --set sim.away=0 --set sim.rate=50
start_cdspd d "${simd[@]}" --dest 127.0.0.1:$RX_PORT
wait_log "$work/d.log" "sim: open" 60 || fail "cdspd did not start"
sleep 0.5
inodes=$(for f in /proc/$d_pid/fd/*; do readlink "$f"; done | sed -n 's/^socket:\[\([0-9]*\)\]$/\1/p')
echo "cdspd's sockets: $(echo $inodes | wc -w)"
# /proc/net/*: column 10 is the inode (2 local address, 5 tx:rx queues,
# 13 drops for UDP); in hex
in_table() { awk -v ino="$2" 'NR > 1 && $10 == ino' "/proc/net/$1" 2>/dev/null; }
udp_ports=()
for ino in $inodes; do
    for t in tcp tcp6 raw raw6; do
        [ -z "$(in_table $t "$ino")" ] || fail "cdspd has a $t socket (inode $ino)"
    done
    awk -v ino="$ino" '$9 == ino' /proc/net/packet 2>/dev/null | grep -q . && fail "cdspd has a packet socket"
    for t in udp udp6; do
        line=$(in_table $t "$ino")
        [ -n "$line" ] || continue
        hexport=$(echo "$line" | awk '{ split($2, a, ":"); print a[2] }')
        udp_ports+=("$t:$((16#$hexport)):$ino")
        echo "  $t socket, local port $((16#$hexport)) (the sender's ephemeral port)"
    done
done
# ss lists an unconnected UDP socket under -l too: shown, the check is above
command -v ss >/dev/null && ss -tuanwp 2>/dev/null | grep -F "pid=$d_pid," | sed 's/^/  ss: /' 
[ ${#udp_ports[@]} -ge 1 ] || fail "no UDP sender socket found"
for u in "${udp_ports[@]}"; do
    IFS=: read -r t port ino <<<"$u"
    [ "$t" = udp ] || continue
    drops0=$(in_table udp "$ino" | awk '{ print $13 }')
    for _ in $(seq 200); do
        head -c 320 /dev/urandom >/dev/udp/127.0.0.1/"$port" 2>/dev/null
    done
    printf 'CDSP\001\001' >/dev/udp/127.0.0.1/"$port" 2>/dev/null
    sleep 0.3
    line=$(in_table udp "$ino")
    drops1=$(echo "$line" | awk '{ print $13 }')
    rxq=$(echo "$line" | awk '{ split($5, q, ":"); print q[2] }')
    echo "  201 datagrams sent to port $port: dropped by the kernel $((drops1 - drops0)), queued $((16#$rxq)) bytes"
    [ $((drops1 - drops0)) -ge 201 ] || fail "only $((drops1 - drops0)) of 201 datagrams dropped at port $port"
    [ $((16#$rxq)) -eq 0 ] || fail "datagrams queued at cdspd's port $port"
done
sleep 0.5
kill -TERM "$d_pid"
wait_for "$d_pid" 10 || fail "cdspd exit status $? after SIGTERM"
wait_for "$rx_pid" 10 || fail "the datagrams cdspd sent while being fed garbage"
cat "$work/rx.out"

echo "--- 2. no privilege needed"
if [ "$(id -u)" -ne 0 ] || ! command -v setpriv >/dev/null; then
    echo "SKIP: needs root and setpriv to drop to nobody"
else
    chmod o+rx "$work" "$(dirname "$work")" 2>/dev/null
    start_rx rx2 --validate --duration 60 --idle 3 --min-poses 40
    setpriv --reuid=nobody --regid=nogroup --clear-groups --inh-caps=-all --bounding-set=-all \
        --no-new-privs "$CDSPD" "${simd[@]}" --dest 127.0.0.1:$RX_PORT --duration 1.5 \
        >"$work/d2.out" 2>"$work/d2.log" &
    d2_pid=$!; pids+=("$d2_pid")
    for _ in $(seq 100); do
        [ -r /proc/$d2_pid/status ] && grep -q "sim: open" "$work/d2.log" && break; sleep 0.1
    done
    grep -E '^(Uid|CapEff|CapBnd|NoNewPrivs):' /proc/$d2_pid/status 2>/dev/null | sed 's/^/  /'
    wait_for "$d2_pid" 60 || fail "cdspd as nobody without capabilities: exit status $?"
    wait_for "$rx2_pid" 10 || fail "receiver (cdspd as nobody)"
    cat "$work/rx2.out"
fi

echo "--- 3. the systemd sandbox (systemd-analyze security, offline)"
if ! command -v systemd-analyze >/dev/null; then
    echo "SKIP: no systemd-analyze"
else
    sed "s#/usr/local/bin/cdspd#$(cd "$(dirname "$CDSPD")" && pwd)/$(basename "$CDSPD")#" \
        daemon/cdspd.service >"$work/cdspd.service"
    if timeout 60 systemd-analyze security --offline=yes "$work/cdspd.service" >"$work/sa.out" 2>&1; then
        grep -F "Overall exposure level" "$work/sa.out" | sed 's/^→ */  /'
        score=$(sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p' "$work/sa.out")
        # systemd's scale: 0 (sandboxed) .. 10 (exposed); "OK" is below 2.5 (docs/security.md)
        awk -v s="${score:-10}" 'BEGIN { exit !(s < 2.5) }' || fail "exposure $score, expected below 2.5"
    else
        echo "SKIP: systemd-analyze security --offline does not work here:"
        tail -3 "$work/sa.out"
    fi
fi

echo "--- 4. hostile files: refused with status 2, named"
expect_rc 2 zero_cfg "$CDSPD" --config /dev/zero --check-config
expect_msg zero_cfg "/dev/zero: file exceeds the limit"
expect_rc 2 rand_cal "$CDSPD" --calib /dev/urandom --radius 10 --dest 127.0.0.1:9 --check-config
expect_msg rand_cal "/dev/urandom: file exceeds the limit"
printf 'image_width: 16385\nimage_height: 16385\ncamera_matrix: {rows: 3, cols: 3, data: [1000, 0, 8000, 0, 1000, 8000, 0, 0, 1]}\n' >"$work/huge.yaml"
expect_rc 2 huge_cal "$CDSPD" --calib "$work/huge.yaml" --radius 10 --dest 127.0.0.1:9 --check-config
expect_msg huge_cal "huge.yaml"
printf 'image_width: 640\nimage_height: 480\ncamera_matrix: {rows: 3, cols: 3, data: [.nan, 0, 320, 0, 500, 240, 0, 0, 1]}\n' >"$work/nan.yaml"
expect_rc 2 nan_cal "$CDSPD" --calib "$work/nan.yaml" --radius 10 --dest 127.0.0.1:9 --check-config
expect_msg nan_cal "nan.yaml"
if [ "$(id -u)" -ne 0 ]; then
    mkdir -p "$work/ro" && chmod a-w "$work/ro"
    expect_rc 2 ro_rec "$CDSPD" "${simd[@]}" --dest 127.0.0.1:9 --record "$work/ro/rec" --check-config
else
    expect_rc 2 ro_rec "$CDSPD" "${simd[@]}" --dest 127.0.0.1:9 --record /proc/cdspd-rec --check-config
fi
grep -h "record" "$work/ro_rec.err" | head -1
echo "PASS: security: no listening socket, incoming datagrams dropped by the kernel, runs unprivileged, sandbox rated, hostile files refused"
