#!/usr/bin/env bash
# tests/daemon/soak.sh: cdspd on its simulated camera at full rate
# (sim.rate=0: frames as fast as they come, most of them dropped by the
# latest-wins pool) for SOAK_SECONDS (default 600; `make soak`; make check
# runs 25 s of it), with a fault every SOAK_PERIOD seconds (default 2), in
# turn:
#   a valid SIGHUP (the pipeline restarts: source, pool, recorder),
#   a broken SIGHUP (refused, the running configuration kept),
#   receiver B gone (its port closed: ICMP port unreachable) / back,
#   the recording directory removed (recording stops) / recreated (the
#   next valid reload records again),
#   and, as root in a mount namespace of its own, the recording disk
#   filled (a tmpfs of 8 MiB) / emptied.
# cdspd also sends MAVLink (udpout://) to tests/daemon/mavlink_rx --soak,
# which stays for the whole run and checks every MAVLink frame on its own
# (crc, ids, every field of each message; see there).
# Receiver A stays for the whole run and checks every datagram
# (cdspd_rx --validate: well formed, seq, the frames' t_host_us and the
# daemon's counters never backwards; every pose against the simulated
# truth); datagrams it did not get in time (loopback drops them when the
# receiver falls behind on a loaded machine) are counted and printed, not
# failed: the daemon never sees them.
#
# Resources, printed at start (after one round of every fault, when the
# allocator has seen each allocation once) and at the end:
#   open descriptors: must be equal (the daemon opens nothing per frame or
#     per fault that it does not close);
#   resident memory: may grow by at most 4 MiB. Why that much: each
#     valid reload frees and reallocates the frame pool, the sim's frames,
#     the solver's workspace (about 1.2 MiB at 320 x 240) from threads
#     that are new each time; glibc's allocator hands a new thread one of
#     up to 8 x cores arenas and keeps freed memory in them, so the first
#     reloads may touch pages of arenas not touched before. A leak of a
#     frame (77 KiB) per reload would exceed 4 MiB after 55 reloads: the
#     10-minute soak makes about 75 valid reloads.
# Exit status 0 when every check passed.
. "$(dirname "$0")/lib.sh"
SOAK_SECONDS=${SOAK_SECONDS:-600}
SOAK_PERIOD=${SOAK_PERIOD:-2}
RSS_ALLOW_KB=4096

if [ -z "${SOAK_IN_NS:-}" ] && [ "$(id -u)" -eq 0 ] && unshare -m true 2>/dev/null; then
    # a mount namespace for the small recording disk; the rest unchanged
    rm -rf "$work"
    SOAK_IN_NS=1 exec unshare -m -- bash "$0" "$@"
fi

cat >"$work/cam.yaml" <<YAML
image_width: 320
image_height: 240
camera_matrix: {rows: 3, cols: 3, data: [400, 0, 159.5, 0, 400, 119.5, 0, 0, 1]}
distortion_model: plumb_bob
distortion_coefficients: {rows: 1, cols: 5, data: [-0.05, 0.01, 0, 0, 0]}
YAML
rec=$work/disk/rec
mkdir -p "$work/disk"
small_disk=""
if [ -n "${SOAK_IN_NS:-}" ] && mount -t tmpfs -o size=8m tmpfs "$work/disk"; then
    small_disk=1
fi
mkdir -p "$rec"

start_rx rxa --validate --allow-seq-gaps --truth sim --calib "$work/cam.yaml" --set radius=10 \
    --set sim.frames=8 --duration $((SOAK_SECONDS + 120)) --idle 20 --min-poses 100
