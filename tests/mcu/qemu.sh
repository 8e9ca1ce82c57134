#!/usr/bin/env bash
# tests/mcu/qemu.sh TIMEOUT BOARD ELF OUT: run a firmware image on a QEMU
# MPS2 board with semihosting, its output shown and saved to OUT.
# Exit status: the firmware's own (0 = main returned 0), 1 on a fault
# (startup.c's handler), 124 when it ran longer than TIMEOUT seconds
# (hung: QEMU is killed), 2 on a usage error or a missing file.
set -u
if [ $# -ne 4 ]; then
    echo "usage: tests/mcu/qemu.sh TIMEOUT BOARD ELF OUT" >&2
    exit 2
fi
timeout_s=$1 board=$2 elf=$3 out=$4
if [ ! -f "$elf" ]; then
    echo "qemu.sh: $elf: no such firmware image" >&2
    exit 2
fi
command -v qemu-system-arm >/dev/null || { echo "qemu.sh: qemu-system-arm is not installed (Debian: qemu-system-arm)" >&2; exit 2; }
mkdir -p "$(dirname "$out")"
timeout --kill-after=5 "$timeout_s" qemu-system-arm -M "$board" \
    -semihosting-config enable=on,target=native -nographic -monitor none -serial none \
    -kernel "$elf" >"$out.tmp" 2>&1 </dev/null
rc=$?
cat "$out.tmp"
mv "$out.tmp" "$out"
case $rc in
0) ;;
124|137) echo "qemu.sh: $elf on $board: no exit within ${timeout_s} s (hung firmware?), killed" >&2; rc=124 ;;
*) echo "qemu.sh: $elf on $board exited with status $rc" >&2 ;;
esac
exit $rc
