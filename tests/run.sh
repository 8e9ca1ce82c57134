#!/usr/bin/env bash
# tests/run.sh RESULTS NAME CMD...: run one check step, show its output, and
# append "NAME PASSED FAILED SECONDS" to RESULTS. cmocka suites report their own
# counts; any other command counts as one test, passed iff it exits 0.
set -u
results=$1 name=$2; shift 2
out=$(mktemp)
t0=$(date +%s)
"$@" >"$out" 2>&1
rc=$?
cat "$out"
# cmocka writes its summary to stderr and the rest to stdout, so lines can
# interleave: match anywhere in a line.
passed=$(grep -o '\[  PASSED  \] [0-9]* test' "$out" | awk '{s+=$4} END {print s+0}')
failed=$(grep -o '\[  FAILED  \] [0-9]* test' "$out" | awk '{s+=$4} END {print s+0}')
if ! grep -q 'test(s) run\.' "$out"; then   # not a cmocka suite
    if [ $rc -eq 0 ]; then passed=1; failed=0; else passed=0; failed=1; fi
elif [ $rc -ne 0 ] && [ "$failed" -eq 0 ]; then        # crashed after its summary
    failed=1
fi
rm -f "$out"
echo "$name $passed $failed $(( $(date +%s) - t0 ))" >>"$results"
[ "$failed" -eq 0 ] && [ $rc -eq 0 ]
