#!/usr/bin/env bash
# tests/vm/run-in-vm.sh: run one command inside a throw-away qemu VM whose
# kernel has the vivid V4L2 test driver loaded, so V4L2 capture code can be
# tested against a real driver on a machine without cameras or module loading.
#
# The kernel is Debian's current linux-image-amd64 (found with apt-cache at run
# time, fetched with apt-get download into a cache under build/, reused while
# Debian's version stays the same). The initramfs is built on every run from
# busybox-static, the vivid module and its dependencies (modules.dep), v4l2-ctl,
# and the files given with --file plus their shared libraries (ldd). Its /init
# loads vivid with a capture and an output node looped together, runs the
# command, prints a result marker on the console and powers the VM off.
# See docs/testing-hardware.md.
#
# Usage: tests/vm/run-in-vm.sh [options] -- CMD [ARGS...]
#   --file HOSTPATH:VMPATH  copy a file into the VM (repeatable); an ELF file
#                           brings its shared libraries (ldd) along
#   --timeout SECONDS       hard limit on the VM run (default 1200)
#   --format WxH:FOURCC     format set on both vivid nodes (default 640x480:GREY)
#   --log FILE              keep the console log there (default: a temp file)
# Inside the VM the command runs as root in /, with CDSP_VIVID_CAP and
# CDSP_VIVID_OUT naming the capture and output device nodes; lo is up
# (127.0.0.1), there is no other network; /tmp is a tmpfs.
#
# Environment: CDSP_VM_CACHE (kernel cache, default build/vm/cache),
# QEMU (default qemu-system-x86_64), CDSP_VM_MEM (MiB, default 512).
#
# Exit status: 0 the command exited 0 in the VM; 1 it exited non-zero (or the
# vivid setup failed); 2 usage error; 3 harness error (kernel download or
# extraction, a missing tool, a file that cannot be copied); 4 the VM hit the
# timeout or stopped without a result marker.
set -uo pipefail

prog=tests/vm/run-in-vm.sh
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

die() { echo "$prog: $2" >&2; exit "$1"; }
usage() { sed -n '15,31p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }

files=()
timeout_s=1200
format=640x480:GREY
log=""
while [ $# -gt 0 ]; do
    case $1 in
    --file)    [ $# -ge 2 ] || usage; files+=("$2"); shift 2 ;;
    --timeout) [ $# -ge 2 ] || usage; timeout_s=$2; shift 2 ;;
    --format)  [ $# -ge 2 ] || usage; format=$2; shift 2 ;;
    --log)     [ $# -ge 2 ] || usage; log=$2; shift 2 ;;
    --)        shift; break ;;
    -h|--help) usage ;;
    *)         echo "$prog: unknown option '$1'" >&2; usage ;;
    esac
