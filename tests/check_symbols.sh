#!/usr/bin/env bash
# libcdsp must not allocate, print or exit: no undefined reference to any of
# these may appear in the archives given as arguments.
set -u
forbidden='malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|vprintf|puts|fputs|putchar|fwrite|exit|_exit|abort|fopen|__assert_fail|__assert_func|stdout|stderr'
rc=0
for a in "$@"; do
    nm_tool=nm
    case "$a" in *m4f*|*m3*|*m7*) nm_tool=arm-none-eabi-nm ;; esac
    case "$a" in *riscv*) nm_tool=riscv64-unknown-elf-nm ;; esac
    bad=$($nm_tool -u "$a" | awk '{print $NF}' | grep -Ew "^($forbidden)$" | sort -u)
    if [ -n "$bad" ]; then
        echo "FAIL $a references: $bad"; rc=1
    else
        echo "ok   $a: undefined symbols are only: $($nm_tool -u "$a" | awk '{print $NF}' | sort -u | tr '\n' ' ')"
    fi
done
exit $rc
