#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid's natural frequency per passage (issue 14, item 4), on LCM's UDP
# multicast inside a private network namespace: sim_publisher --environment
# site sends 16 vehicles 4 s apart (2 s and more of free vibration after
# each) with the site's climate (the modulus follows the deck temperature);
# amfid (daemon.natural_frequency.baseline_n 10) stores f1 for each passage,
# within 1 % of the simulated bridge's first frequency at that deck
# temperature (5.7338 Hz · sqrt(E(T)/E(10 °C)), docs/simulator.md), a damping
# ratio near the model's 3 %, and the compensated f1 once the baseline is
# fitted; passage_t carries both. A restart refits the same baseline from
# the store; a reload says a changed free_s waits for the next start. Then
# 4 vehicles 1.5 s apart: a free vibration cut at the next
# entry (0.5 s, under 4 periods) is refused, stored NULL, counted by reason
# in the log and the meta table.
# Usage: daemon_natfreq.sh AMFID SIM_PUBLISHER LCM_PASSAGES CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 listen=$3 config=$4
N=16
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
q() { sqlite3 "$dir/a.db" "$1"; }

sed -e "s|^    baseline_n: 200 .*|    baseline_n: 10|" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" "$config" > "$dir/amfid.yaml"
grep -q "^    baseline_n: 10" "$dir/amfid.yaml" || fail "no natural_frequency.baseline_n in $config"
start_amfid() {
  # emptied here, not only by the background child's redirection: the wait
  # below must not see the previous run's "running" (a restart's race)
  : > "$dir/amfid.log"
  "$amfid" --config "$dir/amfid.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
  apid=$!; pids="$pids $apid"
  wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
}
stop_amfid() {
  kill -TERM $apid
  wait $apid; rc=$?
  [ $rc -eq 0 ] || fail "amfid exit status $rc"
}

# 1. 14 vehicles, 4 s apart; the passages as published
start_amfid
lcm-logger -c AMFI_PASSAGE -f "$dir/passages.log" > "$dir/logger.log" 2>&1 &
lpid=$!; pids="$pids $lpid"
sleep 0.3
timeout 120 "$sim" --allow-production-bus --vehicles $N --headway 4 --speedup 20 --seed 5 --dt 2.5e-4 \
  --environment site --time-compression 300 --environment-period 1 2> "$dir/sim.log" ||
  fail "sim_publisher exited $?"
sleep 1
stop_amfid
sleep 0.3
kill -INT $lpid; wait $lpid
"$listen" --f1 "$dir/passages.log" > "$dir/published.txt" || fail "lcm_passages"

[ "$(q "SELECT count(*) FROM passages WHERE status = 'ok'")" = $N ] || fail "not $N ok passages"
# the last vehicle's free vibration may be cut by the end of the stream
with=$(q "SELECT count(*) FROM passages WHERE f1_hz IS NOT NULL")
[ "$with" -ge $((N - 1)) ] || fail "$with of $N passages have f1"
# against the simulated bridge: its modulus at the deck temperature of the
# last reading before the passage (1 s of data is 5 min of site time)
q "SELECT p.vehicle_id, p.f1_hz, p.f1_zeta, p.f1_r2,
          (SELECT e.deck_c FROM environment AS e WHERE e.utime <= p.utime
           ORDER BY e.utime DESC LIMIT 1)
   FROM passages AS p WHERE p.f1_hz IS NOT NULL" | tr '|' ' ' > "$dir/f1.txt"
[ "$(awk 'NF == 5' "$dir/f1.txt" | wc -l)" -ge $((N - 2)) ] ||
  fail "f1 and a deck temperature for too few passages: $(cat "$dir/f1.txt")"
awk 'NF == 5 { t = $5; if (t >= 0) e = 1 - 0.0025 * (t - 10); else { if (t < -10) t = -10; e = 1.025 * (1 - 0.02 * t) }
       err = $2 / (5.7338 * sqrt(e)) - 1; if (err < 0) err = -err; if (err > m) m = err
       if ($3 < 0.025 || $3 > 0.035 || $4 < 0.8) bad++ }
     END { printf "f1 max error %.4f against the simulated bridge\n", m; exit !(m < 0.01 && bad == 0) }' \
  "$dir/f1.txt" || fail "f1 off the model: $(cat "$dir/f1.txt")"
comp=$(q "SELECT count(*) FROM passages WHERE f1_comp_hz IS NOT NULL")
[ "$comp" -ge 1 ] || fail "no compensated f1 after a baseline of 10"
grep -q "natural frequency: baseline of 10 estimates" "$dir/amfid.log" || fail "no baseline line"
base=$(sed -n 's/.*natural frequency: baseline of 10 estimates.*: f1 \([0-9.]*\) Hz.*/\1/p' "$dir/amfid.log")
# the compensated f1 near the baseline's (healthy bridge)
[ "$(q "SELECT count(*) FROM passages WHERE f1_comp_hz IS NOT NULL AND abs(f1_comp_hz / $base - 1) > 0.01")" = 0 ] ||
  fail "compensated f1 off the baseline's $base: $(q 'SELECT f1_comp_hz FROM passages')"
# published as stored
pub=$(awk '$4 != "nan" && $4 != "-nan" { n++ } END { print n + 0 }' "$dir/published.txt")
[ "$pub" = "$with" ] || fail "$pub passage_t with f1_hz, $with stored: $(cat "$dir/published.txt")"
[ "$(q "SELECT value FROM meta WHERE key = 'natfreq.estimated'")" = "$with" ] || fail "meta natfreq.estimated"

# 2. a restart: the same baseline from the store
start_amfid
grep -q "natural frequency: baseline from the store: 10 estimates, f1 $base Hz" "$dir/amfid.log" ||
  fail "restart: $(grep 'natural frequency' "$dir/amfid.log")"
# a reload reports a changed free_s, which applies at the next start
sed -i 's/^    free_s: 2 .*/    free_s: 3/' "$dir/amfid.yaml"
kill -HUP $apid
wait_for "reload: configuration .* applied" "$dir/amfid.log" "" 60 || fail "no reload"
grep -q "reload: daemon.natural_frequency.free_s changed; takes effect at the next start" "$dir/amfid.log" ||
  fail "reload: $(grep reload "$dir/amfid.log")"
# 3. vehicles 1.5 s apart: 0.5 s of free vibration each, refused as short
timeout 120 "$sim" --allow-production-bus --vehicles 4 --headway 1.5 --speedup 20 --seed 6 --dt 2.5e-4 \
  --start-utime 1767312000000000 2> "$dir/sim2.log" || fail "sim_publisher exited $?"
sleep 1
stop_amfid
# the first two share the span (one event: the last to leave carries the
# estimate), the third follows 1.5 s later: both cut short; the fourth has
# the stream's tail to itself
[ "$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime >= 1767312000000000 AND f1_hz IS NULL")" = 3 ] ||
  fail "cut free vibrations were not refused: $(q "SELECT vehicle_id, n_vehicles, f1_hz FROM passages WHERE utime >= 1767312000000000")"
short=$(q "SELECT value FROM meta WHERE key = 'natfreq.short'")
[ "${short:-0}" = 2 ] || fail "meta natfreq.short ${short:-none}"
grep -q "natural frequency: 1 passages estimated; not: no_free_vibration 0, short 2, no_peak 0, no_fit 0, damping 0, noisy 0, invalid 0" "$dir/amfid.log" ||
  fail "stop line: $(grep 'natural frequency' "$dir/amfid.log")"
echo "natural frequency on the bus: $with of $N passages, compensated $comp, baseline $base Hz; cut ones refused ($short short)"
