#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The amfi .deb (scripts/package.sh: a release tree for /usr, cpack -G DEB):
# its dependencies are runtime packages (never -dev), its files are where a
# Debian service puts them, the configuration is a conffile, and the packaged
# amfid, unpacked, validates the packaged configuration; every packaged
# program is built with Debian's hardening flags (hardening-check).
# Usage: deb.sh SOURCE_DIR BUILD_DIR
set -u
src=$1 dir=$2
fail() { echo "FAIL: $*"; exit 1; }
deb=$(bash "$src/scripts/package.sh" "$dir") || fail "scripts/package.sh"
[ -f "$deb" ] || fail "no .deb: $deb"
echo "package: $deb ($(stat -c %s "$deb") bytes)"

[ "$(dpkg-deb -f "$deb" Package)" = amfi ] || fail "Package is not amfi"
dep=$(dpkg-deb -f "$deb" Depends)
echo "Depends: $dep"
echo "$dep" | grep -q -- '-dev' && fail "a -dev package among the dependencies"
for p in libsqlite3-0 libyaml-0-2 liblcm1 libsystemd0 libgsl27 libopenblas0 liblapacke systemd; do
  echo "$dep" | grep -q "$p" || fail "Depends lacks $p"
done

files=$(dpkg-deb -c "$deb" | awk '{print $6}')
for f in ./usr/bin/amfid ./usr/bin/amfi-solve ./usr/bin/amfi-report ./usr/bin/amfi-spy ./usr/bin/sim_publisher \
         ./etc/amfid/amfid.yaml ./lib/systemd/system/amfid.service ./usr/lib/sysusers.d/amfid.conf \
         ./usr/lib/tmpfiles.d/amfid.conf ./usr/share/man/man8/amfid.8.gz ./usr/share/man/man5/amfid.yaml.5.gz ./usr/share/doc/amfi/LICENSE \
         ./usr/share/java/amfi_types.jar; do
  echo "$files" | grep -qx "$f" || fail "not in the package: $f"
done
echo "$files" | grep -q '^\./usr/local' && fail "files under /usr/local in the package"
echo "$files" | grep -q '^\./usr/etc' && fail "files under /usr/etc in the package"
x=$(mktemp -d)
trap 'rm -rf "$x"' EXIT
dpkg-deb -e "$deb" "$x/DEBIAN"
grep -qx /etc/amfid/amfid.yaml "$x/DEBIAN/conffiles" || fail "amfid.yaml is not a conffile"
for s in postinst prerm postrm; do sh -n "$x/DEBIAN/$s" || fail "$s does not parse"; done
echo "file list, conffiles, maintainer scripts: ok"

dpkg-deb -x "$deb" "$x/root"
grep -qx 'ExecStart=/usr/bin/amfid --config /etc/amfid/amfid.yaml --db %S/amfid/amfi.db' \
  "$x/root/lib/systemd/system/amfid.service" || fail "the packaged unit does not start /usr/bin/amfid with /etc/amfid/amfid.yaml"
out=$("$x/root/usr/bin/amfid" --check-config --config "$x/root/etc/amfid/amfid.yaml" 2>&1) ||
  { echo "$out"; fail "the packaged amfid on the packaged amfid.yaml"; }
echo "packaged amfid --check-config: ok"

# Hardening: every packaged program built with Debian's hardening flags
# (PIE, stack protector, _FORTIFY_SOURCE, RELRO, BIND_NOW), checked by
# hardening-check (devscripts). Control-flow protection is compiled in
# (-fcf-protection: each object carries the IBT/SHSTK note, checked below on
# amfid's objects) but no program linked on Debian 12 can carry it: glibc's
# start files (Scrt1.o, crti.o, crtn.o) lack the note, and the linker keeps
# only what every input has; hence --nocfprotection.
command -v hardening-check >/dev/null || fail "hardening-check not found: apt-get install devscripts (scripts/install-deps.sh)"
n=0
for f in "$x/root/usr/bin/"* "$x/root/usr/lib/"*/*; do
  [ -f "$f" ] && [ "$(head -c 4 "$f" | od -An -c | tr -d ' ')" = '177ELF' ] || continue
  out=$(hardening-check --nocfprotection "$f" 2>&1) || { echo "$out"; fail "hardening-check ${f#"$x/root"}"; }
  n=$((n + 1))
done
[ "$n" -ge 8 ] || fail "hardening-check saw only $n programs in the package"
obj=$(find "$dir/daemon/CMakeFiles/amfid_lib.dir" -name 'amfid.c.o' | head -n 1)
[ -n "$obj" ] || fail "no amfid.c.o in $dir"
readelf -n "$obj" | grep -q 'x86 feature: IBT, SHSTK' || [ "$(uname -m)" != x86_64 ] ||
  fail "amfid.c.o has no IBT/SHSTK note (-fcf-protection)"
# The distribution's flags reached the tree (scripts/package.sh).
want=$(cd "$src" && DEB_BUILD_MAINT_OPTIONS=hardening=+all dpkg-buildflags --get CFLAGS)
got=$(sed -n 's/^CMAKE_C_FLAGS:STRING=//p' "$dir/CMakeCache.txt")
case "$got" in *"$want"*) ;; *) fail "the package tree's CMAKE_C_FLAGS '$got' lack dpkg-buildflags' CFLAGS '$want'" ;; esac
echo "hardening-check: $n packaged programs ok; dpkg-buildflags honoured"

echo "deb: ok"
