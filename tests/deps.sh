#!/usr/bin/env bash
# Debian packages the project needs, listed per component in
# .ci/packages.d/*.txt (whitespace-separated names, '#' comments).
#   tests/deps.sh check    - exit 1, saying exactly what to run, if any is missing
#   tests/deps.sh install  - apt-get install them (root, or through sudo)
set -u
cd "$(dirname "$0")/.."
# '#' starts a comment, to the end of its line
pkgs=$(sed 's/#.*//' .ci/packages.d/*.txt 2>/dev/null | tr -s ' \t\n' '\n' | grep -v '^$' | sort -u | tr '\n' ' ')
missing=""
for p in $pkgs; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing="$missing $p"
done
case "${1:-check}" in
check)
    if [ -n "$missing" ]; then
        echo "make check needs Debian packages that are not installed:$missing" >&2
        echo "install them with:  sudo make deps   (or: sudo apt-get install$missing)" >&2
        exit 1
    fi ;;
install)
    [ -z "$missing" ] && exit 0
    sudo=""; [ "$(id -u)" -ne 0 ] && sudo="sudo"
    export DEBIAN_FRONTEND=noninteractive
    $sudo apt-get update -q || exit 1
    # shellcheck disable=SC2086
    $sudo apt-get install -y -q --no-install-recommends $missing || exit 1 ;;
*)
    echo "usage: tests/deps.sh check|install" >&2; exit 2 ;;
esac
