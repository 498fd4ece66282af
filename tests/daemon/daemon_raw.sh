#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The passages' raw samples (amfid's module raw, daemon.store.raw) on LCM's
# UDP multicast inside a private network namespace: sim_publisher streams
# two lanes of traffic (vehicles on the span together: events weighed
# jointly) into amfid with keep: all; then
#   - every passage weighed has its raw samples: one raw_windows row per
#     window, the later vehicles of an event linked to its window;
#   - amfi-solve --from-store re-weighs passages (alone and an event's later
#     vehicle) with the site file amfid ran with and gets amfid's GVW and
#     axle loads (tests/common/num_cmp.sh, relative 1e-9) and says
#     "identical"; with another λ it weighs otherwise and says why;
#   - the metrics file counts the windows and the log gives the ratio;
#   - retention: a second run with max_mib small deletes the oldest windows
#     at the drain (logged, counted), the passages all stay, a deleted
#     passage's re-weigh is exit 1 naming retention; with keep: failed only
#     the passages not stored ok keep samples; keep: none none.
# Usage: daemon_raw.sh AMFID SIM_PUBLISHER AMFI_SOLVE CONFIG NUM_CMP
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 solve=$3 config=$4 numcmp=$5
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
q() { sqlite3 "$dir/s.db" "$1"; }
N=24

# the site file: a workspace for events (two two-axle vehicles), the metrics
# file, raw samples kept (the shipped defaults: keep all)
sed -e "s/^  max_axles: [0-9]* /  max_axles: 6 /" \
    -e "s|^  # textfile: .*|  textfile: $dir/amfid.prom|" "$config" > "$dir/amfid.yaml"
grep -q "^  max_axles: 6 " "$dir/amfid.yaml" || fail "the test's solver.max_axles did not apply"
grep -q "^  textfile: $dir/amfid.prom" "$dir/amfid.yaml" || fail "the test's metrics.textfile"
grep -q "^      keep: all " "$dir/amfid.yaml" || fail "$config: daemon.store.raw.keep is not all"
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "check-config"

run_traffic() { # $1: the site file; the store $dir/s.db
  amfid_start "$amfid" "$1"
  timeout 240 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --flow 600 --lanes 2 --min-headway 0.5 --speedup 20 \
    --seed 3 2> "$dir/sim.log" || { cat "$dir/sim.log"; fail "sim_publisher exited $?"; }
  sleep 1
  amfid_stop
}
run_traffic "$dir/amfid.yaml"

# ---- every passage weighed has its samples ---------------------------------
q "SELECT status, count(*) FROM passages GROUP BY status"
total=$(q "SELECT count(*) FROM passages")
[ "$total" -eq $N ] || fail "$total passages stored, $N sent"
weighed=$(q "SELECT count(*) FROM passages WHERE status IN ('ok', 'error', 'multiple', 'overload')")
linked=$(q "SELECT count(*) FROM passage_raw")
[ "$weighed" -ge $((N - 2)) ] || fail "only $weighed of $N passages weighed"
[ "$linked" -eq "$weighed" ] || fail "$linked passages with raw samples, $weighed weighed"
windows=$(q "SELECT count(*) FROM raw_windows")
events=$(q "SELECT count(*) FROM passage_raw WHERE vehicle > 0")
[ "$events" -ge 1 ] || fail "no event of several vehicles in the traffic (seed 3)"
[ "$windows" -eq $((linked - events)) ] || fail "$windows windows for $linked passages, $events linked"
q "SELECT count(*) FROM passage_raw pr JOIN passages p ON p.id = pr.passage_id
   WHERE p.n_vehicles > 1" | grep -qx "$((events * 2))" ||
  echo "note: events of more than two vehicles"
q "SELECT count(*) FROM raw_windows WHERE bytes >= n_samples * 8" | grep -qx 0 ||
  fail "a window's samples not compressed"
grep -q "raw samples: $windows windows written" "$dir/amfid.log" || fail "the drain's raw line"
grep -q "^amfi_raw_windows_total{kind=\"window\"} $windows\$" "$dir/amfid.prom" ||
  fail "metrics: $(grep amfi_raw_windows_total "$dir/amfid.prom")"
grep -q "^amfi_raw_stored_windows $windows\$" "$dir/amfid.prom" || fail "metrics: stored windows"

