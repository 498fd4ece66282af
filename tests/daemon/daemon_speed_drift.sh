#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The speed-drift alert on the bus (issue 12): amfid with solver.speed:
# estimate and alerts.speed_drift.window 4 (threshold 2 %), sim_publisher
# streaming inside a private network namespace.
#   run "high" (4 vehicles): the detector reads every speed 4 % high (--speed-error
#     0.04,0), so each correction is about 1/1.04 - 1 = -3.85 %: the
#     speed_drift alert (info) is raised once, at the 4th estimated passage,
#     stored, published on AMFI_ALERT and logged; amfi-report --speed shows
#     the median correction near -3.85 %; a restart on the same store keeps
#     the alert open and refills the window.
#   run "exact" (4 vehicles): the detector is exact: no alert; the median correction is
#     within 0.5 % of zero.
# Usage: daemon_speed_drift.sh AMFID SIM_PUBLISHER AMFI_REPORT LCM_PASSAGES CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 report=$3 lcmp=$4 config=$5
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=4

sed -e "s/^  speed: measured /  speed: estimate /" -e "s/^    window: 200 /    window: 4 /" \
  "$config" > "$dir/amfid.yaml"
grep -q "^  speed: estimate " "$dir/amfid.yaml" || fail "the test's solver.speed did not apply"
grep -q "^    window: 4 " "$dir/amfid.yaml" || fail "the test's alerts.speed_drift.window did not apply"

# start NAME: amfid on $dir/NAME.db, logging to $dir/NAME.log; sets apid
start() {
  # emptied here, not by the background job's redirection: that runs
  # asynchronously, and the wait below would find the previous run's lines
  : > "$dir/$1.log"
  "$amfid" --config "$dir/amfid.yaml" --db "$dir/$1.db" 2>> "$dir/$1.log" &
  apid=$!; pids="$pids $apid"
  wait_for running "$dir/$1.log" $apid 60 || fail "amfid did not start ($1)"
}
stop() {
  kill -TERM $apid
  # an estimated passage is ~100 sweeps: the drain takes long under ASan
  i=0; while kill -0 $apid 2>/dev/null; do
    i=$((i + 1)); [ $i -lt 3000 ] || fail "amfid did not stop on SIGTERM"; sleep 0.1; done
  wait $apid || fail "amfid exit status $?"
}
# run NAME SPEED_ERROR: N vehicles through amfid into $dir/NAME.db, alerts logged
run() {
  start "$1"
  lcm-logger -c 'AMFI_ALERT' -f "$dir/$1.lcmlog" > "$dir/$1-logger.log" 2>&1 &
  lpid=$!; pids="$pids $lpid"
  sleep 0.3
  timeout 120 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --headway 3 --speedup 10 --seed 7 --speed-error "$2" \
    2> "$dir/$1-sim.log" || fail "sim_publisher exited $? ($1)"
  sleep 1
  stop
  sleep 0.3
  kill -INT $lpid 2>/dev/null; wait $lpid 2>/dev/null
}
q() { sqlite3 "$dir/$1.db" "$2"; }

# ---- the detector 4 % high ----
run high 0.04,0
est=$(q high "SELECT count(*) FROM passages WHERE speed_estimated = 1")
[ "$est" -ge 4 ] || fail "only $est estimated passages (the window is 4)"
raised=$(q high "SELECT count(*) FROM alerts WHERE kind = 'speed_drift' AND raised = 1")
[ "$raised" -eq 1 ] || fail "$raised speed_drift raises stored, expected 1"
[ "$(q high "SELECT count(*) FROM alerts WHERE kind = 'speed_drift' AND raised = 0")" -eq 0 ] ||
  fail "the speed_drift alert was cleared"
[ "$(q high "SELECT level FROM alerts WHERE kind = 'speed_drift'")" = info ] || fail "not an info alert"
# raised at the 4th estimated passage (data time)
fourth=$(q high "SELECT utime FROM passages WHERE speed_estimated = 1 ORDER BY utime, id LIMIT 1 OFFSET 3")
at=$(q high "SELECT utime FROM alerts WHERE kind = 'speed_drift'")
[ "$at" = "$fourth" ] || fail "raised at $at, the 4th estimated passage is at $fourth"
msg=$(q high "SELECT message FROM alerts WHERE kind = 'speed_drift'")
echo "raised: $msg"
echo "$msg" | grep -Eq 'median speed correction -3\.[6-9][0-9] % over the last 4 estimated passages .*reads [34]\.[0-9] % high' ||
  fail "alert message: $msg"
grep -q "ALERT speed_drift (info)" "$dir/high.log" || fail "the alert is not in the journal"
published=$("$lcmp" --site "$dir/high.lcmlog" | grep -c '^AMFI_ALERT ')
[ "$published" -eq 1 ] || fail "$published alerts published on AMFI_ALERT, expected 1"
"$report" --db "$dir/high.db" --speed > "$dir/high.report" 2> "$dir/report.log" || fail "amfi-report --speed"
cat "$dir/high.report"
med=$("$report" --db "$dir/high.db" --speed --format csv | awk -F, '$1 == "all" { print $3 }')
awk -v m="$med" 'BEGIN { exit !(m > -4.1 && m < -3.6) }' || fail "median correction $med %, expected near -3.85 %"
grep -q "^estimated    $est passages" "$dir/high.report" || fail "the report does not count $est estimated passages"
# a restart keeps the alert open and refills the window
start high
grep -q "speed drift: 4 estimated passages from the store; the speed_drift alert is open" "$dir/high.log" ||
  fail "the restart did not restore the speed-drift state"
stop
[ "$(q high "SELECT count(*) FROM alerts WHERE kind = 'speed_drift'")" -eq 1 ] || fail "the restart raised again"

# ---- the detector exact ----
run exact 0,0
est=$(q exact "SELECT count(*) FROM passages WHERE speed_estimated = 1")
[ "$est" -ge 4 ] || fail "only $est estimated passages (exact)"
[ "$(q exact "SELECT count(*) FROM alerts")" -eq 0 ] || fail "alerts with an exact detector: $(q exact "SELECT message FROM alerts")"
published=$("$lcmp" --site "$dir/exact.lcmlog" | grep -c '^AMFI_ALERT ')
[ "$published" -eq 0 ] || fail "$published alerts published with an exact detector"
med=$("$report" --db "$dir/exact.db" --speed --format csv | awk -F, '$1 == "all" { print $3 }')
echo "exact detector: median correction $med % over $est estimated passages, no alert"
awk -v m="$med" 'BEGIN { exit !(m > -0.5 && m < 0.5) }' || fail "median correction $med % with an exact detector"
echo "daemon_speed_drift: ok"
