#!/bin/sh
# systemd/amfid.service checked by systemd-analyze verify, with ExecStart
# pointing at the built amfid (verify checks that the binary exists). Any
# warning fails the test. Usage: systemd_verify.sh UNIT AMFID
set -u
unit=$1 amfid=$2
command -v systemd-analyze >/dev/null || { echo "SKIP: no systemd-analyze"; exit 77; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
sed -e "s|/usr/local/bin/amfid|$amfid|g" "$unit" > "$dir/amfid.service"
out=$(systemd-analyze verify "$dir/amfid.service" 2>&1); rc=$?
[ -z "$out" ] || { echo "systemd-analyze verify said:"; echo "$out"; exit 1; }
[ $rc -eq 0 ] || { echo "systemd-analyze verify exited $rc"; exit 1; }
grep -q '^Type=notify$' "$unit" && grep -q '^WatchdogSec=' "$unit" && grep -q '^User=amfid$' "$unit" &&
  grep -q '^StateDirectory=amfid$' "$unit" || { echo "unit lacks notify, watchdog, user or state directory"; exit 1; }
echo "systemd unit: ok"
