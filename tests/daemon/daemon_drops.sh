#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid's receive side (issue 9, finding 4), on LCM's UDP multicast inside a
# private network namespace: (1) a receive buffer above the kernel's cap is
# reported at start with the sysctl to set; (2) datagrams the kernel drops on
# amfid's socket are counted and reported: amfid is paused (SIGSTOP) with a
# small buffer while sim_publisher streams, then resumed; the log and the
# status message (recorded by lcm-logger) must show the drops; (3) with the
# shipped buffer, the same pause and burst: every message the simulator sent
# either reaches amfid's handlers or is a counted kernel drop (LCM's own
# per-channel queue, 30 messages by default, used to lose most of such a
# burst without a trace: daemon.bus_queue), and with no kernel drop every
# vehicle is weighed.
# The drops are also in the store (meta intake.*) and in amfi-report's
# summary ("bus ... kernel drops").
# Usage: daemon_drops.sh AMFID SIM_PUBLISHER CONFIG AMFI_REPORT
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3 report=$4
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
cap=$(cat /proc/sys/net/core/rmem_max)
# (1) more than the kernel allows
sed "s/^  recv_buf_bytes: .*/  recv_buf_bytes: $((cap + 4096))/" "$config" > "$dir/big.yaml"
"$amfid" --config "$dir/big.yaml" --db "$dir/big.db" 2> "$dir/big.log" &
pid=$!; pids="$pids $pid"
wait_for running "$dir/big.log" $pid 60 || fail "no start"
kill -TERM $pid; wait $pid
grep -q "net.core.rmem_max=$((cap + 4096))" "$dir/big.log" || fail "no warning naming the sysctl to set"
echo "receive buffer above net.core.rmem_max ($cap): warned with the sysctl"
# (2) drops while amfid is paused, small buffer
sed "s/^  recv_buf_bytes: .*/  recv_buf_bytes: 4096/" "$config" > "$dir/small.yaml"
"$amfid" --config "$dir/small.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/amfid.log" $apid 60 || fail "no start"
lcm-logger -c AMFI_STATUS -f "$dir/status.lcmlog" > /dev/null 2>&1 &
lpid=$!; pids="$pids $lpid"
kill -STOP $apid
timeout 60 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 4 --headway 2 --speedup 50 --seed 6 2> "$dir/sim.log" || fail "sim_publisher"
kill -CONT $apid
sleep 2.5
kill -TERM $apid; wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit $rc"
kill -INT $lpid; wait $lpid 2>/dev/null
n=$(sed -n 's/.*the kernel dropped \([0-9]*\) UDP datagrams.*/\1/p' "$dir/amfid.log" | tail -1)
[ -n "$n" ] && [ "$n" -gt 0 ] || fail "no drops reported after a pause with a 4 kB buffer"
[ -s "$dir/status.lcmlog" ] || fail "no status message recorded"
rows=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages")
"$report" --db "$dir/a.db" --summary > "$dir/report.txt" || fail "amfi-report"
grep -q "^bus .* [0-9]* messages received, [0-9]* refused, $n kernel drops, " "$dir/report.txt" ||
  fail "amfi-report does not show the $n kernel drops: $(grep '^bus' "$dir/report.txt")"
echo "paused with a 4 kB receive buffer: the kernel dropped $n datagrams, reported in the log (status_t.datagrams_dropped carries the same count); $rows of 4 vehicles reached amfid"

# (3) the shipped buffer and LCM queue: a burst after a pause loses nothing silently
# (a simulation: the truth channel is subscribed too, so that every message
# sent is one amfid reads)
sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || fail "daemon.simulation did not apply"
"$amfid" --config "$dir/sim.yaml" --db "$dir/c.db" 2> "$dir/burst.log" &
bpid=$!; pids="$pids $bpid"
wait_for running "$dir/burst.log" $bpid 60 || fail "no start"
kill -STOP $bpid
timeout 60 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 4 --headway 2 --speedup 50 --seed 6 2> "$dir/sim3.log" || fail "sim_publisher (3)"
kill -CONT $bpid
sleep 3
kill -TERM $bpid; wait $bpid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit $rc (3)"
sent=$(sed -n 's/.* in \([0-9]*\) messages.*/\1/p' "$dir/sim3.log")
got=$(sed -n 's/.*stopped: .* \([0-9]*\) messages received.*/\1/p' "$dir/burst.log")
kd=$(sed -n 's/.*the kernel dropped \([0-9]*\) UDP datagrams.*/\1/p' "$dir/burst.log" | tail -1)
kd=${kd:-0}
[ -n "$sent" ] && [ -n "$got" ] || fail "no message counts (sim: '$sent', amfid: '$got')"
[ $((got + kd)) -eq "$sent" ] ||
  fail "$sent messages sent, $got received, $kd counted as kernel drops: $((sent - got - kd)) lost without a trace"
ok=$(sqlite3 "$dir/c.db" "SELECT count(*) FROM passages WHERE status = 'ok'")
[ "$kd" -gt 0 ] || [ "$ok" -eq 4 ] || fail "no kernel drop, but $ok of 4 vehicles ok"
echo "a burst of $sent messages while amfid was stopped (SIGSTOP), shipped settings: $got reached amfid's handlers, $kd kernel drops (counted); $ok of 4 vehicles ok"
