#!/bin/sh
# tests/mutants/run.sh OUT TABLE [id,id,...] - the mutation score (make mutants).
#
# Each row of TABLE (tests/mutants/mutants.txt) is one small deliberate
# error: a literal substitution in one file. For each row: copy the base
# tree (OUT/base: the tracked and new files of this tree, built once),
# replace FROM by TO in FILE, where FROM must occur exactly once (a pattern
# that no longer matches is a broken mutant and fails the run loudly, never
# a caught one), rebuild only what the change touches, and run the row's
# suites in order until one fails. A failing (or hanging: 300 s) suite is a
# caught mutant; all passing is a missed one. The score is caught / total.
# Exit status: 0 every mutant caught, 1 some missed, 2 a broken mutant or a
# baseline suite failing (nothing can be scored then).
#
# Suites (column 5, in the order to run): host:NAME / float:NAME (one lib
# test, tests/lib/NAME.c, in that build), host / float (every lib test of
# that build not run yet), tool (tests/tool/test_tool_cli against the
# mutated cdsp_tool), hostunit:NAME (tests/tool/NAME.c, a host library
# suite), daemon:NAME (tests/daemon/NAME.c, a cdspd unit suite).
set -u
out=$1
table=$2
only=${3:-}
root=$(pwd)
base=$out/base
jobs=${MUTANT_JOBS:-2}
mkdir -p "$out/logs"

die() { echo "mutants: $*" >&2; exit 2; }

# --- the base tree: tracked + untracked-not-ignored files, build inside -----
mkdir -p "$base"
git ls-files -co --exclude-standard -z | (cd "$root" && xargs -0 cp -p --parents -t "$base") ||
    die "cannot copy the tree into $base"
# what the table's suites need built
suites_col=$(grep -v '^#' "$table" | grep '|' | awk -F'|' '{print $5}')
targets="mutant-lib-host mutant-lib-float"
echo "$suites_col" | grep -qw tool && targets="$targets mutant-tool"
echo "$suites_col" | grep -q 'hostunit:' && targets="$targets mutant-hostunit"
echo "$suites_col" | grep -q 'daemon:' && targets="$targets mutant-daemon"
echo "mutants: building the base tree ($base)"
# build_targets DIR TARGET...: one make per target, each -j$jobs inside: the
# mutant-* targets are sub-makes that share prerequisites (libcdsp_host.a),
# which two sub-makes running at once would both write
build_targets() {
    local d=$1 t
    shift
    for t in "$@"; do
        make -C "$d" --no-print-directory -j"$jobs" "$t" || return 1
    done
}
build_targets "$base" $targets >"$out/logs/base-build.log" 2>&1 ||
    die "the base tree does not build; see $out/logs/base-build.log"

lib_tests=$(cd "$base" && ls tests/lib/test_*.c | sed 's|tests/lib/||; s|\.c$||')

# run_suites DIR LOG SUITES...: 0 all passed, 1 one failed (its name in $failed)
run_suites() {
    dir=$1
    log=$2
    shift 2
    ran=" "
    failed=
    for s in "$@"; do
        case $s in
        host | float) list=$(for t in $lib_tests; do echo "$s:$t"; done) ;;
        *) list=$s ;;
        esac
        for one in $list; do
            case "$ran" in *" $one "*) continue ;; esac
            ran="$ran$one "
            case $one in
            tool)
                (cd "$dir" && CDSP_TOOL=build/cdsp_tool timeout 600 build/tests/tool/test_tool_cli) \
                    >>"$log" 2>&1 ;;
            hostunit:*)
                t=${one#*:}
                (cd "$dir" && timeout 300 "build/tests/tool/$t") >>"$log" 2>&1 ;;
            daemon:*)
                t=${one#*:}
                mkdir -p "$dir/build/tests/daemon/tmp"
                (cd "$dir" && CDSPD_TMP=build/tests/daemon/tmp timeout 300 "build/tests/daemon/$t") \
                    >>"$log" 2>&1 ;;
            host:* | float:*)
                v=${one%%:*}
                t=${one#*:}
                [ -x "$dir/build/$v/mtests/$t" ] || { echo "no suite $one" >>"$log"; return 3; }
                (cd "$dir" && timeout 300 "build/$v/mtests/$t") >>"$log" 2>&1 ;;
            *) echo "unknown suite $one" >>"$log"; return 3 ;;
            esac
            rc=$?
            if [ $rc -ne 0 ]; then
                failed=$one
                [ $rc -eq 124 ] && failed="$one (timeout)"
                return 1
            fi
        done
    done
    return 0
}

