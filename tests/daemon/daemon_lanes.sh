#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on two-lane traffic (issue 13, vehicles that cannot be separated):
# sim_publisher streams ~40 vehicles of two lanes, Poisson arrivals at a
# mean headway of 3 s per lane, on the bus; amfid as shipped, but with an
# indicator window of 10 evaluated after every ok passage. Checked in the
# store: every vehicle has its passage row; some are stored multiple as
# inseparable, each with its joint estimate (GVW, axles, quality) and a
# reason naming the other vehicle or the figure; every indicator window's
# mean is that of the last `n` ok passages, i.e. no inseparable one was
# counted. Inside a private network namespace.
# Usage: daemon_lanes.sh AMFID SIM_PUBLISHER CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=40

sed -e 's/^    window: 500 /    window: 10 /' -e 's/^    every: 100 /    every: 1 /' \
    -e 's/^    baseline_n: 10000 /    baseline_n: 10 /' "$config" > "$dir/amfid.yaml"
grep -q "^    window: 10 " "$dir/amfid.yaml" && grep -q "^    every: 1 " "$dir/amfid.yaml" &&
  grep -q "^    baseline_n: 10 " "$dir/amfid.yaml" || fail "could not set the indicator window"
amfid_start "$amfid" "$dir/amfid.yaml"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --flow 1200 --lanes 2 --speedup 20 --seed 3 \
  2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop

q() { sqlite3 "$dir/s.db" "$1"; }
rows=$(q "SELECT count(DISTINCT vehicle_id) FROM passages")
all=$(q "SELECT count(*) FROM passages")
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
ins=$(q "SELECT count(*) FROM passages WHERE status = 'multiple' AND reason LIKE 'inseparable: %'")
echo "vehicles: $N simulated, $all passage rows ($rows vehicles), $ok ok, $ins inseparable"
q "SELECT vehicle_id, lane, n_vehicles, printf('%.0f', gvw_kg), printf('%.2f', quality), reason
   FROM passages WHERE status <> 'ok'"
echo "status | vehicles | GVW error mean abs % | worst %"
q "SELECT status, count(*), printf('%.2f', avg(abs(gvw_error_pct))), printf('%.2f', max(abs(gvw_error_pct)))
   FROM passage_errors GROUP BY status"
[ "$all" -eq $N ] && [ "$rows" -eq $N ] || fail "expected $N passage rows, one per vehicle: $all rows, $rows vehicles"
[ "$ins" -ge 2 ] || fail "only $ins inseparable vehicles: the stream did not test them"
# the joint estimate is kept: GVW, every axle load and the quality figure
bad=$(q "SELECT count(*) FROM passages p WHERE status = 'multiple' AND reason LIKE 'inseparable: %'
         AND (gvw_kg IS NULL OR gvw_kg <= 0 OR quality IS NULL OR n_vehicles < 2
              OR (SELECT count(load_kg) FROM axles a WHERE a.passage_id = p.id) <> n_axles)")
[ "$bad" -eq 0 ] || fail "$bad inseparable rows without their joint estimate"
# ... but no weight fed to the STD and mean rules (passages.gvw_comp_kg)
bad=$(q "SELECT count(*) FROM passages WHERE status <> 'ok' AND gvw_comp_kg IS NOT NULL")
[ "$bad" -eq 0 ] || fail "$bad rows not ok with a weight fed to the indicators"
# the reason names the other vehicle and the share, or the quality figure
bad=$(q "SELECT count(*) FROM passages WHERE status = 'multiple' AND reason LIKE 'inseparable: %'
         AND NOT (reason GLOB 'inseparable: axles within * m of vehicle [0-9]*''s for [0-9]* % of its crossing*kg the two together*'
                  OR reason GLOB 'inseparable: axles at one point with vehicle [0-9]*''s all along*kg the [0-9]* together*'
                  OR reason GLOB 'inseparable: its weight moves * % when * (quality * > *)*kg together'
                  OR reason GLOB 'inseparable: vehicle [0-9]* was on the span inside its window*')")
[ "$bad" -eq 0 ] || fail "$bad inseparable rows whose reason does not say why"
# other vehicles of an event stay ok when separable
sep=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND n_vehicles >= 2")
[ "$sep" -ge 2 ] || fail "only $sep vehicles of events stayed ok"
# the indicators: each window's mean GVW is that of the n ok passages up to it
nind=$(q "SELECT count(*) FROM indicators")
[ "$nind" -ge 5 ] || fail "only $nind indicator evaluations"
bad=$(q "WITH okp AS (SELECT utime, gvw_kg, row_number() OVER (ORDER BY utime) AS k
                     FROM passages WHERE status = 'ok')
         SELECT count(*) FROM indicators i WHERE NOT abs(i.mean_kg -
           (SELECT avg(gvw_kg) FROM okp WHERE okp.utime <= i.utime
              AND okp.k > (SELECT max(k) FROM okp WHERE okp.utime <= i.utime) - i.n)) <= 0.01")
[ "$bad" -eq 0 ] || fail "$bad of $nind indicator windows are not the mean of their ok passages"
late=$(q "SELECT count(*) FROM passages WHERE status = 'multiple' AND reason LIKE 'inseparable: %'
          AND utime > (SELECT min(utime) FROM indicators)")
[ "$late" -ge 1 ] || fail "no inseparable vehicle fell inside an indicator window"
echo "daemon_lanes: ok ($ins inseparable, $sep of events ok, $nind indicator windows checked)"
