#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# flow-calc-rate.sh BUILD_DIR OUT [VEHICLES [RATES]]: what amfid's
# calculation rate (solver.calc_rate_hz) costs and gives on the heaviest
# stream of issue 26, the EU truck mix on one lane at 1800 vehicles an hour
# (sim_publisher with the shipped site and population, seed 3; 300 vehicles
# are 673 s of data). The log is simulated once; then, for each rate (default
# 5000, the shipped one, 2500, 2000 and 1000 Hz; the model fit's rate is at
# most the solver's), amfid replays it as fast as it can (file://, one BLAS
# thread, simulation: true so that the truth is stored). Printed, a row per
# rate: user CPU, the speed-up over real time per core (data s / CPU s) and
# on the wall clock (amfid's two solver threads), peak RSS, passages ok, and
# the GVW error of the ok ones against the simulation's truth (mean abs,
# worst, count over 5 %) and its COST 323 class (amfi-accuracy, gross
# weight, RR2, environment I); then by vehicles weighed together, and the
# gross-weight class per vehicle class. A finished rate's store is kept:
# delete OUT/rRATE.db to run it again.
# Needs BUILD_DIR a release tree (cmake -DCMAKE_BUILD_TYPE=Release).
set -eu
build=$1 out=$2 n=${3:-300} rates=${4:-"5000 2500 2000 1000"}
src=$(cd "$(dirname "$0")/../.." && pwd)
export AMFI_DATA_DIR="$src/config:$src/sim_publisher/data" OPENBLAS_NUM_THREADS=1
mkdir -p "$out"
amfid=$build/daemon/amfid sim=$build/sim_publisher/sim_publisher acc=$build/tools/ops/amfi-accuracy
[ -x "$amfid" ] && [ -x "$sim" ] || { echo "flow-calc-rate.sh: no amfid or sim_publisher in $build" >&2; exit 2; }
[ -s "$out/bus.key" ] || "$amfid" --make-bus-key "$out/bus.key" > /dev/null
if [ ! -s "$out/f1800.lcmlog" ]; then
  "$sim" --lcm-url none --bus-key "$out/bus.key" --log "$out/f1800.lcmlog" --vehicles "$n" \
    --flow 1800 --lanes 1 --speedup max --seed 3 \
    --population "$src/sim_publisher/data/population-eu.csv" 2> "$out/sim.log"
fi
data_s=$(sed -n 's/.* over \([0-9.]*\) s of data.*/\1/p' "$out/sim.log")
[ -n "$data_s" ] || { echo "flow-calc-rate.sh: no data duration in $out/sim.log" >&2; exit 1; }
echo "# one lane, 1800 vehicles an hour, EU mix: $n vehicles, $data_s s of data"
echo
# cost323 RATE [CLASS]: the COST 323 class of the ok passages' gross weights
cost323() {
  { echo criterion,measured_kg,reference_kg
    sqlite3 -csv "$out/r$1.db" "SELECT 'gross', e.gvw_kg, e.true_gvw_kg FROM passage_errors e
      JOIN passages p ON p.id = e.passage_id WHERE e.status = 'ok' AND ('$2' = '' OR p.class = '$2')"
  } > "$out/acc.csv"
  "$acc" --input "$out/acc.csv" | sed -n 's/.*"criterion":"gross","n":\([0-9]*\).*"class":"\([^"]*\)".*/\2 (n \1)/p'
}
echo "| calc_rate_hz | user CPU s | x real time per core | x real time, wall | peak RSS MB | ok | mean abs % | worst % | > 5 % | COST 323 gross |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for r in $rates; do
  fit=$r; [ "$r" -gt 2000 ] && fit=2000
  sed -e "s/^  calc_rate_hz: 5000 /  calc_rate_hz: $r /" \
      -e "s/^    calc_rate_hz: 2000 /    calc_rate_hz: $fit /" \
      -e "s/^  simulation: false /  simulation: true  /" "$src/config/amfid.yaml" > "$out/r$r.yaml"
  grep -q "^  calc_rate_hz: $r " "$out/r$r.yaml" || { echo "flow-calc-rate.sh: the rate did not apply" >&2; exit 1; }
  if [ ! -s "$out/r$r.time" ] || [ ! -s "$out/r$r.db" ]; then
    rm -f "$out/r$r.db"
    /usr/bin/time -o "$out/r$r.time" -f "%e %U %M" "$amfid" --config "$out/r$r.yaml" --bus-key "$out/bus.key" \
      --db "$out/r$r.db" --lcm-url "file://$out/f1800.lcmlog?speed=0" 2> "$out/r$r.log"
  fi
  set -- $(cat "$out/r$r.time")
  wall=$1 user=$2 rss=$3
  row=$(sqlite3 -separator ' ' "$out/r$r.db" "
    SELECT (SELECT count(*) FROM passages WHERE status = 'ok') || '/' || (SELECT count(*) FROM passages),
           printf('%.2f', avg(abs(gvw_error_pct))), printf('%+.2f', (SELECT gvw_error_pct FROM passage_errors
             WHERE status = 'ok' ORDER BY abs(gvw_error_pct) DESC LIMIT 1)),
           sum(abs(gvw_error_pct) > 5)
    FROM passage_errors WHERE status = 'ok'")
  set -- $row
  cls=$(cost323 "$r" "")
  awk -v r="$r" -v u="$user" -v w="$wall" -v m="$rss" -v d="$data_s" -v ok="$1" -v ma="$2" -v wo="$3" -v o5="$4" \
    -v c="$cls" 'BEGIN { printf "| %s | %.1f | %.1f | %.1f | %.1f | %s | %s | %s | %s | %s |\n", r, u, d / u, d / w, m / 1024, ok, ma, wo, o5, c }'
done
echo
echo "By vehicles weighed together (ok: n, mean abs %, worst abs %):"
for r in $rates; do
  printf '%s Hz:' "$r"
  sqlite3 -separator ' ' "$out/r$r.db" "
    SELECT p.n_vehicles, count(*), printf('%.2f', avg(abs(e.gvw_error_pct))), printf('%.2f', max(abs(e.gvw_error_pct)))
    FROM passage_errors e JOIN passages p ON p.id = e.passage_id WHERE e.status = 'ok'
    GROUP BY p.n_vehicles ORDER BY 1" | awk '{ printf " %s: %s, %s / %s;", $1, $2, $3, $4 } END { print "" }'
done
echo
echo "COST 323 gross weight per vehicle class (ok passages):"
classes=$(sqlite3 "$out/r$(echo $rates | cut -d' ' -f1).db" "SELECT DISTINCT class FROM passages WHERE class IS NOT NULL ORDER BY 1")
for r in $rates; do
  printf '%s Hz:' "$r"
  for c in $classes; do printf ' %s %s;' "$c" "$(cost323 "$r" "$c")"; done
  echo
done
