#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-solve --from-store DB --passage ID on a store amfid wrote from a
# recorded bus (sim_publisher --log, replayed through file://: no network):
# the re-weigh is amfid's ("identical"); kept as float32 it is within 1e-6
# of amfid's and says why; another sensor position in the site file is
# named as the difference; and every way of having no samples
# is exit 1 with a message saying which: no such passage, not kept (keep
# none), a store older than version 11, a truncated blob and a damaged one
# (named by passage, never a crash); the command line's misuses are exit 2.
# Usage: solve_from_store.sh AMFI_SOLVE AMFID SIM_PUBLISHER CONFIG
set -u
solve=$1 amfid=$2 sim=$3 config=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# expect STATUS PATTERN ARGS...: amfi-solve exits STATUS with PATTERN on stderr
expect() {
  want=$1 pat=$2; shift 2
  "$solve" "$@" > "$dir/out" 2> "$dir/err"; got=$?
  [ "$got" -eq "$want" ] || fail "amfi-solve $*: exit $got, expected $want: $(cat "$dir/err")"
  grep -q -- "$pat" "$dir/err" || fail "amfi-solve $*: '$(cat "$dir/err")' lacks '$pat'"
  echo "ok: exit $got: $(cat "$dir/err")"
}

# a recorded bus of 4 vehicles, unsigned (a lab bus: daemon.bus.auth off)
sed -e "s/^    auth: required /    auth: off /" "$config" > "$dir/site.yaml"
grep -q "^    auth: off " "$dir/site.yaml" || fail "the test's daemon.bus.auth did not apply"
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/bus.log" --vehicles 4 --headway 3 --speedup max --seed 5 \
  2> "$dir/sim.log" || { cat "$dir/sim.log"; fail "sim_publisher"; }
"$amfid" --config "$dir/site.yaml" --db "$dir/s.db" --lcm-url "file://$dir/bus.log?speed=0" \
  2> "$dir/amfid.log" || { tail "$dir/amfid.log"; fail "amfid on the recorded bus"; }
n=$(sqlite3 "$dir/s.db" "SELECT count(*) FROM passage_raw")
[ "$n" -eq 4 ] || fail "$n passages with raw samples, 4 expected"

# the re-weigh: amfid's weight, bit for bit with the same site file
"$solve" --config "$dir/site.yaml" --from-store "$dir/s.db" --passage 2 > "$dir/ok.json" ||
  fail "re-weigh of passage 2"
grep -q '"explained":"identical' "$dir/ok.json" || fail "not identical: $(cat "$dir/ok.json")"
grep -q '"from_store":{"db":"[^"]*","passage_id":2,"window_id":2,"vehicle":0' "$dir/ok.json" ||
  fail "from_store: $(cat "$dir/ok.json")"
# a sensor moved in the site file: the difference says so
sed -e "s/^  - {id: 0, at_m: 10, weight: 1}/  - {id: 0, at_m: 9.5, weight: 1}/" "$dir/site.yaml" \
  > "$dir/moved.yaml"
grep -q "at_m: 9.5" "$dir/moved.yaml" || fail "the test's sensor position did not apply"
"$solve" --config "$dir/moved.yaml" --from-store "$dir/s.db" --passage 2 > "$dir/moved.json" ||
  fail "re-weigh with the sensor moved"
grep -q '"explained":"the site file puts sensor 0 at 9.5 m, amfid had it at 10 m"' "$dir/moved.json" ||
  fail "moved: $(sed 's/.*"difference"//' "$dir/moved.json")"

# kept as float32: the re-weigh differs from amfid's by the rounding alone,
# and says so
sed -e "s/^      precision: float64 /      precision: float32 /" "$dir/site.yaml" > "$dir/f32.yaml"
grep -q "^      precision: float32 " "$dir/f32.yaml" || fail "the test's precision did not apply"
"$amfid" --config "$dir/f32.yaml" --db "$dir/f32.db" --lcm-url "file://$dir/bus.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid precision float32"
[ "$(sqlite3 "$dir/f32.db" "SELECT sum(bytes) FROM raw_windows")" -lt \
  "$(sqlite3 "$dir/s.db" "SELECT sum(bytes) / 2 + 2000 FROM raw_windows")" ] ||
  fail "float32 does not take about half the bytes"
