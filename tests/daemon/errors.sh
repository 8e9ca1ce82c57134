#!/usr/bin/env bash
# tests/daemon/errors.sh: cdspd's failure behaviour, each with its message
# and exit status (docs/cdspd.md, EXIT STATUS):
#   usage and configuration errors -> 2, naming the option/key and problem;
#   --check-config prints a configuration that reads back;
#   a source that cannot be opened -> 3 after open_timeout;
#   SIGHUP with a broken file keeps the running configuration (datagrams go
#   on, sequence continuous), a good file is applied, SIGUSR1 logs the
#   statistics, SIGTERM stops at once with 0;
#   in namespaces of its own (tests/daemon/netns.sh): an unreachable
#   destination next to a reachable one, broadcast and multicast, and a
#   full disk under --record.
. "$(dirname "$0")/lib.sh"

base=(--calib "$CALIB" --radius 10 --dest 127.0.0.1:9)

echo "--- usage and configuration errors: exit status 2"
expect_rc 2 usage "$CDSPD" --no-such-option
expect_msg usage "usage: cdspd"
expect_rc 2 extra "$CDSPD" "${base[@]}" stray-argument
expect_msg extra "unexpected argument 'stray-argument'"
expect_rc 2 nocalib "$CDSPD" --radius 10 --dest 127.0.0.1:9
expect_msg nocalib "key 'calib': required"
expect_rc 2 noradius "$CDSPD" --calib "$CALIB" --dest 127.0.0.1:9
expect_msg noradius "key 'radius': required"
expect_rc 2 nodest "$CDSPD" --calib "$CALIB" --radius 10
expect_msg nodest "key 'dest': required"
expect_rc 2 badradius "$CDSPD" --calib "$CALIB" --radius ten --dest 127.0.0.1:9
expect_msg badradius "--radius: key 'radius': expected a number"
expect_rc 2 badset "$CDSPD" "${base[@]}" --set sim.rate=fast
expect_msg badset "--set: key 'sim.rate': expected a number in [0, 100000], got 'fast'"
expect_rc 2 pointfit "$CDSPD" "${base[@]}" --set solver.point_fit=true
expect_msg pointfit "key 'solver.point_fit': needs solver.refine_step 3 or more"
expect_rc 2 badsource "$CDSPD" "${base[@]}" --source webcam
expect_msg badsource "key 'source': unknown source 'webcam'"
expect_rc 2 baddest "$CDSPD" --calib "$CALIB" --radius 10 --dest 127.0.0.1:99999
expect_msg baddest "key 'dest': '127.0.0.1:99999': port '99999'"
printf 'image_width: 640\nimage_height: 480\ncamera_matrix: {rows: 3, cols: 3, data: [1, 2]}\n' >"$work/broken-cam.yaml"
expect_rc 2 badcalib "$CDSPD" --calib "$work/broken-cam.yaml" --radius 10 --dest 127.0.0.1:9
expect_msg badcalib "broken-cam.yaml"
printf 'radius: 10\nsim:\n  rate: 25\n  frame: 8\n' >"$work/typo.yaml"
expect_rc 2 typo "$CDSPD" --config "$work/typo.yaml" --calib "$CALIB" --dest 127.0.0.1:9
expect_msg typo "typo.yaml:4:3: unknown key 'sim.frame'"
expect_rc 2 noconfig "$CDSPD" --config "$work/missing.yaml" "${base[@]}"
expect_msg noconfig "missing.yaml"
expect_rc 2 checkbad "$CDSPD" --config "$work/typo.yaml" --check-config --calib "$CALIB" --dest 127.0.0.1:9

echo "--- --check-config"
expect_rc 0 check "$CDSPD" "${base[@]}" --set sim.rate=30 --format json --check-config
grep -q '^# cdspd: configuration OK' "$work/check.out" || fail "--check-config said nothing"
cp "$work/check.out" "$work/effective.yaml"
expect_rc 0 recheck "$CDSPD" --config "$work/effective.yaml" --check-config
cmp -s <(tail -n +2 "$work/check.out") <(tail -n +2 "$work/recheck.out") ||
    fail "the printed configuration does not read back to itself"
grep -q '^format: json' "$work/recheck.out" && grep -q '^  rate: 30' "$work/recheck.out" ||
    fail "--check-config lost the command line's values"

