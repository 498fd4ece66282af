#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The amfi .deb (scripts/package.sh: a release tree for /usr, cpack -G DEB):
# its dependencies are runtime packages (never -dev), its files are where a
# Debian service puts them, the configuration is a conffile, and the packaged
# amfid, unpacked, validates the packaged configuration.
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
echo "deb: ok"
