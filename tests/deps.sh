#!/usr/bin/env bash
# tests/deps.sh MODE [GROUP...]: the Debian packages the project needs,
# listed per component in .ci/packages.d/GROUP.txt (whitespace-separated
# names, '#' comments). With no GROUP, or GROUP "all": every list.
#   check    exit 2, naming the missing packages and the command that
#            installs them, if any is not installed; else exit 0
#   ensure   install the missing ones: as root with apt-get, as a user with
#            non-interactive sudo through `sudo -n`; otherwise do what
#            `check` does (exit 2, before anything is compiled)
#   install  the same as ensure (`make deps`)
#   list     print the packages, one line
# `make demo` ensures the group "demo" (what the demo builds and runs, not
# OpenCV, qemu or the VM kernel), `make check` every group, `make` the
# build groups (checks only: a plain build never installs).
# apt-get runs non-interactively; `apt-get update` first when the package
# lists are empty, and once more if an install fails on stale lists.
# Exit status: 0 all present (or installed), 1 apt-get failed, 2 missing
# and not installable from here, or a usage error.
set -u
cd "$(dirname "$0")/.." || exit 2
mode=${1:-check}
[ $# -gt 0 ] && shift
groups=("$@")
[ ${#groups[@]} -eq 0 ] && groups=(all)

files=()
for g in "${groups[@]}"; do
    if [ "$g" = all ]; then
        files+=(.ci/packages.d/*.txt)
    elif [ -f ".ci/packages.d/$g.txt" ]; then
        files+=(".ci/packages.d/$g.txt")
    else
        echo "tests/deps.sh: no package list .ci/packages.d/$g.txt" >&2
        exit 2
    fi
done
# '#' starts a comment, to the end of its line
pkgs=$(sed 's/#.*//' "${files[@]}" | tr -s ' \t\n' '\n' | grep -v '^$' | sort -u | tr '\n' ' ')

missing_pkgs() {
    # one dpkg-query for all; a package dpkg has never heard of prints
    # nothing on stdout and counts as missing
    local installed p out=""
    # shellcheck disable=SC2086
    installed=$(dpkg-query -W -f='${Package} ${Status}\n' $pkgs 2>/dev/null |
                awk '$NF == "installed" && $(NF-1) == "ok" {print $1}')
    for p in $pkgs; do
        grep -qx "$p" <<<"$installed" || out="$out $p"
    done
    echo "${out# }"
}

what="${groups[*]}"
[ "$what" = all ] && what="make check"

case "$mode" in
list)
    echo "$pkgs"; exit 0 ;;
check|ensure|install) ;;
*)
    echo "usage: tests/deps.sh check|ensure|install|list [GROUP...]" >&2; exit 2 ;;
esac

if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "tests/deps.sh: this is not a Debian system (no dpkg-query); install the equivalents of:" >&2
    echo "  $pkgs" >&2
    exit 2
fi
missing=$(missing_pkgs)
[ -z "$missing" ] && exit 0

sudo=""
if [ "$mode" != check ] && [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
        sudo="sudo -n"
    else
        mode=check # nothing to install with: say what to run
    fi
fi
if [ "$mode" = check ]; then
    n=$(wc -w <<<"$missing")
    echo "cdsp ($what) needs $n Debian package(s) that are not installed:" >&2
    echo "  $missing" >&2
    if [ "$(id -u)" -eq 0 ]; then
        echo "install them with:  apt-get install $missing   (or: make deps)" >&2
    else
        echo "install them with:  sudo apt-get install $missing   (or: sudo make deps)" >&2
    fi
    exit 2
fi

export DEBIAN_FRONTEND=noninteractive
apt_install() {
    # shellcheck disable=SC2086
    $sudo apt-get install -y -q --no-install-recommends $missing
}
echo "cdsp ($what): installing $(wc -w <<<"$missing") Debian package(s):$(printf ' %s' $missing)" >&2
if ! compgen -G "/var/lib/apt/lists/*_Packages*" >/dev/null; then
    echo "cdsp: the package lists are empty: apt-get update first" >&2
    $sudo apt-get update -q || exit 1
fi
if ! apt_install; then
    echo "cdsp: apt-get install failed: updating the package lists and trying once more" >&2
    $sudo apt-get update -q || exit 1
    apt_install || exit 1
fi
missing=$(missing_pkgs)
if [ -n "$missing" ]; then
    echo "cdsp: still not installed after apt-get: $missing" >&2
    exit 1
fi
exit 0
