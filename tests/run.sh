#!/usr/bin/env bash
# tests/run.sh RESULTS NAME CMD...: run one check step, show its output, and
# append "NAME PASSED FAILED" to RESULTS. cmocka suites report their own
# counts; any other command counts as one test, passed iff it exits 0.
set -u
results=$1 name=$2; shift 2
out=$(mktemp)
"$@" >"$out" 2>&1
rc=$?
cat "$out"
passed=$(sed -n 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' "$out" | awk '{s+=$1} END {print s+0}')
failed=$(sed -n 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' "$out" | awk '{s+=$1} END {print s+0}')
if ! grep -q '^\[==========\] .* ran\.' "$out"; then   # not a cmocka suite
    if [ $rc -eq 0 ]; then passed=1; failed=0; else passed=0; failed=1; fi
elif [ $rc -ne 0 ] && [ "$failed" -eq 0 ]; then        # crashed after its summary
    failed=1
fi
rm -f "$out"
echo "$name $passed $failed" >>"$results"
[ "$failed" -eq 0 ] && [ $rc -eq 0 ]
