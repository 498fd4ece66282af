#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The metrics file while amfid runs (issue 11), on LCM's UDP multicast in a
# private network namespace: metrics.textfile rewritten every second while
# 30 vehicles stream; a reader copies it 20 times a second and every copy
# must be a whole, valid file (tests/daemon/prom_check.awk): the rename is atomic.
# At the end its counters equal the store's and the simulator's.
# Usage: daemon_metrics.sh AMFID SIM_PUBLISHER CONFIG PROM_CHECK_AWK
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3 check=$4
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
# (a simulation: the truth is read too, every message sent is counted)
sed -e "s|^  # textfile: .*|  textfile: $dir/m/amfid.prom|" -e "s/^  interval_s: 15 /  interval_s: 1 /" \
  -e "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/a.yaml"
grep -q "^  interval_s: 1 " "$dir/a.yaml" || fail "the test's metrics settings did not apply"
mkdir "$dir/m"
"$amfid" --config "$dir/a.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
timeout 120 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 30 --headway 2 --speedup 15 --seed 9 2> "$dir/sim.log" &
spid=$!; pids="$pids $spid"
copies=0 seen=""
while kill -0 $spid 2>/dev/null; do
  if [ -f "$dir/m/amfid.prom" ]; then
    cp "$dir/m/amfid.prom" "$dir/copy.prom"
    awk -f "$check" "$dir/copy.prom" > "$dir/check.txt" || fail "copy $copies: $(cat "$dir/check.txt")"
    copies=$((copies + 1))
    seen="$seen $(sed -n 's/^amfi_messages_received_total //p' "$dir/copy.prom")"
  fi
  sleep 0.05
done
wait $spid || fail "sim_publisher"
sleep 2
kill -TERM $apid; wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exited $rc"
[ "$copies" -ge 20 ] || fail "only $copies copies read"
[ "$(echo $seen | tr ' ' '\n' | sort -un | wc -l)" -ge 3 ] || fail "the file was not rewritten while amfid ran: $seen"
ls "$dir/m" | grep -v '^amfid.prom$' && fail "temporary files left in the metrics folder"
awk -f "$check" "$dir/m/amfid.prom" > /dev/null || fail "the final file"
metric() { sed -n "s/^$1 //p" "$dir/m/amfid.prom"; }
sent=$(sed -n 's/.* in \([0-9]*\) messages.*/\1/p' "$dir/sim.log")
got=$(metric amfi_messages_received_total)
drops=$(metric amfi_datagrams_dropped_total)
[ $((got + drops)) -eq "$sent" ] || fail "metrics: $got received + $drops dropped, $sent sent"
for s in ok gap late overload multiple invalid error; do
  [ "$(metric "amfi_passages_total{status=\"$s\"}")" = "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages WHERE status = '$s'")" ] ||
    fail "metrics: $s passages differ from the store"
done
echo "metrics: $copies copies read while amfid ran, every one whole and valid; final counters equal the store ($(metric 'amfi_passages_total{status="ok"}') ok) and the simulator ($sent messages)"
