#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-solve corrects the detector as the site file's detector: section says
# (a clock offset and a speed scale found by commissioning): a passage
# reported 12 ms late and 3 % fast, solved with those corrections, weighs
# what the exact report weighs; without them it weighs wrong.
# Usage: solve_detector.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR
set -u
solve=$1 mkcase=$2 cfgdir=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
"$mkcase" --out "$dir/c.csv" --speed 20 --axle-loads-kg 6000,12000 --axle-spacing 4.5 \
  --pre 0.5 --post 0.5 > /dev/null || fail "amfi-mkcase"
gvw() { sed -n 's/.*"gvw_kg":\([-0-9.e+]*\),.*/\1/p'; }
exact=$("$solve" --config "$cfgdir/paper-20m.yaml" --accel "$dir/c.csv" --speed 20 \
  --axle-spacing 4.5 --entry-time 0.5 | gvw) || fail "exact solve"
{ cat "$cfgdir/paper-20m.yaml"; printf 'detector:\n  clock_offset_s: 0.012\n  speed_scale: 1.03\n'; } \
  > "$dir/det.yaml"
# the detector's report: 12 ms late, speed and spacing 3 % high
wrong=$("$solve" --config "$cfgdir/paper-20m.yaml" --accel "$dir/c.csv" --speed 20.6 \
  --axle-spacing 4.635 --entry-time 0.512 | gvw) || fail "uncorrected solve"
fixed=$("$solve" --config "$dir/det.yaml" --accel "$dir/c.csv" --speed 20.6 \
  --axle-spacing 4.635 --entry-time 0.512 | gvw) || fail "corrected solve"
awk -v e="$exact" -v w="$wrong" -v f="$fixed" 'BEGIN {
  de = (f - e) / e; dw = (w - e) / e
  printf "exact %.1f kg, reported uncorrected %.1f kg (%+.2f %%), corrected %.1f kg (%+.2e)\n", e, w, 100 * dw, f, de
  exit !(de < 1e-9 && de > -1e-9 && (dw > 0.05 || dw < -0.05)) }' ||
  fail "the detector's corrections do not restore the exact report's weight"
"$solve" --config "$dir/det.yaml" --accel "$dir/c.csv" --speed 20.6 --axle-spacing 4.635 \
  --entry-time 0.512 > /dev/null || fail "exit status"
printf 'detector:\n  speed_scale: 3\n' > "$dir/bad.yaml"
"$solve" --config "$dir/bad.yaml" --accel "$dir/c.csv" --speed 20 --axle-spacing 4.5 \
  2> "$dir/err" > /dev/null && fail "speed_scale 3 accepted"
grep -q "bad.yaml:2: detector.speed_scale" "$dir/err" || fail "bad key message: $(cat "$dir/err")"
echo "amfi-solve applies detector.clock_offset_s and detector.speed_scale"
