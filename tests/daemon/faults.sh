#!/usr/bin/env bash
# tests/daemon/faults.sh: faults injected into a running cdspd, each with the
# behaviour docs/cdspd.md and README "Operations" promise (every datagram
# checked by cdspd_rx --validate, see there):
#   1. file: frames of mixed sizes and depths, a truncated and a non-image
#      file: usable frames solved, the others counted bad (bad-frame
#      datagrams for frames smaller than the calibration's), exit 0 at the end;
#   2. the receiver gone (ICMP port unreachable) and back on the same port:
#      the daemon keeps sending, the returning receiver sees seq carry on;
#   3. a SIGHUP storm: 100 reloads, valid and broken files alternating,
#      while streaming: every broken one refused, every valid one applied,
#      poses in every window of ten reloads, seq continuous throughout;
#   3b. SIGHUP and SIGUSR1 sent while the configuration is still being read
#      (from a FIFO): held, then taken (a reload, a report), never fatal;
#   4. the recording directory removed, then (another run) made read-only:
#      recording stops with one error line, datagrams go on, exit 0;
#   5. the wall clock stepped back an hour and forward two (an LD_PRELOAD
#      shim, CLOCKSHIM): t_host_us (CLOCK_MONOTONIC) stays monotonic, seq
#      continuous, frames paced as before, poses within tolerance;
#   6. in a network namespace of its own (root): the receiver firewalled by
#      nftables, dropped on input (silent loss) and rejected on output
#      (EPERM: counted, logged at most once per 10 s), then let through
#      again: sending resumes and is logged;
#   7. the aravis source (FAKECAM given): a pixel format the camera does
#      not offer -> status 3 naming it; the camera frozen (SIGSTOP: it stops
#      answering without closing anything) and thawed: source-down, then
#      reopened, poses again.
# Usage: faults.sh [FAKECAM]. Exit status 0 when all pass.
. "$(dirname "$0")/lib.sh"
fakecam=${1:-}

# A small camera: the sim renders in tenths of a second (each valid reload
# of the storm renders again).
cat >"$work/cam.yaml" <<YAML
image_width: 320
image_height: 240
camera_matrix: {rows: 3, cols: 3, data: [400, 0, 159.5, 0, 400, 119.5, 0, 0, 1]}
distortion_model: plumb_bob
distortion_coefficients: {rows: 1, cols: 5, data: [-0.05, 0.01, 0, 0, 0]}
YAML
cam=$work/cam.yaml
simk=(--set radius=10 --set sim.frames=4 --set sim.away=0)
simd=(--calib "$cam" --radius 10 --set sim.frames=4 --set sim.away=0 --set stats_interval=0)

echo "--- 1. file: frames of mixed sizes and depths, broken files"
rec=$work/rec
start_rx rx0 --duration 60 --idle 3
start_cdspd d0 "${simd[@]}" --set sim.rate=20 --dest 127.0.0.1:$RX_PORT --duration 1 \
    --record "$rec" --set record_every=1
