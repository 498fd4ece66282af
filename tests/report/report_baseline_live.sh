#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_baseline_live.sh: a baseline set with amfi-report while amfid runs
# is used by the running amfid, without a restart. sim_publisher streams a
# healthy bridge on LCM inside a private network namespace
# (common/bus_prologue.sh); amfid establishes its automatic baseline; then
# amfi-report --set-baseline writes a very different one into the live
# store, and the evaluations amfid stores from then on must be against it
# (indicators.baseline_mean_kg), with amfid's log saying so, the same amfid
# process throughout.
# Usage: report_baseline_live.sh AMFID SIM_PUBLISHER AMFI_REPORT CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 report=$3 config=$4
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }

# test-sized indicator settings: a baseline after 100 ok passages, then an
# evaluation every 10 over a window of 50
sed -e "s/^    window: 500 /    window: 50 /" -e "s/^    every: 100 /    every: 10 /" \
    -e "s/^    baseline_n: 10000 /    baseline_n: 100 /" "$config" > "$dir/amfid.yaml"
for k in "window: 50 " "every: 10 " "baseline_n: 100 "; do
  grep -q "^    $k" "$dir/amfid.yaml" || fail "the test's indicator setting '$k' did not apply"
done
amfid_start "$amfid" "$dir/amfid.yaml"
"$sim" --dt 2.5e-4 --allow-production-bus --vehicles 200 --headway 2 --speedup 20 --seed 7 2> "$dir/sim.log" &
spid=$!; pids="$pids $spid"
wait_for "baseline established" "$dir/amfid.log" $apid 300 || fail "no automatic baseline"
auto=$(sqlite3 "$dir/s.db" "SELECT mean_kg FROM baseline ORDER BY id DESC LIMIT 1")
echo "automatic baseline: mean $auto kg"
pre=$(sqlite3 "$dir/s.db" "SELECT coalesce(max(id), 0) FROM indicators")
"$report" --db "$dir/s.db" --set-baseline 30000,500,50 --note "live" > "$dir/report.out" 2> "$dir/report.log" ||
  fail "amfi-report --set-baseline: $(cat "$dir/report.log")"
wait_for "baseline changed in the store, applied: mean 30000 kg" "$dir/amfid.log" $apid 60 ||
  fail "amfid did not apply the new baseline"
# the evaluation being stored as the log line was read may be the old one's
set_at=$(($(sqlite3 "$dir/s.db" "SELECT coalesce(max(id), 0) FROM indicators") + 1))
wait $spid || fail "sim_publisher failed"
sleep 2 # the passages in flight
amfid_stop
q() { sqlite3 "$dir/s.db" "$1"; }
after=$(q "SELECT count(*) FROM indicators WHERE id > $set_at")
new=$(q "SELECT count(*) FROM indicators WHERE id > $set_at AND baseline_mean_kg = 30000")
before=$(q "SELECT count(*) FROM indicators WHERE id <= $pre AND baseline_mean_kg = 30000")
echo "evaluations after the new baseline: $after, of them against it: $new (before it: $before)"
[ "$after" -ge 3 ] || fail "only $after evaluations after the new baseline"
[ "$new" -eq "$after" ] || fail "$((after - new)) evaluations after the new baseline not against it"
[ "$before" -eq 0 ] || fail "evaluations before the new baseline against it"
[ "$(grep -c 'running: amfid' "$dir/amfid.log")" -eq 1 ] || fail "amfid restarted"
rec=$(q "SELECT value FROM meta WHERE key = 'daemon.indicators'")
case "$rec" in
"window=50 every=10 baseline_n=100 std_alert_ratio="*) ;;
*) fail "amfid did not record its indicator parameters in meta daemon.indicators: '$rec'" ;;
esac
# the model_mismatch rule (fit_ratio.png and amfi-web draw its levels)
mf=$(q "SELECT value FROM meta WHERE key = 'alerts.model_fit'")
[ "$mf" = "enabled=1 window=25 raise=0.10000000000000001 clear=0.050000000000000003 raise_after=10 clear_after=25" ] ||
  fail "amfid did not record its model fit rule in meta alerts.model_fit: '$mf'"
case "$(q "SELECT value FROM meta WHERE key = 'daemon.classes'")" in
"scheme=eu group_spacing_m="*) ;;
*) fail "amfid did not record its classes in meta daemon.classes" ;;
esac
echo "baseline applied without a restart: ok"
