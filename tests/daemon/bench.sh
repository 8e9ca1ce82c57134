#!/usr/bin/env bash
# tests/daemon/bench.sh [FAKECAM]: cdspd's figures for `make bench`.
#   1. sim source, the paper's camera (2448 x 2048, f = 3478.26 px), a
#      slowly moving pipe (tracking mode), frames as fast as the capture
#      thread copies them: processed frames per second with the processing
#      thread pinned to one core, and ready -> sent latency under that load;
#   2. the same at 200 frames per second: ready -> sent latency p50/p99;
#   3. the fake GigE Vision camera at 2048 x 2048, 25 fps (the paper's
#      camera: 23 fps at 2448 x 2048): frames dropped by cdspd (pool drops,
#      Aravis buffer underruns) must be 0.
# The numbers come from cdspd's own statistics line over a window opened by
# SIGUSR1 once the source runs and closed by SIGTERM. Prints a table; exit
# status 0 (figures, not a test), 1 when a step could not run.
. "$(dirname "$0")/lib.sh"
fakecam=${1:-}
cat >"$work/paper.yaml" <<'YAML'
image_width: 2448
image_height: 2048
camera_matrix: {rows: 3, cols: 3, data: [3478.26, 0, 1223.5, 0, 3478.26, 1023.5, 0, 0, 1]}
distortion_model: plumb_bob
distortion_coefficients: {rows: 1, cols: 5, data: [0, 0, 0, 0, 0]}
YAML
seconds=${BENCH_SECONDS:-8}
ncpu=$(nproc)
pin=(--set proc_cpu=0); [ "$ncpu" -ge 2 ] && pin+=(--set capture_cpu=1)

# window NAME OPEN_PATTERN: SIGUSR1 once OPEN_PATTERN is logged, SIGTERM after
# $seconds; leaves the final statistics line in $line.
window() {
    local name=$1 pat=$2 pid
    pid=$(eval echo "\$${name}_pid")
    wait_log "$work/$name.log" "$pat" 120 || fail "$name: the source did not open"
    sleep 1
    kill -USR1 "$pid"
    sleep "$seconds"
    kill -TERM "$pid"
    wait_for "$pid" 30 || fail "$name: exit status $?"
    line=$(grep "final: " "$work/$name.log")
}
field() { sed -n "s/.*$1 \([0-9.]*\)\(\/s\)\{0,1\}.*/\1/p" <<<"$line" | head -n1; }
lat()   { sed -n "s/.*ready->sent p50 \([0-9.]*\) ms p99 \([0-9.]*\) ms.*/\1 \2/p" <<<"$line"; }

sim=(--calib "$work/paper.yaml" --radius 10 --dest 127.0.0.1:9 --set sim.frames=4 --set sim.away=0
     --set "sim.sway=[0.5, 0, 1]" --set sim.tilt_deg=0.2 --set sim.nod_deg=0.2 --set stats_interval=0
     "${pin[@]}")
echo "bench-daemon: rendering 4 frames of 2448x2048 per run (about 10 s each)..."
start_cdspd s0 "${sim[@]}" --set sim.rate=0
window s0 "sim: open"
fps0=$(sed -n 's/.*processed [0-9]* (\([0-9.]*\)\/s).*/\1/p' <<<"$line")
read -r p50_0 p99_0 <<<"$(lat)"
start_cdspd s1 "${sim[@]}" --set sim.rate=200
window s1 "sim: open"
fps1=$(sed -n 's/.*processed [0-9]* (\([0-9.]*\)\/s).*/\1/p' <<<"$line")
drop1=$(sed -n 's/.*dropped \([0-9]*\), bad.*/\1/p' <<<"$line")
read -r p50_1 p99_1 <<<"$(lat)"

gige="not run (no fake camera)"
if [ -n "$fakecam" ] && [ -x "$fakecam" ]; then
    exec 8>/tmp/cdsp-fakecam-gvcp.lock
    flock -w 300 8 || fail "the fake camera's lock is held by another test for 300 s"
    # the camera draws its 4 poses before it says ready (about 1.5 s each
    # here), then serves them at the full rate
    "$fakecam" -i 127.0.0.1 --duration 600 --cycle 4 --size 2048x2048 --rate 25 >"$work/cam.out" 2>"$work/cam.err" &
    cam=$!; pids+=("$cam")
    wait_log "$work/cam.out" "^cdsp_fakecam: ready" 300 || fail "cdsp_fakecam did not start"
    cat "$work/cam.out"
    cat >"$work/fc.yaml" <<'YAML'
image_width: 2048
image_height: 2048
camera_matrix: {rows: 3, cols: 3, data: [2560, 0, 1023.5, 0, 2560, 1023.5, 0, 0, 1]}
distortion_model: plumb_bob
distortion_coefficients: {rows: 1, cols: 5, data: [-0.05, 0.01, 0, 0, 0]}
YAML
    start_cdspd g --source aravis:127.0.0.1 --calib "$work/fc.yaml" --radius 10 --dest 127.0.0.1:9 \
        --set stats_interval=0 "${pin[@]}"
    window g "aravis:127.0.0.1: open"
    kill -TERM "$cam"; wait "$cam" 2>/dev/null
    fpsg=$(sed -n 's/.*processed [0-9]* (\([0-9.]*\)\/s).*/\1/p' <<<"$line")
    dropg=$(sed -n 's/.*dropped \([0-9]*\), bad.*/\1/p' <<<"$line")
    badg=$(sed -n 's/.*, bad \([0-9]*\), status.*/\1/p' <<<"$line")
    under=$(sed -n 's/.*, \([0-9]*\) underruns.*/\1/p' "$work/g.log" | tail -n1)
    read -r p50_g p99_g <<<"$(lat)"
    gige="$fpsg fps processed; dropped by cdspd: $dropg (pool) + $under (Aravis underruns); incomplete from the network: $badg; ready->sent p50 $p50_g ms, p99 $p99_g ms"
fi

verdict() { awk -v v="$1" -v t="$2" -v op="$3" 'BEGIN { ok = (op == ">=") ? v >= t : v < t; print ok ? "met" : "MISSED" }'; }
echo
echo "== cdspd (2 cores, shared; processing thread pinned to CPU 0)"
printf '| %-58s | %-26s | %-12s |\n' figure measured target
printf '| %-58s | %-26s | %-12s |\n' "sim 2448x2048, tracked: processed fps, as fast as possible" "$fps0" ">= 200: $(verdict "$fps0" 200 '>=')"
printf '| %-58s | %-26s | %-12s |\n' "  ready->sent latency p50 / p99 at that load" "$p50_0 / $p99_0 ms" ""
printf '| %-58s | %-26s | %-12s |\n' "sim 2448x2048 at 200 fps: processed fps (dropped)" "$fps1 ($drop1)" ""
printf '| %-58s | %-26s | %-12s |\n' "  ready->sent latency p50 / p99" "$p50_1 / $p99_1 ms" "p99 < 5 ms: $(verdict "$p99_1" 5 '<')"
echo "fake GigE camera 2048x2048 at 25 fps: $gige"
