#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# tools/research/class-accuracy.sh on three vehicles of each class of the EU
# mix (class A road, no noise, the detector's speed): the table's shape
# (header, a gross row for every class and for all, criteria and classes of
# COST 323's names), the numbers and classes read back from amfi-accuracy's
# JSON lines for every row, the vehicles' classes as amfi-solve decided them,
# its vehicles.csv and pairs.txt, the same table again from the run's files
# (SOLVED), a run with three sensors (SENSORS), and refusals of a bad
# sample size, a bad position and a population without classes.
# Not the accuracy targets (docs/results/class-accuracy.md).
# Usage: class_accuracy.sh TOOL BIN_DIR POPULATION_EU
set -u
tool=$1 bin=$2 pop=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

SIM_ARGS="--dt 2.5e-4" sh "$tool" "$bin" "$dir/out" 3 "$pop" > "$dir/table.txt" 2> "$dir/err"
rc=$?
[ $rc -eq 0 ] || { cat "$dir/err"; fail "class-accuracy.sh exited $rc"; }
cat "$dir/table.txt"
t=$dir/out
head -1 "$dir/table.txt" | awk '{ exit !($1 == "class" && $2 == "n" && $3 == "criterion" &&
  $4 == "mean_pct" && $5 == "std_pct" && $6 == "pi_pct" && $7 == "pi0_pct" && $8 == "cost323" && NF == 8) }' ||
  fail "header: $(head -1 "$dir/table.txt")"
# the sample: three of each of the seven classes
[ "$(tail -n +2 "$t/sample.csv" | wc -l)" -eq 21 ] || fail "the sample has not 21 vehicles"
[ "$(tail -n +2 "$t/vehicles.csv" | wc -l)" -eq 21 ] || fail "vehicles.csv has not 21 vehicles"
awk -F, 'NF != 8 { print "line " NR ": " NF " fields"; bad++ }
  NR > 1 && $2 != $3 { print "vehicle " $1 ": class " $2 ", amfi-solve " $3; bad++ }
  NR > 1 { n = split($4, g, "-"); a = 0; for (i = 1; i <= n; i++) a += g[i]
           if (split($7, x, ";") != a || split($8, y, ";") != a) { print "vehicle " $1 ": axles"; bad++ } }
  END { exit bad > 0 }' "$t/vehicles.csv" || fail "vehicles.csv"
# pairs.txt: a header and a row per class
[ "$(wc -l < "$t/pairs.txt")" -eq 8 ] || fail "pairs.txt: $(cat "$t/pairs.txt")"
grep -qx "classed otherwise by amfi-solve: 0 *" "$dir/table.txt" || fail "the classed-otherwise line"
grep -qx "refused by amfi-solve: 0 *" "$dir/table.txt" || fail "the refused line"
# every row: a known class and criterion, n a whole number; with a COST 323
# class the numbers, else '-' and the reason
rows=$(grep -c '^[A-Za-z0-9]* *[0-9]*  [a-z_]* ' "$dir/table.txt")
[ "$rows" -ge 20 ] || fail "only $rows rows"
sed -n '2,$p' "$dir/table.txt" | grep -v '^classed\|^refused' | awk '
  $1 !~ /^(R2|R3|R4|A22|A23|A32|A33|all)$/ { print "class: " $0; bad++ }
  $3 !~ /^(gross|group|single|group_axle)$/ { print "criterion: " $0; bad++ }
  $2 !~ /^[0-9]+$/ { print "n: " $0; bad++ }
  $8 ~ /^(A\(5\)|B\+\(7\)|B\(10\)|C\(15\)|D\+\(20\)|D\(25\)|E\([0-9]+\))$/ {
    for (i = 4; i <= 7; i++) if ($i !~ /^[-+]?[0-9.]+$/) { print "number " i ": " $0; bad++ } ; next }
  $8 == "none:" && $4 == "-" { next }
  { print "class column: " $0; bad++ }
  END { exit bad > 0 }' || fail "a malformed row"
# a gross row for every class and for all; R2 has no groups; all counts every vehicle
for c in R2 R3 R4 A22 A23 A32 A33; do
  grep -q "^$c  *3  gross " "$dir/table.txt" || fail "no gross row of 3 for $c"
