#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Bounded intake: the few messages that once stopped amfid from weighing (a
# misbehaving or misconfigured instrument sends the same), spliced by
# lcm_intake_forge into a clean stream and replayed through file:// (no network),
# amfid with the shipped configuration. Each case: every real vehicle is
# weighed ok, the forged messages are refused with a reason naming the
# channel and the field, and the refusals are counted in the store's
# summaries (table refusals) instead of one row each.
#   rate         one accel block at 999 Hz before the stream (every passage gap)
#   future       256 vehicles dated 2286 (every real vehicle invalid)
#   slow         one vehicle at 1 m/s (real passages multiple)
#   flood        3000 refused vehicles (3000 fsync'd rows)
#   environment  forged deck temperatures between the real ones, and 2000
#                readings in one second (all stored, the compensation shifted)
#   reference    calibration references from another source or out of range
# Usage: daemon_intake.sh AMFID SIM_PUBLISHER LCM_FORGE CONFIG [CASE...]
set -u
amfid=$1 sim=$2 forge=$3 config=$4
shift 4
cases=${*:-rate future slow flood environment reference}
N=12
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
fail() { echo "FAIL: $case: $*"; tail -20 "$dir/$case.log" 2>/dev/null; exit 1; }
q() { sqlite3 "$dir/$case.db" "$1"; }
case=clean
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/clean.lcmlog" --vehicles $N --headway 4 --speedup max --seed 2 \
  2> "$dir/sim.log" || fail "sim_publisher: $(tail -3 "$dir/sim.log")"
for case in $cases; do
  "$forge" "$case" "$dir/clean.lcmlog" "$dir/$case.lcmlog" || fail "lcm_intake_forge"
  "$amfid" --config "$config" --db "$dir/$case.db" \
    --lcm-url "file://$dir/$case.lcmlog?speed=0" 2> "$dir/$case.log" || fail "amfid exit status $?"
  ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND vehicle_id < 800000")
  [ "$ok" -eq $N ] ||
    fail "$ok of $N real vehicles ok: $(q "SELECT status, count(*), min(reason) FROM passages WHERE vehicle_id < 800000 GROUP BY status")"
  refused() { q "SELECT coalesce(sum(count), 0) FROM refusals WHERE input = '$1' AND reason = '$2'"; }
  case $case in
  rate)
    grep -q "AMFI_ACCEL: accel_block_t sensor 0 seq 0 rejected: sample_rate_hz 999 differs from sensors\[0\].rate_hz (1000 Hz)" \
      "$dir/$case.log" || fail "the 999 Hz block is not refused by name"
    [ "$(refused accel invalid)" -eq 1 ] || fail "refusals: accel invalid $(refused accel invalid), want 1"
    q "SELECT example FROM refusals WHERE input = 'accel'" | grep -q "sample_rate_hz 999" ||
      fail "the summary's example is not the refused block" ;;
  future)
    # the first burst waits (no data yet) and is refused when the data come;
    # the rest is over the vehicle channel's rate: counted, no row each
    inv=$(q "SELECT count(*) FROM passages WHERE vehicle_id >= 800000 AND status = 'invalid' AND reason LIKE '%s past the newest data time (daemon.intake.vehicle_ahead_s 120 s)%'")
    lim=$(refused vehicle rate_limited)
    [ $((inv + lim)) -eq 257 ] || fail "$inv invalid rows + $lim rate-limited, want 257 forged vehicles"
    # the one sent once the data flowed: refused on arrival, stored at the data's time
    q "SELECT status, reason FROM passages WHERE vehicle_id = 801000 AND utime < 4102444800000000" |
      grep -q "^invalid|AMFI_VEHICLE: vehicle_t 801000 rejected: utime [0-9]* s past the newest data time (daemon.intake.vehicle_ahead_s 120 s)" ||
      fail "vehicle 801000: $(q "SELECT status, utime, reason FROM passages WHERE vehicle_id = 801000")"
    [ "$inv" -le 200 ] || fail "$inv rows for the forged vehicles (the rate limit's burst is 100)"
    [ "$(q "SELECT count(*) FROM passages WHERE utime > 4102444800000000")" -eq 0 ] ||
      fail "a row dated after 2100: $(q "SELECT vehicle_id, utime FROM passages WHERE utime > 4102444800000000 LIMIT 1")" ;;
  slow)
    q "SELECT status, reason FROM passages WHERE vehicle_id = 810000" |
      grep -q "^invalid|AMFI_VEHICLE: vehicle_t 810000 rejected: speed_mps 1 below daemon.intake.min_speed_mps (2 m/s)" ||
      fail "the 1 m/s vehicle: $(q "SELECT status, reason FROM passages WHERE vehicle_id = 810000")" ;;
  flood)
    inv=$(q "SELECT count(*) FROM passages WHERE vehicle_id >= 820000 AND status = 'invalid'")
    lim=$(refused vehicle rate_limited)
    [ $((inv + lim)) -eq 3000 ] || fail "$inv invalid rows + $lim rate-limited, want 3000"
    [ "$inv" -le 200 ] || fail "$inv rows for 3000 refused vehicles (one each)"
    [ "$(q "SELECT count(*) FROM refusals")" -le 4 ] || fail "$(q "SELECT count(*) FROM refusals") summary rows" ;;
  environment)
    [ "$(q "SELECT count(*) FROM environment WHERE deck_c > 30")" -eq 0 ] ||
      fail "a forged deck temperature was stored"
    rows=$(q "SELECT count(*) FROM environment")
    span=$(q "SELECT (max(utime) - min(utime)) / 1000000 FROM passages WHERE vehicle_id < 800000")
    [ "$rows" -le $((span / 20 + 4)) ] || fail "$rows environment rows over $span s of data"
    [ "$(refused environment implausible)" -ge 2 ] || fail "implausible: $(refused environment implausible)"
    [ "$(refused environment rate_limited)" -ge 1800 ] || fail "rate_limited: $(refused environment rate_limited)"
    q "SELECT example FROM refusals WHERE input = 'environment' AND reason = 'implausible'" |
      grep -q "AMFI_ENVIRONMENT: environment_t rejected: deck_c 35.00 °C is 2[35].00 °C from the last accepted reading" ||
      fail "the forged reading's refusal is not summarised by name"
    [ "$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND abs(deck_c - 10) > 2.01")" -eq 0 ] ||
      fail "a passage got a forged deck temperature" ;;
  reference)
    [ "$(q "SELECT count(*) FROM passages WHERE reference_gvw_kg IS NOT NULL")" -eq 0 ] ||
      fail "a reference GVW was taken: $(q "SELECT vehicle_id, reference_gvw_kg FROM passages WHERE reference_gvw_kg IS NOT NULL LIMIT 3")"
    odd=$(q "SELECT count(*) FROM passages WHERE vehicle_id % 2 = 1")
    [ "$(refused vehicle source)" -eq "$odd" ] || fail "source: $(refused vehicle source), want $odd"
    [ "$(refused vehicle implausible)" -eq $((N - odd)) ] ||
      fail "implausible: $(refused vehicle implausible), want $((N - odd))"
    grep -q "reference_gvw_kg 14829 not taken: source 'rogue-detector' is not in daemon.intake.calibration_sources" \
      "$dir/$case.log" || fail "the foreign reference is not logged by name" ;;
  esac
  echo "$case: $N of $N real vehicles ok; $(q "SELECT group_concat(input || '/' || reason || ' ' || count, ', ') FROM refusals")"
done
