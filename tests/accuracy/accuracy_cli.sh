#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-accuracy on a file whose gross-weight errors have the published
# case's mean and standard deviation (15 trucks, m = 1.38 %, s = 3.43 %:
# B(10), pi = 95.7 %, pi0 = 85.19 % under RR2, I), on a file of several
# criteria, and on bad input (one line naming FILE:LINE, exit 1).
# Usage: accuracy_cli.sh AMFI_ACCURACY
set -u
acc=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
# 15 errors: standardised z scaled to s = 3.43 around m = 1.38, reference 30 t
awk 'BEGIN {
  n = 15; for (i = 1; i <= n; i++) { z[i] = sin(2.1 * i) + 0.3 * cos(5.3 * i); s += z[i] }
  m = s / n; for (i = 1; i <= n; i++) ss += (z[i] - m)^2; sd = sqrt(ss / (n - 1))
  print "criterion,measured_kg,reference_kg"
  for (i = 1; i <= n; i++) {
    e = 1.38 + 3.43 * (z[i] - m) / sd
    printf "gross,%.6f,30000\n", 30000 * (1 + e / 100)
  } }' > "$dir/pub.csv"
out=$("$acc" --input "$dir/pub.csv" --condition RR2 --environment I) || fail "exit $? on the published case"
echo "$out" | head -1 | grep -q '"criterion":"gross","n":15' || fail "no gross line: $out"
echo "$out" | grep -q '"class":"B(10)"' || fail "not B(10): $out"
echo "$out" | awk -F'"pi0_pct":' 'NR == 1 { split($2, a, ","); d = a[1] - 85.19; exit !(d < 0.01 && d > -0.01) }' ||
  fail "pi0 is not 85.19: $out"
echo "$out" | awk -F'"pi_pct":' 'NR == 1 { split($2, a, ","); d = a[1] - 95.7; exit !(d < 0.05 && d > -0.05) }' ||
  fail "pi is not 95.7: $out"
echo "$out" | tail -1 | grep -q '"criterion":"overall".*"class":"B(10)","set_by":"gross"' ||
  fail "overall line: $out"
# an initial verification is stricter: B(10) at 0.8 delta = 8 %, pi 88.1 %
out=$("$acc" --input "$dir/pub.csv" --initial-verification) || fail "initial verification exit $?"
echo "$out" | head -1 | grep -q '"pi_pct":88.1.*"class":"B(10)","delta_pct":8.0,' ||
  fail "initial verification: $out"
# several criteria: the overall class is the worst
{ cat "$dir/pub.csv"
  awk 'BEGIN { for (i = 1; i <= 20; i++) printf "single,%.3f,8000\n", 8000 * (1 + (0.5 * sin(i)) / 100) }'
} > "$dir/two.csv"
out=$("$acc" --input "$dir/two.csv") || fail "exit $? on two criteria"
[ "$(echo "$out" | wc -l)" -eq 3 ] || fail "expected three lines: $out"
echo "$out" | sed -n 2p | grep -q '"criterion":"single","n":20.*"class":"A(5)"' || fail "single: $out"
echo "$out" | tail -1 | grep -q '"class":"B(10)","set_by":"gross"' || fail "overall of two: $out"
# a measured value below zero (an axle of a group the solver split unevenly)
# is an error of its own, not bad input: -150 % among nine small errors, mean -14 %
{ echo "criterion,measured_kg,reference_kg"
  echo "group_axle,-3000,6000"
  awk 'BEGIN { for (i = 1; i <= 9; i++) printf "group_axle,%.3f,6000\n", 6000 * (1 + 0.05 * sin(i)) }'
} > "$dir/neg.csv"
out=$("$acc" --input "$dir/neg.csv" 2> "$dir/err") || fail "a negative measured value: exit $?: $(cat "$dir/err")"
echo "$out" | head -1 | grep -q '"criterion":"group_axle","n":10,' || fail "negative measured: $out"
echo "$out" | head -1 | awk -F'"mean_pct":' '{ split($2, a, ","); exit !(a[1] < -13 && a[1] > -15) }' ||
  fail "negative measured: the mean error is not about -14 %: $out"
# bad input: one line naming the place, exit 1
bad() { # NAME CONTENT WANT
  printf '%b' "$2" > "$dir/$1.csv"
  "$acc" --input "$dir/$1.csv" > "$dir/out" 2> "$dir/err"; rc=$?
  [ $rc -eq 1 ] || fail "$1: exit $rc, want 1"
  [ "$(wc -l < "$dir/err")" -eq 1 ] || fail "$1: not one line: $(cat "$dir/err")"
  grep -q "$3" "$dir/err" || fail "$1: '$(cat "$dir/err")' lacks '$3'"
}
bad header 'crit,measured,reference\ngross,1,2\n' "header.csv:1: the header must be"
bad criterion 'criterion,measured_kg,reference_kg\ngross,100,100\naxle,1,100\n' "criterion.csv:3: criterion: 'axle' is not gross"
bad number 'criterion,measured_kg,reference_kg\ngross,abc,100\n' "number.csv:2: measured_kg: 'abc' is not a number"
bad reference 'criterion,measured_kg,reference_kg\ngross,100,0\n' "reference.csv:2: reference_kg: 0 kg is outside"
bad measured 'criterion,measured_kg,reference_kg\ngross,-2e6,30000\n' "measured.csv:2: measured_kg: -2e+06 kg is outside"
bad fields 'criterion,measured_kg,reference_kg\ngross,100\n' "fields.csv:2: 2 fields, expected 3"
bad empty '' "empty.csv: empty file"
bad norows 'criterion,measured_kg,reference_kg\n' "norows.csv: no data rows"
bad one 'criterion,measured_kg,reference_kg\ngross,100,100\n' "gross: no class: fewer than 2 values"
"$acc" --input "$dir/missing.csv" 2> "$dir/err"; [ $? -eq 1 ] || fail "a missing file is not exit 1"
grep -q "missing.csv: cannot open" "$dir/err" || fail "missing file: $(cat "$dir/err")"
"$acc" --input "$dir/pub.csv" --condition R1 2> "$dir/err"; [ $? -eq 2 ] || fail "--condition R1 not exit 2"
grep -q "amfi-accuracy: --condition: 'R1' is not r1, r2, RR1 or RR2" "$dir/err" || fail "$(cat "$dir/err")"
echo "amfi-accuracy: the published case B(10), two criteria, a negative axle, 10 bad inputs refused by name"