wait_for "$d0_pid" 60 || fail "cdspd (recording frames) exit status $?"
wait_for "$rx0_pid" 10 || fail "receiver (recording frames)"
mapfile -t good < <(ls "$rec"/*.pgm | head -6)
[ ${#good[@]} -eq 6 ] || fail "recorded ${#good[@]} frames, expected at least 6"
mix=$work/mix
mkdir -p "$mix"
for i in 0 1 2 3 4 5; do cp "${good[$i]}" "$mix/f$((2 * i))0.pgm"; done
# between them: a smaller frame, a larger one, a 16-bit one of the right
# size (usable: solved), a truncated file, a file that is not an image
{ printf 'P5\n160 120\n255\n'; head -c $((160 * 120)) /dev/zero; } >"$mix/f01.pgm"
{ printf 'P5\n640 480\n255\n'; head -c $((640 * 480)) /dev/zero; } >"$mix/f03.pgm"
{ printf 'P5\n320 240\n65535\n'; head -c $((320 * 240 * 2)) /dev/zero; } >"$mix/f05.pgm"
head -c 1000 "${good[0]}" >"$mix/f07.pgm"
echo "not a frame" >"$mix/f09.pgm"
n_bad=4   # f01 (smaller), f03 (larger), f07 (truncated), f09 (not an image)
start_rx rx1 --validate --duration 60 --idle 3 --min-bad $n_bad --expect-status bad-frame
start_cdspd d1 --calib "$cam" --radius 10 --source "file:$mix/*.pgm" --set file.rate=10 \
    --set stats_interval=0 --dest 127.0.0.1:$RX_PORT
wait_for "$d1_pid" 60; rc=$?
[ $rc -eq 0 ] || fail "cdspd on mixed files: exit status $rc, expected 0 at their end"
wait_for "$rx1_pid" 10 || fail "receiver (mixed files)"
cat "$work/rx1.out"
grep -q "no more frames" "$work/d1.log" || fail "the file source did not report its end"
grep -E "f0[1379]\.pgm" "$work/d1.log" | head -4
for f in f03 f07 f09; do grep -q "$f.pgm" "$work/d1.log" || fail "no message naming $f.pgm"; done
n_pose=$(sed -n 's/.*final: .* pose \([0-9]*\), no pipe.*/\1/p' "$work/d1.log")
[ "${n_pose:-0}" -ge 6 ] || fail "$n_pose poses from the 6 good frames"

echo "--- 2. the receiver gone (port unreachable) and back"
start_rx rx2 --validate --duration 60 --idle 5
port=$RX_PORT
start_cdspd d2 "${simd[@]}" --set sim.rate=50 --dest 127.0.0.1:$port
wait_log "$work/d2.log" "sim: open" 60 || fail "cdspd did not start"
sleep 1
kill -TERM "$rx2_pid"; wait_for "$rx2_pid" 10 || fail "receiver 2 (before it went)"
cat "$work/rx2.out"
last=$(sed -n 's/.*datagrams.*frames [0-9]*\.\.\([0-9]*\);.*/\1/p' "$work/rx2.out")
sleep 2   # nobody on the port: every datagram draws an ICMP port unreachable
kill -0 "$d2_pid" 2>/dev/null || fail "cdspd died while its receiver was gone"
start_rx rx3 --validate --bind 127.0.0.1:$port --duration 60 --idle 5 --min-poses 20 --truth sim \
    --calib "$cam" "${simk[@]}" --set sim.rate=50
sleep 2
kill -TERM "$d2_pid"
wait_for "$d2_pid" 10 || fail "cdspd exit status $? after SIGTERM (receiver came back)"
wait_for "$rx3_pid" 10 || fail "the receiver that came back"
cat "$work/rx3.out"
first=$(sed -n 's/.*datagrams.*frames \([0-9]*\)\.\.[0-9]*;.*/\1/p' "$work/rx3.out")
[ "${first:-0}" -gt "${last:-0}" ] || fail "frames did not carry on ($last before, $first after)"
grep -q "send errors 0" "$work/d2.log" || echo "(send errors counted while the port was closed)"

echo "--- 3. SIGHUP storm: 100 reloads, valid and broken alternating, while streaming"
cat >"$work/good.yaml" <<YAML
source: sim
calib: $cam
radius: 10
sim: {frames: 2, rate: 50, away: 0}
stats_interval: 0
YAML
start_rx rx4 --validate --config "$work/good.yaml" --truth sim --duration 900 --idle 10 \
    --min-poses 100
echo "dest: [127.0.0.1:$RX_PORT]" >>"$work/good.yaml"
cp "$work/good.yaml" "$work/run.yaml"
start_cdspd d4 --config "$work/run.yaml"
wait_log "$work/d4.log" "sim: open" 60 || fail "cdspd did not start"
for i in $(seq 1 100); do
    if [ $((i % 2)) -eq 1 ]; then
        case $((i % 4)) in
        1) printf 'radius: [10\nsim: {frames: 4\n' ;;             # YAML syntax
        3) sed 's/^radius: 10/radius: -1/' "$work/good.yaml" ;;    # a value out of range
        esac >"$work/run.yaml"
    else
        cp "$work/good.yaml" "$work/run.yaml"
    fi
    kill -HUP "$d4_pid"
    # one reload at a time: signals coalesce, each must be taken before the next
    if [ $((i % 2)) -eq 1 ]; then pat="keeping the running" want=$(((i + 1) / 2))
    else pat="reloaded: source" want=$((i / 2)); fi
    for _ in $(seq 300); do
        [ "$(grep -c "$pat" "$work/d4.log")" -ge $want ] && break
        kill -0 "$d4_pid" 2>/dev/null || fail "cdspd died at reload $i"
        sleep 0.1
    done
    [ "$(grep -c "$pat" "$work/d4.log")" -ge $want ] || fail "reload $i not taken within 30 s"
    if [ $((i % 10)) -eq 0 ]; then
        # poses in this window of ten reloads: once the last valid reload's
        # source is open (the sim renders its frames again at each one),
        # SIGUSR1's statistics line counts them
        for _ in $(seq 600); do
            grep -E "reloaded: source|sim: open" "$work/d4.log" | tail -1 | grep -q "sim: open" && break
            sleep 0.1
        done
        sleep 0.5
        n_before=$(grep -c "SIGUSR1: " "$work/d4.log")
        kill -USR1 "$d4_pid"
        for _ in $(seq 100); do
            [ "$(grep -c "SIGUSR1: " "$work/d4.log")" -gt "$n_before" ] && break; sleep 0.1
        done
        np=$(grep "SIGUSR1: .* pose [0-9]" "$work/d4.log" | tail -1 | sed -n 's/.* pose \([0-9]*\),.*/\1/p')
        [ "${np:-0}" -gt 0 ] || fail "no pose during reloads $((i - 9))..$i"
    fi
