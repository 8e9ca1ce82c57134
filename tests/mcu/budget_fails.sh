#!/usr/bin/env bash
# budget_fails.sh SIZE.PY-COMMAND... MAP...: the budget check can fail.
# Reads the three measured figures of the M4F points path (size.py with
# limits it cannot exceed), then for each budget in turn: a limit equal to
# the figure must pass (the budget is "at most"), one byte below it must
# fail with exit status 1 and a FAIL line naming that budget, its limit and
# the measured figure, while the other two pass.
set -u
maps=() cmd=()
for a in "$@"; do
    case "$a" in *.map) maps+=("$a") ;; *) cmd+=("$a") ;; esac
done
big=2147483647
report=$("${cmd[@]}" --budget flash=$big --budget ram=$big --budget stack=$big "${maps[@]}") || {
    echo "FAIL size.py did not run"; exit 1; }
declare -A val
for b in flash ram stack; do
    val[$b]=$(echo "$report" | awk -v b="$b" '$1 == b && $3 == "B" && $4 == "of" {print $2}')
    if ! [[ "${val[$b]}" =~ ^[0-9]+$ ]]; then
        echo "FAIL no measured figure for budget $b in size.py's report"; exit 1
    fi
done
rc=0
for b in flash ram stack; do
    for lim in "${val[$b]}" $(( ${val[$b]} - 1 )); do
        args=()
        for o in flash ram stack; do
            args+=(--budget "$o=$([ "$o" = "$b" ] && echo "$lim" || echo $big)")
        done
        out=$("${cmd[@]}" "${args[@]}" --enforce "${maps[@]}"); st=$?
        fails=$(echo "$out" | grep '^FAIL budget' || true)
        if [ "$lim" -eq "${val[$b]}" ]; then
            if [ $st -ne 0 ] || [ -n "$fails" ]; then
                echo "FAIL $b limit = measured ${val[$b]} B: exit $st, $fails"; rc=1
            else
                echo "ok   $b limit = measured ${val[$b]} B: met"
            fi
        else
            want="FAIL budget $b (m4f, points path, "
            if [ $st -ne 1 ] || [ "$(echo "$fails" | grep -c .)" -ne 1 ] ||
               [[ "$fails" != "$want"*"measured ${val[$b]} B > limit $lim B" ]]; then
                echo "FAIL $b limit $lim B (one short): exit $st, '$fails'"; rc=1
            else
                echo "ok   $b limit $lim B: exit 1, $fails"
            fi
        fi
    done
done
exit $rc
