#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid runs the scale indicator and the known-truck runs (issue 14,
# docs/indicators.md section 8) on
# LCM's UDP multicast inside a private network namespace, with
# sim_publisher --environment site (the climate time-compressed 2000 times,
# an environment_t every 10 s of data time) and a small scale block
# (alerts.scale.block 50, baseline_blocks 4, tuned for a 10 % loss at 10
# design false alarms a year at 500 vehicles a day, so that a test of a few
# hundred vehicles sees it); every 10th vehicle is the calibration truck
# (sim_publisher --calibration-every 10, vehicle_t.reference_gvw_kg):
#   1. 300 healthy vehicles: every solved passage gets a deck temperature
#      (passages.deck_c, none skipped), the baseline is fitted once
#      (scale_evals row 'baseline'), two blocks follow, no scale_shift alert;
#      the 30 truck runs are stored with their reference, evaluated
#      (scale_evals 'known_truck'), no known_truck alert. Two vehicle_t with
#      a bad reference (500 kg, infinite) are refused: stored as invalid,
#      the reason naming the channel and the field, counted;
#   2. amfid restarts: the 300 passages are replayed from the store (no
#      second baseline), then 200 vehicles on a bridge with 10 % less
#      stiffness: the warning alerts scale_shift and known_truck are raised
#      once each (alerts table, the journal, the alert channel, the metrics
#      file), scale_shift within the four damaged blocks;
#      Every ok passage fed the STD and mean rules its GVW at the
#      calibration temperature (passages.gvw_comp_kg; the prior slopes of
#      the temperature model before the scale baseline, checked to 1e-9);
#   3. a third start restores the open alerts (not raised again);
#   4. amfi-report shows the indicators' series.
# Usage: daemon_scale.sh AMFID SIM_PUBLISHER AMFI_REPORT LCM_INJECT CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 report=$3 inject=$4 config=$5
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -15 "$f"; done; exit 1; }
q() { sqlite3 "$dir/a.db" "$1"; }

sed -e "s|^  # textfile: .*|  textfile: $dir/amfid.prom|" \
    -e "s/^    block: 500 /    block: 50 /" -e "s/^    baseline_blocks: 40 /    baseline_blocks: 4 /" \
    -e "/^  scale:/,/^  known_truck:/s/^    design_shift: 0.025 /    design_shift: 0.1 /" \
    -e "/^  scale:/,/^  known_truck:/s/^    false_alarms_per_year: 0.05 /    false_alarms_per_year: 10 /" \
    -e "s/^    vehicles_per_day: 2000 /    vehicles_per_day: 500 /" \
    -e "s/^  queue_size: 256 /  queue_size: 4096 /" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" \
    "$config" > "$dir/amfid.yaml"
for k in "block: 50 " "baseline_blocks: 4 " "design_shift: 0.1 " "false_alarms_per_year: 10 " \
         "vehicles_per_day: 500 "; do
  grep -q "^    $k" "$dir/amfid.yaml" || fail "the test's alerts.scale $k did not apply"
done
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "check-config"

start() { # NAME: amfid on a.db, logging to NAME.log
  : > "$dir/$1.log"
  "$amfid" --config "$dir/amfid.yaml" --db "$dir/a.db" 2>> "$dir/$1.log" &
  apid=$!; pids="$pids $apid"
  wait_for running "$dir/$1.log" $apid 60 || fail "amfid did not start ($1)"
}
stop() {
  kill -TERM $apid
  i=0; while kill -0 $apid 2>/dev/null; do
    i=$((i + 1)); [ $i -lt 3000 ] || fail "amfid did not stop on SIGTERM"; sleep 0.1; done
  wait $apid || fail "amfid exit status $?"
}
# sim NAME ARGS...: vehicles live on the bus, the site's climate on
sim() {
  name=$1; shift
  timeout 300 "$sim" --allow-production-bus --headway 3 --speedup 60 --seed 3 --dt 2.5e-4 --environment site \
    --time-compression 2000 --environment-period 10 --calibration-every 10 \
    --log "$dir/$name.lcmlog" "$@" 2> "$dir/$name-sim.log" ||
    fail "sim_publisher exited $? ($name)"
  sleep 2
}

# 1. healthy
start healthy
sim healthy --vehicles 300
"$inject" --bad-reference "$dir/healthy.lcmlog" "$dir/bad.lcmlog" || fail "lcm_inject"
lcm-logplayer -s 1 "$dir/bad.lcmlog" > "$dir/player.log" 2>&1 || fail "lcm-logplayer"
sleep 1
stop
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
[ "$ok" -ge 290 ] || fail "$ok ok passages of 300"
[ "$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND deck_c IS NULL")" -eq 0 ] ||
  fail "ok passages without a deck temperature"