done
[ $# -ge 1 ] || { echo "$prog: no command given after --" >&2; usage; }
[[ $timeout_s =~ ^[1-9][0-9]*$ ]] || die 2 "--timeout '$timeout_s': expected a positive number of seconds"
[[ $format =~ ^([1-9][0-9]*)x([1-9][0-9]*):([A-Z0-9 ]{4})$ ]] ||
    die 2 "--format '$format': expected WIDTHxHEIGHT:FOURCC, e.g. 640x480:GREY"
fmt_w=${BASH_REMATCH[1]} fmt_h=${BASH_REMATCH[2]} fmt_cc=${BASH_REMATCH[3]}
for f in "${files[@]}"; do
    [[ $f == *:/* ]] || die 2 "--file '$f': expected HOSTPATH:/ABSOLUTE/VMPATH"
    [ -f "${f%%:*}" ] || die 3 "--file '$f': host file '${f%%:*}' does not exist"
done

qemu=${QEMU:-qemu-system-x86_64}
mem=${CDSP_VM_MEM:-512}
cache=${CDSP_VM_CACHE:-$repo/build/vm/cache}
for tool in "$qemu" apt-get apt-cache dpkg-deb depmod cpio timeout flock ldd /bin/busybox /usr/bin/v4l2-ctl; do
    command -v "$tool" >/dev/null 2>&1 ||
        die 3 "'$tool' not found (Debian packages: see .ci/packages.d/vm.txt; run 'make deps')"
done

work=$(mktemp -d "${TMPDIR:-/tmp}/cdsp-vm.XXXXXX") || die 3 "cannot create a temporary directory"
x=""   # kernel extraction directory, while one exists
trap 'rm -rf "$work" ${x:+"$x"}' EXIT
trap 'exit 130' INT TERM

# ---------------------------------------------------------------------------
# Kernel: vmlinuz, modules.dep and the modules vivid needs, in $cache/<ver>/.
# ---------------------------------------------------------------------------
mkdir -p "$cache" || die 3 "cannot create the kernel cache '$cache'"
exec 9>"$cache/.lock"
flock 9 || die 3 "cannot lock '$cache/.lock'"

pkg=$(apt-cache depends linux-image-amd64 2>/dev/null |
      sed -n 's/^ *Depends: *<\{0,1\}\(linux-image-[0-9][^ >]*-amd64\)>\{0,1\} *$/\1/p' | head -n1)
if [ -n "$pkg" ]; then
    kver=${pkg#linux-image-}
else
    # No package lists (offline, or apt-get update never ran): use the newest
    # kernel already in the cache, if any.
    kver=$(ls -1 "$cache" 2>/dev/null | grep -E '^[0-9].*-amd64$' |
           while read -r d; do [ -f "$cache/$d/.complete" ] && echo "$d"; done | sort -V | tail -n1)
    [ -n "$kver" ] || die 3 "apt-cache does not name the kernel of linux-image-amd64 and the cache '$cache' is empty (run 'apt-get update')"
    pkg=linux-image-$kver
    echo "$prog: apt-cache names no kernel; using the cached $kver" >&2
fi
kdir=$cache/$kver

if [ ! -f "$kdir/.complete" ]; then
    deb=$(ls -1 "$cache/${pkg}_"*_amd64.deb 2>/dev/null | head -n1)
    if [ -z "$deb" ]; then
        echo "$prog: downloading $pkg (about 70 MB) into $cache" >&2
        (cd "$cache" && apt-get download -q "$pkg" >"$work/apt.log" 2>&1) || {
            cat "$work/apt.log" >&2; die 3 "apt-get download $pkg failed"; }
        deb=$(ls -1 "$cache/${pkg}_"*_amd64.deb 2>/dev/null | head -n1)
        [ -n "$deb" ] || die 3 "apt-get download $pkg left no .deb in '$cache'"
    fi
    echo "$prog: extracting $(basename "$deb")" >&2
    # About 400 MB unpacked: next to the cache, not in a possibly small /tmp.
    x=$cache/.extract-$$
    rm -rf "$x" && mkdir -p "$x"
    dpkg-deb -x "$deb" "$x" || die 3 "dpkg-deb cannot extract '$deb' (delete it to download again)"
    # Debian ships no modules.dep (postinst runs depmod): make one.
    if [ ! -d "$x/lib/modules/$kver" ] && [ -d "$x/usr/lib/modules/$kver" ]; then
        mkdir -p "$x/lib" && ln -s ../usr/lib/modules "$x/lib/modules"
    fi
    [ -f "$x/boot/vmlinuz-$kver" ] || die 3 "'$deb' holds no boot/vmlinuz-$kver"
    depmod -b "$x" "$kver" || die 3 "depmod failed on the modules of '$deb'"
    mdir=$x/lib/modules/$kver
    line=$(grep -E '^([^:]*/)?vivid\.ko(\.xz|\.zst|\.gz)?:' "$mdir/modules.dep") ||
        die 3 "modules.dep of $kver lists no vivid module"
    vivid=${line%%:*}
    read -r -a deps <<<"${line#*:}"
    rm -rf "$kdir.new" && mkdir -p "$kdir.new/modules" || die 3 "cannot write '$kdir.new'"
    cp "$x/boot/vmlinuz-$kver" "$kdir.new/vmlinuz" && cp "$mdir/modules.dep" "$kdir.new/" ||
        die 3 "cannot copy the kernel into '$kdir.new'"
    # modules.dep lists dependencies so that loading them last-to-first works
    # (as modprobe does); vivid itself comes last.
    order=()
    for ((i = ${#deps[@]} - 1; i >= 0; i--)); do order+=("${deps[i]}"); done
    order+=("$vivid")
    n=0
    for m in "${order[@]}"; do
        n=$((n + 1))
        base=$(basename "$m"); base=${base%.xz}; base=${base%.zst}; base=${base%.gz}
        dst=$kdir.new/modules/$(printf '%02d' "$n")-$base
        case $m in   # busybox insmod wants plain .ko files
        *.xz)  xz -dc "$mdir/$m" >"$dst" ;;
        *.zst) zstd -qdc "$mdir/$m" >"$dst" ;;
        *.gz)  gzip -dc "$mdir/$m" >"$dst" ;;
        *)     cp "$mdir/$m" "$dst" ;;
        esac || die 3 "cannot copy module '$m'"
    done
    touch "$kdir.new/.complete"
    rm -rf "$kdir" && mv "$kdir.new" "$kdir" || die 3 "cannot move '$kdir.new' to '$kdir'"
    rm -rf "$x"
    x=""
    # Keep only this kernel: drop older versions and their packages.
    for old in "$cache"/*; do
        case $old in
        "$kdir"|"$deb") ;;
        *) rm -rf "$old" ;;
        esac
    done
fi
flock -u 9

# ---------------------------------------------------------------------------
# Initramfs.
# ---------------------------------------------------------------------------
root=$work/root
mkdir -p "$root"/{bin,sbin,usr/bin,usr/sbin,dev,proc,sys,tmp,run,lib/modules/vivid} || die 3 "cannot stage the initramfs"
cp /bin/busybox "$root/bin/busybox" || die 3 "cannot copy /bin/busybox"
cp "$kdir"/modules/*.ko "$root/lib/modules/vivid/" || die 3 "cannot copy the modules from '$kdir'"

# copy_in HOSTPATH VMPATH: the file, and its shared libraries if it is ELF.
copy_in() {
    local src=$1 dst=$2 lib
    mkdir -p "$root$(dirname "$dst")" && cp -L --preserve=mode "$src" "$root$dst" ||
        die 3 "cannot copy '$src' into the VM as '$dst'"
    [ "$(head -c4 "$src" | od -An -c | tr -d ' ')" = '177ELF' ] || return 0
    # ldd prints "name => /path (addr)" and "/path/ld-linux... (addr)".
    ldd "$src" 2>/dev/null | sed -n 's/^.*=> \(\/[^ ]*\) .*$/\1/p; s/^[[:space:]]*\(\/[^ ]*\) (.*$/\1/p' |
    while read -r lib; do
        [ -e "$root$lib" ] && continue
        mkdir -p "$root$(dirname "$lib")" && cp -L "$lib" "$root$lib" ||
            die 3 "cannot copy '$lib' (needed by '$src') into the VM"
    done || exit 3
}
copy_in /usr/bin/v4l2-ctl /usr/bin/v4l2-ctl
for f in "${files[@]}"; do copy_in "${f%%:*}" "${f#*:}"; done

# shq ARG: ARG quoted for a POSIX shell.
shq() { printf "'%s'" "${1//\'/\'\\\'\'}"; }
cmd=""
for a in "$@"; do cmd="$cmd $(shq "$a")"; done

token=$(od -An -tx1 -N8 /dev/urandom | tr -d ' \n')
cat >"$root/init" <<EOF
#!/bin/busybox sh
/bin/busybox --install -s
export PATH=/usr/local/bin:/usr/bin:/bin:/usr/sbin:/sbin HOME=/ TERM=dumb
mount -t proc proc /proc
mount -t sysfs sys /sys
mount -t devtmpfs dev /dev
mount -t tmpfs tmp /tmp
ip link set lo up   # for tests that talk UDP on 127.0.0.1 inside the VM
result() { echo "CDSP-VM-RESULT $token \$*"; sync; poweroff -f; sleep 5; echo o >/proc/sysrq-trigger; exit 1; }
setup() { "\$@" >/tmp/setup.log 2>&1 || { cat /tmp/setup.log; result "FAIL setup: \$*"; }; }
for m in /lib/modules/vivid/*.ko; do
    case \$m in
    *-vivid.ko) setup insmod "\$m" node_types=0x101 input_types=0x81 ;;
    *)          setup insmod "\$m" ;;
    esac
done
CDSP_VIVID_CAP= CDSP_VIVID_OUT=
i=0
while [ \$i -lt 50 ]; do
    for n in /sys/class/video4linux/video*; do
        case \$(cat "\$n/name" 2>/dev/null) in
        *vid-cap) CDSP_VIVID_CAP=/dev/\${n##*/} ;;
        *vid-out) CDSP_VIVID_OUT=/dev/\${n##*/} ;;
        esac
    done
    [ -c "\$CDSP_VIVID_CAP" ] && [ -c "\$CDSP_VIVID_OUT" ] && break
    i=\$((i + 1)); sleep 0.2
done
[ -c "\$CDSP_VIVID_CAP" ] && [ -c "\$CDSP_VIVID_OUT" ] || result "FAIL setup: vivid created no capture/output node"
export CDSP_VIVID_CAP CDSP_VIVID_OUT
echo "vivid: capture \$CDSP_VIVID_CAP, output \$CDSP_VIVID_OUT, $fmt_w x $fmt_h '$fmt_cc', loop_video=1, osd_text_mode=2 (no text overlay)"
setup v4l2-ctl -d "\$CDSP_VIVID_CAP" -i 3
setup v4l2-ctl -d "\$CDSP_VIVID_CAP" -v "width=$fmt_w,height=$fmt_h,pixelformat=$fmt_cc"
setup v4l2-ctl -d "\$CDSP_VIVID_OUT" -x "width=$fmt_w,height=$fmt_h,pixelformat=$fmt_cc"
setup v4l2-ctl -d "\$CDSP_VIVID_CAP" -c loop_video=1
setup v4l2-ctl -d "\$CDSP_VIVID_CAP" -c osd_text_mode=2
cd /
echo running:$(shq "$cmd")
$cmd </dev/null
rc=\$?
if [ \$rc -eq 0 ]; then result PASS; else result "FAIL rc=\$rc"; fi
EOF
chmod 755 "$root/init"
(cd "$root" && find . | cpio -o -H newc --quiet >"$work/initramfs.cpio") || die 3 "cpio failed to pack the initramfs"

# ---------------------------------------------------------------------------
# Boot. TCG: KVM is not available on the machines this runs on (FACTS.md).
# ---------------------------------------------------------------------------
[ -n "$log" ] || log=$work/console.log
mkdir -p "$(dirname "$log")" || die 3 "cannot create the directory of '$log'"
echo "$prog: booting $kver with a $(( $(stat -c %s "$work/initramfs.cpio") / 1048576 )) MiB initramfs, timeout ${timeout_s} s"
start=$(date +%s)
timeout -k 10 "$timeout_s" "$qemu" -accel tcg -m "$mem" -smp 1 -nic none \
    -kernel "$kdir/vmlinuz" -initrd "$work/initramfs.cpio" \
    -append "console=ttyS0 quiet loglevel=3 panic=-1" \
    -nographic -no-reboot </dev/null >"$log" 2>&1
qrc=$?
# The console log without the firmware's terminal escapes and the marker.
tr -d '\r' <"$log" | sed 's/\x1b\[[0-9;?]*[A-Za-z]//g; s/\x1bc//g' | grep -v "CDSP-VM-RESULT $token"
marker=$(tr -d '\r' <"$log" | sed -n "s/^.*CDSP-VM-RESULT $token //p" | tail -n1)
elapsed=$(( $(date +%s) - start ))
case $marker in
PASS)   echo "$prog: PASS ($kver, ${elapsed} s in the VM)"; exit 0 ;;
FAIL*)  echo "$prog: ${marker} ($kver, ${elapsed} s in the VM)"; exit 1 ;;
esac
if [ $qrc -eq 124 ] || [ $qrc -eq 137 ]; then
    echo "$prog: FAIL: the VM ran into the ${timeout_s} s timeout without a result"
else
    echo "$prog: FAIL: the VM stopped (qemu status $qrc) without a result marker"
fi
exit 4
