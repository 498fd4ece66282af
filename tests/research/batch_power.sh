#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-batch-power: a synthetic per-vehicle file whose inferred STD grows
# exactly linearly with damage gives a monotonic trend with R² ~ 1 in every
# trial with the same vehicles at every level; bad files give FILE:LINE and
# exit 1; a bad command line exits 2.
# Usage: batch_power.sh AMFI_BATCH_POWER
set -u
bp=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# 200 vehicles, one repetition: inferred = 8 t + (true − 8 t)·(1 + 4d).
awk 'BEGIN {
  print "condition,repetition,damage,record,gvw_true_kg,gvw_fixed_kg"
  split("0 0.025 0.05 0.075 0.1", d, " ")
  for (l = 1; l <= 5; l++)
    for (i = 1; i <= 200; i++) {
      t = 4000 + 50 * i
      printf "table5_same,1,%s,%d,%.1f,%.1f\n", d[l], i, t, 8000 + (t - 8000) * (1 + 4 * d[l])
    }
}' > "$dir/linear.csv"
"$bp" --vehicles "$dir/linear.csv" --reps 1 --n 200 --trials 200 > "$dir/out.md" 2> "$dir/err" ||
  fail "exit $? on a valid file: $(cat "$dir/err")"
cat "$dir/out.md"
grep -q "×1.400 at 10 %" "$dir/out.md" || fail "the STD ratio of the file is 1.4"
grep -q "^| same vehicles at every level | 200 | 100.0 % | 100.0 % | 100.0 % | 1.000 |" \
  "$dir/out.md" || fail "same vehicles: not monotonic with R² 1 in every trial"
[ "$(grep -c '^| ' "$dir/out.md")" -eq 4 ] || fail "expected a header and three rows"

expect() {  # EXIT_STATUS MESSAGE_PATTERN ARGS...
  want=$1 pat=$2; shift 2
  "$bp" "$@" > /dev/null 2> "$dir/err"; rc=$?
  [ $rc -eq "$want" ] || fail "$*: exit $rc, expected $want"
  grep -q -e "$pat" "$dir/err" || fail "$*: message '$(cat "$dir/err")' lacks '$pat'"
}
sed '5s/,0,/,0.3,/' "$dir/linear.csv" > "$dir/b1.csv"
expect 1 "b1.csv:5: damage: '0.3'" --vehicles "$dir/b1.csv"
sed '30s/,[0-9.]*$/,abc/' "$dir/linear.csv" > "$dir/b2.csv"
expect 1 "b2.csv:30: gvw_fixed_kg: 'abc'" --vehicles "$dir/b2.csv"
printf 'x,y\n' > "$dir/b3.csv"
expect 1 "b3.csv:1: header" --vehicles "$dir/b3.csv"
awk 'NR != 250' "$dir/linear.csv" > "$dir/b4.csv"
expect 1 "b4.csv:250: .*record 50, but 49 at damage 0" --vehicles "$dir/b4.csv"
head -300 "$dir/linear.csv" > "$dir/b5.csv"
expect 1 "has no row at damage 0.05" --vehicles "$dir/b5.csv"
printf 'condition,repetition,damage,record,gvw_true_kg,gvw_fixed_kg\ntable5_same,1,0,1,9000\0,1\n' \
  > "$dir/b6.csv"
expect 1 "b6.csv:2: NUL byte" --vehicles "$dir/b6.csv"
expect 1 "no-such.csv" --vehicles "$dir/no-such.csv"
expect 1 "0 vehicles of condition 'ideal'" --vehicles "$dir/linear.csv" --condition ideal
expect 2 "--n: '0'" --n 0
expect 2 "unknown option" --frobnicate 1
echo "amfi-batch-power: ok"