echo "--- the example configuration is valid and shows every key"
expect_rc 0 example "$CDSPD" --config daemon/cdspd.yaml --calib "$CALIB" --check-config
diff <(grep -v '^#' "$work/example.out" | sed 's/:.*//') \
     <(grep -v '^ *#' daemon/cdspd.yaml | grep -E '^ *[a-z0-9_]+:' | sed 's/:.*//') ||
    fail "daemon/cdspd.yaml does not list the keys cdspd has, in its order"

echo "--- a source that is not there: exit status 3"
expect_rc 3 nofiles "$CDSPD" "${base[@]}" --source "file:$work/none/*.pgm" --set open_timeout=1 --set retry_min=0.2
expect_msg nofiles "no file matches"
expect_msg nofiles "gave up after open_timeout"
if "$CDSPD" --version | grep -q '^sources:.* v4l2'; then
    expect_rc 3 nov4l2 "$CDSPD" "${base[@]}" --source v4l2:/dev/video-cdspd-none --set open_timeout=1
    expect_msg nov4l2 "v4l2: cannot open /dev/video-cdspd-none: No such file or directory"
fi
if "$CDSPD" --version | grep -q '^sources:.* libcamera'; then
    # no camera on this machine (a real one would be found and used)
    expect_rc 3 nolibcamera "$CDSPD" "${base[@]}" --source libcamera --set open_timeout=1
    expect_msg nolibcamera "libcamera: no camera found"
    expect_rc 3 nolibcamera2 "$CDSPD" "${base[@]}" --source libcamera:/base/cdspd-none --set open_timeout=1
    expect_msg nolibcamera2 "libcamera: no camera"
else
    expect_rc 2 nolibcamera "$CDSPD" "${base[@]}" --source libcamera
    expect_msg nolibcamera "the libcamera source is not built in"
fi

echo "--- systemd: the unit, and the notifications (READY, WATCHDOG, RELOADING, STOPPING)"
if command -v systemd-analyze >/dev/null 2>&1; then
    sed "s#/usr/local/bin/cdspd#$(cd "$(dirname "$CDSPD")" && pwd)/$(basename "$CDSPD")#" \
        daemon/cdspd.service >"$work/cdspd.service"
    systemd-analyze verify "$work/cdspd.service" || fail "systemd-analyze verify daemon/cdspd.service"
    # the template (several cameras): verified as an instance, and the same
    # unit as cdspd.service but for the instance's config, state and user
    sed "s#/usr/local/bin/cdspd#$(cd "$(dirname "$CDSPD")" && pwd)/$(basename "$CDSPD")#" \
        daemon/cdspd@.service >"$work/cdspd@front.service"
    systemd-analyze verify "$work/cdspd@front.service" || fail "systemd-analyze verify daemon/cdspd@.service"
    diff <(sed -e '1,/^\[Unit\]/d' -e 's#/etc/cdspd/cdspd.yaml#/etc/cdspd/%i.yaml#' \
               -e 's#^Description=cdsp capture daemon: pipe axis poses from a camera,#Description=cdsp capture daemon %i: pipe axis poses from camera %i,#' \
               -e 's#^StateDirectory=cdspd$#StateDirectory=cdspd/%i#' -e 's#^User=cdspd$#User=cdspd-%i#' \
               daemon/cdspd.service) <(sed '1,/^\[Unit\]/d' daemon/cdspd@.service) ||
        fail "daemon/cdspd@.service differs from daemon/cdspd.service beyond the instance's lines"
fi
if [ -x "${NOTIFY_RX:-}" ] && "$CDSPD" --version | grep -q '^sd_notify: yes'; then
    sock=$(cd "$work" && pwd)/notify.sock   # NOTIFY_SOCKET must be absolute
    "$NOTIFY_RX" "$sock" 30 >"$work/notify.out" 2>"$work/notify.err" &
    npid=$!; pids+=("$npid")
    for _ in $(seq 50); do [ -S "$sock" ] && break; sleep 0.1; done
    NOTIFY_SOCKET=$sock WATCHDOG_USEC=400000 start_cdspd dn "${base[@]}" \
        --set sim.frames=8 --set sim.rate=50 --duration 3
    wait_log "$work/dn.log" "sim: open" 20 || fail "cdspd (notify) did not start"
    sleep 1
    kill -HUP "$dn_pid"
    wait_for "$dn_pid" 20 || fail "cdspd (notify) exit status $?"
    sleep 0.3
    kill -TERM "$npid"; wait "$npid" 2>/dev/null
    cat "$work/notify.out" | sort -k2 | uniq -c -f1 | sed 's/^/  /'
    grep -q " READY=1" "$work/notify.out" || fail "no READY=1"
    grep -q " RELOADING=1" "$work/notify.out" || fail "no RELOADING=1 on SIGHUP"
    grep -q " STOPPING=1" "$work/notify.out" || fail "no STOPPING=1"
    [ "$(grep -c " WATCHDOG=1" "$work/notify.out")" -ge 8 ] || fail "the watchdog was fed too rarely"
    grep -q "not feeding the watchdog" "$work/dn.log" && fail "the watchdog was not fed while all ran"
    # READY comes after the source opened (the sim renders first)
    [ "$(grep -m1 -n " READY=1" "$work/notify.out" | cut -d: -f1)" -le \
      "$(grep -m1 -n " STOPPING=1" "$work/notify.out" | cut -d: -f1)" ] || fail "READY after STOPPING"
