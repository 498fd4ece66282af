#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_trucks.sh: the heavy traffic by class end to end: amfi-population
# --traffic eu (the shipped population-eu.csv is its seed-1 output; class
# shares), sim_publisher --out with multi-axle vehicles weighed by
# amfi-solve given every spacing, the stream's vehicle_t (every spacing)
# and truth_t (every axle), and impossible vehicles in a population refused
# with FILE:LINE, never a crash.
#   sim_trucks.sh SIM_PUBLISHER AMFI_POPULATION AMFI_SOLVE LCM_TRUCKS DATA_DIR
set -eu
sim=$1
pop=$2
solve=$3
trucks=$4
data=$5
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# The shipped population is amfi-population's seed 1, 5000 vehicles.
"$pop" --traffic eu --out "$work/eu.csv" --vehicles 5000 --seed 1 >"$work/pop.json" ||
  fail "amfi-population --traffic eu exited $?"
cmp -s "$work/eu.csv" "$data/population-eu.csv" ||
  fail "population-eu.csv is not amfi-population --traffic eu --vehicles 5000 --seed 1"
head -1 "$work/eu.csv" | grep -qx 'timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,spacings_m' ||
  fail "class-format header: $(head -1 "$work/eu.csv")"
# class shares within 2.5 points of the model's (binomial sd at 5000 < 0.7)
for c in R2:20.3 R3:8.0 R4:4.0 A22:12.2 A23:41.7 A32:7.8 A33:6.0; do
  name=${c%%:*} want=${c#*:}
  got=$(tr -d ' \n' <"$work/pop.json" | sed "s/.*\"$name\":{\"vehicles\":[0-9]*,\"share_pct\":\([0-9.]*\).*/\1/")
  awk -v g="$got" -v w="$want" -v n="$name" 'BEGIN { printf "%s: %.1f %% (model %.1f %%)\n", n, g, w;
    exit (g - w > 2.5 || w - g > 2.5) }' || fail "class $name share $got %"
done
# the old header is still read and still written by default
"$pop" --out "$work/two.csv" --vehicles 50 --seed 1 >/dev/null || fail "two-axle population"
head -1 "$work/two.csv" | grep -qx 'timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m' ||
  fail "two-axle header"

# Offline passages of multi-axle vehicles (class A road, no noise): every
# axle in meta.csv; amfi-solve given every spacing weighs them within 5 %.
"$sim" --population "$work/eu.csv" --out "$work/out" --vehicles 8 --first 0 --profile A \
  --dt 2.5e-4 2>"$work/out.err" || { cat "$work/out.err" >&2; fail "sim_publisher --out"; }
multi=0
tail -n +2 "$work/out/meta.csv" | while IFS=, read -r name speed _ _ entry gvw _ _ _ _ _ _ _ _ _ _ _ _ na sps kgs _; do
  sum=$(printf '%s' "$kgs" | tr ';' '\n' | awk '{ s += $1 } END { printf "%.3f", s }')
  awk -v a="$sum" -v b="$gvw" 'BEGIN { exit (a - b > 1e-3 || b - a > 1e-3) }' ||
    fail "$name: axle loads sum to $sum, gvw $gvw"
  n=$(printf '%s\n' "$sps" | awk -F';' '{ print NF }')
  [ "$n" -eq $((na - 1)) ] || fail "$name: $n spacings for $na axles"
  out=$("$solve" --accel "$work/out/$name.csv" --speed "$speed" \
        --axle-spacing "$(printf '%s' "$sps" | tr ';' ',')" --entry-time "$entry") ||
    fail "amfi-solve on $name exited $?"
  inferred=$(printf '%s' "$out" | sed 's/.*"gvw_kg":\([-0-9.e+]*\).*/\1/')
  awk -v a="$inferred" -v b="$gvw" -v n="$name" -v k="$na" 'BEGIN {
    e = (a - b) / b; printf "%s: %d axles, true %.0f kg, inferred %.0f kg (%+.2f %%)\n", n, k, b, a, 100 * e;
    exit (e < -0.05 || e > 0.05) }' || fail "$name: GVW error over 5 %"
done || exit 1
awk -F, 'NR > 1 && $19 > 2 { n++ } END { exit !(n >= 4) }' "$work/out/meta.csv" ||
  fail "fewer than 4 multi-axle vehicles among 8"

# The stream: vehicle_t with every spacing, truth_t with every axle.
"$sim" --population "$work/eu.csv" --lcm-url none --log "$work/s.log" --speedup max \
  --vehicles 10 --headway 2.5 --dt 2.5e-4 2>"$work/s.err" ||
  { cat "$work/s.err" >&2; fail "stream"; }
"$trucks" "$work/s.log" >"$work/s.txt" || { cat "$work/s.txt"; fail "lcm_trucks"; }
[ "$(grep -c '^V ' "$work/s.txt")" -eq 10 ] || fail "vehicle_t count"
[ "$(grep -c '^T ' "$work/s.txt")" -eq 10 ] || fail "truth_t count"
awk '$1 == "V" && $3 >= 5 { n++ } END { exit !(n >= 3) }' "$work/s.txt" ||
  { cat "$work/s.txt"; fail "fewer than 3 vehicles with 5 axles or more on the bus"; }
