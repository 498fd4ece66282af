#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# cmake --install into a DESTDIR staging tree, then check what a site gets:
# the programs, the configuration, the unit, sysusers/tmpfiles, the man pages,
# the docs; the installed amfid validates the installed configuration; the
# installed unit, as installed, passes systemd-analyze verify with the staged
# prefix mounted over the real one (a private mount namespace: nothing is
# written outside the staging tree); every man page renders.
# Usage: install.sh BUILD_DIR BINDIR SYSCONFDIR UNITDIR SYSUSERSDIR TMPFILESDIR MANDIR DOCDIR DATADIR PREFIX
set -u
build=$1 bindir=$2 sysconfdir=$3 unitdir=$4 sysusersdir=$5 tmpfilesdir=$6 mandir=$7 docdir=$8 datadir=$9
shift 9
prefix=$1
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

DESTDIR=$stage cmake --install "$build" >"$stage.log" 2>&1 || { cat "$stage.log"; rm -f "$stage.log"; fail "cmake --install"; }
rm -f "$stage.log"

for f in "$bindir/amfid" "$bindir/amfi-solve" "$bindir/amfi-report" "$bindir/amfi-spy" \
         "$bindir/sim_publisher" "$sysconfdir/amfid/amfid.yaml" "$unitdir/amfid.service" \
         "$sysusersdir/amfid.conf" "$tmpfilesdir/amfid.conf" "$mandir/man8/amfid.8.gz" \
         "$mandir/man5/amfid.yaml.5.gz" "$mandir/man1/amfi-solve.1.gz" "$mandir/man1/amfi-report.1.gz" \
         "$mandir/man1/sim_publisher.1.gz" "$datadir/amfi/population.csv" "$datadir/amfi/amfi-alert-mail" \
         "$docdir/README.md" "$docdir/LICENSE" "$docdir/docs/daemon.md" "$datadir/java/amfi_types.jar" \
         "$bindir/amfi-web" "$unitdir/amfi-web.service" "$mandir/man1/amfi-web.1.gz" "$docdir/docs/web.md" \
         "$datadir/amfi/site.yaml"; do
  [ -e "$stage$f" ] || fail "not installed: $f"
done
echo "installed files: ok"

# The installed daemon on the installed configuration.
out=$("$stage$bindir/amfid" --check-config --config "$stage$sysconfdir/amfid/amfid.yaml" 2>&1) ||
  { echo "$out"; fail "installed amfid --check-config on the installed amfid.yaml"; }
# the short site file beside it checks too (the example's warnings aside)
out=$("$stage$bindir/amfid" --check-config --config "$stage$datadir/amfi/site.yaml" 2>&1) ||
  { echo "$out"; fail "installed amfid --check-config on the installed site.yaml"; }
echo "installed amfid --check-config: ok"
for p in amfid amfi-solve amfi-report sim_publisher amfi-mkcase amfi-bench amfi-population amfi-fleet-bench amfi-sync amfi-web amfi-top; do
  v=$("$stage$bindir/$p" --version 2>&1) || fail "installed $p --version exited non-zero"
  case "$v" in "$p "[0-9]*) ;; *) fail "installed $p --version said: $v" ;; esac
done
echo "installed programs answer --version: ok ($v)"

# The unit names the installed binary and configuration, as installed.
unit=$stage$unitdir/amfid.service
grep -qx "ExecStart=$bindir/amfid --config $sysconfdir/amfid/amfid.yaml --db %S/amfid/amfi.db" "$unit" ||
  fail "ExecStart does not name $bindir/amfid and $sysconfdir/amfid/amfid.yaml: $(grep ^ExecStart= "$unit")"
for k in '^Type=notify$' '^WatchdogSec=' '^User=amfid$' '^StateDirectory=amfid$' '^Documentation=man:amfid(8)'; do
  grep -q "$k" "$unit" || fail "unit lacks $k"
done
# amfid's unit: the bus key as a credential, the sandbox's IP allow list
# (this host and the multicast bus) and the directives of a tight sandbox.
for k in "^LoadCredential=amfi-bus-key:$sysconfdir/amfid/bus.key$" '^IPAddressDeny=any$' \
         '^IPAddressAllow=localhost 224.0.0.0/4$' '^SystemCallFilter=~@privileged @resources$' \
         '^ProtectProc=invisible$' '^RemoveIPC=yes$' '^PrivateMounts=yes$'; do
  grep -q "$k" "$unit" || fail "amfid.service lacks $k"
