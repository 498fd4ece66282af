#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on bad input from the bus (no network: an LCM log read through
# file://): a duplicate, a truncated and an unknown-sensor accel block,
# random bytes on each input channel, an invalid vehicle, two blocks out of
# order. amfid must count them, store the invalid vehicle with its reason,
# weigh the real vehicles, and exit cleanly.
# Usage: daemon_bad_input.sh AMFID SIM_PUBLISHER LCM_INJECT CONFIG
set -u
amfid=$1 sim=$2 inject=$3 config=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
# a simulation: the truth channel is subscribed (and its decoder exercised)
sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || { echo "FAIL: daemon.simulation did not apply"; exit 1; }
config=$dir/sim.yaml
fail() { echo "FAIL: $*"; tail -30 "$dir/amfid.log"; exit 1; }
"$sim" --lcm-url none --log "$dir/clean.log" --vehicles 3 --headway 4 --speedup max --seed 2 \
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