done
grep -q "^R2 .* group" "$dir/table.txt" && fail "R2 has a group row"
grep -q "^all  *21  gross .* A(5)$" "$dir/table.txt" || fail "all: not 21 gross weights in A(5)"
# each row is amfi-accuracy's line for that class and criterion
sed -n '2,$p' "$dir/table.txt" | grep -v '^classed\|^refused' | while read -r c n k m s p p0 cl _; do
  l=$(grep "\"criterion\":\"$k\"" "$t/accuracy-$c.json") || fail "$c $k: not in accuracy-$c.json"
  printf '%s' "$l" | grep -q "\"n\":$n," || fail "$c $k: n $n, JSON $l"
  if [ "$cl" = "none:" ]; then
    printf '%s' "$l" | grep -q '"class":null' || fail "$c $k: no class in the table, JSON $l"
  else
    printf '%s' "$l" | grep -qF "\"class\":\"$cl\"" || fail "$c $k: class $cl, JSON $l"
    printf '%s\n' "$l" | awk -v m="$m" -v s="$s" -v p="$p" -v p0="$p0" '
      function v(k) { match($0, "\"" k "\":[-0-9.e+]+"); return substr($0, RSTART + length(k) + 3, RLENGTH - length(k) - 3) + 0 }
      function off(a, b, tol) { return a - b > tol || b - a > tol }
      { exit off(m, v("mean_pct"), 0.006) || off(s, v("std_pct"), 0.006) ||
             off(p, v("pi_pct"), 0.06) || off(p0, v("pi0_pct"), 0.06) }' ||
      fail "$c $k: numbers $m $s $p $p0, JSON $l"
  fi
done || exit 1
# the inputs amfi-accuracy read: a header and one row per weighed value
head -1 "$t/weights-all.csv" | grep -qx "criterion,measured_kg,reference_kg" || fail "weights-all.csv header"
[ "$(grep -c '^gross,' "$t/weights-all.csv")" -eq 21 ] || fail "weights-all.csv: not 21 gross rows"

# the same run judged again from its files: the same table
SOLVED=$t sh "$tool" "$bin" "$dir/again" 3 "$pop" > "$dir/again.txt" 2> "$dir/err" ||
  { cat "$dir/err"; fail "SOLVED: exit $?"; }
cmp -s "$dir/table.txt" "$dir/again.txt" || fail "SOLVED: another table: $(diff "$dir/table.txt" "$dir/again.txt")"

# SENSORS: three sensors in the run's site file, used by both the simulator
# and amfi-solve (one vehicle of each class; every one weighed)
SENSORS="5 10 15" SIM_ARGS="--dt 2.5e-4" sh "$tool" "$bin" "$dir/three" 1 "$pop" > "$dir/three.txt" 2> "$dir/err" ||
  { cat "$dir/err"; fail "SENSORS: exit $?"; }
[ "$(grep -c '^  - {id: [0-2], at_m: \(5\|10\|15\), weight: 1}$' "$dir/three/site.yaml")" -eq 3 ] &&
  [ "$(grep -c '^sensors:' "$dir/three/site.yaml")" -eq 1 ] || fail "SENSORS: site.yaml: $(cat "$dir/three/site.yaml")"
head -1 "$dir/three/sim/v00001.csv" | grep -qx 't,accel_0,accel_1,accel_2' ||
  fail "SENSORS: the record's header $(head -1 "$dir/three/sim/v00001.csv")"
grep -qx "refused by amfi-solve: 0 *" "$dir/three.txt" || fail "SENSORS: $(tail -1 "$dir/three.txt")"
grep -q "^all  *7  gross " "$dir/three.txt" || fail "SENSORS: no gross row of 7"
SENSORS="5 x" sh "$tool" "$bin" "$dir/bad" 1 "$pop" > /dev/null 2> "$dir/err" && fail "SENSORS 5 x accepted"
grep -q "SENSORS: 'x' is not a position in m" "$dir/err" || fail "SENSORS 5 x: $(cat "$dir/err")"

# refusals: a bad sample size, a population without a class column
sh "$tool" "$bin" "$dir/bad" x "$pop" > /dev/null 2> "$dir/err" && fail "PER_CLASS x accepted"
grep -q "PER_CLASS: 'x' is not a whole number" "$dir/err" || fail "PER_CLASS x: $(cat "$dir/err")"
printf 'timestamp_s,lane,speed_mps,gvw_kg,axle1_kg,axle2_kg,spacing1_m\n1,1,25,8000,4000,4000,4.2\n' > "$dir/two.csv"
sh "$tool" "$bin" "$dir/bad" 3 "$dir/two.csv" > /dev/null 2> "$dir/err" && fail "a population without classes accepted"
grep -q "two.csv: no class column" "$dir/err" || fail "no class column: $(cat "$dir/err")"
echo "class_accuracy: $rows rows, every class and criterion read back from amfi-accuracy"