done
n_kept=$(grep -c "keeping the running configuration" "$work/d4.log")
n_applied=$(grep -c "reloaded: source sim" "$work/d4.log")
echo "100 SIGHUPs: $n_kept broken files refused, $n_applied valid ones applied"
[ "$n_kept" -eq 50 ] && [ "$n_applied" -eq 50 ] || fail "expected 50 refused and 50 applied"
sleep 1
kill -TERM "$d4_pid"
wait_for "$d4_pid" 10 || fail "cdspd exit status $? after the storm"
wait_for "$rx4_pid" 20 || fail "the receiver saw a gap, a bad datagram or a wrong pose in the storm"
cat "$work/rx4.out"

echo "--- 3b. SIGHUP and SIGUSR1 while the configuration is still being read"
# The configuration comes from a FIFO: cdspd waits in its open (wchan
# wait_for_partner) until the test writes it, so both signals arrive at
# that exact point on any machine. Held until the signal thread runs, they
# are then taken: one reload (of the same file: applied) and one report.
mkfifo "$work/slow.yaml"
start_cdspd d4b --config "$work/slow.yaml"
for _ in $(seq $((300 * scale))); do
    [ "$(cat /proc/"$d4b_pid"/wchan 2>/dev/null)" = wait_for_partner ] && break; sleep 0.1
done
[ "$(cat /proc/"$d4b_pid"/wchan 2>/dev/null)" = wait_for_partner ] ||
    fail "cdspd did not reach the configuration's open"
