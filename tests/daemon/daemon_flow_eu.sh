#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on dense truck traffic: sim_publisher streams 30 vehicles of the EU
# mix (population-eu.csv: 2-6 axle rigid and articulated trucks) on one
# lane at 1800 vehicles an hour (2 s mean headway) on the bus; three trucks
# on the span together have more than 12 axles, an event libamfi refused
# while its event limit was one vehicle's (AMFI_MAX_AXLES): every vehicle of
# it was stored multiple. Checked in the store: every vehicle has its row,
# at least 28 of 30 ok, and some were weighed in events of three or more.
# Inside a private network namespace.
# Usage: daemon_flow_eu.sh AMFID SIM_PUBLISHER CONFIG POPULATION
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3 population=$4
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=30

sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || { echo "FAIL: daemon.simulation did not apply"; exit 1; }
config=$dir/sim.yaml
amfid_start "$amfid" "$config"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --flow 1800 --lanes 1 --speedup 10 --seed 7 \
  --population "$population" 2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 2
amfid_stop

q() { sqlite3 "$dir/s.db" "$1"; }
all=$(q "SELECT count(*) FROM passages")
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
echo "vehicles: $N simulated, $all passage rows, $ok ok"
q "SELECT status, reason, count(*) FROM passages WHERE status <> 'ok' GROUP BY 1, 2"
echo "n_vehicles | vehicles | ok | GVW error mean abs % | worst %"
q "SELECT p.n_vehicles, count(*), sum(p.status = 'ok'),
          printf('%.2f', avg(abs(e.gvw_error_pct))), printf('%.2f', max(abs(e.gvw_error_pct)))
   FROM passages p JOIN passage_errors e ON e.passage_id = p.id GROUP BY p.n_vehicles"
[ "$all" -eq $N ] || fail "expected $N passage rows, one per vehicle: $all"
[ "$ok" -ge 28 ] || fail "only $ok of $N ok (< 28)"
three=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND n_vehicles >= 3")
[ "$three" -ge 3 ] || fail "only $three vehicles weighed in events of three or more"
echo "daemon_flow_eu: ok ($three in events of three or more)"
