#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid end to end: the real sim_publisher and amfid on LCM's UDP multicast
# inside a private network namespace (nothing leaves it), then the stored
# rows: every vehicle a passage row, GVW against the truth, a SIGHUP reload
# while traffic streams, a clean shutdown on SIGTERM (integrity_check ok),
# SIGTERM mid-stream losing no received vehicle, and a log replayed twice
# at two speeds through LCM's file:// provider giving identical rows (one
# recorded live with lcm-logger, one written by sim_publisher --log).
# Usage: daemon_e2e.sh AMFID SIM_PUBLISHER AMFI_REPORT CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 report=$3 config=$4
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=12

# Indicators small enough to evaluate in a short test.
# A solver queue of 4: replaying a log must hold the bus, not overflow
# (every row ok, none lost or "overload").
sed -e "s/^    window: 500/    window: 10/" -e "s/^    every: 100/    every: 5/" \
    -e "s/^    baseline_n: 10000/    baseline_n: 10/" -e "s/^  queue_size: 256/  queue_size: 4/" \
    -e "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/amfid.yaml"
grep -q "^  queue_size: 4 " "$dir/amfid.yaml" || fail "the test's queue size did not apply"
# a simulation: the truth channel subscribed and stored
grep -q "^  simulation: true$" "$dir/amfid.yaml" || fail "daemon.simulation did not apply"
grep -q "^    baseline_n: 10 " "$dir/amfid.yaml" || fail "the test's indicator settings did not apply"
"$amfid" --config "$dir/amfid.yaml" --check-config >/dev/null || fail "check-config"

# 1. Live: amfid listening, sim_publisher publishing at 20x real time.
"$amfid" --config "$dir/amfid.yaml" --db "$dir/live.db" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
lcm-logger -f "$dir/recorded.lcmlog" > "$dir/logger.log" 2>&1 &  # every channel
lpid=$!; pids="$pids $lpid"
timeout 120 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --headway 3 --speedup 20 --seed 3 2> "$dir/sim.log" &
spid=$!; pids="$pids $spid"
sleep 0.5
kill -HUP $apid  # reload while the traffic streams
wait $spid || fail "sim_publisher exited $?"
grep -q "reload: configuration .* applied" "$dir/amfid.log" || fail "SIGHUP: no reload in the log"
kill -0 $apid 2>/dev/null || fail "amfid died on SIGHUP"
sleep 1
kill -TERM $apid
i=0; while kill -0 $apid 2>/dev/null; do
  i=$((i + 1)); [ $i -lt 600 ] || fail "amfid did not stop on SIGTERM"; sleep 0.1; done
wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit status $rc"
kill -INT $lpid; wait $lpid 2>/dev/null
rows=$(sqlite3 "$dir/live.db" "SELECT count(*) FROM passages")
ok=$(sqlite3 "$dir/live.db" "SELECT count(*) FROM passages WHERE status = 'ok'")
truth=$(sqlite3 "$dir/live.db" "SELECT count(*) FROM truth")
echo "live: $rows passage rows ($ok ok), $truth truth rows for $N vehicles"
[ "$rows" -eq $N ] || fail "expected $N passage rows, got $rows"
[ "$truth" -eq $N ] || fail "expected $N truth rows, got $truth"
[ "$ok" -ge $((N - 1)) ] || fail "only $ok of $N passages ok"
sqlite3 "$dir/live.db" "PRAGMA integrity_check" | grep -qx ok || fail "integrity_check"
err=$(sqlite3 "$dir/live.db" "SELECT max(abs(p.gvw_kg - t.gvw_kg) / t.gvw_kg) FROM passages p
      JOIN truth t USING (vehicle_id) WHERE p.status = 'ok'")
echo "live: largest GVW error $(awk -v e="$err" 'BEGIN { printf "%.2f %%", 100 * e }')"
awk -v e="$err" 'BEGIN { exit !(e < 0.08) }' || fail "GVW error $err over 8 %"
"$report" --db "$dir/live.db" > "$dir/report.txt" || fail "amfi-report"

# 2. SIGTERM mid-stream: every vehicle amfid received is a row (the ones
#    whose data never came as gap), the database is intact.
"$amfid" --config "$dir/amfid.yaml" --db "$dir/term.db" 2> "$dir/term.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/term.log" $apid 60 || fail "amfid did not start"
# -k 10: sim_publisher once did not exit after its SIGTERM summary under
# ASan and the test hung at the wait below until ctest's 600 s (not
# diagnosed); amfid is what this section tests
timeout -k 10 120 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --headway 3 --speedup 20 --seed 5 2> "$dir/simterm.log" &
spid=$!; pids="$pids $spid"
sleep 1.2  # about half the traffic
kill -TERM $apid
wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit status $rc after SIGTERM mid-stream"
kill $spid 2>/dev/null; wait $spid 2>/dev/null
[ $? -ne 137 ] || echo "note: sim_publisher needed SIGKILL 10 s after SIGTERM"
received=$(sed -n 's/.*stopped: .* blocks, \([0-9]*\) vehicles.*/\1/p' "$dir/term.log")
rows=$(sqlite3 "$dir/term.db" "SELECT count(*) FROM passages")
echo "SIGTERM mid-stream: $received vehicles received, $rows rows ($(sqlite3 "$dir/term.db" \
  "SELECT group_concat(status || ' ' || n, ', ') FROM (SELECT status, count(*) n FROM passages GROUP BY 1)"))"
[ -n "$received" ] && [ "$received" -gt 0 ] || fail "no vehicle received before SIGTERM"
[ "$rows" -eq "$received" ] || fail "$received vehicles received but $rows rows stored"
sqlite3 "$dir/term.db" "PRAGMA integrity_check" | grep -qx ok || fail "integrity_check after SIGTERM"

# 3. Replay: the live traffic as lcm-logger recorded it (amfid's own
#    output channels included, which it must ignore), read twice through
#    file:// at two speeds: the same rows as each other and as the live run.
q="SELECT vehicle_id, utime, status, printf('%.6f', gvw_kg), printf('%.6g', lambda) FROM passages ORDER BY id"
[ -s "$dir/recorded.lcmlog" ] || fail "lcm-logger recorded nothing"
for speed in 0 8; do
  "$amfid" --config "$dir/amfid.yaml" --db "$dir/rec$speed.db" \
    --lcm-url "file://$dir/recorded.lcmlog?speed=$speed" 2> "$dir/rec$speed.log" ||
    fail "amfid on the lcm-logger log (speed $speed)"
  sqlite3 "$dir/rec$speed.db" "$q" > "$dir/rec$speed.txt"
done
sqlite3 "$dir/live.db" "$q" > "$dir/live.txt"
[ "$(wc -l < "$dir/rec0.txt")" -eq $N ] || fail "lcm-logger replay: $(wc -l < "$dir/rec0.txt") rows"
# the same rows, the weights and λ compared as numbers (tests/common/num_cmp.sh,
# 1e-9 relative), not byte for byte
num_cmp() { sh "$(dirname "$0")/../common/num_cmp.sh" "$1" "$2"; }
num_cmp "$dir/rec0.txt" "$dir/rec8.txt" || fail "lcm-logger log replayed at two speeds: rows differ"
num_cmp "$dir/rec0.txt" "$dir/live.txt" || fail "lcm-logger replay differs from the live rows"
echo "lcm-logger log: $N identical rows replayed at speed 0 and 8, the same as live"

# 4. A log written by sim_publisher itself, read twice through file:// at
#    two speeds: same rows.
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/traffic.log" --vehicles $N --headway 3 --speedup max --seed 4 \
  2> "$dir/simlog.log" || fail "sim_publisher --log"
for speed in 0 8; do
  "$amfid" --config "$dir/amfid.yaml" --db "$dir/replay$speed.db" \
    --lcm-url "file://$dir/traffic.log?speed=$speed" 2> "$dir/replay$speed.log" ||
    fail "amfid on the log (speed $speed)"
done
sqlite3 "$dir/replay0.db" "$q" > "$dir/a.txt"
sqlite3 "$dir/replay8.db" "$q" > "$dir/b.txt"
[ "$(wc -l < "$dir/a.txt")" -eq $N ] || fail "replay: $(wc -l < "$dir/a.txt") rows"
[ "$(grep -c '|ok|' "$dir/a.txt")" -eq $N ] || fail "replay: not every passage ok: $(cut -d'|' -f3 "$dir/a.txt" | sort | uniq -c)"
num_cmp "$dir/a.txt" "$dir/b.txt" || fail "replays at two speeds differ"
echo "replay: $N identical rows at speed 0 (as fast as possible) and 8"
echo "daemon end to end: ok"
