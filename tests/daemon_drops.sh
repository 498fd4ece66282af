#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid's receive side (issue 9, finding 4), on LCM's UDP multicast inside a
# private network namespace: (1) a receive buffer above the kernel's cap is
# reported at start with the sysctl to set; (2) datagrams the kernel drops on
# amfid's socket are counted and reported: amfid is paused (SIGSTOP) with a
# small buffer while sim_publisher streams, then resumed; the log and the
# status message (recorded by lcm-logger) must show the drops.
# Usage: daemon_drops.sh AMFID SIM_PUBLISHER CONFIG
set -u
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
amfid=$1 sim=$2 config=$3
dir=$(mktemp -d)
pids=""
cleanup() { for p in $pids; do kill -9 "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
cap=$(cat /proc/sys/net/core/rmem_max)
# (1) more than the kernel allows
sed "s/^  recv_buf_bytes: .*/  recv_buf_bytes: $((cap + 4096))/" "$config" > "$dir/big.yaml"
"$amfid" --config "$dir/big.yaml" --db "$dir/big.db" 2> "$dir/big.log" &
pid=$!; pids="$pids $pid"
i=0; until grep -q running "$dir/big.log"; do i=$((i + 1)); [ $i -lt 100 ] || fail "no start"; sleep 0.1; done
kill -TERM $pid; wait $pid
grep -q "net.core.rmem_max=$((cap + 4096))" "$dir/big.log" || fail "no warning naming the sysctl to set"
echo "receive buffer above net.core.rmem_max ($cap): warned with the sysctl"
# (2) drops while amfid is paused, small buffer
sed "s/^  recv_buf_bytes: .*/  recv_buf_bytes: 4096/" "$config" > "$dir/small.yaml"
"$amfid" --config "$dir/small.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
i=0; until grep -q running "$dir/amfid.log"; do i=$((i + 1)); [ $i -lt 100 ] || fail "no start"; sleep 0.1; done
lcm-logger -c AMFI_STATUS -f "$dir/status.lcmlog" > /dev/null 2>&1 &
lpid=$!; pids="$pids $lpid"
kill -STOP $apid
timeout 60 "$sim" --vehicles 4 --headway 2 --speedup 50 --seed 6 2> "$dir/sim.log" || fail "sim_publisher"
kill -CONT $apid
sleep 2.5
kill -TERM $apid; wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit $rc"
kill -INT $lpid; wait $lpid 2>/dev/null
n=$(sed -n 's/.*the kernel dropped \([0-9]*\) UDP datagrams.*/\1/p' "$dir/amfid.log" | tail -1)
[ -n "$n" ] && [ "$n" -gt 0 ] || fail "no drops reported after a pause with a 4 kB buffer"
[ -s "$dir/status.lcmlog" ] || fail "no status message recorded"
rows=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages")
echo "paused with a 4 kB receive buffer: the kernel dropped $n datagrams, reported in the log (status_t.datagrams_dropped carries the same count); $rows of 4 vehicles reached amfid"
