#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid records the environment (issue 14), on LCM's UDP multicast inside a
# private network namespace: sim_publisher --environment site publishes a
# few vehicles and an environment_t every second of data time; amfid stores
# every reading it published (counted in sim_publisher's own log of what it
# sent) in the table environment. Then bad environment_t on the bus (40
# random bytes, deck_c NaN, air_c 95 °C, a reading dated 10 days after the
# stream) are refused, logged naming the channel and field, counted by
# reason in the log at stop and in the metrics file, and never stored; a
# good reading after them is. amfi-report prints the temperature line.
# Usage: daemon_environment.sh AMFID SIM_PUBLISHER LCM_ENVIRONMENT LCM_INJECT AMFI_REPORT CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 envsum=$3 inject=$4 report=$5 config=$6
N=6
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }

# a metrics file written at stop, to read the refusal counters from
# (the simulated climate is time-compressed: its deck temperature changes far
# faster than a real deck's, which daemon.intake.deck_max_rate_c_per_min refuses)
sed -e "s|^  # textfile: .*|  textfile: $dir/amfid.prom|" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" "$config" > "$dir/amfid.yaml"
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "check-config"
"$amfid" --config "$dir/amfid.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"

# 1. live traffic with the site's climate; sim_publisher logs what it sends
timeout 120 "$sim" --allow-production-bus --vehicles $N --headway 3 --speedup 20 --seed 3 --dt 2.5e-4 \
  --environment site --time-compression 73000 --environment-period 1 \
  --log "$dir/sent.lcmlog" 2> "$dir/sim.log" || fail "sim_publisher exited $?"
"$envsum" "$dir/sent.lcmlog" > "$dir/sent.txt" || fail "lcm_environment"
sent=$(sed -n 's/^env \([0-9]*\) .*/\1/p' "$dir/sent.txt")
[ "${sent:-0}" -ge 10 ] || fail "sim_publisher sent ${sent:-no} environment_t: $(cat "$dir/sent.txt")"

# 2. bad readings on the bus, then a good one
"$inject" --bad-environment "$dir/sent.lcmlog" "$dir/bad.lcmlog" || fail "lcm_inject"
sleep 0.5
lcm-logplayer -s 1 "$dir/bad.lcmlog" > "$dir/player.log" 2>&1 || fail "lcm-logplayer"
sleep 1.5
kill -TERM $apid
i=0; while kill -0 $apid 2>/dev/null; do
  i=$((i + 1)); [ $i -lt 600 ] || fail "amfid did not stop on SIGTERM"; sleep 0.1; done
wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exit status $rc"

rows=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM environment")
[ "$rows" -eq $((sent + 1)) ] || fail "$rows environment rows; sim_publisher sent $sent, plus 1 good injected"
passages=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages")
[ "$passages" -eq $N ] || fail "$passages passages for $N vehicles"
# what was stored is what was sent: first and last data time, deck range
set -- $(sed -n 's/^env //p' "$dir/sent.txt")
first=$2 last=$3 dmin=$8 dmax=$9
[ "$(sqlite3 "$dir/a.db" "SELECT min(utime) FROM environment")" = "$first" ] || fail "first reading"
[ "$(sqlite3 "$dir/a.db" "SELECT max(utime) FROM environment WHERE utime <= $last")" = "$last" ] ||
  fail "last reading"
[ "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM environment WHERE utime = $last + 1000000 AND deck_c = 5.5 AND air_c = 4.5")" = 1 ] ||
  fail "the good reading after the bad ones is not stored"
[ "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM environment WHERE received_utime < 1700000000000000")" = 0 ] ||
  fail "received_utime is not the wall clock"
sqlite3 "$dir/a.db" "SELECT printf('%.4f %.4f', min(deck_c), max(deck_c)) FROM environment WHERE utime <= $last" > "$dir/range.txt"
# (lcm_environment prints two decimals)
awk -v a="$dmin" -v b="$dmax" '{ d1 = $1 - a; d2 = $2 - b
  exit !(d1 < 0.0051 && d1 > -0.0051 && d2 < 0.0051 && d2 > -0.0051) }' "$dir/range.txt" ||
  fail "deck range stored $(cat "$dir/range.txt"), sent $dmin .. $dmax"

# the refusals: logged with channel and field, counted by reason
for what in "AMFI_ENVIRONMENT: malformed environment_t (40 bytes) rejected" \
            "AMFI_ENVIRONMENT: environment_t rejected: deck_c nan" \
            "AMFI_ENVIRONMENT: environment_t rejected: air_c 95 " \
            "AMFI_ENVIRONMENT: environment_t rejected: utime .* s from the stream's newest data time (more than daemon.environment_max_skew_s 3600 s)"; do
  grep -q "$what" "$dir/amfid.log" || fail "no log line for: $what"
done
grep -q "refused since start: AMFI_ENVIRONMENT (environment) invalid: 3$" "$dir/amfid.log" ||
  fail "invalid refusals not counted: $(grep 'refused since start' "$dir/amfid.log")"
grep -q "environment: $((sent + 4)) readings decoded, 4 refused, $((sent + 1)) stored$" \
  "$dir/amfid.log" || fail "stop line: $(grep 'environment:' "$dir/amfid.log" | tail -1)"
grep -q 'amfi_messages_refused_total{input="environment",reason="invalid"} 3$' "$dir/amfid.prom" ||
  fail "metrics: $(grep refused "$dir/amfid.prom")"
[ "$(sqlite3 "$dir/a.db" "SELECT value FROM meta WHERE key = 'intake.environment_refused'")" = 4 ] ||
  fail "meta intake.environment_refused"
"$report" --db "$dir/a.db" --summary > "$dir/report.txt" || fail "amfi-report"
grep -Eq "^temperature +deck -?[0-9.]+ \.\. -?[0-9.]+ °C, air .*, $((sent + 1)) readings, " "$dir/report.txt" ||
  fail "report: $(grep -i temperature "$dir/report.txt")"
echo "environment on the bus: $sent readings sent and stored (+1 after 4 refused), deck $dmin .. $dmax °C"