kill -HUP "$d4b_pid"
kill -USR1 "$d4b_pid"
sleep 0.2
kill -0 "$d4b_pid" 2>/dev/null || fail "a SIGHUP or SIGUSR1 during start-up killed cdspd"
# written twice: the held SIGHUP's reload reads the FIFO again; the second
# writer only once the first read is over ("starting" is logged after the
# file is closed), or both writes would reach the first read as one text
# (timeout: a writer whose reader never comes must not outlive the test)
timeout $((120 * scale)) cp "$work/good.yaml" "$work/slow.yaml" &
pids+=("$!")
wait_log "$work/d4b.log" "starting: source" 60 || fail "cdspd did not read its configuration"
timeout $((120 * scale)) cp "$work/good.yaml" "$work/slow.yaml" &
pids+=("$!")
wait_log "$work/d4b.log" "reloaded: source" 60 || fail "the SIGHUP held during start-up was not taken"
wait_log "$work/d4b.log" "SIGUSR1: " 60 || fail "the SIGUSR1 held during start-up was not taken"
kill -TERM "$d4b_pid"
wait_for "$d4b_pid" 20 || fail "cdspd exit status $? after the start-up signals"
echo "signals held during start-up: one reload and one report taken, exit 0"

echo "--- 4. the recording directory removed, then made read-only"
start_rx rx5 --validate --duration 60 --idle 3 --min-poses 40 --truth sim --calib "$cam" \
    "${simk[@]}" --set sim.rate=50
start_cdspd d5 "${simd[@]}" --set sim.rate=50 --dest 127.0.0.1:$RX_PORT --record "$work/gone" \
    --set record_every=1
wait_log "$work/d5.log" "sim: open" 60 || fail "cdspd did not start"
sleep 1
# renamed away first: atomic, whatever the writer is doing; then deleted
mv "$work/gone" "$work/gone.old" && rm -rf "$work/gone.old"
wait_log "$work/d5.log" "recording stopped" 10 || fail "no message when the directory went"
grep "recording stopped" "$work/d5.log"
[ "$(grep -c "recording stopped" "$work/d5.log")" -eq 1 ] || fail "more than one error line"
sleep 1
kill -TERM "$d5_pid"
wait_for "$d5_pid" 10 || fail "cdspd exit status $? (directory removed)"
wait_for "$rx5_pid" 10 || fail "datagrams stopped with the directory removed"
cat "$work/rx5.out"
# read-only: root writes anyway, so as root cdspd runs as nobody (it needs
# no privilege: docs/security.md); the directory is its own, then chmod a-w
ro=$work/ro
mkdir -p "$ro"
as=()
skip_ro=""
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null; then
    chown nobody "$ro"
    chmod o+rx "$work" "$(dirname "$work")" 2>/dev/null
    as=(setpriv --reuid=nobody --regid=nogroup --clear-groups)
    # a tree under a private home (/root is 0700) keeps nobody from the
    # program and the calibration: then root cannot show a read-only
    # directory, and this part is skipped
    "${as[@]}" test -x "$CDSPD" -a -r "$cam" -a -w "$ro" 2>/dev/null ||
        skip_ro="nobody cannot reach $CDSPD, $cam or $ro from here"
fi
if [ -n "$skip_ro" ]; then
    echo "SKIP: the recording directory made read-only ($skip_ro)"
else
# a sanitizer build run as nobody: its log (log_path) in a directory of
# nobody's and its suppression files copied where nobody can read them
# (the originals may sit under a private home); reports come back to
# $work/san.* after the run, where cleanup's check finds them
san_env=()
if [ -n "${CDSPD_SAN:-}" ] && [ ${#as[@]} -gt 0 ]; then
    mkdir -p "$work/san-nobody" && chown nobody "$work/san-nobody"
    for v in ASAN_OPTIONS UBSAN_OPTIONS TSAN_OPTIONS LSAN_OPTIONS; do
        [ -n "${!v:-}" ] || continue
        val=""
        IFS=: read -r -a opts <<<"${!v}"
        for o in "${opts[@]}"; do
            case $o in
            log_path=*) o="log_path=$work/san-nobody/san" ;;
            suppressions=*)
                cp "${o#suppressions=}" "$work/$v.supp" && chmod a+r "$work/$v.supp"
                o="suppressions=$work/$v.supp" ;;
            esac
            val=${val:+$val:}$o
        done
        san_env+=("$v=$val")
    done
