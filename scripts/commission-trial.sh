#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# commission-trial.sh: one simulated commissioning, end to end
# (docs/results/commissioning.md):
#   1. sim_publisher --as-built CASE --calibration-runs: the calibration runs
#      of the two default trucks on the as-built bridge;
#   2. amfi-commission --config DESIGN on those runs: SITE.yaml;
#   3. sim_publisher --as-built CASE --out: traffic on the same as-built bridge
#      (the shipped two-axle population, class A, no noise unless SIM_ARGS);
#   4. amfi-solve --config SITE.yaml on every vehicle with the detector's
#      values (meta.csv), against its true static GVW;
#   5. amfi-accuracy (RR2, environment I) on the gross weights.
# Prints one line: key=value pairs (f1, stiffness, GVW errors, class, time).
#
# usage: commission-trial.sh BIN_DIR DESIGN.yaml CASE.yaml OUT_DIR
#          [RUNS_PER_TRUCK (10)] [VEHICLES (200)] [POPULATION.csv]
# environment: COMMISSION_ARGS (extra amfi-commission options; the paper's
#                Table 5 detector, SIM_ARGS="--noise 0.03 --speed-error
#                0,0.03": "--speed-sd 0.03 --hold clock"),
#              SIM_ARGS (extra sim_publisher options for both simulations),
#              CAL_ARGS (extra sim_publisher options for the calibration runs
#                        only, after SIM_ARGS),
#              SOLVE_ARGS (extra amfi-solve options, e.g. --estimate-speed),
#              SEED (seed of the road and the traffic, 11),
#              CAL_SEED (the calibration runs' seed, SEED: the same road)
set -u
bin=$1 design=$2 case=$3 out=$4
rpt=${5:-10} nveh=${6:-200}
here=$(cd "$(dirname "$0")" && pwd)
pop=${7:-$here/../sim_publisher/data/population.csv}
seed=${SEED:-11}
sim=$bin/sim_publisher/sim_publisher
com=$bin/tools/ops/amfi-commission
solve=$bin/tools/ops/amfi-solve
acc=$bin/tools/ops/amfi-accuracy
die() { echo "commission-trial: $*" >&2; exit 1; }

rm -rf "$out" && mkdir -p "$out" || die "cannot create $out"
# The calibration trucks cross the same road as the traffic (the seed draws
# the road profile, one carpet per seed): a site has one road. On another
# seed's road the trucks were weighed against another road's bias: the
# design bridge weighed with its exact model gives the seed-11 traffic a
# mean +0.70 %, the same traffic's mean axle force over the span being
# +0.78 % above the static loads, and that mean force ranges -1.3 .. +1.3 %
# over seeds 1-14 (docs/results/commissioning.md, "The positive mean").
# CAL_SEED: another road for the calibration (the former trials: the
# configuration's seed, 1).
# shellcheck disable=SC2086
"$sim" --config "$design" --as-built "$case" --calibration-runs "$out/cal" \
  --runs-per-truck "$rpt" --seed "${CAL_SEED:-$seed}" ${SIM_ARGS:-} ${CAL_ARGS:-} 2>"$out/sim-cal.err" || die "sim_publisher --calibration-runs: $(cat "$out/sim-cal.err")"
t0=$(date +%s.%N)
# shellcheck disable=SC2086
"$com" --config "$design" --runs "$out/cal/RUNS.csv" --out "$out/site.yaml" \
  --report "$out/report" ${COMMISSION_ARGS:-} >"$out/commission.json" 2>"$out/commission.err" ||
  die "amfi-commission exited $?: $(cat "$out/commission.err")"
t1=$(date +%s.%N)
# shellcheck disable=SC2086
"$sim" --config "$design" --as-built "$case" --out "$out/traffic" --vehicles "$nveh" \
  --population "$pop" --seed "$seed" ${SIM_ARGS:-} 2>"$out/sim-traffic.err" ||
  die "sim_publisher --out: $(cat "$out/sim-traffic.err")"

