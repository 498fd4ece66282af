#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# year_sim.sh: amfi-year-sim (issue 14) on a short evaluation: the table has
# a healthy row and one row per damage level for drift off and on, every
# 10 % run detects within days, the same seed gives the same table, and bad
# options are refused naming the flag.
#   year_sim.sh AMFI_YEAR_SIM
set -eu
ys=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

"$ys" --years 1 --det-runs 3 --damage 0.1 --seed 3 >"$work/a.md" 2>"$work/a.err" ||
  { cat "$work/a.err" >&2; fail "run"; }
cat "$work/a.md"
[ "$(grep -c '^| o[nf]* | healthy | 1 years' "$work/a.md")" -eq 2 ] || fail "healthy rows"
for d in off on; do
  row=$(grep "^| $d | 10.0 % |" "$work/a.md") || fail "no 10 % row with drift $d"
  echo "$row" | grep -q '3/3 detected' || fail "drift $d: 10 % not always detected: $row"
  days=$(echo "$row" | awk -F'|' '{gsub(/ /, "", $9); print $9}')
  awk -v x="$days" 'BEGIN { exit !(x > 0 && x < 7) }' || fail "drift $d: p95 $days days"
done
"$ys" --years 1 --det-runs 3 --damage 0.1 --seed 3 >"$work/b.md" 2>/dev/null
cmp -s "$work/a.md" "$work/b.md" || fail "the same seed gave another table"
for bad in "--drift sideways" "--damage 0.9" "--years 0"; do
  if "$ys" $bad >/dev/null 2>"$work/bad.err"; then fail "$bad accepted"; fi
  grep -q -- "${bad%% *}" "$work/bad.err" || fail "$bad: message does not name the flag"
done
echo "year_sim: ok"
