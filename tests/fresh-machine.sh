#!/usr/bin/env bash
# tests/fresh-machine.sh: the README's quick start as a first-time user
# meets it (`make check-fresh`; not part of `make check`). Builds a minimal
# Debian bookworm root with debootstrap (variant minbase, plus git, make and
# ca-certificates: no compiler, no sudo, no pkg-config), copies this working
# tree into it (tracked and untracked files, not build/), and inside it with
# chroot:
#   1. as an unprivileged user without sudo, `make demo` must stop before
#      compiling anything, with exit status 2 and the apt-get command to run;
#   2. as root, `make demo` (DEMO_SECONDS, default 15) must install what it
#      needs by itself and print poses;
#   3. as root, `make check` must install the rest and pass.
# Needs root (debootstrap, chroot, mounts) and about 3 GB of disk; takes
# 15-40 minutes. The mirror is the one this machine's apt uses.
# Environment: FRESH_DIR (default /var/tmp) for the root, KEEP_ROOT=1 to
# keep it, FRESH_STEPS (default "user demo check") to run fewer steps,
# FRESH_CACHE=FILE.tar to save the untouched debootstrap result there (or,
# when FILE.tar exists, to start from it instead of running debootstrap).
# Logs: build/fresh/*.log. Exit status: 0 every step passed, 1 a step
# failed, 2 cannot run here (not root, no mirror, debootstrap failed).
set -u
here=$(cd "$(dirname "$0")/.." && pwd)
logs=$here/build/fresh
steps=${FRESH_STEPS:-user demo check}
demo_seconds=${DEMO_SECONDS:-15}
mkdir -p "$logs" || exit 2

say() { echo "fresh-machine: $*"; }
[ "$(id -u)" -eq 0 ] || { say "needs root (debootstrap, chroot, mounts)"; exit 2; }

mirror=$(sed -n 's/^URIs:[[:space:]]*//p' /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -n1 | awk '{print $1}')
[ -n "$mirror" ] || mirror=$(awk '$1 == "deb" && $3 ~ /^bookworm$/ {print $2; exit}' /etc/apt/sources.list 2>/dev/null)
[ -n "$mirror" ] || { say "cannot tell which Debian mirror apt uses here"; exit 2; }

if ! command -v debootstrap >/dev/null 2>&1; then
    say "installing debootstrap"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends debootstrap \
        >"$logs/debootstrap-install.log" 2>&1 || { say "cannot install debootstrap"; exit 2; }
fi

