# tests/daemon/lib.sh: helpers of the daemon's end-to-end scripts (sourced).
# Every process started here is recorded and stopped on exit; every wait is
# bounded. Needs CDSPD, CDSPD_RX (and CDSP_LISTEN where used) in the
# environment (daemon/daemon.mk sets them) and CDSPD_TMP for scratch files.
set -u
for v in CDSPD CDSPD_RX; do
    [ -x "${!v:-}" ] || { echo "$0: \$$v must name the built program" >&2; exit 2; }
done
mkdir -p "${CDSPD_TMP:-/tmp}" || exit 2
mkdir -p "${CDSPD_TMP:-/tmp}" && work=$(mktemp -d "${CDSPD_TMP:-/tmp}/$(basename "$0" .sh).XXXXXX") || exit 2
CALIB=daemon/demo-camera.yaml
pids=()

# CDSPD_SAN set (daemon/sanitize.mk): cdspd is a sanitizer build. Every
# finding goes to $work/san.PID (log_path), and a script that leaves one
# fails at its exit whatever else it checked.
if [ -n "${CDSPD_SAN:-}" ]; then
    for v in ASAN_OPTIONS UBSAN_OPTIONS TSAN_OPTIONS; do
        export "$v=${!v:+${!v}:}log_path=$work/san"
    done
fi
san_reports() {
    local f found=1
    for f in "$work"/san.*; do
        [ -s "$f" ] || continue
        echo "FAIL: sanitizer report $(basename "$f"):" >&2
        head -n 60 "$f" >&2
        found=0
    done
    return $found
}

cleanup() {
    local p
    for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null; done
    for p in "${pids[@]}"; do
        for _ in $(seq 30); do kill -0 "$p" 2>/dev/null || break; sleep 0.1; done
        kill -KILL "$p" 2>/dev/null
        wait "$p" 2>/dev/null
    done
    local rc=0
    [ -n "${CDSPD_SAN:-}" ] && san_reports && rc=1
    [ -n "${KEEP_TMP:-}" ] || rm -rf "$work"
    [ $rc -eq 0 ] || exit 1
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

fail() {
    echo "FAIL: $*" >&2
    local f
    for f in "$work"/*.log "$work"/*.err "$work"/*.out; do
        [ -s "$f" ] || continue
        echo "--- $(basename "$f") (last 25 lines)" >&2
        tail -n 25 "$f" >&2
    done
    exit 1    # cleanup (the EXIT trap) shows any sanitizer report
}

# start_rx NAME ARGS...: cdspd_rx in the background; sets RX_PORT and NAME_pid.
# Its counts so far are in NAME.progress (wait_rx).
start_rx() {
    local name=$1; shift
    rm -f "$work/$name.port" "$work/$name.progress"
    # --progress is cdspd_rx's (wait_rx reads it); other receivers started
    # through here (mavlink_rx) do not take it
    local progress=()
    [ "$(basename "$CDSPD_RX")" = cdspd_rx ] && progress=(--progress "$work/$name.progress")
    "$CDSPD_RX" --port-file "$work/$name.port" "${progress[@]}" "$@" \
        >"$work/$name.out" 2>"$work/$name.err" &
    local pid=$!
    pids+=("$pid")
    eval "${name}_pid=$pid"
    for _ in $(seq 50); do
        [ -s "$work/$name.port" ] && { RX_PORT=$(cat "$work/$name.port"); return 0; }
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    fail "cdspd_rx $name did not start"
}

# start_cdspd NAME ARGS...: cdspd in the background, log in NAME.log; sets NAME_pid.
start_cdspd() {
    local name=$1; shift
    "$CDSPD" "$@" >"$work/$name.out" 2>"$work/$name.log" &
    local pid=$!
    pids+=("$pid")
    eval "${name}_pid=$pid"
}

# CDSPD_WAIT_SCALE (integer, default 1): every bound of wait_for and
# wait_log multiplied by it, for the sanitizer builds (daemon/sanitize.mk),
# which run several times slower; the waits end as soon as the event comes.
scale=${CDSPD_WAIT_SCALE:-1}

# wait_for PID SECONDS: its exit status, or 124 (and it is killed) after SECONDS.
wait_for() {
    local pid=$1 n=$(( $2 * 10 * scale ))
    while [ $n -gt 0 ]; do
        if ! kill -0 "$pid" 2>/dev/null; then
            wait "$pid"
            return $?
        fi
        sleep 0.1
        n=$((n - 1))
    done
    kill -KILL "$pid" 2>/dev/null
    wait "$pid" 2>/dev/null
    return 124
}

# wait_log FILE PATTERN SECONDS: until grep finds PATTERN in FILE.
wait_log() {
    local n=$(( $3 * 10 * scale ))
    while [ $n -gt 0 ]; do
        grep -q -- "$2" "$1" 2>/dev/null && return 0
        sleep 0.1
        n=$((n - 1))
    done
    return 1
}

# wait_rx NAME COUNT MIN SECONDS: until receiver NAME has counted at least
# MIN of COUNT (received, poses, statuses, source-down, bad, reconnects), or
# fail after SECONDS. Tests wait for counts, not for time, so what they
# assert does not change with the machine's speed (a slow machine only
# waits longer; SECONDS is a bound on a hang, far above the time needed).
wait_rx() {
    local name=$1 key=$2 min=$3 n=$(( $4 * 10 )) v
    while [ $n -gt 0 ]; do
        v=$(sed -n "s/.*\(^\| \)$key \([0-9]*\).*/\2/p" "$work/$name.progress" 2>/dev/null)
        [ -n "$v" ] && [ "$v" -ge "$min" ] && return 0
        sleep 0.1
        n=$((n - 1))
    done
    fail "$name: $key ${v:-0} after $4 s, expected at least $min"
}

# expect_rc WANT NAME CMD...: run CMD (bounded 30 s), its exit status must be WANT.
expect_rc() {
    local want=$1 name=$2 rc; shift 2
    timeout -k 5 30 "$@" >"$work/$name.out" 2>"$work/$name.err"
    rc=$?
    [ $rc -eq "$want" ] || fail "$name: exit status $rc, expected $want"
}

# expect_msg NAME TEXT: NAME.err (or .log) holds TEXT.
expect_msg() {
    grep -qF -- "$2" "$work/$1.err" "$work/$1.log" 2>/dev/null ||
        fail "$1: expected the message '$2'"
}