grep -q "scale indicator: $ok passages fed (.*), 0 solved passages without a deck temperature within 7200 s (skipped)" \
  "$dir/healthy.log" || fail "stop line: $(grep 'scale indicator:' "$dir/healthy.log")"
grep -q "scale indicator: baseline of 4 blocks fitted" "$dir/healthy.log" || fail "no baseline"
# the STD and mean rules' input: compensated (daemon.indicators.temperature);
# the first 200 (the scale baseline's) by the prior slopes 0.0025 and 0.018
# per °C (knee 0, floor -10, calibration 10 °C)
[ "$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND gvw_comp_kg IS NULL")" -eq 0 ] ||
  fail "ok passages without the weight fed to the STD rule"
bad=$(q "SELECT count(*) FROM (SELECT gvw_kg, gvw_comp_kg, deck_c FROM passages WHERE status = 'ok' ORDER BY id LIMIT 200)
         WHERE abs(gvw_comp_kg / (gvw_kg * exp(-(0.0025 * (max(deck_c, 0) - 10) + 0.018 * min(max(deck_c, -10), 0))))
                   - 1) > 1e-9")
[ "$bad" -eq 0 ] || fail "$bad of the first 200 passages not compensated by the prior slopes"
[ "$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND abs(deck_c - 10) > 1 AND gvw_comp_kg = gvw_kg")" -eq 0 ] ||
  fail "passages away from 10 °C fed raw"
grep -q "STD and mean rules: $ok passages fed at the calibration temperature (10.0 °C), 0 raw" \
  "$dir/healthy.log" || fail "stop line: $(grep 'STD and mean rules' "$dir/healthy.log")"
[ "$(q "SELECT count(*) FROM scale_evals WHERE kind = 'scale_shift' AND state = 'baseline'")" -eq 1 ] ||
  fail "baseline rows"
blocks=$(q "SELECT count(*) FROM scale_evals WHERE kind = 'scale_shift' AND state <> 'baseline'")
[ "$blocks" -eq $(( (ok - 200) / 50 )) ] || fail "$blocks blocks after the baseline for $ok passages"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'scale_shift'")" -eq 0 ] ||
  fail "scale_shift on a healthy bridge: $(q "SELECT message FROM alerts")"
grep -q 'amfi_scale_passages_total{use="no_temperature"} 0$' "$dir/amfid.prom" || fail "metrics"
# the truck: 30 runs stored with the population's heaviest record's GVW
runs=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND reference_gvw_kg = 14829")
[ "$runs" -ge 28 ] || fail "$runs known-truck runs stored of 30"
[ "$(q "SELECT count(*) FROM passages WHERE reference_gvw_kg IS NOT NULL AND vehicle_id % 10 <> 0")" -eq 0 ] ||
  fail "a reference on a vehicle that is not the truck"
[ "$(q "SELECT count(*) FROM scale_evals WHERE kind = 'known_truck'")" -eq "$runs" ] ||
  fail "known_truck rows: $(q "SELECT count(*) FROM scale_evals WHERE kind = 'known_truck'") for $runs runs"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'known_truck'")" -eq 0 ] ||
  fail "known_truck on a healthy bridge: $(q "SELECT group_concat(printf('%.4f/%s', value, state), ' ') FROM scale_evals WHERE kind = 'known_truck'")"
# the bad references: refused where they enter, stored as invalid, counted
for id in 434343 434344; do
  [ "$(q "SELECT count(*) FROM passages WHERE vehicle_id = $id AND status = 'invalid' AND reason LIKE 'AMFI_VEHICLE: vehicle_t $id rejected: reference_gvw_kg out of [1000, 100000] kg%' AND reference_gvw_kg IS NULL")" -eq 1 ] ||
    fail "vehicle $id: $(q "SELECT status, reason FROM passages WHERE vehicle_id = $id")"
  grep -q "AMFI_VEHICLE: vehicle_t $id rejected: reference_gvw_kg out of" "$dir/healthy.log" ||
    fail "vehicle $id not logged"
done
grep -q 'amfi_messages_refused_total{input="vehicle",reason="invalid"} 2$' "$dir/amfid.prom" ||
  fail "metrics: $(grep refused "$dir/amfid.prom")"