# --- baseline: every suite the table names passes on the unmutated tree ----
# (MUTANTS_NO_BASELINE=1 skips it: quick reruns of a few rows only)
if [ "${MUTANTS_NO_BASELINE:-0}" != 1 ]; then
all_suites=$(grep -v '^#' "$table" | grep '|' | awk -F'|' '{print $5}' | tr ' ' '\n' | sort -u | tr '\n' ' ')
echo "mutants: baseline ($all_suites)"
run_suites "$base" "$out/logs/base-run.log" $all_suites
case $? in
0) ;;
1) die "baseline suite $failed fails on the unmutated tree; see $out/logs/base-run.log" ;;
*) die "baseline: see $out/logs/base-run.log" ;;
esac
fi

rm -f "$out/score"
tab=$(printf '\t')
grep -v '^#' "$table" | grep '|' | while IFS='|' read -r id file from to suites what; do
    id=$(echo "$id" | tr -d ' ')
    file=$(echo "$file" | tr -d ' ')
    from=$(echo "$from" | sed 's/^ //; s/ $//')
    to=$(echo "$to" | sed 's/^ //; s/ $//')
    if [ -n "$only" ]; then
        case ",$only," in *",$id,"*) ;; *) continue ;; esac
    fi
    dir=$out/m-$id
    log=$out/logs/$id.log
    rm -rf "$dir"
    cp -a "$base" "$dir"
    [ -f "$dir/$file" ] || { echo "BROKEN $id: no file $file"; echo "broken $id" >>"$out/score"; continue; }
    # exactly one literal occurrence of FROM, replaced by TO
    n=$(MUT_FROM=$from perl -0ne '$c = () = /\Q$ENV{MUT_FROM}\E/g; print $c' "$dir/$file")
    if [ "$n" != 1 ]; then
        echo "BROKEN $id: '$from' occurs $n times in $file (want exactly 1)"
        echo "broken $id" >>"$out/score"
        rm -rf "$dir"
        continue
    fi
    MUT_FROM=$from MUT_TO=$to perl -0pi -e 's/\Q$ENV{MUT_FROM}\E/$ENV{MUT_TO}/' "$dir/$file"
    # the substituted file only: rebuild what depends on it
    touch "$dir/$file"
    btargets=
    for s in $suites; do
        case $s in
        host | host:*) btargets="$btargets mutant-lib-host" ;;
        float*) btargets="$btargets mutant-lib-float" ;;
        tool) btargets="$btargets mutant-tool" ;;
        hostunit:*) btargets="$btargets mutant-hostunit" ;;
        daemon:*) btargets="$btargets mutant-daemon" ;;
        esac
    done
    btargets=$(echo $btargets | tr ' ' '\n' | sort -u | tr '\n' ' ')
    { echo "mutant $id: $file: '$from' -> '$to'"; echo "$what"; } >"$log"
    # (stdin from /dev/null: the loop reads the table from stdin, and a
    # suite that reads its own, cdsp_tool's "-" inputs, would take the
    # rows left)
    if ! build_targets "$dir" $btargets >>"$log" 2>&1 </dev/null; then
        echo "BROKEN $id: does not build ($what); see $log"
        echo "broken $id" >>"$out/score"
        rm -rf "$dir"
        continue
    fi
    run_suites "$dir" "$log" $suites </dev/null
    case $? in
    0) echo "missed  $id${tab}$file: $what"; echo "missed $id" >>"$out/score" ;;
    1) echo "caught  $id${tab}by $failed${tab}$file: $what"; echo "caught $id" >>"$out/score" ;;
    *) echo "BROKEN $id: suites ($suites); see $log"; echo "broken $id" >>"$out/score" ;;
    esac
    rm -rf "$dir"
done | tee "$out/report.txt"

[ -f "$out/score" ] || die "no mutant ran"
total=$(wc -l <"$out/score")
ncaught=$(grep -c '^caught' "$out/score")
nmissed=$(grep -c '^missed' "$out/score")
nbroken=$(grep -c '^broken' "$out/score")
echo "mutants: score $ncaught / $total caught ($nmissed missed, $nbroken broken); logs in $out/logs" |
    tee -a "$out/report.txt"
[ "$nbroken" -eq 0 ] || exit 2
[ "$nmissed" -eq 0 ] || exit 1
exit 0