fi
start_rx rx6 --validate --duration 60 --idle 3 --min-poses 40
env "${san_env[@]}" "${as[@]}" "$CDSPD" "${simd[@]}" --set sim.rate=50 --dest 127.0.0.1:$RX_PORT \
    --record "$ro" --set record_every=1 >"$work/d6.out" 2>"$work/d6.log" &
d6_pid=$!; pids+=("$d6_pid")
wait_log "$work/d6.log" "sim: open" 60 || fail "cdspd (as ${as[2]:-itself}) did not start"
sleep 1
chmod a-w "$ro"
wait_log "$work/d6.log" "recording stopped" 10 || fail "no message when the directory became read-only"
grep "recording stopped" "$work/d6.log"
sleep 1
kill -TERM "$d6_pid"
wait_for "$d6_pid" 10; rc6=$?
for f in "$work"/san-nobody/san.*; do [ -e "$f" ] && mv "$f" "$work/"; done
[ $rc6 -eq 0 ] || fail "cdspd exit status $rc6 (read-only directory)"
wait_for "$rx6_pid" 10 || fail "datagrams stopped with the directory read-only"
cat "$work/rx6.out"
fi
chmod u+w "$ro"

echo "--- 5. the wall clock stepped back 1 h, then forward 2 h"
if [ -z "${CLOCKSHIM:-}" ] || [ -n "${CDSPD_SAN:-}" ]; then
    echo "SKIP: no clock shim (CLOCKSHIM), or a sanitizer build (its runtime must come first)"
else
    start_rx rx7 --validate --duration 60 --idle 3 --min-poses 150 --truth sim --calib "$cam" \
        "${simk[@]}" --set sim.rate=50
    CLOCKSHIM_STEPS="1:-3600,2.5:7200" LD_PRELOAD=$CLOCKSHIM start_cdspd d7 "${simd[@]}" \
        --set sim.rate=50 --set status_interval=0.2 --dest 127.0.0.1:$RX_PORT --duration 4 \
        --record "$work/clock" --set record_every=10
    wait_for "$d7_pid" 60 || fail "cdspd (clock stepped) exit status $?"
    wait_for "$rx7_pid" 10 || fail "receiver (clock stepped): t_host_us, seq or poses"
    cat "$work/rx7.out"
    # 4 s at 50 frames/s: about 200 frames, whatever the wall clock did
    nf=$(sed -n 's/.*final: .*frames in \([0-9]*\) .*/\1/p' "$work/d7.log")
    echo "frames in 4 s with the wall clock stepped: $nf"
    [ "${nf:-0}" -ge 150 ] && [ "${nf:-0}" -le 260 ] || fail "$nf frames in 4 s at 50/s"
fi

echo "--- 6. the receiver firewalled (nftables, own network namespace)"
if [ "$(id -u)" -ne 0 ] || ! command -v nft >/dev/null || ! unshare -n true 2>/dev/null; then
    echo "SKIP: needs root, nft (nftables) and network namespaces"
else
    unshare -n -- bash "$(dirname "$0")/firewall.sh" "$work" || fail "firewall tests"
fi

echo "--- 7. aravis: a pixel format not offered; the camera frozen and thawed"
if [ -z "$fakecam" ] || ! "$CDSPD" --version | grep -q '^sources:.* aravis'; then
    echo "SKIP: no fake camera given, or no aravis source"