fi

echo "--- --frames: a run of a known length"
# exactly 12 frames processed (the processing thread ends the stream after
# the 12th, whatever the machine's speed), then exit status 0
start_cdspd df "${base[@]}" --set sim.rate=50 --set stats_interval=0 --frames 12 --duration 120
wait_for "$df_pid" 150 || fail "cdspd --frames: exit status $?"
grep -q -- "--frames 12 reached: stopping" "$work/df.log" || fail "cdspd --frames: no stop message"
nproc=$(sed -n 's/.*final: .*processed \([0-9]*\) .*/\1/p' "$work/df.log")
[ "${nproc:-0}" -eq 12 ] || fail "cdspd --frames 12 processed '$nproc' frames"
echo "--frames 12: $nproc frames processed"

echo "--- signals: SIGHUP with a broken file keeps running; a good one is applied"
cat >"$work/run.yaml" <<YAML
source: sim
calib: $CALIB
radius: 10
sim: {frames: 8, rate: 50, away: 0}
stats_interval: 0
YAML
start_rx rx --config "$work/run.yaml" --truth sim --duration 60 --idle 3 --min-poses 100
echo "dest: [127.0.0.1:$RX_PORT]" >>"$work/run.yaml"
cp "$work/run.yaml" "$work/good.yaml"
start_cdspd d --config "$work/run.yaml"
wait_log "$work/d.log" "sim: open" 20 || fail "cdspd did not start"
sleep 1
printf 'radius: [10\nsim: {frames: 8\n' >"$work/run.yaml"
kill -HUP "$d_pid"
wait_log "$work/d.log" "keeping the running configuration" 5 || fail "no message on a broken reload"
grep -F "reload: $work/run.yaml:" "$work/d.log" | head -1
sleep 1
kill -0 "$d_pid" 2>/dev/null || fail "cdspd died on a broken reload"
sed 's/^stats_interval: 0/stats_interval: 0\nstatus_interval: 0.4/' "$work/good.yaml" >"$work/run.yaml"
kill -HUP "$d_pid"
wait_log "$work/d.log" "reloaded: source sim" 5 || fail "a good reload was not applied"
wait_log "$work/d.log" "sim: open" 10 || fail "no frames after the reload"
sleep 1
kill -USR1 "$d_pid"
wait_log "$work/d.log" "SIGUSR1: " 5 || fail "no statistics on SIGUSR1"
grep "SIGUSR1: " "$work/d.log"
t0=$(date +%s%N)
kill -TERM "$d_pid"
wait_for "$d_pid" 5; rc=$?
t1=$(date +%s%N)
[ $rc -eq 0 ] || fail "SIGTERM: exit status $rc, expected 0"
echo "SIGTERM -> exit 0 in $(( (t1 - t0) / 1000000 )) ms"
[ $(( (t1 - t0) / 1000000 )) -lt 2000 ] || fail "SIGTERM took over 2 s"
wait_for "$rx_pid" 10 || fail "the receiver saw a gap or a wrong pose across the reloads"
cat "$work/rx.out"

echo "--- namespaces: unreachable destination, broadcast, multicast, full disk"
if [ "$(id -u)" -ne 0 ] || ! unshare -n -m true 2>/dev/null; then
    echo "SKIP: network and mount namespaces need root (unshare -n -m)"
else
    unshare -n -m -- bash "$(dirname "$0")/netns.sh" "$work" || fail "tests in namespaces"
fi
echo "PASS: errors and signals"