# ---- re-weighed from the store: amfid's weights -----------------------------
# the first four weighed alone and every event's later vehicle
ids=$(q "SELECT pr.passage_id FROM passage_raw pr JOIN passages p ON p.id = pr.passage_id
         WHERE p.gvw_kg IS NOT NULL AND (p.n_vehicles = 1 AND pr.passage_id IN
           (SELECT passage_id FROM passage_raw ORDER BY passage_id LIMIT 6) OR pr.vehicle > 0)
         ORDER BY pr.passage_id")
[ "$(echo $ids | wc -w)" -ge 5 ] || fail "too few passages to re-weigh: $ids"
: > "$dir/stored.txt"; : > "$dir/reweighed.txt"
for id in $ids; do
  "$solve" --config "$dir/amfid.yaml" --from-store "$dir/s.db" --passage "$id" > "$dir/j$id.json" \
    2> "$dir/solve.err" || { cat "$dir/solve.err"; fail "amfi-solve --from-store --passage $id"; }
  g=$(sed 's/.*"passage_gvw_kg":\([^,}]*\).*/\1/' "$dir/j$id.json")
  grep -q '"explained":"identical' "$dir/j$id.json" ||
    fail "passage $id: $(sed 's/.*"difference"//' "$dir/j$id.json")"
  echo "$id $g" >> "$dir/reweighed.txt"
  q "SELECT id, gvw_kg FROM passages WHERE id = $id" | tr '|' ' ' >> "$dir/stored.txt"
done
sh "$numcmp" -r 1e-9 "$dir/stored.txt" "$dir/reweighed.txt" || fail "re-weighed GVW differ from amfid's"
echo "daemon_raw: $(echo $ids | wc -w) passages re-weighed to amfid's GVW:"
paste "$dir/stored.txt" "$dir/reweighed.txt"
# the axle loads too (the event's vehicle included)
for id in $ids; do
  q "SELECT group_concat(load_kg, ' ') FROM (SELECT load_kg FROM axles WHERE passage_id = $id
     ORDER BY idx)" > "$dir/a_stored.txt"
  sed 's/.*"stored":{[^}]*"axle_kg":\[\([^]]*\)\].*/\1/' "$dir/j$id.json" | tr ',' ' ' \
    > "$dir/a_json.txt"
  sh "$numcmp" -r 1e-9 "$dir/a_stored.txt" "$dir/a_json.txt" || fail "passage $id: stored axles"
done
# another λ: weighed otherwise, and said why
first=$(echo $ids | cut -d' ' -f1)
"$solve" --config "$dir/amfid.yaml" --from-store "$dir/s.db" --passage "$first" --lambda 1e-7 \
  > "$dir/lam.json" || fail "amfi-solve --lambda 1e-7"
grep -q '"explained":"the lambda given here' "$dir/lam.json" || fail "--lambda: $(cat "$dir/lam.json")"
grep -q '"difference":{"gvw_kg":0[,.]' "$dir/lam.json" && fail "--lambda 1e-7 weighed the same"

# ---- retention by size, at the drain; keep failed; keep none ------------------
kept_before=$(q "SELECT count(*) FROM raw_windows")
oldest=$(q "SELECT passage_id FROM passage_raw ORDER BY passage_id LIMIT 1")
sed -e "s/^      max_mib: [0-9.]* /      max_mib: 0.05 /" "$dir/amfid.yaml" > "$dir/small.yaml"
grep -q "^      max_mib: 0.05 " "$dir/small.yaml" || fail "the test's max_mib did not apply"
run_traffic "$dir/small.yaml"
bytes=$(q "SELECT sum(bytes) FROM raw_windows")
[ "$bytes" -le 52429 ] || fail "$bytes bytes of raw samples kept, max_mib 0.05"
[ "$(q "SELECT count(*) FROM passages")" -eq $((2 * N)) ] || fail "a passage deleted"
grep -q "raw samples: [0-9]* windows deleted older than 90 days, [1-9][0-9]* beyond 0.05 MiB" \
  "$dir/amfid.log" || fail "retention not logged"
grep -q '^amfi_raw_deleted_total{rule="size"} [1-9]' "$dir/amfid.prom" ||
  fail "retention not counted: $(grep amfi_raw_deleted "$dir/amfid.prom")"
q "SELECT count(*) FROM passage_raw WHERE passage_id = $oldest" | grep -qx 0 ||
  fail "the oldest window ($oldest) kept"
"$solve" --config "$dir/amfid.yaml" --from-store "$dir/s.db" --passage "$oldest" \
  > /dev/null 2> "$dir/gone.err" && fail "re-weighed a deleted passage"
grep -q "passage $oldest .* has no raw samples: .*deleted by retention" "$dir/gone.err" ||
  fail "deleted: $(cat "$dir/gone.err")"
echo "daemon_raw: retention kept $(q "SELECT count(*) FROM raw_windows") windows ($bytes bytes) of $((kept_before + windows))"

rm -f "$dir/s.db" "$dir/s.db-wal" "$dir/s.db-shm"
sed -e "s/^      keep: all /      keep: failed /" "$dir/amfid.yaml" > "$dir/failed.yaml"
run_traffic "$dir/failed.yaml"
q "SELECT count(*) FROM passage_raw pr JOIN passages p ON p.id = pr.passage_id
   WHERE p.status = 'ok' AND p.n_vehicles = 1" | grep -qx 0 ||
  fail "keep failed: an ok passage's samples kept"
# weighed and not ok: a solver error, queue overload, inseparable (multiple
# with a weight; a tracker's multiple was never weighed)
weighed_notok="status IN ('error', 'overload') OR (status = 'multiple' AND gvw_kg IS NOT NULL)"
notok=$(q "SELECT count(*) FROM passages WHERE $weighed_notok")
q "SELECT count(*) FROM passages p WHERE ($weighed_notok)
   AND NOT EXISTS (SELECT 1 FROM passage_raw WHERE passage_id = p.id)" | grep -qx 0 ||
  fail "keep failed: a passage not ok without its samples"
kept_failed=$(q "SELECT count(*) FROM passage_raw")
rm -f "$dir/s.db" "$dir/s.db-wal" "$dir/s.db-shm"
sed -e "s/^      keep: all /      keep: none /" "$dir/amfid.yaml" > "$dir/none.yaml"
run_traffic "$dir/none.yaml"
[ "$(q "SELECT count(*) FROM raw_windows")" -eq 0 ] || fail "keep none: samples kept"
echo "daemon_raw: keep failed kept the $notok passages not ok ($kept_failed with their events' partners), keep none nothing"
