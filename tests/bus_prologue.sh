# SPDX-License-Identifier: GPL-3.0-or-later
# bus_prologue.sh: sourced first by the tests that run amfid and the other
# programs on the LCM bus (tests/daemon_*.sh). It re-runs the sourcing
# script inside a private network namespace with loopback up and LCM's
# multicast routed to it (nothing leaves the namespace), then gives the
# script a temporary folder $dir, a list $pids of processes to kill, and a
# cleanup at exit that kills them and removes $dir. As the script's first
# command after `set -u`:
#   . "$(dirname "$0")/bus_prologue.sh"
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
dir=$(mktemp -d)
pids=""
cleanup() { for p in $pids; do kill -9 "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
