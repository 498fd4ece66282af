#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# daemon_year.sh: a site's year through amfid (issue 14's stream test).
# sim_publisher simulates 2000 healthy vehicles in the coupled model with the
# site's climate and drifting mix (--environment site), time-compressed so
# that they span a year of deck temperatures (5.6 vehicles a site day, one
# every 3 s of data: compression 5143), then vehicles on a bridge with 10 %
# less stiffness, as many as the tool's 95th-percentile scale delay plus 300;
# a calibration truck every 98th vehicle.
# amfid reads them through LCM's log provider (file://, the same intake as the
# UDP bus: subscriptions, decoding, checks; the live UDP path with these
# indicators is tests/daemon/daemon_scale.sh) with the shipped amfid.yaml except
# what a year of 2000 vehicles needs: the STD rule's baseline 1000 (of
# 10 000), the scale block 100 x 10 (of 500 x 40), the scale's flow 5.6 a day.
# Checked:
#   1. every vehicle stored, >= 99.5 % ok; the deck spans a year (frost
#      below 0 °C and summer above 20 °C);
#   2. no warning-level alert (std_increase, scale_shift, known_truck,
#      natfreq, model_mismatch) over the healthy vehicles;
#   3. the 10 % loss raises scale_shift and known_truck within the delay
#      amfi-year-sim predicts for the same settings (its 95th percentile
#      over 40 runs, vehicles for the scale, runs for the truck);
#   4. amfi-report shows the indicators.
# This is the suite's size. The year at 14 a day (5000 healthy, 1500 damaged:
# about 9 minutes under the sanitizers) is this script with
#   YEAR_HEALTHY=5000 YEAR_PER_DAY=14 YEAR_DAMAGED=1500
# and tools/bench/amfi-year-stream runs such years outside the suite, printing
# every alert (docs/results/model-fit.md, natural-frequency.md).
# The vehicles are drawn by amfi-population.
# Usage: daemon_year.sh AMFID SIM_PUBLISHER AMFI_YEAR_SIM AMFI_POPULATION AMFI_REPORT CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 ysim=$3 pop=$4 report=$5 config=$6
HEALTHY=${YEAR_HEALTHY:-2000} PER_DAY=${YEAR_PER_DAY:-5.6} DAMAGED=${YEAR_DAMAGED:-} CALIB=98
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -15 "$f"; done; exit 1; }
q() { sqlite3 "$dir/a.db" "$1"; }

sed -e "s/^    baseline_n: 10000 /    baseline_n: 1000 /" \
    -e "s/^    block: 500 /    block: 100 /" -e "s/^    baseline_blocks: 40 /    baseline_blocks: 10 /" \
    -e "s/^    vehicles_per_day: 2000 /    vehicles_per_day: $PER_DAY /" \
    -e "s/^  queue_size: 256 /  queue_size: 100000 /" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" \
    "$config" > "$dir/amfid.yaml"
for k in "baseline_n: 1000 " "block: 100 " "baseline_blocks: 10 " "vehicles_per_day: $PER_DAY "; do
  grep -q "^    $k" "$dir/amfid.yaml" || fail "the test's $k did not apply"
done
grep -q "^    temperature: compensated " "$dir/amfid.yaml" || fail "not the shipped compensated STD rule"
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "check-config"

# the tool's prediction for the same settings (drift on, 40 damaged runs)
"$ysim" --flow $PER_DAY --baseline-n 1000 --scale-block 100 --scale-baseline-blocks 10 \
  --damage 0.1 --drift on --years 3 --det-runs 40 --seed 5 > "$dir/tool.md" 2> "$dir/tool.log" ||
  fail "amfi-year-sim"
p95() { grep "^| $1 | on | 10.0 % |" "$dir/tool.md" | awk -F'|' '{gsub(/ /, "", $8); print $8}'; }
tool_scale=$(p95 scale_shift) tool_truck=$(p95 known_truck)
[ -n "$tool_scale" ] && [ -n "$tool_truck" ] || fail "no prediction: $(cat "$dir/tool.md")"

# the damaged stretch: long enough for the tool's p95 of both (and a block
# to spare), unless given
[ -n "$DAMAGED" ] || DAMAGED=$(awk -v s="$tool_scale" -v t="$tool_truck" -v c=$CALIB \
  'BEGIN { d = s + 300; if (t * c + 300 > d) d = t * c + 300; printf "%d", d }')
