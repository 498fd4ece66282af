#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# commission_segments.sh: amfi-commission --segments N fits each segment's
# stiffness and refuses, with one line naming what trades, the runs that
# cannot tell the segments apart.
#   - an as-built bridge whose left half is 10 % softer than the design's,
#     4 calibration runs, the detector, sensor and bearings held (cheap: the
#     design at 2000 Hz): --segments 2 finds each half within 2 % and writes
#     them, with their uncertainty, in SITE.yaml's comment block, its
#     bridge.segments and the report;
#   - --segments 4 on 8 runs of the same bridge with its one sensor at
#     mid-span: the two segments beside the sensor trade (refused, naming
#     them, or the segment the sensor barely sees); 4 runs for --segments 4 (too few runs for the parameters); a
#     design whose elements do not divide into the segments; the range.
# Usage: commission_segments.sh SIM_PUBLISHER AMFI_COMMISSION DESIGN.yaml AS_BUILT.yaml
set -u
sim=$1 com=$2 design0=$3 asb=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# the design at a coarse calculation rate (the test's time, not the method's)
sed 's/^\(  calc_rate_hz:\) *5000 /\1 2000 /' "$design0" > "$dir/design.yaml"
grep -q '^  calc_rate_hz: 2000 ' "$dir/design.yaml" || fail "calc_rate_hz not set in the design copy"
design=$dir/design.yaml
hold="--hold bearings --hold sensor --hold clock --hold speed"

"$sim" --config "$design" --as-built "$asb" --calibration-runs "$dir/c4" --runs-per-truck 2 \
  2>/dev/null || fail "sim_publisher --calibration-runs (4) exited $?"
"$sim" --config "$design" --as-built "$asb" --calibration-runs "$dir/c8" --runs-per-truck 4 \
  2>/dev/null || fail "sim_publisher --calibration-runs (8) exited $?"

# refuse CODE PATTERN ARGS...: exit CODE, one line on stderr matching
# PATTERN, nothing on stdout, no site file
refuse() {
  code=$1 pat=$2
  shift 2
  rm -f "$dir/site.yaml"
  # shellcheck disable=SC2086
  "$com" "$@" > "$dir/out" 2> "$dir/err"
  rc=$?
  [ "$rc" -eq "$code" ] || fail "$*: exit $rc, expected $code ($(cat "$dir/err"))"
  [ "$(wc -l < "$dir/err")" -eq 1 ] || fail "$*: not one line on stderr: $(cat "$dir/err")"
  grep -qE -- "$pat" "$dir/err" || fail "$*: '$(cat "$dir/err")' does not match '$pat'"
  [ ! -s "$dir/out" ] || fail "$*: printed $(cat "$dir/out")"
  [ ! -e "$dir/site.yaml" ] || fail "$*: wrote a site file"
  echo "refused ($rc): $(cat "$dir/err")"
}

# shellcheck disable=SC2086
refuse 2 "segments: '9' is not a number in \[2, 8\]" --config "$design" --runs "$dir/c4/RUNS.csv" --out "$dir/site.yaml" \
  --segments 9
# shellcheck disable=SC2086
refuse 1 "4 runs for 4 fitted parameters .*at least 8 runs" --config "$design" \
  --runs "$dir/c4/RUNS.csv" --out "$dir/site.yaml" $hold --segments 4
# shellcheck disable=SC2086
refuse 1 "20 elements do not divide into 3 equal segments" --config "$design" \
  --runs "$dir/c4/RUNS.csv" --out "$dir/site.yaml" $hold --segments 3
# shellcheck disable=SC2086
refuse 1 "cannot tell the segment [0-9] stiffness from|segment [0-9].s stiffness .* more than 2 %" --config "$design" \
  --runs "$dir/c8/RUNS.csv" --out "$dir/site.yaml" $hold --segments 4

# the two halves
# shellcheck disable=SC2086
"$com" --config "$design" --runs "$dir/c4/RUNS.csv" --out "$dir/site.yaml" --report "$dir/rep" \
  $hold --segments 2 > "$dir/out" 2> "$dir/err" || fail "--segments 2 exited $?: $(cat "$dir/err")"
cat "$dir/out"
# each half's E·I scale within 2 % of the truth, and a finite uncertainty
# below 2 % (the truth: 0.9 on 0 .. 10 m, 1 on 10 .. 20 m)
sed 's/{"from_m"/\n{"from_m"/g' "$dir/out" | awk -v F=0 '
  /"stiffness_scale"/ && /"from_m"/ {
    match($0, /"from_m":[-0-9.e+]*/); x0 = substr($0, RSTART + 9, RLENGTH - 9)
    match($0, /"stiffness_scale":[-0-9.e+]*/); s = substr($0, RSTART + 18, RLENGTH - 18)
    match($0, /"sd_rel":[-0-9.e+]*/); sd = substr($0, RSTART + 9, RLENGTH - 9)
    truth = (x0 + 0 < 10) ? 0.9 : 1.0
    e = 100 * (s / truth - 1)
    printf "segment from %s m: x%.4f (truth %.2f, %+.2f %%) +- %.2f %%\n", x0, s, truth, e, 100 * sd
    n++
    if (e > 2 || e < -2 || !(sd > 0) || sd > 0.02) bad = 1
  }
  END { if (n != 2) { print "FAIL: " n " segments in the JSON"; exit 1 } exit bad }' ||
  fail "a segment's stiffness is off"
# the comment block, the site's segments, the report
grep -q '^#   flexural stiffness per segment' "$dir/site.yaml" || fail "no per-segment lines in SITE.yaml"
[ "$(grep -cE '^#  +(0\.00 \.\. 10\.00|10\.00 \.\. 20\.00) m  x[0-9.]+ \+- 0\.0[0-9]+' "$dir/site.yaml")" -eq 2 ] ||
  fail "SITE.yaml's comment block lacks a segment's value +- uncertainty: $(grep -A3 'per segment' "$dir/site.yaml")"
[ "$(grep -cE '^    - \{from_m: (0|10), to_m: (10|20), EI_nm2: ' "$dir/site.yaml")" -eq 2 ] ||
  fail "SITE.yaml's bridge.segments: $(grep -A3 'segments:' "$dir/site.yaml")"
grep -q '^## Stiffness per segment' "$dir/rep/report.md" || fail "no per-segment section in the report"
echo "ok"
