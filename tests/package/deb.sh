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
         ./lib/systemd/system/amfi-sync.service ./lib/systemd/system/amfi-ingest.service \
         ./lib/systemd/system/amfi-web.service \
         ./usr/lib/tmpfiles.d/amfid.conf ./usr/share/man/man8/amfid.8.gz ./usr/share/man/man5/amfid.yaml.5.gz ./usr/share/doc/amfi/LICENSE \
         ./usr/share/java/amfi_types.jar ./usr/share/amfi/roles.sql ./usr/bin/amfi-top \
         ./usr/share/man/man1/amfi-top.1.gz; do
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

# The packaged units' exposure (systemd-analyze security, offline, on the
# unit files as packaged).
exposure() {
  systemd-analyze security --offline=true "$1" 2>&1 | sed -n 's/^.*Overall exposure level for [^:]*: \([0-9.]*\) .*$/\1/p'
}
for u in amfid:1.5 amfi-sync:1.5; do
  e=$(exposure "$x/root/lib/systemd/system/${u%%:*}.service")
  [ -n "$e" ] || fail "no exposure level for ${u%%:*}.service"
  awk -v e="$e" -v m="${u#*:}" 'BEGIN { exit !(e <= m) }' ||
    fail "${u%%:*}.service: exposure $e above ${u#*:} (systemd-analyze security --offline=true)"
  echo "${u%%:*}.service: exposure $e"
done

# The maintainer scripts, run by dpkg itself on a fake root (dpkg --root
# --force-script-chrootless: the scripts work under $DPKG_ROOT, with the real
# systemd-sysusers, systemd-tmpfiles and deb-systemd-helper). The service
# manager is a stand-in that logs its calls: the fake root holds
# run/systemd/system, and systemctl and deb-systemd-invoke come first on PATH.
r=$x/fake
mkdir -p "$x/stub" "$r/var/lib/dpkg/info" "$r/var/lib/dpkg/updates" "$r/run/systemd/system"
: >"$r/var/lib/dpkg/status"
for s in systemctl deb-systemd-invoke; do
  printf '#!/bin/sh\necho "%s $*" >>"%s"\n' "$s" "$x/calls" >"$x/stub/$s"
  chmod +x "$x/stub/$s"
done
dpkgr() {
  : >"$x/calls"
  PATH=$x/stub:$PATH dpkg --root="$r" --force-script-chrootless --force-depends --force-not-root \
    --force-confold --log=/dev/null "$@" >"$x/dpkg.log" 2>&1 || { cat "$x/dpkg.log"; fail "dpkg $*"; }
}
called() { grep -qx "$1" "$x/calls"; }
# The units besides amfid's, installed disabled and never enabled by the
# package; every maintainer script names all of them (stopped on remove,
# restarted on upgrade, masked on remove, forgotten on purge).
optional="amfi-sync.service amfi-ingest.service amfi-web.service"
all="amfid.service $optional"
none_enabled() { # WHEN
  for u in $optional; do
    [ -L "$wants/$u" ] && fail "$1 enabled $u"
  done
  return 0
}
wants=$r/etc/systemd/system/multi-user.target.wants
mode() { stat -c '%a %U:%G' "$1"; }

# 1. First installation with the shipped example: users, directories, the
# bus key; amfid neither enabled nor started, and the operator told why.
dpkgr -i "$deb"
grep -q '^amfid:' "$r/etc/passwd" || fail "postinst: no user amfid"
grep -q '^amfi-sync:' "$r/etc/passwd" || fail "postinst: no user amfi-sync"
grep -q '^amfid:x:[0-9]*:amfi-sync$' "$r/etc/group" || fail "postinst: amfi-sync not in group amfid: $(grep ^amfid: "$r/etc/group")"
grep -q '^amfi-sync:x:[0-9]*:.*amfid' "$r/etc/group" && fail "amfid is in amfi-sync's group"
[ "$(mode "$r/etc/amfi-sync")" = "700 root:root" ] || fail "/etc/amfi-sync is $(mode "$r/etc/amfi-sync"), not 700 root:root"
[ "$(mode "$r/etc/amfid/bus.key")" = "600 root:root" ] || fail "bus.key is $(mode "$r/etc/amfid/bus.key" 2>&1), not 600 root:root"
[ "$(stat -c %s "$r/etc/amfid/bus.key")" -eq 32 ] || fail "bus.key is not 32 bytes"
key=$(od -An -tx1 "$r/etc/amfid/bus.key" | tr -d ' \n')
[ -L "$wants/amfid.service" ] && fail "postinst enabled amfid with the example configuration"
called 'deb-systemd-invoke start amfid.service' && fail "postinst started amfid with the example configuration"
grep -q 'still the example (site.id local)' "$x/dpkg.log" || fail "postinst does not say why amfid is not started"
none_enabled postinst
for u in $optional; do
  called "deb-systemd-invoke start $u" && fail "postinst started $u"