port_a=$RX_PORT
start_rx rxb --validate --allow-seq-gaps --duration $((SOAK_SECONDS + 120))
port_b=$RX_PORT
[ -x "${MAVLINK_RX:-}" ] || fail "\$MAVLINK_RX must name the built program"
CDSPD_RX=$MAVLINK_RX start_rx rxm --soak --duration $((SOAK_SECONDS + 120)) --idle 20 --min-targets 100
read -r port_m _ <<<"$RX_PORT"
cat >"$work/good.yaml" <<YAML
source: sim
calib: $work/cam.yaml
radius: 10
dest: [127.0.0.1:$port_a, 127.0.0.1:$port_b]
mavlink: [udpout://127.0.0.1:$port_m]
sim: {frames: 8, rate: 0, threads: 1}
record: $rec
record_every: 500
stats_interval: 0
YAML
cp "$work/good.yaml" "$work/run.yaml"
start_cdspd d --config "$work/run.yaml"
wait_log "$work/d.log" "sim: open" 60 || fail "cdspd did not start"

rss() { sed -n 's/^VmRSS:[^0-9]*\([0-9]*\).*/\1/p' "/proc/$d_pid/status"; }
nfd() { ls "/proc/$d_pid/fd" | wc -l; }
count() { grep -c -- "$1" "$work/d.log"; }
# wait until PATTERN is in the log COUNT times (bounded)
wait_count() {
    for _ in $(seq 300); do
        [ "$(count "$1")" -ge "$2" ] && return 0
        kill -0 "$d_pid" 2>/dev/null || fail "cdspd died"
        sleep 0.1
    done
    fail "waited 30 s for '$1' (x$2)"
}

rss_trend=()
n_hup=0 n_ok=0 n_bad=0 n_rx=0 n_rm=0 n_fill=0 k=0 rx_gone="" rss0="" fd0="" rss_max=0
t_end=$(( $(date +%s) + SOAK_SECONDS ))
while [ "$(date +%s)" -lt $t_end ] || [ $k -lt 6 ]; do
    sleep "$SOAK_PERIOD"
    kill -0 "$d_pid" 2>/dev/null || fail "cdspd died during the soak"
    case $((k % 6)) in
    0)  cp "$work/good.yaml" "$work/run.yaml"
        n_hup=$((n_hup + 1)); n_ok=$((n_ok + 1)); kill -HUP "$d_pid"
        wait_count "reloaded: source" $n_ok ;;
    1)  printf 'radius: [10\n' >"$work/run.yaml"
        n_hup=$((n_hup + 1)); n_bad=$((n_bad + 1)); kill -HUP "$d_pid"
        wait_count "keeping the running configuration" $n_bad ;;
    2)  kill -TERM "$rxb_pid"
        wait_for "$rxb_pid" 10 || fail "receiver B found an invalid datagram"
        rx_gone=1; n_rx=$((n_rx + 1)) ;;
    3)  start_rx rxb --validate --allow-seq-gaps --bind 127.0.0.1:$port_b \
            --duration $((SOAK_SECONDS + 120)); rx_gone="" ;;
    4)  mv "$rec" "$rec.old" && rm -rf "$rec.old"; n_rm=$((n_rm + 1))
        wait_count "recording stopped" $((n_rm + n_fill))
        mkdir -p "$rec" ;;
    5)  if [ -n "$small_disk" ]; then
            # the next valid reload records again; fill the disk first
            cp "$work/good.yaml" "$work/run.yaml"
            n_hup=$((n_hup + 1)); n_ok=$((n_ok + 1)); kill -HUP "$d_pid"
            wait_count "reloaded: source" $n_ok
            head -c 16m /dev/zero >"$work/disk/filler" 2>/dev/null
            n_fill=$((n_fill + 1))
            wait_count "recording stopped" $((n_rm + n_fill))
            rm -f "$work/disk/filler"
        fi ;;
    esac
    k=$((k + 1))
    r=$(rss); [ "${r:-0}" -gt $rss_max ] && rss_max=$r
    [ $((k % 6)) -eq 0 ] && rss_trend+=("$r")
    if [ $k -eq 6 ]; then
        rss0=$r fd0=$(nfd)
        echo "start (after one round of faults): resident ${rss0} KiB, ${fd0} descriptors"
    fi
done
[ -n "$rx_gone" ] && start_rx rxb --validate --allow-seq-gaps --bind 127.0.0.1:$port_b --duration 60
sleep 1
rss1=$(rss) fd1=$(nfd)
echo "end ($SOAK_SECONDS s, $k faults): resident ${rss1} KiB (max ${rss_max}), ${fd1} descriptors"
# the resident memory after every round of faults, at most 12 of them evenly spread
n_t=${#rss_trend[@]}
idx=$(for j in $(seq 0 11); do [ $n_t -gt 0 ] && echo $(( j * (n_t - 1) / 11 )); done | uniq)
echo "resident KiB after rounds of faults ($n_t rounds):$(for j in $idx; do echo -n " ${rss_trend[$j]}"; done)"
kill -USR1 "$d_pid"
wait_count "SIGUSR1: " 1
grep "SIGUSR1: .* pose [0-9]" "$work/d.log" | sed "s/.*total: /totals: /"
kill -TERM "$d_pid"
wait_for "$d_pid" 20; rc=$?
sleep 0.5   # the last datagrams in
kill -TERM "$rxa_pid" "$rxb_pid" "$rxm_pid"
wait_for "$rxa_pid" 20; rca=$?
wait_for "$rxb_pid" 20; rcb=$?
wait_for "$rxm_pid" 20; rcm=$?
[ -n "$small_disk" ] && umount "$work/disk"
cat "$work/rxa.out"
cat "$work/rxm.out"
echo "faults: $n_hup SIGHUPs ($n_ok valid, $n_bad broken), receiver B away $n_rx times," \
     "recording directory removed $n_rm times, disk filled $n_fill times$([ -n "$small_disk" ] || echo " (no small disk: not root)")"
echo "send errors: $(grep -c 'cannot send' "$work/d.log") lines logged"
[ $rc -eq 0 ] || fail "cdspd exit status $rc after SIGTERM"
[ $rca -eq 0 ] || fail "receiver A found an invalid datagram, a counter backwards or a wrong pose"
[ $rcb -eq 0 ] || fail "receiver B found an invalid datagram"
[ $rcm -eq 0 ] || { cat "$work/rxm.err" >&2; fail "the MAVLink receiver found an invalid frame"; }
grep -q "seq out of order 0" "$work/rxa.out" || fail "seq out of order at receiver A"
[ "$fd1" -eq "$fd0" ] || fail "open descriptors: $fd0 at start, $fd1 at the end"
[ $((rss1 - rss0)) -le $RSS_ALLOW_KB ] ||
    fail "resident memory grew by $((rss1 - rss0)) KiB (allowed $RSS_ALLOW_KB)"
echo "PASS: soak $SOAK_SECONDS s: resident $rss0 -> $rss1 KiB ($((rss1 - rss0)) KiB, allowed $RSS_ALLOW_KB), descriptors $fd0 -> $fd1, every datagram and MAVLink frame valid"