# each vehicle's truth has its vehicle_t's axle count
awk '$1 == "V" { v[$2] = $3 } $1 == "T" { if (v[$2] != $3) bad++ } END { exit bad > 0 }' \
  "$work/s.txt" || fail "truth_t and vehicle_t axle counts differ"

# The calibration truck (--calibration-every): the heaviest record by all
# its axles, announced with that GVW, which its truth_t confirms.
"$sim" --population "$work/eu.csv" --lcm-url none --log "$work/cal.log" --speedup max \
  --vehicles 4 --headway 3 --calibration-every 2 --dt 2.5e-4 2>"$work/cal.err" ||
  { cat "$work/cal.err" >&2; fail "stream with --calibration-every"; }
"$trucks" "$work/cal.log" >"$work/cal.txt" || fail "lcm_trucks (calibration)"
awk '$1 == "V" && $5 > 0 { ref[$2] = $5; n++ }
     $1 == "T" && ($2 in ref) { d = $4 - ref[$2]; if (d > 1 || d < -1) bad++; ok++ }
     END { exit !(n == 2 && ok == 2 && !bad) }' "$work/cal.txt" ||
  { cat "$work/cal.txt"; fail "calibration truck: reference GVW and truth differ"; }
awk '$1 == "V" && $5 > 0 { print "calibration truck: " $3 " axles, reference " $5 " kg" }' \
  "$work/cal.txt" | head -1

# The drifting mix (--environment site) draws from the classes too.
"$sim" --population "$work/eu.csv" --lcm-url none --log "$work/env.log" --speedup max \
  --vehicles 12 --headway 3 --environment site --time-compression 36500 --dt 2.5e-4 \
  2>"$work/env.err" || { cat "$work/env.err" >&2; fail "stream with --environment site"; }
"$trucks" "$work/env.log" >"$work/env.txt" || fail "lcm_trucks (environment)"
[ "$(grep -c '^T ' "$work/env.txt")" -eq 12 ] || fail "environment: truth_t count"
awk '$1 == "V" && $3 > 2 { n++ } END { exit !(n >= 4) }' "$work/env.txt" ||
  { cat "$work/env.txt"; fail "environment: fewer than 4 multi-axle vehicles of 12"; }

# Impossible vehicles: refused with FILE:LINE, exit 1, no crash.
hdr='timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,spacings_m'
good='1.0,1,25,A23,33000,5,7000;11000;5000;5000;5000,3.70;6.00;1.31;1.31'
bad_case() { # NAME LINE2 EXPECTED
  printf '%s\n%s\n%s\n' "$hdr" "$good" "$2" >"$work/$1.csv"
  rc=0
  "$sim" --population "$work/$1.csv" --out "$work/o-$1" --vehicles 2 2>"$work/$1.err" || rc=$?
  [ "$rc" = 1 ] || { cat "$work/$1.err" >&2; fail "$1: exit $rc, expected 1"; }
  grep -q "^$work/$1.csv:3: .*$3" "$work/$1.err" ||
    fail "$1: message '$(cat "$work/$1.err")' lacks FILE:3: ... $3"
  echo "$1: $(cat "$work/$1.err")"
}
bad_case unknown_class '2.0,1,25,A99,33000,5,7000;11000;5000;5000;5000,3.70;6.00;1.31;1.31' \
  "not a known class"
bad_case axle_count '2.0,1,25,A23,33000,4,7000;11000;5000;10000,3.70;6.00;1.31' \
  "class A23 has 5 axles"
bad_case spacings '2.0,1,25,A23,33000,5,7000;11000;5000;5000;5000,3.70;6.00;1.31' \
  "3 values for 5 axles"
bad_case loads '2.0,1,25,A23,33000,5,7000;11000;5000;10000,3.70;6.00;1.31;1.31' \
  "4 values for 5 axles"
bad_case negative '2.0,1,25,A23,33000,5,7000;11000;-5000;10000;10000,3.70;6.00;1.31;1.31' \
  "out of range"
bad_case absurd '2.0,1,25,A23,73000,5,7000;11000;5000;5000;45000,3.70;6.00;1.31;1.31' \
  "value 5, 45000, is out of range"
bad_case group '2.0,1,25,A23,33000,5,7000;11000;5000;5000;5000,3.70;6.00;3.50;1.31' \
  "of a group of class A23"
# a wide-format record with three axles that fit no class: read, but
# refused when it is to be simulated
printf 'timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,axle3_kg,spacing1_m,spacing2_m\n1,1,25,20000,6000,7000,7000,4.0,1.3\n2,1,25,20000,6000,7000,7000,4.0,4.0\n' >"$work/wide.csv"
rc=0
"$sim" --population "$work/wide.csv" --out "$work/o-wide" --vehicles 2 2>"$work/wide.err" || rc=$?
[ "$rc" = 1 ] && grep -q "^sim_publisher: $work/wide.csv:3: .*no vehicle class" "$work/wide.err" ||
  { cat "$work/wide.err" >&2; fail "wide record without a class: exit $rc"; }
echo "wide: $(cat "$work/wide.err")"
echo "sim_trucks: ok"
