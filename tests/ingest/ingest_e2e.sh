#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-ingest end to end: sim_publisher's traffic (8 vehicles, two
# sensors) written as a data logger and a detector would give it
# (ingest_tool from-log: one MiniSEED file per channel, Steim-2 counts of
# 1e-6 m/s², and the detector's V lines), published by amfi-ingest on the
# bus of the test's own network namespace (common/bus_prologue.sh) to a
# running amfid. The passages must be those amfid stores from sim_publisher's
# own log (the LCM path): every vehicle a row, every row ok, the GVW the
# same within 0.1 % and within 8 % of the truth. Then the same with one
# MiniSEED record of sensor 0 removed where vehicle 4 enters: that passage
# is stored as gap (no sample invented), the others as before.
# Usage: ingest_e2e.sh AMFID SIM_PUBLISHER AMFI_INGEST INGEST_TOOL CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 ingest=$3 tool=$4 config=$5
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=8

# two sensors; the truth channel subscribed for the LCM path's comparison
sed -e 's/^  - {id: 0, at_m: 10, weight: 1}$/  - {id: 0, at_m: 7}\n  - {id: 1, at_m: 13}/' \
    -e "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/amfid.yaml"
grep -q "at_m: 13" "$dir/amfid.yaml" || fail "the test's sensors did not apply"
cat >> "$dir/amfid.yaml" <<YAML
ingest:
  channels:
    - {seed: XX.BRG.00.HN0, sensor: 0, gain: 1.0e-6}
    - {seed: XX.BRG.00.HN1, sensor: 1, gain: 1.0e-6}
  line:
    listen: ""
YAML
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "amfid --check-config"
"$ingest" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "amfi-ingest --check-config"

# The simulation, and amfid on its log: the LCM path.
"$sim" --dt 2.5e-4 --config "$dir/amfid.yaml" --lcm-url none --log "$dir/sim.lcmlog" --vehicles $N \
  --headway 3 --speedup max --seed 4 2> "$dir/sim.log" || fail "sim_publisher"
"$amfid" --config "$dir/amfid.yaml" --db "$dir/lcm.db" \
  --lcm-url "file://$dir/sim.lcmlog?speed=0" 2> "$dir/lcm.log" || fail "amfid on the log"
# The logger's files and the detector's lines.
"$tool" from-log "$dir/sim.lcmlog" "$dir" 2> "$dir/fromlog.log" || fail "ingest_tool from-log"
[ "$(grep -c '^V ' "$dir/vehicles.txt")" -eq $N ] || fail "expected $N vehicle lines"

run() { # NAME S0-FILE: amfid live, amfi-ingest publishing; the store as $dir/NAME.db
  amfid_start "$amfid" "$dir/amfid.yaml"
  "$ingest" --config "$dir/amfid.yaml" --speedup 20 "$2" "$dir/s1.mseed" \
    --lines "$dir/vehicles.txt" 2> "$dir/ingest-$1.log" || fail "amfi-ingest exit status $?"
  # amfid has every vehicle (its status line counts them), then drains
  i=0; until [ "$(sqlite3 "$dir/s.db" "SELECT count(*) FROM passages" 2>/dev/null)" = $N ]; do
    i=$((i + 1)); [ $i -lt 600 ] || fail "$1: amfid stored $(sqlite3 "$dir/s.db" \
      "SELECT count(*) FROM passages") of $N passages"; sleep 0.1; done
  amfid_stop
  mv "$dir/s.db" "$dir/$1.db"
  cp "$dir/amfid.log" "$dir/amfid-$1.log"
}
run ingest "$dir/s0.mseed"
grep -q "amfi-ingest: [0-9]* records, $N lines; published [0-9]* accel blocks .* and $N vehicles, signed" \
  "$dir/ingest-ingest.log" || fail "amfi-ingest's summary"
grep -q "bad record 0, bad line 0, unmapped channel 0, gap 0 .*, overlap 0 .*, publish failed 0" \
  "$dir/ingest-ingest.log" || fail "amfi-ingest counted problems in clean data"

rows=$(sqlite3 "$dir/ingest.db" "SELECT count(*) FROM passages")
ok=$(sqlite3 "$dir/ingest.db" "SELECT count(*) FROM passages WHERE status = 'ok'")
lok=$(sqlite3 "$dir/lcm.db" "SELECT count(*) FROM passages WHERE status = 'ok'")
echo "through amfi-ingest: $rows rows, $ok ok; the LCM path: $lok ok"
[ "$rows" -eq $N ] && [ "$ok" -eq $N ] && [ "$lok" -eq $N ] || fail "not every passage ok"
sqlite3 "$dir/ingest.db" "ATTACH '$dir/lcm.db' AS l;
  SELECT p.vehicle_id, p.utime - q.utime, printf('%.1f', p.gvw_kg), printf('%.1f', q.gvw_kg),
         printf('%.4f', abs(p.gvw_kg - q.gvw_kg) / q.gvw_kg)
  FROM passages p JOIN l.passages q USING (vehicle_id) ORDER BY 1" > "$dir/cmp.txt"
cat "$dir/cmp.txt"
[ "$(wc -l < "$dir/cmp.txt")" -eq $N ] || fail "the vehicle ids differ between the paths"
awk -F'|' '$2 != 0 || $5 > 0.001 { bad = 1 } END { exit bad }' "$dir/cmp.txt" ||
  fail "a passage differs from the LCM path's (time or GVW by more than 0.1 %)"
# against the truth (truth.csv from the simulation)
err=$(sqlite3 "$dir/ingest.db" <<SQL
CREATE TEMP TABLE t (vehicle_id INTEGER, gvw_kg REAL);
.mode csv
.import --skip 1 $dir/truth.csv t
.mode list
SELECT max(abs(p.gvw_kg - t.gvw_kg) / t.gvw_kg) FROM passages p JOIN t USING (vehicle_id)
  HAVING count(*) = $N;
SQL
)
echo "largest GVW error against the truth: $err"
awk -v e="$err" 'BEGIN { exit !(e ~ /^[0-9.e-]+$/ && e + 0 < 0.08) }' ||
  fail "GVW error '$err' over 8 % (or not every vehicle's truth)"

# One record of sensor 0 lost where vehicle 4 enters: a gap, not invented samples.
u4=$(awk '/^V / && / id=4$/ { print $2 }' "$dir/vehicles.txt")
"$tool" cut "$dir/s0.mseed" "$dir/s0-cut.mseed" "$u4" > "$dir/cut.txt" || fail "ingest_tool cut"
run gap "$dir/s0-cut.mseed"
grep -q "sensor 0: gap of" "$dir/ingest-gap.log" || fail "amfi-ingest did not report the gap"
st=$(sqlite3 "$dir/gap.db" "SELECT group_concat(vehicle_id || ':' || status, ' ') FROM passages ORDER BY vehicle_id")
echo "with a record lost: $st"
[ "$(sqlite3 "$dir/gap.db" "SELECT status FROM passages WHERE vehicle_id = 4")" = gap ] ||
  fail "vehicle 4's passage is not a gap"
[ "$(sqlite3 "$dir/gap.db" "SELECT count(*) FROM passages WHERE status = 'ok'")" -eq $((N - 1)) ] ||
  fail "the other passages are not all ok"
echo "ingest end to end: ok"
