#!/usr/bin/env bash
# tests/tool/update_docs.sh [CDSP_TOOL] [DOC]: refresh the manual pages in
# docs/cdsp_tool.md from the tool's own --help, between the markers
#   <!-- help:COMMAND -->  ...  <!-- /help:COMMAND -->
# test_tool_cli checks that the document and --help agree, so run this
# after changing a command's options or help text.
set -euo pipefail
tool=${1:-build/cdsp_tool}
doc=${2:-docs/cdsp_tool.md}
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
cp "$doc" "$tmp"
for cmd in $(sed -n 's/^<!-- help:\([a-z]*\) -->$/\1/p' "$doc"); do
    help=$(mktemp)
    "$tool" "$cmd" --help >"$help"
    awk -v cmd="$cmd" -v helpfile="$help" '
        $0 == "<!-- help:" cmd " -->" {
            print; print "```text"
            while ((getline line < helpfile) > 0) print line
            print "```"; skip = 1; next
        }
        $0 == "<!-- /help:" cmd " -->" { skip = 0 }
        !skip { print }
    ' "$tmp" >"$tmp.new"
    mv "$tmp.new" "$tmp"
    rm -f "$help"
done
cp "$tmp" "$doc"
