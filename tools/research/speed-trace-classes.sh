#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# speed-trace-classes.sh BUILD_DIR OUT [PER_CLASS [CLASSES]]: why the speed
# search (docs/solver.md, "Speed estimation") finds a two-axle vehicle's
# speed and hardly a multi-axle one's (docs/results/class-accuracy.md).
# The first PER_CLASS (4) vehicles of each of CLASSES ("R2 R3 A23 A33") in
# the EU population cross the paper's bridge alone (sim_publisher --out,
# CONFIG config/paper-20m.yaml, class A road, no noise unless SIM_ARGS), the
# detector's speed off by N(0, 3 %) (--speed-error 0,0.03, seed 1), its
# spacings exact; amfi-solve --estimate-speed weighs each and writes the
# search's coarse grid (--speed-trace: speed, J, dip). Printed, per vehicle:
# class, axles, the true, detector's and estimated speed (relative error,
# %), the grid point nearest the truth: its J above the grid's smallest J
# and its dip measure (negative: below the local trend) against the
# deepest dip on the grid and where that is (% from the truth), and the
# smallest J's place; then per class the RMS of the detector's and the
# estimate's errors.
set -eu
bin=$1 out=$2 per=${3:-4} classes=${4:-"R2 R3 A23 A33"}
src=$(cd "$(dirname "$0")/../.." && pwd)
cfg=${CONFIG:-$src/config/paper-20m.yaml}
pop=$src/sim_publisher/data/population-eu.csv
export AMFI_DATA_DIR="$src/config:$src/sim_publisher/data" OPENBLAS_NUM_THREADS=1
rm -rf "$out" && mkdir -p "$out"
awk -F, -v per="$per" -v cls=" $classes " 'NR == 1 { print; next }
  index(cls, " " $4 " ") && ++k[$4] <= per { print }' "$pop" > "$out/sample.csv"
n=$(($(wc -l < "$out/sample.csv") - 1))
# shellcheck disable=SC2086
"$bin/sim_publisher/sim_publisher" --config "$cfg" --population "$out/sample.csv" --out "$out/sim" \
  --vehicles "$n" --seed 1 --speed-error 0,0.03 ${SIM_ARGS:-} 2> "$out/sim.err"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  { s = $c["axle_spacings_m"]; gsub(";", ",", s)
    print $c["name"], $c["speed_mps"], $c["speed_true_mps"], $c["entry_time_s"], s }' \
  "$out/sim/meta.csv" > "$out/passages.txt"
awk -F, 'NR > 1 { print $4, $6 }' "$out/sample.csv" > "$out/classes.txt"
echo "| vehicle | class | axles | true m/s | detector % | estimate % | J at truth above min | dip at truth | deepest dip (at %) | min J at % |"
echo "|---|---|---|---|---|---|---|---|---|---|"
paste -d' ' "$out/passages.txt" "$out/classes.txt" | while read -r name v vt entry sp cls na; do
  r=$("$bin/tools/ops/amfi-solve" --config "$cfg" --accel "$out/sim/$name.csv" --speed "$v" \
        --axle-spacing "$sp" --entry-time "$entry" --estimate-speed --speed-trace "$out/$name.trace" \
        2> "$out/$name.err") || { echo "| $name | $cls | $na | refused: $(tail -1 "$out/$name.err") |"; continue; }
  ve=$(echo "$r" | sed -n 's/.*"speed_mps":\([-0-9.e+]*\).*/\1/p')
  echo "$cls $vt $v $ve" >> "$out/errors.txt"
  awk -F, -v vt="$vt" -v v="$v" -v ve="$ve" -v nm="$name" -v cls="$cls" -v na="$na" '
    NR == 1 { next }
    { s[NR] = $1; j[NR] = $2; d[NR] = $3; n = NR
      if (jmin == "" || $2 < jmin) { jmin = $2; vmin = $1 }
      if ($3 != "" && $3 != "nan" && (dmin == "" || $3 < dmin)) { dmin = $3; vd = $1 }
      e = $1 - vt; if (e < 0) e = -e
      if (best == "" || e < best) { best = e; k = NR } }
    END { printf "| %s | %s | %s | %.2f | %+.2f | %+.2f | %.1f | %s | %s (%+.2f) | %+.2f |\n", nm, cls, na, vt,
            100 * (v / vt - 1), 100 * (ve / vt - 1), j[k] - jmin, d[k], dmin, 100 * (vd / vt - 1), 100 * (vmin / vt - 1) }' \
    "$out/$name.trace"
done
echo
echo "RMS speed error by class, detector / estimate (%):"
awk '{ d = 100 * ($3 / $2 - 1); e = 100 * ($4 / $2 - 1); n[$1]++; sd[$1] += d * d; se[$1] += e * e }
  END { for (c in n) printf "  %s (%d): %.2f / %.2f\n", c, n[c], sqrt(sd[c] / n[c]), sqrt(se[c] / n[c]) }' \
  "$out/errors.txt" | sort
