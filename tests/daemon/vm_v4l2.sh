#!/usr/bin/env bash
# tests/daemon/vm_v4l2.sh CDSPD RX FEED: cdspd's v4l2 source against a real
# V4L2 driver: the kernel's vivid in a qemu VM (tests/vm/run-in-vm.sh), once
# in GREY with a corrupted frame and the device unplugged and back, once in
# YUYV, 320x240 (TCG is slow: small frames). The check
# runs inside the VM (tests/daemon/vm_inner.sh) and prints PASS/FAIL on the
# console. Exit status 0 when both pass. VM_RUNS chooses the runs
# (default "GREY-loss YUYV-plain"; daemon/sanitize.mk runs GREY-loss with
# the ASan build, with VM_CDSPD_DURATION=60: cdspd's least run time in
# the "loss" mode, 25 s by default; it runs on until the receiver has its
# poses after the reopen).
set -u
cdspd=$1 rx=$2 feed=$3
shift 3
work=$(mktemp -d "${CDSPD_TMP:-/tmp}/vm_v4l2.XXXXXX") || exit 2
trap 'rm -rf "$work"' EXIT
cp "$(dirname "$0")/cam320.yaml" "$work/cam.yaml"
rc=0
for run in ${VM_RUNS:-GREY-loss YUYV-plain}; do
    fourcc=${run%-*} mode=${run#*-}
    echo "=== v4l2 $fourcc ($mode) in the VM"
    tests/vm/run-in-vm.sh --timeout "${VM_TIMEOUT:-1200}" --format "320x240:$fourcc" \
        --file "$cdspd:/bin/cdspd" --file "$rx:/bin/cdspd_rx" --file "$feed:/bin/v4l2_feed" \
        --file "tests/daemon/vm_inner.sh:/bin/vm_inner.sh" --file "$work/cam.yaml:/etc/cdspd-cam.yaml" \
        -- sh /bin/vm_inner.sh "$fourcc" "$mode" ${VM_CDSPD_DURATION:-} || rc=1
done
exit $rc
