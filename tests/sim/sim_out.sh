#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_publisher's offline output: the files amfi-solve reads, meta.csv with
# the truth, the same seed giving the same numbers (tests/common/num_cmp.sh, 1e-9
# relative: floating point is not compared byte for byte), and the weights
# amfi-solve infers from them close to the truth on the ideal defaults.
# Usage: sim_out.sh SIM_PUBLISHER AMFI_SOLVE
set -u
sim=$1
solve=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
same() { sh "$(dirname "$0")/../common/num_cmp.sh" "$1" "$2" >/dev/null; }

"$sim" --out "$dir/a" --vehicles 4 --seed 5 || fail "sim_publisher exited $?"
"$sim" --out "$dir/b" --vehicles 4 --seed 5 || fail "second run exited $?"
"$sim" --out "$dir/c" --vehicles 4 --seed 6 || fail "third run exited $?"
for f in meta.csv v00001.csv v00004.csv; do
  same "$dir/a/$f" "$dir/b/$f" || fail "same seed, different $f"
done
same "$dir/a/v00001.csv" "$dir/c/v00001.csv" && fail "another seed gave the same v00001.csv"
head -1 "$dir/a/meta.csv" | grep -q '^name,speed_mps,speed_true_mps,axle_spacing_m,entry_time_s,gvw_kg,axle1_kg,axle2_kg,mean_force1_N,mean_force2_N,damage,noise' ||
  fail "meta.csv header: $(head -1 "$dir/a/meta.csv")"
[ "$(wc -l < "$dir/a/meta.csv")" -eq 5 ] || fail "meta.csv rows"
head -1 "$dir/a/v00001.csv" | grep -qx 't,accel' || fail "passage header"

# Weigh every passage with amfi-solve; ideal data: within 5 % of the truth.
tail -n +2 "$dir/a/meta.csv" | while IFS=, read -r name speed _ spacing entry gvw _; do
  out=$("$solve" --accel "$dir/a/$name.csv" --speed "$speed" --axle-spacing "$spacing" \
        --entry-time "$entry") || fail "amfi-solve on $name exited $?"
  inferred=$(printf '%s' "$out" | sed 's/.*"gvw_kg":\([-0-9.e+]*\).*/\1/')
  awk -v a="$inferred" -v b="$gvw" -v n="$name" 'BEGIN {
    e = (a - b) / b; printf "%s: true %.0f kg, inferred %.0f kg (%+.2f %%)\n", n, b, a, 100 * e;
    exit (e < -0.05 || e > 0.05) }' || fail "$name: GVW error over 5 %"
done || exit 1

# Configuration file: built-in default < its simulation: section < flag.
mkdir "$dir/cfg"
printf 'simulation: {vehicles: 2, seed: 5}\n' > "$dir/cfg/two.yaml"
"$sim" --config "$dir/cfg/two.yaml" --out "$dir/e" || fail "--config exited $?"
[ "$(wc -l < "$dir/e/meta.csv")" -eq 3 ] || fail "simulation.vehicles: 2 not applied"
same "$dir/a/v00001.csv" "$dir/e/v00001.csv" || fail "simulation.seed: 5 not applied"
"$sim" --config "$dir/cfg/two.yaml" --out "$dir/f" --vehicles 3 || fail "--vehicles over --config exited $?"
[ "$(wc -l < "$dir/f/meta.csv")" -eq 4 ] || fail "--vehicles 3 did not override simulation.vehicles"
same "$dir/a/v00001.csv" "$dir/f/v00001.csv" || fail "simulation.seed lost under --vehicles"
# A relative population is read from the file's folder, wherever we run.
printf 'timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m\n%s\n%s\n' \
  '5.856,1,21.82,8003,3820,4183,4.19' '16.827,1,25.52,10034,4828,5206,3.93' > "$dir/cfg/wim.csv"
printf 'simulation:\n  population: wim.csv\n  vehicles: 2\n' > "$dir/cfg/wim.yaml"
(cd / && "$sim" --config "$dir/cfg/wim.yaml" --out "$dir/g") || fail "relative population exited $?"
cut -d, -f3 "$dir/g/meta.csv" | tr '\n' ' ' | grep -q '^speed_true_mps 21.82 25.52 $' ||
  fail "relative population not read: $(cut -d, -f3 "$dir/g/meta.csv" | tr '\n' ' ')"
