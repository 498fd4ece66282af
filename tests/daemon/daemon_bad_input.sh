#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on bad input from the bus (no network: an LCM log read through
# file://): a duplicate, a truncated and an unknown-sensor accel block,
# random bytes on each input channel, an invalid vehicle, two blocks out of
# order. amfid must count them, store the invalid vehicle with its reason,
# weigh the real vehicles, and exit cleanly.
# Loads no vehicle carries (samples x 30: single axles over 10 x any legal
# load) and a detector record the samples do not match (spacings x 4: a rear
# axle below zero): stored ok with the classification's refusal in
# passages.loads_refused, the overload NULL, and amfi-report --overloads
# lists them as refused with that reason, never as overloads.
# Usage: daemon_bad_input.sh AMFID SIM_PUBLISHER LCM_INJECT CONFIG AMFI_REPORT
set -u
amfid=$1 sim=$2 inject=$3 config=$4 report=$5
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
# a simulation: the truth channel is subscribed (and its decoder exercised)
sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || { echo "FAIL: daemon.simulation did not apply"; exit 1; }
config=$dir/sim.yaml
fail() { echo "FAIL: $*"; tail -30 "$dir/amfid.log"; exit 1; }
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/clean.log" --vehicles 3 --headway 4 --speedup max --seed 2 \
  2> "$dir/sim.log" || fail "sim_publisher"
"$inject" "$dir/clean.log" "$dir/bad.log" || fail "lcm_inject"
"$amfid" --config "$config" --db "$dir/a.db" --lcm-url "file://$dir/bad.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ $rc -eq 0 ] || fail "amfid exit status $rc"
for what in "malformed accel_block_t" "malformed vehicle_t" "malformed truth_t" \
            "vehicle_t 424242 rejected: speed_mps" "sensor 99 .* rejected: sensor_id not in the configuration" \
            "vehicle_t 424243 rejected: n_spacings must be n_axles - 1" \
            "vehicle_t 424244 rejected: n_axles out of range for the solver"; do
  grep -q "$what" "$dir/amfid.log" || fail "no log line for: $what"
done
grep -q "stopped: 6 passages stored (3 ok)" "$dir/amfid.log" || fail "counts: $(grep stopped "$dir/amfid.log")"
sqlite3 "$dir/a.db" "SELECT status FROM passages WHERE vehicle_id = 424242" | grep -qx invalid ||
  fail "the invalid vehicle was not stored as invalid"
# spacings that do not match the axle count, more axles than the solver takes
# (solver.max_axles 6):
# stored invalid with the reason, no class
for v in "424243|n_spacings must be n_axles - 1" "424244|n_axles out of range for the solver"; do
  sqlite3 "$dir/a.db" "SELECT count(*) FROM passages WHERE vehicle_id = ${v%%|*} AND status = 'invalid'
                       AND instr(reason, '${v#*|}') > 0 AND class IS NULL" | grep -qx 1 ||
    fail "vehicle ${v%%|*}: $(sqlite3 "$dir/a.db" "SELECT * FROM passages WHERE vehicle_id = ${v%%|*}")"
done
[ "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages WHERE status = 'ok'")" -eq 3 ] ||
  fail "the three real vehicles are not all ok"
echo "bad input: $(grep -c 'rejected' "$dir/amfid.log") rejections logged, 3 vehicles ok, 3 invalid stored"

# Vehicles and no sensor data at all (the DAQ is down): each vehicle is
# stored as gap with its reason, and amfid stops cleanly (it used to crash
# at shutdown reading the sample rate of a sensor that never sent a block).
"$inject" --vehicles-only "$dir/clean.log" "$dir/novdata.log" || fail "lcm_inject --vehicles-only"
"$amfid" --config "$config" --db "$dir/b.db" --lcm-url "file://$dir/novdata.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ $rc -eq 0 ] || fail "amfid on vehicles without data: exit status $rc"
[ "$(sqlite3 "$dir/b.db" "SELECT count(*) FROM passages WHERE status = 'gap' AND reason <> ''")" -eq 3 ] ||
  fail "vehicles without data: $(sqlite3 "$dir/b.db" "SELECT status, reason FROM passages")"