# every vehicle weighed with the commissioned site file
echo "criterion,measured_kg,reference_kg" > "$out/gross.csv"
# the detector's spacings: axle_spacing_m carries its errors; the list of
# every spacing (axle_spacings_m) is the truth, so a multi-axle vehicle's
# list is scaled by the detector's first spacing over the true one
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  { n = split($c["axle_spacings_m"], s, ";")
    k = ("axle_spacing_true_m" in c) ? $c["axle_spacing_m"] / $c["axle_spacing_true_m"] : 1
    sp = ""
    for (i = 1; i <= n; i++) sp = sp (i > 1 ? "," : "") (n == 1 ? $c["axle_spacing_m"] : s[i] * k)
    print $c["name"], $c["entry_time_s"], $c["speed_mps"], sp, $c["gvw_kg"] }' \
  "$out/traffic/meta.csv" > "$out/vehicles.txt" || die "meta.csv"
while read -r name entry speed sp gvw; do
  # one vehicle: --vehicle, or (SOLVE_ARGS: --estimate-speed does not take
  # --vehicle) the same passage given by --entry-time, --speed, --axle-spacing
  if [ -z "${SOLVE_ARGS:-}" ]; then set -- --vehicle "$entry:$speed:$sp"
  else set -- --entry-time "$entry" --speed "$speed" --axle-spacing "$sp"; fi
  # shellcheck disable=SC2086
  r=$("$solve" --config "$out/site.yaml" --accel "$out/traffic/$name.csv" \
        "$@" ${SOLVE_ARGS:-} 2>>"$out/solve.err") || die "amfi-solve $name: $(tail -1 "$out/solve.err")"
  got=$(printf '%s' "$r" | sed 's/.*"gvw_kg":\([-0-9.e+]*\).*/\1/')
  echo "gross,$got,$gvw"
done < "$out/vehicles.txt" >> "$out/gross.csv"
"$acc" --input "$out/gross.csv" --condition RR2 --environment I > "$out/accuracy.json" ||
  die "amfi-accuracy exited $?"
cls=$(sed -n 's/.*"criterion":"gross".*"class":"\([^"]*\)".*/\1/p' "$out/accuracy.json")

# the commissioned model against the as-built one (f1 and E·I from the
# site files through amfi-commission's JSON; the truth from the case file
# is the caller's to compare)
j=$(cat "$out/commission.json")
# the first occurrence of a key (the top level's: --segments adds each
# segment's stiffness_scale after it)
num() { printf '%s' "$j" | grep -o "\"$1\":[-0-9.e+]*" | head -n 1 | cut -d: -f2; }
# --segments (COMMISSION_ARGS): each segment's E·I scale and its relative
# uncertainty, front to back ("stiffness" is then the reference segment's)
segs=$(printf '%s' "$j" | grep -o '"to_m":[-0-9.e+]*,"stiffness_scale":[-0-9.e+]*,"sd_rel":[-0-9.e+]*' |
  awk -F'[:,]' '{ printf "%s%.4f+-%.2f%%", (NR > 1 ? "/" : ""), $4, 100 * $6 }')
awk -F, -v f1="$(num f1_commissioned_hz)" -v fm="$(num f1_measured_hz)" \
    -v st="$(num stiffness_scale)" -v ms="$(num mass_scale)" -v ka="$(num bearing_kL_EI)" \
    -v so="$(num sensor_offset_m)" -v ck="$(num clock_offset_s)" -v ss="$(num speed_scale)" \
    -v cls="$cls" -v secs="$(echo "$t1 - $t0" | bc)" -v segs="$segs" '
  NR > 1 { e = 100 * ($2 - $3) / $3; n++; s += e; a += (e < 0 ? -e : e)
           if (n == 1 || (e < 0 ? -e : e) > (w < 0 ? -w : w)) w = e }
  END { printf "f1_meas=%.4f f1_model=%.4f stiffness=%.4f mass=%.4f kappa=%.3f sensor=%+.3f " \
               "clock=%+.5f speed=%.4f vehicles=%d gvw_mean=%+.2f gvw_mean_abs=%.2f " \
               "gvw_worst=%+.2f class=%s commission_s=%.0f%s\n",
               fm, f1, st, ms, ka, so, ck, ss, n, s / n, a / n, w, cls, secs,
               (segs == "" ? "" : " segments=" segs) }' "$out/gross.csv"
