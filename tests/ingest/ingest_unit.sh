#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# systemd/amfi-ingest.service as generated: the installed binary on amfid's
# configuration (validated before the start), the bus key as a credential,
# amfid's sandbox (IP only with this host and the multicast bus), and an
# exposure level (systemd-analyze security, offline) no worse than amfid's
# bound, 1.5 (77: no systemd-analyze).
# Usage: ingest_unit.sh UNIT BINDIR SYSCONFDIR
set -u
unit=$1 bindir=$2 sysconfdir=$3
fail() { echo "FAIL: $*"; exit 1; }
command -v systemd-analyze > /dev/null || { echo "no systemd-analyze"; exit 77; }
grep -qx "ExecStart=$bindir/amfi-ingest --config $sysconfdir/amfid/amfid.yaml" "$unit" ||
  fail "ExecStart: $(grep ^ExecStart= "$unit")"
grep -qx "ExecStartPre=$bindir/amfi-ingest --config $sysconfdir/amfid/amfid.yaml --check-config" "$unit" ||
  fail "no --check-config before the start"
for k in "^LoadCredential=amfi-bus-key:$sysconfdir/amfid/bus.key$" '^IPAddressDeny=any$' \
         '^IPAddressAllow=localhost 224.0.0.0/4$' '^SystemCallFilter=~@privileged @resources$' \
         '^User=amfid$' '^NoNewPrivileges=yes$' '^ProtectSystem=strict$' '^PrivateDevices=yes$' \
         '^CapabilityBoundingSet=$' '^Documentation=man:amfi-ingest(1)'; do
  grep -q "$k" "$unit" || fail "amfi-ingest.service lacks $k"
done
e=$(systemd-analyze security --offline=true "$unit" 2>&1 |
    sed -n 's/^.*Overall exposure level for [^:]*: \([0-9.]*\) .*$/\1/p')
[ -n "$e" ] || fail "no exposure level"
awk -v e="$e" 'BEGIN { exit !(e <= 1.5) }' || fail "exposure $e above 1.5"
echo "amfi-ingest.service: exposure $e: ok"
