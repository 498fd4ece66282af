#!/usr/bin/env bash
# The main job, for now: install what is missing, build, and weigh the shipped
# baseline passage (18 t, 25 m/s, 1000 Hz accelerometer, 2 % noise) with
# amfi-solve, choosing λ by the L-curve. The monitoring daemon replaces this.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
mkdir -p "$top/build"
bash "$top/scripts/build.sh" "$top/build/release" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
bin="$top/build/release/tools"
case_csv="$top/examples/baseline-18t.csv.gz"
out="$top/build/main"
mkdir -p "$out"
echo "== amfi-solve on $case_csv (true GVW 18 002 kg: axles 10 398 + 7 604 kg)"
"$bin/amfi-solve" --accel "$case_csv" --speed 25 --axle-spacing 5 --entry-time 0.5 \
  --lambda auto --forces "$out/forces.csv" --lcurve "$out/lcurve.csv" | tee "$out/result.json"
echo "== axle forces every 0.1 s (t from entry, N):"
awk -F, 'NR == 1 { printf "%6s %7s %12s %12s\n", $1, $2, $3, $4 }
          NR > 1 && (NR - 2) % 500 == 0 { printf "%6.2f %7.2f %12.0f %12.0f\n", $1, $2, $3, $4 }' "$out/forces.csv"
echo "== written: $out/result.json, $out/forces.csv, $out/lcurve.csv"
