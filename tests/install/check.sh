#!/usr/bin/env bash
# tests/install/check.sh: `make install` into a scratch DESTDIR (PREFIX
# /usr/local), then: every file where it belongs; a program built against
# it with `pkg-config --cflags --libs cdsp` (the sysroot of DESTDIR) runs
# and solves a rendered pipe; every man page renders with man -l and groff
# parses it without a warning; the installed unit names the installed
# paths. Then a PREFIX install without DESTDIR (a user's home) and uninstall.
set -u
BUILD=${BUILD:-build}
mkdir -p "$BUILD/tests" || exit 2
work=$(mktemp -d "$BUILD/tests/install.XXXXXX") || exit 2
work=$(cd "$work" && pwd)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

echo "--- make install DESTDIR=... PREFIX=/usr/local"
dest=$work/dest
make --no-print-directory -s install DESTDIR="$dest" PREFIX=/usr/local BUILD="$BUILD" \
    >"$work/install.log" 2>&1 || { cat "$work/install.log"; fail "make install"; }
for f in bin/cdsp_tool bin/cdspd lib/libcdsp.a include/cdsp.h lib/pkgconfig/cdsp.pc \
         share/man/man1/cdsp_tool.1 share/man/man1/cdsp_tool-solve.1 share/man/man8/cdspd.8 \
         lib/systemd/system/cdspd.service share/doc/cdsp/cdspd.yaml share/doc/cdsp/protocol.md; do
    [ -s "$dest/usr/local/$f" ] || fail "not installed: /usr/local/$f"
done
[ -s "$dest/etc/cdspd/cdspd.yaml" ] || fail "not installed: /etc/cdspd/cdspd.yaml"
[ ! -x "$BUILD/cdsp_calib" ] || [ -x "$dest/usr/local/bin/cdsp_calib" ] || fail "cdsp_calib not installed"
grep -q "^ExecStart=/usr/local/bin/cdspd --config /etc/cdspd/cdspd.yaml" \
    "$dest/usr/local/lib/systemd/system/cdspd.service" || fail "the unit's ExecStart"
find "$dest" -type f | sed "s|^$dest||" | sort

echo "--- a program against it: pkg-config --cflags --libs cdsp"
pc() {
    PKG_CONFIG_SYSROOT_DIR=$dest PKG_CONFIG_LIBDIR=$dest/usr/local/lib/pkgconfig pkg-config "$@"
}
pc --modversion cdsp
flags=$(pc --cflags --libs cdsp) || fail "pkg-config cdsp"
echo "cc ... $flags"
${CC:-cc} -std=c99 -Wall -Wextra -pedantic -Werror tests/install/hello_cdsp.c $flags \
    -o "$work/hello" || fail "cannot build against the installed libcdsp"
"$work/hello" || fail "the program built against the installed libcdsp"

echo "--- man pages: man -l renders, groff without warnings"
for m in "$dest"/usr/local/share/man/man*/*; do
    groff -man -Tutf8 -ww -z "$m" 2>"$work/groff.err"
    [ ! -s "$work/groff.err" ] || { cat "$work/groff.err"; fail "groff warns about $(basename "$m")"; }
    if command -v man >/dev/null; then
        MANWIDTH=80 man -l "$m" 2>"$work/man.err" | grep -q "^NAME" ||
            { cat "$work/man.err"; fail "man -l $(basename "$m") shows no NAME"; }
    fi
    echo "$(basename "$m"): $(MANWIDTH=200 man -l "$m" 2>/dev/null | sed -n '/^NAME/{n;p;q}' | sed 's/^ *//')"
done
# the pages say what --help says: every option of cdsp_tool solve is in its page
for o in $("$BUILD/cdsp_tool" solve --help | sed -n 's/^    \(-., \)\?\(--[a-z-]*\).*/\2/p'); do
    MANWIDTH=200 man -l "$dest/usr/local/share/man/man1/cdsp_tool-solve.1" 2>/dev/null | grep -q -- "$o" ||
        fail "cdsp_tool-solve.1 lacks $o"
done
for o in $("$BUILD/cdspd" --help | sed -n 's/^  \(-., \)\? *\(--[a-z-]*\).*/\2/p'); do
    MANWIDTH=200 man -l "$dest/usr/local/share/man/man8/cdspd.8" 2>/dev/null | grep -q -- "$o" ||
        fail "cdspd.8 lacks $o"
done

echo "--- PREFIX without DESTDIR, then uninstall"
prefix=$work/home/.local
make --no-print-directory -s install PREFIX="$prefix" BUILD="$BUILD" >"$work/install2.log" 2>&1 ||
    { cat "$work/install2.log"; fail "make install PREFIX=$prefix"; }
grep -q "^ExecStart=$prefix/bin/cdspd --config $prefix/etc/cdspd/cdspd.yaml" \
    "$prefix/lib/systemd/system/cdspd.service" || fail "the unit under PREFIX"
PKG_CONFIG_LIBDIR=$prefix/lib/pkgconfig pkg-config --cflags cdsp | grep -q -- "-I$prefix/include" ||
    fail "cdsp.pc under PREFIX"
make --no-print-directory -s uninstall PREFIX="$prefix" BUILD="$BUILD" >/dev/null 2>&1 || fail "uninstall"
left=$(find "$prefix" -type f ! -path "*/etc/*" | wc -l)
[ "$left" -eq 0 ] || { find "$prefix" -type f; fail "uninstall left $left files"; }
echo "PASS: install"
