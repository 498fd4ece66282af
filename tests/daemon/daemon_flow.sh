#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on random traffic (issue 13): sim_publisher streams ~60 vehicles of
# one lane with Poisson arrivals at a mean headway of 3 s (--flow 1200) on
# the bus; amfid, as shipped, weighs vehicles that share the span together.
# Checked in the store: every vehicle has its passage row (none lost), at
# least 99 % of them ok, and events of several vehicles occurred; the share
# and the GVW error by event size are printed. Inside a private network
# namespace.
# Usage: daemon_flow.sh AMFID SIM_PUBLISHER CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=60

# a simulation: the truth channel is subscribed (and its decoder exercised)
sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || { echo "FAIL: daemon.simulation did not apply"; exit 1; }
config=$dir/sim.yaml
amfid_start "$amfid" "$config"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --flow 1200 --lanes 1 --speedup 20 --seed 5 \
  2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop

q() { sqlite3 "$dir/s.db" "$1"; }
rows=$(q "SELECT count(DISTINCT vehicle_id) FROM passages")
all=$(q "SELECT count(*) FROM passages")
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
truth=$(q "SELECT count(*) FROM truth")
echo "vehicles: $N simulated, $truth truths, $all passage rows ($rows vehicles), $ok ok"
q "SELECT status, reason, count(*) FROM passages WHERE status <> 'ok' GROUP BY 1, 2"
echo "n_vehicles | vehicles | ok | GVW error mean abs % | worst % | mean quality"
q "SELECT p.n_vehicles, count(*), sum(p.status = 'ok'),
          printf('%.2f', avg(abs(e.gvw_error_pct))), printf('%.2f', max(abs(e.gvw_error_pct))),
          CASE WHEN avg(p.quality) IS NULL THEN '-' ELSE printf('%.2f', avg(p.quality)) END
   FROM passages p JOIN passage_errors e ON e.passage_id = p.id GROUP BY p.n_vehicles"
[ "$all" -eq $N ] && [ "$rows" -eq $N ] || fail "expected $N passage rows, one per vehicle: $all rows, $rows vehicles"
awk -v ok="$ok" -v n=$N 'BEGIN { exit !(ok >= 0.99 * n) }' || fail "only $ok of $N ok (< 99 %)"
multi=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND n_vehicles >= 2")
[ "$multi" -ge 5 ] || fail "only $multi vehicles weighed together: the stream did not test events"
three=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND n_vehicles >= 3")
bad=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND (n_vehicles > 1) <> (quality IS NOT NULL)")
[ "$bad" -eq 0 ] || fail "$bad ok rows with a quality that does not match n_vehicles"
echo "daemon_flow: ok ($multi vehicles weighed together, $three in events of three or more)"