: > "$dir/f32-stored.txt"; : > "$dir/f32-reweighed.txt"
for id in 1 2 3 4; do
  "$solve" --config "$dir/f32.yaml" --from-store "$dir/f32.db" --passage $id > "$dir/f32.json" ||
    fail "re-weigh of float32 passage $id"
  grep -q '"precision":"float32"' "$dir/f32.json" || fail "precision: $(cat "$dir/f32.json")"
  grep -q '"explained":"identical\|"explained":"the samples were kept rounded to float32' \
    "$dir/f32.json" || fail "float32: $(sed 's/.*"difference"//' "$dir/f32.json")"
  sed 's/.*"passage_gvw_kg":\([^,}]*\).*/\1/' "$dir/f32.json" >> "$dir/f32-reweighed.txt"
  sqlite3 "$dir/f32.db" "SELECT gvw_kg FROM passages WHERE id = $id" >> "$dir/f32-stored.txt"
done
sh "$(dirname "$0")/../common/num_cmp.sh" -r 1e-6 "$dir/f32-stored.txt" "$dir/f32-reweighed.txt" ||
  fail "float32 re-weigh further than 1e-6 from amfid's"
paste "$dir/f32-stored.txt" "$dir/f32-reweighed.txt"

# the command line
expect 2 "needs --from-store" --passage 2
expect 2 "needs --passage" --from-store "$dir/s.db"
expect 2 "not a passage id" --from-store "$dir/s.db" --passage 0
expect 2 "not with --accel" --from-store "$dir/s.db" --passage 2 --accel x.csv
# no samples, each reason named
expect 1 "there is no passage 99" --config "$dir/site.yaml" --from-store "$dir/s.db" --passage 99
expect 1 "cannot open the store" --from-store "$dir/none.db" --passage 1
sed -e "s/^      keep: all /      keep: none /" "$dir/site.yaml" > "$dir/none.yaml"
"$amfid" --config "$dir/none.yaml" --db "$dir/none.db" --lcm-url "file://$dir/bus.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid keep none"
expect 1 "passage 1 (vehicle 1, status ok) has no raw samples: not kept" \
  --config "$dir/site.yaml" --from-store "$dir/none.db" --passage 1
cp "$dir/s.db" "$dir/v10.db"
sqlite3 "$dir/v10.db" "DROP TABLE passage_raw; DROP TABLE raw_windows;
  DELETE FROM schema_migrations WHERE version = 11; PRAGMA user_version = 10" ||
  fail "the version-10 copy"
expect 1 "passage 1 has no raw samples: the store is at version 10" \
  --config "$dir/site.yaml" --from-store "$dir/v10.db" --passage 1
# damaged blobs: named by passage, exit 1 (no crash, no half window)
sqlite3 "$dir/s.db" "UPDATE raw_windows SET samples = substr(samples, 1, bytes - 20),
  bytes = bytes - 20 WHERE id = 3;
  UPDATE raw_windows SET samples = CAST(substr(samples, 1, 100) || x'deadbeef' ||
  substr(samples, 105) AS BLOB) WHERE id = 4" || fail "damaging the blobs"
expect 1 "passage 3: raw window 3: raw samples: the blob of [0-9]* bytes does not decode" \
  --config "$dir/site.yaml" --from-store "$dir/s.db" --passage 3
expect 1 "passage 4: raw window 4: raw samples: .* does not decode" \
  --config "$dir/site.yaml" --from-store "$dir/s.db" --passage 4
echo "solve_from_store: re-weighed identically; every missing or damaged window named"
