#!/usr/bin/env bash
# daemon/demo.sh CDSPD CDSP_TOOL SECONDS: `make demo`. cdspd on its
# simulated camera (daemon/demo-camera.yaml, a 10 mm pipe swaying in front
# of it) sends binary datagrams to 127.0.0.1; `cdsp_tool listen` prints
# every pose. Runs until Ctrl-C, or SECONDS seconds when > 0.
set -u
cdspd=$1 tool=$2 seconds=${3:-0}
port=${DEMO_PORT:-23770}
here=$(cd "$(dirname "$0")" && pwd)
dur=()
# cdspd's --duration counts from the moment its camera is open (after the
# simulated camera has rendered its frames, which takes a while on a slow
# machine); the listener runs until cdspd has stopped, however long that is.
if [ "$seconds" != 0 ]; then dur=(--duration "$seconds"); fi
args=(--calib "$here/demo-camera.yaml" --radius 10 --dest "127.0.0.1:$port" --set stats_interval=5)
# cdspd logs "rendering N frames" once; nothing streams until they are ready
echo "demo: the simulated camera pre-renders its frames (a few seconds), then poses stream;" \
     "Ctrl-C stops."
"$tool" listen "127.0.0.1:$port" &
lpid=$!
"$cdspd" "${args[@]}" "${dur[@]}" &
dpid=$!
trap 'kill -TERM $dpid $lpid 2>/dev/null' INT TERM
wait $dpid
rc=$?
sleep 0.3
kill -TERM $lpid 2>/dev/null
wait $lpid 2>/dev/null
exit $rc
