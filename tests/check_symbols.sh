#!/usr/bin/env bash
# libcdsp must not allocate, print or exit: no symbol the archive needs from
# outside may be one of these. Prints what each archive does need. It must
# also keep no mutable global state (reentrancy): no .data or .bss symbols.
set -u
forbidden='malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|vprintf|puts|fputs|putchar|fwrite|exit|_exit|abort|fopen|__assert_fail|__assert_func|stdout|stderr'
rc=0
for a in "$@"; do
    nm_tool=nm
    case "$a" in *m4f*|*m3*|*m7*) nm_tool=arm-none-eabi-nm ;; esac
    case "$a" in *riscv*) nm_tool=riscv64-unknown-elf-nm ;; esac
    defined=$($nm_tool -g --defined-only "$a" 2>/dev/null | awk 'NF == 3 {print $3}' | sort -u)
    needed=$($nm_tool -u "$a" | awk 'NF == 2 {print $2}' | sort -u | comm -23 - <(echo "$defined"))
    bad=$(echo "$needed" | grep -Ew "^($forbidden)$")
    if [ -n "$bad" ]; then
        echo "FAIL $a needs: $(echo $bad)"; rc=1
    else
        echo "ok   $a needs only: $(echo $needed)"
    fi
    # symbol types d/D (.data), b/B (.bss), c/C (common): mutable globals or statics
    state=$($nm_tool "$a" | awk 'NF == 3 && $2 ~ /^[dDbBcC]$/ {print $3}' | sort -u)
    if [ -n "$state" ]; then
        echo "FAIL $a has mutable global/static state: $(echo $state)"; rc=1
    else
        echo "ok   $a has no mutable global or static data"
    fi
done
exit $rc