last=$(q "SELECT max(utime) FROM passages")

# 2. restart, 10 % stiffness loss
start damaged
lcm-logger -c 'AMFI_ALERT' -f "$dir/alerts.lcmlog" > "$dir/logger.log" 2>&1 &
lpid=$!; pids="$pids $lpid"
sleep 0.3
grep -Eq "scale indicator: $ok passages replayed from the store \((normal|watch), $runs known-truck runs\)" "$dir/damaged.log" ||
  fail "replay line: $(grep 'scale indicator' "$dir/damaged.log")"
sim damaged --vehicles 200 --first 300 --damage 0.1 --start-utime $((last + 10000000))
stop
kill -TERM $lpid; wait $lpid 2>/dev/null
[ "$(q "SELECT count(*) FROM scale_evals WHERE kind = 'scale_shift' AND state = 'baseline'")" -eq 1 ] ||
  fail "the restart fitted a second baseline"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'scale_shift' AND raised = 1 AND level = 'warning'")" -eq 1 ] ||
  fail "scale_shift raised $(q "SELECT count(*) FROM alerts WHERE kind = 'scale_shift' AND raised = 1") times; blocks: $(q "SELECT group_concat(printf('%.3f/%.2f', value, cusum), ' ') FROM scale_evals")"
at=$(q "SELECT utime FROM alerts WHERE kind = 'scale_shift'")
after=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime > $last AND utime <= $at")
[ "$after" -le 200 ] && [ "$after" -ge 50 ] || fail "raised after $after damaged passages"
grep -q "ALERT scale_shift (warning): scale of inferred GVW" "$dir/damaged.log" || fail "journal"
grep -aq scale_shift "$dir/alerts.lcmlog" || fail "the alert is not on the alert channel"
grep -q 'amfi_alert_open{kind="scale_shift"} 1$' "$dir/amfid.prom" || fail "metrics: alert open"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'known_truck' AND raised = 1 AND level = 'warning'")" -eq 1 ] ||
  fail "known_truck raised $(q "SELECT count(*) FROM alerts WHERE kind = 'known_truck' AND raised = 1") times; runs: $(q "SELECT group_concat(printf('%.4f/%s', value, state), ' ') FROM scale_evals WHERE kind = 'known_truck'")"
grep -q "ALERT known_truck (warning)" "$dir/damaged.log" || fail "journal: known_truck"
grep -aq known_truck "$dir/alerts.lcmlog" || fail "known_truck is not on the alert channel"

# 3. the open alert survives a restart
start third
grep -q "the scale_shift alert is open; the known_truck alert is open" "$dir/third.log" ||
  fail "open alerts not restored: $(grep 'scale indicator' "$dir/third.log")"
stop
[ "$(q "SELECT count(*) FROM alerts WHERE kind IN ('scale_shift', 'known_truck')")" -eq 2 ] ||
  fail "raised again"

# 4. the report
"$report" --db "$dir/a.db" --summary > "$dir/report.txt" || fail "amfi-report"
grep -Eq "^scale +[0-9]+ blocks, newest .* CUSUM [0-9.]+ of [0-9.]+, alert; all blocks " "$dir/report.txt" ||
  fail "report: $(cat "$dir/report.txt")"
grep -Eq "^known truck +[0-9]+ runs, ratio inferred/reference \(compensated\) mean " "$dir/report.txt" ||
  fail "report: $(cat "$dir/report.txt")"
fed=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
grep -Eq "^GVW, fed +n $fed, mean [0-9]+ kg, STD [0-9]+ kg, .*\(the STD and mean rules' input" "$dir/report.txt" ||
  fail "report: no line of the STD rule's input: $(cat "$dir/report.txt")"
if command -v gnuplot > /dev/null; then
  "$report" --db "$dir/a.db" --plot "$dir/plots" > "$dir/plot.txt" 2>&1 || fail "--plot: $(cat "$dir/plot.txt")"
  for p in scale known_truck temperature; do
    [ -s "$dir/plots/$p.png" ] || fail "no $p.png: $(cat "$dir/plot.txt")"
    grep -q "^plot  $dir/plots/$p.png  " "$dir/plot.txt" || fail "$p.png not listed"
  done
  [ -n "${AMFI_KEEP_PLOTS:-}" ] && cp -r "$dir/plots" "$AMFI_KEEP_PLOTS"
fi
echo "scale on the bus: $ok healthy passages, $blocks blocks, raised after $after damaged passages; $runs healthy truck runs"
