#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# systemd/amfi-web.service as generated: the installed binary on amfid's
# store, on loopback, Chart.js from where the build says; a dynamic user in
# amfid's group; amfi-sync's sandbox with IP only with this host; an
# exposure level (systemd-analyze security, offline) of at most 1.5, as
# amfi-ingest's (77: no systemd-analyze).
# Usage: web_unit.sh UNIT BINDIR CHARTJS
set -u
unit=$1 bindir=$2 chartjs=$3
fail() { echo "FAIL: $*"; exit 1; }
command -v systemd-analyze > /dev/null || { echo "no systemd-analyze"; exit 77; }
grep -qx "ExecStart=$bindir/amfi-web --db %S/amfid/amfi.db --listen 127.0.0.1:8080 --chartjs $chartjs" "$unit" ||
  fail "ExecStart: $(grep ^ExecStart= "$unit")"
for k in '^DynamicUser=yes$' '^SupplementaryGroups=amfid$' '^IPAddressDeny=any$' \
         '^IPAddressAllow=localhost$' '^SystemCallFilter=~@privileged @resources$' \
         '^NoNewPrivileges=yes$' '^ProtectSystem=strict$' '^PrivateDevices=yes$' \
         '^CapabilityBoundingSet=$' '^MemoryDenyWriteExecute=yes$' '^Documentation=man:amfi-web(1)'; do
  grep -q "$k" "$unit" || fail "amfi-web.service lacks $k"
done
grep -q '^StateDirectory=' "$unit" && fail "amfi-web.service has a StateDirectory= (systemd would chown amfid's)"
grep -q '^User=amfid$' "$unit" && fail "amfi-web.service runs as amfid"
e=$(systemd-analyze security --offline=true "$unit" 2>&1 |
    sed -n 's/^.*Overall exposure level for [^:]*: \([0-9.]*\) .*$/\1/p')
[ -n "$e" ] || fail "no exposure level"
awk -v e="$e" 'BEGIN { exit !(e <= 1.5) }' || fail "exposure $e above 1.5"
echo "amfi-web.service: exposure $e: ok"