done
echo "postinst, example: users, /etc/amfi-sync 0700, bus key 0600 32 bytes; amfid neither enabled nor started: ok"

# 2. Upgrade (the same package again): the key kept, running services
# restarted, still not enabled.
dpkgr -i "$deb"
[ "$(od -An -tx1 "$r/etc/amfid/bus.key" | tr -d ' \n')" = "$key" ] || fail "an upgrade replaced the bus key"
called "deb-systemd-invoke try-restart $all" || { cat "$x/calls"; fail "upgrade: no try-restart of $all"; }
[ -L "$wants/amfid.service" ] && fail "upgrade enabled amfid with the example configuration"
none_enabled "an upgrade"
echo "postinst, upgrade: key kept, try-restart of every unit: ok"

# 3. Removal: every unit stopped (amfid last), then masked; a configured site reinstalled from
# nothing (purge, then a configured amfid.yaml kept by --force-confold):
# enabled and started; an upgrade of it restarted.
dpkgr -r amfi
called "deb-systemd-invoke stop $optional amfid.service" || { cat "$x/calls"; fail "prerm remove: no stop of $optional amfid.service"; }
for u in $all; do
  [ "$(readlink "$r/etc/systemd/system/$u")" = /dev/null ] || fail "postrm remove: $u not masked"
done
dpkgr --purge amfi
mkdir -p "$r/etc/amfid"
sed 's/^  id: local /  id: a7-km42 /' "$x/root/etc/amfid/amfid.yaml" >"$r/etc/amfid/amfid.yaml"
grep -q '^  id: a7-km42 ' "$r/etc/amfid/amfid.yaml" || fail "cannot configure the test site"
mkdir -p "$r/etc/amfid" && printf 'host:5432:fleet:amfi_sync:secret\n' >"$r/etc/amfid/pgpass" && chmod 600 "$r/etc/amfid/pgpass"
dpkgr -i "$deb"
[ -L "$wants/amfid.service" ] || fail "postinst did not enable amfid for a configured site"
called 'deb-systemd-invoke start amfid.service' || { cat "$x/calls"; fail "postinst did not start amfid for a configured site"; }
none_enabled "postinst for a configured site"
[ -f "$r/etc/amfi-sync/pgpass" ] && [ ! -e "$r/etc/amfid/pgpass" ] || fail "postinst did not move /etc/amfid/pgpass to /etc/amfi-sync/"
dpkgr -i "$deb"
called "deb-systemd-invoke try-restart $all" || { cat "$x/calls"; fail "configured upgrade: no try-restart of $all"; }
[ -L "$wants/amfid.service" ] || fail "an upgrade disabled amfid"
echo "configured site: enabled and started at install, restarted at upgrade; amfi-sync's pgpass moved to /etc/amfi-sync: ok"

# 4. A configuration amfid refuses: nothing started or restarted.
printf 'site:\n  id: "bad id"\n' >>"$r/etc/amfid/amfid.yaml"
dpkgr -i "$deb"
grep -q 'try-restart\|start' "$x/calls" && { cat "$x/calls"; fail "postinst (re)started amfid on a configuration it refuses"; }
grep -q 'does not check' "$x/dpkg.log" || fail "postinst does not say the configuration is refused"
echo "refused configuration: not restarted: ok"

# 5. Purge: every unit's enablement and state gone (amfi-sync, amfi-ingest
# and amfi-web enabled by the operator, as systemctl enable does it), the
# bus key and the empty directories too; the operator's pgpass stays.
for u in $optional; do
  ln -s "/lib/systemd/system/$u" "$wants/$u"
done
dpkgr -r amfi
dpkgr --purge amfi
for u in $all; do
  [ -L "$wants/$u" ] && fail "purge left $u enabled"
  [ -L "$r/etc/systemd/system/$u" ] && fail "purge left $u masked"
done
left=$(ls "$r/var/lib/systemd/deb-systemd-helper-enabled" "$r/var/lib/systemd/deb-systemd-helper-masked" 2>/dev/null | grep 'amfi')
[ -z "$left" ] || fail "purge left deb-systemd-helper state: $left"
[ -e "$r/etc/amfid" ] && fail "purge left /etc/amfid: $(ls -A "$r/etc/amfid")"
[ -f "$r/etc/amfi-sync/pgpass" ] || fail "purge removed the operator's /etc/amfi-sync/pgpass"
echo "purge: every unit's enablement, masks and state, the bus key, /etc/amfid: gone: ok"
echo "deb: ok"
