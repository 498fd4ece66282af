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
. "$(dirname "$0")/../common/proc.sh"
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
  wait_for running "$dir/amfid.log" $apid || fail "amfid did not start"
}
amfid_stop() {
  stop_pid $apid || fail "amfid exit status $? (or no stop on SIGTERM)"
}
