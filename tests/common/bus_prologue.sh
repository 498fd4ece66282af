# SPDX-License-Identifier: GPL-3.0-or-later
# bus_prologue.sh: sourced first by the tests that run amfid and the other
# programs on the LCM bus (tests/daemon_*.sh). It re-runs the sourcing
# script inside a private network namespace with loopback up and LCM's
# multicast routed to it (nothing leaves the namespace), then gives the
# script a temporary folder $dir, a list $pids of processes to kill, a
# cleanup at exit that kills them and removes $dir, and the test's bus key
# (tests/common/bus_key.sh: $bus_key, found by every program through
# CREDENTIALS_DIRECTORY). As the script's first
# command after `set -u`:
#   . "$(dirname "$0")/../common/bus_prologue.sh"
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
dir=$(mktemp -d)
pids=""
cleanup() { for p in $pids; do kill -9 "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
. "$(dirname "$0")/../common/bus_key.sh"
# amfid_start AMFID CONFIG: amfid on the bus in the background, store
# $dir/s.db, log $dir/amfid.log, pid $apid (killed at exit); returns once it
# runs. amfid_stop: SIGTERM, wait for its drain (up to 300 s: minutes under
# ASan) and require exit status 0. Both call the script's `fail`.
amfid_start() {
  # emptied here, not only by the background child's redirection: the wait
  # below must not see an earlier run's "running" (a restart's race)
  : > "$dir/amfid.log"
  "$1" --config "$2" --db "$dir/s.db" 2> "$dir/amfid.log" &
  apid=$!; pids="$pids $apid"
  _i=0; until grep -q "running" "$dir/amfid.log"; do
    _i=$((_i + 1)); [ $_i -lt 100 ] || fail "amfid did not start"; sleep 0.1; done
}
amfid_stop() {
  kill -TERM $apid
  _i=0; while kill -0 $apid 2>/dev/null; do
    _i=$((_i + 1)); [ $_i -lt 3000 ] || fail "amfid did not stop on SIGTERM"; sleep 0.1; done
  wait $apid || fail "amfid exit status $?"
}