root=$(mktemp -d "${FRESH_DIR:-/var/tmp}/cdsp-fresh.XXXXXX") || exit 2
chmod 755 "$root" # mktemp's 0700 would keep the unprivileged step out of /
mounts=()
cleanup() {
    local i
    for ((i = ${#mounts[@]} - 1; i >= 0; i--)); do
        umount -l "${mounts[$i]}" 2>/dev/null
    done
    # never follow a mount left behind into the host's /dev or /proc
    if [ -z "${KEEP_ROOT:-}" ]; then
        rm -rf --one-file-system "$root"
    else
        say "root kept in $root"
    fi
}
trap cleanup EXIT
trap 'exit 1' INT TERM HUP

t0=$(date +%s)
cache=${FRESH_CACHE:-}
if [ -n "$cache" ] && [ -f "$cache" ]; then
    say "unpacking the fresh root saved in $cache into $root"
    tar --numeric-owner -C "$root" -xpf "$cache" || { say "cannot unpack $cache"; exit 2; }
else
    say "debootstrap --variant=minbase bookworm into $root"
    if ! debootstrap --variant=minbase --include=git,make,ca-certificates bookworm "$root" "$mirror" \
            >"$logs/debootstrap.log" 2>&1; then
        tail -n 20 "$logs/debootstrap.log"
        say "debootstrap failed (log: $logs/debootstrap.log)"
        exit 2
    fi
    if [ -n "$cache" ]; then # the untouched root, for the next run
        tar --numeric-owner -C "$root" -cf "$cache" . && say "fresh root saved in $cache"
    fi
fi
say "root ready in $(( $(date +%s) - t0 )) s"

bind() { # bind SRC DST: a mount inside the root, undone on exit
    mkdir -p "$2" && mount --bind "$1" "$2" && mounts+=("$2")
}
mount -t proc proc "$root/proc" && mounts+=("$root/proc")
bind /sys "$root/sys"
bind /dev "$root/dev"
bind /dev/pts "$root/dev/pts"
[ -d /dev/shm ] && bind /dev/shm "$root/dev/shm"
# One fake GigE Vision camera per machine (GVCP's port on 127.0.0.1): the
# tests in the root share the host's lock with the tests outside it.
: >>/tmp/cdsp-fakecam-gvcp.lock
: >"$root/tmp/cdsp-fakecam-gvcp.lock"
mount --bind /tmp/cdsp-fakecam-gvcp.lock "$root/tmp/cdsp-fakecam-gvcp.lock" &&
    mounts+=("$root/tmp/cdsp-fakecam-gvcp.lock")
cp /etc/resolv.conf "$root/etc/resolv.conf" 2>/dev/null
# debootstrap writes no /etc/hosts; every installed Debian system has one
# (the installer writes it), and programs resolve "localhost" through it.
[ -s "$root/etc/hosts" ] || printf '127.0.0.1\tlocalhost\n::1\t\tlocalhost ip6-localhost ip6-loopback\n' \
    >"$root/etc/hosts"

# The working tree as a user would clone it: tracked and untracked files
# that git does not ignore (so no build/), at /root/cdsp.
copy_tree() {
    mkdir -p "$1" &&
    (cd "$here" && git ls-files -z --cached --others --exclude-standard |
        tar --null --ignore-failed-read -T - -cf - 2>/dev/null) | tar -C "$1" -xf -
}
copy_tree "$root/root/cdsp" || { say "cannot copy the repository in"; exit 2; }

in_root() { chroot "$root" /usr/bin/env -i HOME=/root TERM=dumb PATH=/usr/sbin:/usr/bin:/sbin:/bin \
                LANG=C.UTF-8 "$@"; }
failed=0
pass() { say "PASS: $*"; }
fail() { say "FAIL: $*"; failed=1; }

for step in $steps; do
    case $step in
    user)
        # nobody, no sudo in the root: the demo must say what to install
        copy_tree "$root/tmp/cdsp-user" && chown -R 65534:65534 "$root/tmp/cdsp-user"
        in_root setpriv --reuid=65534 --regid=65534 --clear-groups \
            bash -c 'cd /tmp/cdsp-user && HOME=/tmp make demo' >"$logs/user-demo.log" 2>&1
        rc=$?
        cat "$logs/user-demo.log"
        if [ $rc -eq 2 ] && grep -q 'install them with:  sudo apt-get install' "$logs/user-demo.log" &&
           ! grep -qE 'cc: (No such file|not found)|error:' "$logs/user-demo.log"; then
            pass "as a user without sudo, make demo exits 2 naming the packages (nothing compiled)"
        else
            fail "as a user without sudo, make demo: exit $rc (log: $logs/user-demo.log)"
        fi ;;
    demo)
        t=$(date +%s)
        in_root bash -c "cd /root/cdsp && DEMO_SECONDS=$demo_seconds make demo" >"$logs/demo.log" 2>&1
        rc=$?
        tail -n 15 "$logs/demo.log"
        poses=$(grep -c ' ok  P_C' "$logs/demo.log")
        if [ $rc -eq 0 ] && [ "$poses" -gt 5 ]; then
            pass "make demo as root: installed what it needs, $poses pose lines in $(( $(date +%s) - t )) s"
        else
            fail "make demo as root: exit $rc, $poses pose lines (log: $logs/demo.log)"
        fi
        # what the demo installed: no OpenCV, qemu or kernel
        if in_root dpkg-query -W -f='${Package} ${Status}\n' 2>/dev/null |
           grep -E '^(libopencv|qemu-system|linux-image)[^ ]* .* installed$' >"$logs/demo-extra.txt"; then
            fail "make demo installed more than the demo needs: $(tr '\n' ' ' <"$logs/demo-extra.txt")"
        fi ;;
    check)
        t=$(date +%s)
        in_root bash -c "cd /root/cdsp && make check" >"$logs/check.log" 2>&1
        rc=$?
        tail -n 5 "$logs/check.log"
        line=$(grep -E '^check: [0-9]+ passed, [0-9]+ failed' "$logs/check.log" | tail -n1)
        if [ $rc -eq 0 ] && [ -n "$line" ]; then
            pass "make check as root: $line in $(( $(date +%s) - t )) s"
        else
            grep -E 'FAIL|failed' "$logs/check.log" | grep -v ' 0 failed' | tail -n 20
            fail "make check as root: exit $rc, '${line:-no closing line}' (log: $logs/check.log)"
        fi ;;
    *)
        say "unknown step '$step' (user, demo, check)"; exit 2 ;;
    esac
done
say "done in $(( $(date +%s) - t0 )) s"
exit $failed