total=$((HEALTHY + DAMAGED))
tc=$(awk -v d=$PER_DAY 'BEGIN { printf "%.6g", 86400 / d / 3 }')
"$pop" --out "$dir/pop.csv" --vehicles $total --seed 7 > /dev/null || fail "amfi-population"
timeout 900 "$sim" --lcm-url none --population "$dir/pop.csv" --log "$dir/year.lcmlog" --vehicles $total --headway 3 \
  --speedup max --seed 7 --dt 2.5e-4 --environment site --time-compression "$tc" \
  --environment-period 10 --calibration-every $CALIB --damage 0.1 --damage-step-at $HEALTHY \
  2> "$dir/sim.log" || fail "sim_publisher exited $?"
timeout 900 "$amfid" --config "$dir/amfid.yaml" --db "$dir/a.db" \
  --lcm-url "file://$dir/year.lcmlog?speed=0" 2> "$dir/amfid.log" || fail "amfid exited $?"

# 1. every vehicle, the year's temperatures
[ "$(q "SELECT count(*) FROM passages")" -eq $total ] || fail "$(q "SELECT count(*) FROM passages") passages of $total"
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
[ $((ok * 1000)) -ge $((total * 995)) ] || fail "$ok ok of $total: $(q "SELECT status, count(*) FROM passages GROUP BY 1")"
onset=$(q "SELECT utime FROM passages ORDER BY utime LIMIT 1 OFFSET $HEALTHY")
range=$(q "SELECT printf('%.1f .. %.1f', min(deck_c), max(deck_c)) FROM passages WHERE utime < $onset")
[ "$(q "SELECT min(deck_c) < 0 AND max(deck_c) > 20 FROM passages WHERE utime < $onset")" -eq 1 ] ||
  fail "the healthy deck spans only $range °C"

# 2. no warning alert on the healthy bridge
early=$(q "SELECT group_concat(kind || ' at passage ' || (SELECT count(*) FROM passages p WHERE p.utime <= a.utime), '; ')
           FROM alerts a WHERE level = 'warning' AND raised = 1 AND utime < $onset")
[ -z "$early" ] || fail "warning alerts on the healthy bridge: $early"
info=$(q "SELECT count(*) FROM alerts WHERE level = 'info' AND raised = 1 AND utime < $onset")

# 3. the loss: detected within the tool's delay
after() { # KIND: ok passages (known_truck: truck runs) from the onset to the first raise
  at=$(q "SELECT min(utime) FROM alerts WHERE kind = '$1' AND raised = 1 AND utime >= $onset")
  [ -n "$at" ] || { echo none; return; }
  if [ "$1" = known_truck ]; then
    q "SELECT count(*) FROM passages WHERE status = 'ok' AND reference_gvw_kg IS NOT NULL AND utime >= $onset AND utime <= $at"
  else
    q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime >= $onset AND utime <= $at"
  fi
}
s=$(after scale_shift) t=$(after known_truck) d=$(after std_increase)
[ "$s" != none ] && [ "$s" -le "$tool_scale" ] ||
  fail "scale_shift after $s damaged vehicles, the tool's p95 $tool_scale; blocks: $(q "SELECT group_concat(printf('%.3f/%.1f', value, cusum), ' ') FROM scale_evals WHERE kind = 'scale_shift'")"
[ "$t" != none ] && [ "$t" -le "$tool_truck" ] ||
  fail "known_truck after $t damaged runs, the tool's p95 $tool_truck"

# 4. the report
"$report" --db "$dir/a.db" --summary > "$dir/report.txt" || fail "amfi-report"
grep -Eq "^scale +[0-9]+ blocks, .*alert" "$dir/report.txt" || fail "report: $(cat "$dir/report.txt")"
grep -Eq "^known truck +[0-9]+ runs" "$dir/report.txt" || fail "report: $(cat "$dir/report.txt")"
echo "year through amfid: $ok ok of $total, healthy deck $range °C, no warning over $HEALTHY healthy" \
     "($info info raises); after the 10 % loss: scale_shift at $s vehicles (tool p95 $tool_scale)," \
     "known_truck at $t runs (tool p95 $tool_truck), std_increase at $d"