else
    exec 8>/tmp/cdsp-fakecam-gvcp.lock
    flock -w 300 8 || fail "the fake camera's lock is held by another test for 300 s"
    "$fakecam" -i 127.0.0.1 --duration 600 --cycle 25 >"$work/cam.out" 2>"$work/cam.err" &
    cam_pid=$!; pids+=("$cam_pid")
    # it draws its poses before 'ready': a hang bound, not a speed requirement
    wait_log "$work/cam.out" '^cdsp_fakecam: ready' 600
    grep -q '^cdsp_fakecam: ready' "$work/cam.out" || fail "cdsp_fakecam did not start"
    # frame_timeout 5: a camera drawing slowly on a loaded machine is not lost
    arv=(--source aravis:127.0.0.1 --calib "$CALIB" --radius 10 --set retry_min=0.5 --set retry_max=2
         --set aravis.frame_timeout=5 --set stats_interval=0 --set status_interval=0.25)
    # (A pixel format the camera does not offer can no longer be produced
    # here: the fake camera now serves every format cdspd converts, and
    # tests/daemon/aravis_formats.sh runs each of them. Names cdspd does not
    # know are refused by the configuration, tests/daemon/test_config.c.)
    start_rx rx8 --validate --truth fakecam --cycle 25 --calib "$CALIB" --duration 300 --idle 30 \
        --min-poses 10 --expect-status source-down --min-reconnects 1
    start_cdspd d8 "${arv[@]}" --dest 127.0.0.1:$RX_PORT
    wait_log "$work/d8.log" "aravis:127.0.0.1: open" 30 || fail "cdspd did not open the camera"
    # poses_seen N SECONDS: SIGUSR1's windows add up to N poses (counts, not time)
    poses_seen() {
        local want=$1 got=0 n _
        for _ in $(seq "$2"); do
            n=$(grep -c "SIGUSR1: " "$work/d8.log")
            kill -USR1 "$d8_pid"
            for _ in $(seq 50); do [ "$(grep -c "SIGUSR1: " "$work/d8.log")" -gt "$n" ] && break; sleep 0.1; done
            got=$((got + $(grep "SIGUSR1: .* pose [0-9]" "$work/d8.log" | tail -1 | sed -n 's/.* pose \([0-9]*\),.*/\1/p')))
            [ $got -ge "$want" ] && return 0
            sleep 1
        done
        return 1
    }
    poses_seen 5 120 || fail "no 5 poses from the camera within 120 s"
    n_lost=$(grep -c "lost: " "$work/d8.log")
    kill -STOP "$cam_pid"
    for _ in $(seq 300); do [ "$(grep -c "lost: " "$work/d8.log")" -gt "$n_lost" ] && break; sleep 0.1; done
    [ "$(grep -c "lost: " "$work/d8.log")" -gt "$n_lost" ] || fail "cdspd did not notice the frozen camera"
    grep "lost: " "$work/d8.log" | tail -1
    sleep 1
    n_re=$(grep -c "aravis:127.0.0.1: reopened" "$work/d8.log")
    kill -CONT "$cam_pid"
    for _ in $(seq 600); do [ "$(grep -c "aravis:127.0.0.1: reopened" "$work/d8.log")" -gt "$n_re" ] && break; sleep 0.1; done
    [ "$(grep -c "aravis:127.0.0.1: reopened" "$work/d8.log")" -gt "$n_re" ] || fail "cdspd did not reopen the thawed camera"
    poses_seen 5 120 || fail "no 5 poses within 120 s after the camera was thawed"
    kill -TERM "$d8_pid"
    wait_for "$d8_pid" 10 || fail "cdspd exit status $? after SIGTERM (frozen camera)"
    sleep 0.5
    kill -TERM "$rx8_pid"   # its --idle is long (a slow camera): it sums up now
    wait_for "$rx8_pid" 10 || fail "receiver (frozen camera)"
    cat "$work/rx8.out"
    kill -TERM "$cam_pid"; wait_for "$cam_pid" 10 >/dev/null 2>&1
fi
echo "PASS: faults: mixed frames, receiver gone, SIGHUP storm, recording directory, clock steps, firewall, camera"