# The stream goes to the file's daemon.channels; lcm_url: none from the file
# publishes nothing, so the log alone receives it.
printf '%s\n' 'daemon: {channels: {accel: SITE_A, vehicle: SITE_V, truth: SITE_T}}' \
  'simulation: {vehicles: 1, stream: {lcm_url: none, speedup: max}}' > "$dir/cfg/ch.yaml"
"$sim" --config "$dir/cfg/ch.yaml" 2>/dev/null; [ $? -eq 2 ] || fail "lcm_url: none without a log not refused"
"$sim" --config "$dir/cfg/ch.yaml" --log "$dir/ch.log" 2>/dev/null || fail "--log over lcm_url: none exited $?"
for c in SITE_A SITE_V SITE_T; do grep -aq "$c" "$dir/ch.log" || fail "nothing on channel $c"; done
grep -aq AMFI_ "$dir/ch.log" && fail "published on a default channel"

# A site with three sensors: every sensor's column, named by its id, and
# their positions in meta.csv; amfi-solve weighs from all three (it refuses
# a file with fewer columns than the site has sensors).
printf '%s\n' 'bridge: {span_m: 20}' 'sensors:' '  - {id: 3, at_m: 5}' '  - {id: 7, at_m: 10}' \
  '  - {id: 12, at_m: 15}' > "$dir/cfg/three.yaml"
"$sim" --config "$dir/cfg/three.yaml" --out "$dir/h" --vehicles 2 --seed 5 || fail "three sensors: exited $?"
head -1 "$dir/h/v00001.csv" | grep -qx 't,accel_3,accel_7,accel_12' ||
  fail "three sensors: header $(head -1 "$dir/h/v00001.csv")"
awk -F, 'NR > 1 && NF != 4 { print "row " NR ": " NF " fields"; bad = 1 } END { exit bad }' "$dir/h/v00001.csv" ||
  fail "three sensors: a row without every sensor"
# the middle sensor's column is the one-sensor site's at 10 m (same seed, same vehicle)
awk -F, 'NR == FNR { if (FNR > 1) m[FNR] = $2; next }
  FNR > 1 { d = $3 - m[FNR]; if (d < 0) d = -d; s = $3 < 0 ? -$3 : $3; if (d > 1e-9 * s + 1e-12) bad = 1 }
  END { exit bad }' "$dir/a/v00001.csv" "$dir/h/v00001.csv" || fail "three sensors: accel_7 is not the 10 m sensor's record"
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next } { print $c["sensor_x_m"] }' "$dir/h/meta.csv" |
  grep -qx '5;10;15' || fail "three sensors: meta.csv sensor_x_m"
tail -n +2 "$dir/h/meta.csv" | while IFS=, read -r name speed _ spacing entry gvw _; do
  out=$("$solve" --config "$dir/cfg/three.yaml" --accel "$dir/h/$name.csv" --speed "$speed" \
        --axle-spacing "$spacing" --entry-time "$entry") || fail "amfi-solve, three sensors, $name: exit $?"
  inferred=$(printf '%s' "$out" | sed 's/.*"gvw_kg":\([-0-9.e+]*\).*/\1/')
  awk -v a="$inferred" -v b="$gvw" -v n="$name" 'BEGIN {
    e = (a - b) / b; printf "%s, three sensors: true %.0f kg, inferred %.0f kg (%+.2f %%)\n", n, b, a, 100 * e;
    exit (e < -0.05 || e > 0.05) }' || fail "$name, three sensors: GVW error over 5 %"
done || exit 1

# Bad command lines are refused with one line and status 2.
"$sim" --lcm-url none --vehicles 3 2>/dev/null; [ $? -eq 2 ] || fail "streaming to nothing not refused"
"$sim" --out "$dir/d" --damage 2 2>/dev/null; [ $? -eq 2 ] || fail "damage 2 not refused"
"$sim" --out "$dir/d" --profile Z 2>/dev/null; [ $? -eq 2 ] || fail "profile Z not refused"
"$sim" --out "$dir/d" --population /nonexistent.csv 2>/dev/null; [ $? -eq 1 ] || fail "missing population not refused"
echo "sim_publisher output: ok"