done
# amfi-sync's unit: the installed binary on amfid's configuration and store,
# as its own user in amfid's group (the store group-readable), its
# connection and password only as systemd credentials from its own
# directory (never in the unit), and without amfid's StateDirectory (which
# systemd would hand to amfi-sync's user).
sunit=$stage$unitdir/amfi-sync.service
grep -qx "ExecStart=$bindir/amfi-sync --config $sysconfdir/amfid/amfid.yaml --db %S/amfid/amfi.db --pg service=amfi --interval 60" "$sunit" ||
  fail "amfi-sync.service ExecStart: $(grep ^ExecStart= "$sunit" 2>&1)"
for k in '^Type=notify$' '^WatchdogSec=' '^User=amfi-sync$' '^Group=amfi-sync$' '^SupplementaryGroups=amfid$' \
         '^RestartPreventExitStatus=2 3$' "^LoadCredential=amfi-sync:$sysconfdir/amfi-sync$" \
         '^Environment=PGPASSFILE=%d/amfi-sync_pgpass$' '^Environment=PGSERVICEFILE=%d/amfi-sync_pg_service.conf$' \
         '^SystemCallFilter=~@privileged @resources$' '^ProtectProc=invisible$' '^RemoveIPC=yes$' \
         '^PrivateMounts=yes$' '^Documentation=man:amfi-sync(1)'; do
  grep -q "$k" "$sunit" || fail "amfi-sync.service lacks $k"
done
grep -q '^StateDirectory=' "$sunit" && fail "amfi-sync.service has a StateDirectory= (systemd would chown amfid's to amfi-sync)"
grep -q '^User=amfid$' "$sunit" && fail "amfi-sync.service runs as amfid"
grep -v '^#' "$sunit" | grep -qi 'password=' && fail "amfi-sync.service holds a password"
# sysusers.d and tmpfiles.d, parsed and applied by systemd itself on an
# empty root: two users, amfi-sync in amfid's group (not the reverse),
# /etc/amfi-sync root's only.
tmpfs=$stage/sdroot
mkdir -p "$tmpfs/etc"
out=$(systemd-sysusers --root="$tmpfs" "$stage$sysusersdir/amfid.conf" 2>&1) || { echo "$out"; fail "systemd-sysusers on $sysusersdir/amfid.conf"; }
grep -q '^amfid:' "$tmpfs/etc/passwd" && grep -q '^amfi-sync:' "$tmpfs/etc/passwd" ||
  fail "sysusers: users $(cut -d: -f1 "$tmpfs/etc/passwd" | tr '\n' ' ')"
grep -q '^amfid:x:[0-9]*:amfi-sync$' "$tmpfs/etc/group" || fail "sysusers: amfi-sync not in amfid's group: $(cat "$tmpfs/etc/group")"
grep -q '^amfi-sync:x:[0-9]*:$' "$tmpfs/etc/group" || fail "sysusers: amfi-sync's group has members: $(cat "$tmpfs/etc/group")"
out=$(systemd-tmpfiles --root="$tmpfs" --create "$stage$tmpfilesdir/amfid.conf" 2>&1) || { echo "$out"; fail "systemd-tmpfiles on $tmpfilesdir/amfid.conf"; }
[ "$(stat -c '%a %U' "$tmpfs$sysconfdir/amfi-sync")" = "700 root" ] ||
  fail "tmpfiles: $sysconfdir/amfi-sync is $(stat -c '%a %U' "$tmpfs$sysconfdir/amfi-sync" 2>&1), not 700 root"
[ "$(stat -c '%a %U' "$tmpfs$sysconfdir/amfid")" = "755 root" ] || fail "tmpfiles: $sysconfdir/amfid"
echo "units, sysusers.d, tmpfiles.d: ok"
if command -v systemd-analyze >/dev/null && [ "$prefix" != /usr ] && [ "$prefix" != / ]; then
  # Mount the staged prefix over the real one, so the unit is checked exactly
  # as installed (the binary it starts, the man page it documents).
  v=$(unshare --mount sh -c 'mount --bind "$1$2" "$2" && systemd-analyze verify "$3" "$4" 2>&1; echo "rc=$?"' \
      verify "$stage" "$prefix" "$unit" "$sunit")
  [ "$v" = "rc=0" ] || { echo "$v"; fail "systemd-analyze verify of the installed unit"; }
  echo "systemd-analyze verify (installed units, staged prefix mounted on $prefix): ok"
else
  fail "cannot verify the unit: no systemd-analyze, or the prefix $prefix cannot be mounted over"
fi

# Every installed man page renders without a warning.
n=0
for page in "$stage$mandir"/man*/*; do
  w=$(MANWIDTH=80 man --warnings -l "$page" 2>&1 >/dev/null)
  [ -z "$w" ] || { echo "$w"; fail "man -l $page"; }
  MANWIDTH=80 man -l "$page" 2>/dev/null | grep -q NAME || fail "man -l $page: no NAME section"
  n=$((n + 1))
done
[ "$n" -ge 1 ] || fail "no man pages installed"
echo "man pages: $n render"
echo "install: ok"