echo "vehicles without sensor data: 3 stored as gap, clean stop"

# Samples within the intake's limits but far beyond a real bridge's (x 5000):
# the solver's weights are beyond the store's ranges. Each passage is stored
# as error with the reason; the store is not "degraded", nothing is held.
"$inject" --scale-accel 5000 "$dir/clean.log" "$dir/huge.log" || fail "lcm_inject --scale-accel"
"$amfid" --config "$config" --db "$dir/c.db" --lcm-url "file://$dir/huge.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ $rc -eq 0 ] || fail "amfid on absurd samples: exit status $rc"
n=$(sqlite3 "$dir/c.db" "SELECT count(*) FROM passages WHERE status = 'error' AND reason LIKE 'result not storable: %out of range%'")
[ "$n" -eq 3 ] || fail "absurd samples: $(sqlite3 "$dir/c.db" "SELECT status, reason FROM passages")"
grep -q "store_degraded" "$dir/amfid.log" && fail "absurd samples made the store degraded"
echo "absurd samples: 3 passages stored as error (result not storable), store never degraded"

# Loads the classification refuses (classify/: a single axle or a group
# below zero, or above 10 x any legal load of its axle count). Samples x 30:
# each axle of the three two-axle vehicles carries over 115 t (10 x the
# 11.5 t any single axle may carry); spacings x 4: the solve puts the rear
# axle below zero (at least the third vehicle's, about -2.4 t). Each such
# passage is stored ok with its class, a NULL overload and the reason; a
# passage is refused exactly when one of its stored axle loads is below zero
# or above 115 t. amfi-report --overloads counts none of them as an
# overload and lists each as refused with the stored reason.
refused_check() { # DB WHAT GLOB MIN
  q() { sqlite3 "$1" "$2"; }
  n=$(q "$1" "SELECT count(*) FROM passages WHERE status = 'ok' AND class = 'R2' AND overload IS NULL
             AND loads_refused GLOB '$3'")
  [ "$n" -ge "$4" ] || fail "$2: $n passages stored with a refusal '$3', want >= $4: $(q "$1" "SELECT id, status, class, overload, loads_refused FROM passages")"
  bad=$(q "$1" "SELECT count(*) FROM passages p WHERE status = 'ok' AND (loads_refused IS NOT NULL) <>
                EXISTS (SELECT 1 FROM axles a WHERE a.passage_id = p.id AND (a.load_kg < 0 OR a.load_kg > 115000))")
  [ "$bad" -eq 0 ] || fail "$2: $bad passages whose refusal does not match their loads: $(q "$1" "SELECT p.id, p.loads_refused, group_concat(a.load_kg) FROM passages p JOIN axles a ON a.passage_id = p.id GROUP BY p.id")"
  "$report" --db "$1" --overloads > "$dir/over.txt" 2> "$dir/over.err" || fail "$2: amfi-report --overloads: $(cat "$dir/over.err")"
  grep -q "^checked $((3 - n)) ok passages: .*, 0 overloaded in all" "$dir/over.txt" ||
    fail "$2: amfi-report counts a refused passage as checked or overloaded: $(cat "$dir/over.txt")"
  grep -q "^== loads refused ($n ok passages" "$dir/over.txt" || fail "$2: no section of refused loads: $(cat "$dir/over.txt")"
  for id in $(q "$1" "SELECT id FROM passages WHERE loads_refused IS NOT NULL"); do
    grep -qF " $id  $(q "$1" "SELECT printf('%10d  %4d  %-7.7s', vehicle_id, lane, class) FROM passages WHERE id = $id")" "$dir/over.txt" &&
      grep -qF "loads refused: $(q "$1" "SELECT loads_refused FROM passages WHERE id = $id")" "$dir/over.txt" ||
      fail "$2: passage $id not listed refused with its stored reason: $(cat "$dir/over.txt")"
  done
  "$report" --db "$1" --overloads --format csv > "$dir/over.csv" 2> "$dir/over.err" || fail "$2: --format csv"
  [ "$(grep -c ',refused,' "$dir/over.csv")" -eq "$n" ] && [ "$(wc -l < "$dir/over.csv")" -eq $((n + 1)) ] ||
    fail "$2: the CSV is not one refused line per refused passage: $(cat "$dir/over.csv")"
}
"$inject" --scale-accel 30 "$dir/clean.log" "$dir/heavy.log" || fail "lcm_inject --scale-accel 30"
"$amfid" --config "$config" --db "$dir/h.db" --lcm-url "file://$dir/heavy.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid on loads over 10 x legal: exit status $?"
refused_check "$dir/h.db" "loads x 30" 'single axle [12]: load * kg, over 10 x any legal load of 1 axle (11500 kg)' 3
"$inject" --scale-spacing 4 "$dir/clean.log" "$dir/long.log" || fail "lcm_inject --scale-spacing 4"
"$amfid" --config "$config" --db "$dir/l.db" --lcm-url "file://$dir/long.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid on spacings x 4: exit status $?"
refused_check "$dir/l.db" "spacings x 4" 'axle 2: load -* kg < 0 (a single axle)' 1
echo "refused loads: $(sqlite3 "$dir/h.db" "SELECT count(*) FROM passages WHERE loads_refused IS NOT NULL") of 3 over 10 x legal, $(sqlite3 "$dir/l.db" "SELECT count(*) FROM passages WHERE loads_refused IS NOT NULL") of 3 below zero; stored with the reason, listed refused by amfi-report"

# Two vehicles side by side (every vehicle with a twin on the other lane:
# same entry, speed and spacings; the samples hold one vehicle): axles at
# one point all along, merged by the solver. Each is stored multiple, not
# error (with OpenBLAS's SkylakeX kernel the event once failed as a whole,
# "sweep failed: numerical failure"), with the reason naming the other and
# the pair's weight, which is the one vehicle's (truth within 5 %) and the
# sum of the two rows' weights.
"$inject" --twin-lanes "$dir/clean.log" "$dir/twins.log" || fail "lcm_inject --twin-lanes"
"$amfid" --config "$config" --db "$dir/d.db" --lcm-url "file://$dir/twins.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ $rc -eq 0 ] || fail "amfid on twins: exit status $rc"
q() { sqlite3 "$dir/d.db" "$1"; }
pairs="passages a JOIN passages b ON b.vehicle_id = a.vehicle_id + 1000000
       JOIN truth t ON t.vehicle_id = a.vehicle_id"
n=$(q "SELECT count(*) FROM passages WHERE status = 'multiple' AND n_vehicles = 2
       AND reason GLOB 'inseparable: axles at one point with vehicle [0-9]*''s all along*; [0-9]* kg the 2 together*'")
[ "$n" -eq 6 ] || fail "twins: $n of 6 rows multiple with the reason: $(q "SELECT vehicle_id, status, reason FROM passages")"
npairs=$(q "SELECT count(*) FROM $pairs")
bad=$(q "SELECT count(*) FROM $pairs
         WHERE NOT (abs((a.gvw_kg + b.gvw_kg) / t.gvw_kg - 1) < 0.05
                    AND abs(CAST(substr(a.reason, instr(a.reason, '; ') + 2) AS REAL)
                            - (a.gvw_kg + b.gvw_kg)) <= 1
                    AND instr(a.reason, 'vehicle ' || b.vehicle_id || '''s') > 0)")
[ "$npairs" -eq 3 ] && [ "$bad" -eq 0 ] ||
  fail "twins: $npairs pairs with truth, $bad whose sum or reason is wrong: $(q "SELECT a.vehicle_id, a.gvw_kg + b.gvw_kg, t.gvw_kg, a.reason FROM $pairs")"
echo "twins side by side: 6 rows multiple; each pair against the vehicle's truth: $(q "SELECT group_concat(printf('%+.2f %%', 100 * ((a.gvw_kg + b.gvw_kg) / t.gvw_kg - 1)), ', ') FROM $pairs")"
