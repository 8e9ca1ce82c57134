#!/usr/bin/env bash
# tests/daemon/fields.sh: one field list everywhere. The names come from
# the programs' own output (not typed here):
#   1. the fields of `cdsp_tool solve`'s and `overlay`'s JSON records (a pose
#      and an error) = the table "JSON records" of docs/cdsp_tool.md;
#   2. the fields of cdspd's JSON datagrams (a pose, a no-pipe, with
#      sim.truth) = the table "JSON record" of docs/protocol.md;
#   3. the pose fields (those of a pose record that an error lacks) are the
#      same, in the same order, in solve and cdspd, and in both tables;
#   4. solve --csv's header = the JSON record's fields flattened by the one
#      rule of docs/cdsp_tool.md (vector _x _y _z, per contour _1 _2, lines
#      _1_a .., nested sigma.point -> sigma_point_x), in the JSON order,
#      for a pose and for an error.
# Needs CDSP_TOOL and jq besides lib.sh's variables.
. "$(dirname "$0")/lib.sh"
[ -x "${CDSP_TOOL:-}" ] || { echo "$0: \$CDSP_TOOL must name cdsp_tool" >&2; exit 2; }

# table_fields DOC HEADING: the first column of the first table after the
# heading line, backquotes removed, one per line.
table_fields() {
    awk -v h="$2" '$0 == h { s = 1; next } s && /^\| `/ { t = 1; split($0, c, "|");
        gsub(/[ `]/, "", c[2]); print c[2]; next } t { exit }' "$1"
}
# keys FILE: top-level keys of each JSON line, in order, one per line (a union, first seen first)
keys() { jq -r 'keys_unsorted[]' "$1" | awk '!seen[$0]++'; }
# pose_keys FILE: keys of the pose records that no error record has, in order
pose_keys() {
    comm -23 <(jq -r 'select(.status == "ok") | keys_unsorted[]' "$1" | awk '!seen[$0]++' | sort) \
             <(jq -r 'select(.status == "error") | keys_unsorted[]' "$1" | sort -u) >"$work/pk.set"
    jq -r 'select(.status == "ok") | keys_unsorted[]' "$1" | awk '!seen[$0]++' | grep -Fxf "$work/pk.set"
}
same() { # NAME A B: the two files list the same lines
    diff "$2" "$3" >"$work/diff.txt" || { cat "$work/diff.txt" >&2; fail "$1"; }
}

frames=$work/frames
timeout -k 5 120 "$CDSP_TOOL" sim --calib "$CALIB" -n 2 --out "$frames" -p 0,0,400 -d 0.1,1,0.05 \
    -r 10 >"$work/sim.out" 2>&1 || fail "cdsp_tool sim"
printf 'P5\n2 2\n255\nxx' >"$frames/cut.pgm"   # a truncated raster: an error record

echo "--- 1. cdsp_tool solve / overlay JSON = docs/cdsp_tool.md"
"$CDSP_TOOL" solve --calib "$frames/camera.yaml" --radius 10 "$frames"/frame_0000.pgm \
    "$frames/cut.pgm" >"$work/solve.jsonl" 2>/dev/null
"$CDSP_TOOL" overlay --calib "$frames/camera.yaml" --radius 10 --out "$work/ov" \
    "$frames"/frame_0000.pgm >"$work/overlay.jsonl" 2>/dev/null || fail "cdsp_tool overlay"
[ "$(grep -c '"status":"ok"' "$work/solve.jsonl")" -eq 1 ] &&
    [ "$(grep -c '"status":"error"' "$work/solve.jsonl")" -eq 1 ] || fail "solve: not one pose, one error"
cat "$work/solve.jsonl" "$work/overlay.jsonl" >"$work/tool.jsonl"
table_fields docs/cdsp_tool.md "## JSON records" | sort >"$work/doc_tool.txt"
keys "$work/tool.jsonl" | sort >"$work/out_tool.txt"
same "docs/cdsp_tool.md's JSON table and solve/overlay's fields differ (< doc, > output)" \
    "$work/doc_tool.txt" "$work/out_tool.txt"
echo "$(wc -l <"$work/doc_tool.txt") fields"

echo "--- 2. cdspd JSON = docs/protocol.md"
# a free port: the test receiver binds port 0, says which, and is stopped
start_rx probe --duration 30
kill -TERM "$probe_pid"; wait "$probe_pid" 2>/dev/null
listen_port=$RX_PORT
# the listener re-emits JSON datagrams as they came
start_cdspd d2 --calib "$CALIB" --radius 10 --set sim.frames=8 --set sim.away=0.25 --set sim.rate=50 \
    --set sim.truth=true --format json --dest "127.0.0.1:$listen_port" --duration 1 \
    --set stats_interval=0
"$CDSP_TOOL" listen "127.0.0.1:$listen_port" --json --duration 60 >"$work/daemon.jsonl" \
    2>"$work/listen.err" &
lpid=$!; pids+=("$lpid") # (cdspd pre-renders for a second or more: the listener is up by then)
wait_for "$d2_pid" 90 || fail "cdspd: exit status $?"
sleep 0.3; kill -TERM "$lpid"; wait "$lpid" 2>/dev/null
[ "$(grep -c '"status":"ok"' "$work/daemon.jsonl")" -ge 1 ] &&
    [ "$(grep -c '"error":"no-pipe"\|"error":"few-points"' "$work/daemon.jsonl")" -ge 1 ] ||
    fail "cdspd: not both a pose and a no-pipe datagram"
table_fields docs/protocol.md "## JSON record" | sort >"$work/doc_daemon.txt"
keys "$work/daemon.jsonl" | sort >"$work/out_daemon.txt"
same "docs/protocol.md's JSON table and cdspd's fields differ (< doc, > output)" \
    "$work/doc_daemon.txt" "$work/out_daemon.txt"
echo "$(wc -l <"$work/doc_daemon.txt") fields"

echo "--- 3. the pose fields: one list, one order"
pose_keys "$work/solve.jsonl" >"$work/pose_tool.txt"
pose_keys "$work/daemon.jsonl" >"$work/pose_daemon.txt"
same "solve's and cdspd's pose fields differ" "$work/pose_tool.txt" "$work/pose_daemon.txt"
table_fields docs/cdsp_tool.md "## JSON records" | grep -Fxf "$work/pose_tool.txt" >"$work/pd1.txt"
table_fields docs/protocol.md "## JSON record" | grep -Fxf "$work/pose_tool.txt" >"$work/pd2.txt"
same "docs/cdsp_tool.md lists the pose fields in another order" "$work/pose_tool.txt" "$work/pd1.txt"
same "docs/protocol.md lists the pose fields in another order" "$work/pose_tool.txt" "$work/pd2.txt"
tr '\n' ' ' <"$work/pose_tool.txt"; echo

echo "--- 4. solve --csv = the JSON fields, flattened"
"$CDSP_TOOL" solve --calib "$frames/camera.yaml" --radius 10 --csv "$frames"/frame_0000.pgm \
    "$frames/cut.pgm" >"$work/solve.csv" 2>/dev/null
head -1 "$work/solve.csv" | tr ',' '\n' >"$work/csv_cols.txt"
# the flattening rule of docs/cdsp_tool.md, applied to each JSON record
flat='def ix($k; $i; $n): if $n == 2 then ($i + 1 | tostring)
          elif $k == "lines" then ["a", "b", "c"][$i] else ["x", "y", "z"][$i] end;
      . as $r | [paths(type != "array" and type != "object") as $p | $p | . as $q
        | [range(0; length) as $j | $q[$j]
           | if type == "number" then ix($q[0]; .; ($r | getpath($q[0:$j]) | length)) else . end]
        | join("_")] | .[]'
for status in ok error; do
    grep "\"status\":\"$status\"" "$work/solve.jsonl" | jq -r "$flat" >"$work/flat_$status.txt"
    grep -Fxf "$work/flat_$status.txt" "$work/csv_cols.txt" >"$work/csv_$status.txt"
    same "the CSV header, restricted to a $status record's fields, is not that record flattened" \
        "$work/flat_$status.txt" "$work/csv_$status.txt"
done
sort -u "$work/flat_ok.txt" "$work/flat_error.txt" >"$work/flat_all.txt"
sort "$work/csv_cols.txt" >"$work/csv_sorted.txt"
same "the CSV has columns the JSON records lack, or lacks some" "$work/flat_all.txt" "$work/csv_sorted.txt"
echo "$(wc -l <"$work/csv_cols.txt") columns"
echo "PASS: one field list"
