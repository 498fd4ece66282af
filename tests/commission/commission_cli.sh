#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# commission_cli.sh: amfi-commission refuses bad inputs and run sets that
# cannot identify the model with one clear line on stderr and a non-zero
# exit (1 for the input, 2 for the command line), and writes no site file:
# missing files, a run whose loads do not match its axles, too few runs,
# speeds too alike, runs without enough free vibration, a multi-channel run
# file without one of the site's sensors; with each run's speed estimated
# (--speed-sd): the clock not held, speeds that scatter too much for the
# runs to fix the detector's scale.
# Usage: commission_cli.sh SIM_PUBLISHER AMFI_COMMISSION DESIGN.yaml
set -u
sim=$1 com=$2 design=$3
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# refuse CODE PATTERN ARGS...: exit CODE, one line on stderr matching
# PATTERN, nothing on stdout, no site file
refuse() {
  code=$1 pat=$2
  shift 2
  rm -f "$dir/site.yaml"
  "$com" "$@" > "$dir/out" 2> "$dir/err"
  rc=$?
  [ "$rc" -eq "$code" ] || fail "$*: exit $rc, expected $code ($(cat "$dir/err"))"
  [ "$(wc -l < "$dir/err")" -eq 1 ] || fail "$*: not one line on stderr: $(cat "$dir/err")"
  grep -qE -- "$pat" "$dir/err" || fail "$*: '$(cat "$dir/err")' does not match '$pat'"
  [ ! -s "$dir/out" ] || fail "$*: printed $(cat "$dir/out")"
  [ ! -e "$dir/site.yaml" ] || fail "$*: wrote a site file"
  echo "refused ($rc): $(cat "$dir/err")"
}

# a good set of runs (the design as built), two per truck, and variants
"$sim" --config "$design" --calibration-runs "$dir/ok" --runs-per-truck 2 2>/dev/null ||
  fail "sim_publisher --calibration-runs exited $?"
"$sim" --config "$design" --calibration-runs "$dir/alike" --runs-per-truck 3 \
  --calibration-speeds 20,21 2>/dev/null || fail "sim_publisher (alike speeds) exited $?"
"$sim" --config "$design" --calibration-runs "$dir/short" --runs-per-truck 2 \
  --tail 0.55 2>/dev/null || fail "sim_publisher (short tail) exited $?"
R=$dir/ok/RUNS.csv

# the command line
refuse 2 'runs.*required' --config "$design" --out "$dir/site.yaml"
refuse 2 'out.*required' --config "$design" --runs "$R"
refuse 2 "'wheels' is not" --config "$design" --runs "$R" --out "$dir/site.yaml" --hold wheels
# missing files
refuse 1 'nonexistent.yaml' --config "$dir/nonexistent.yaml" --runs "$R" --out "$dir/site.yaml"
refuse 1 'nothere.csv' --config "$design" --runs "$dir/nothere.csv" --out "$dir/site.yaml"
sed 's/^run001.csv,/gone.csv,/' "$R" > "$dir/ok/gone.csv.runs"
refuse 1 'gone.csv.runs:2: file: .*gone.csv' --config "$design" --runs "$dir/ok/gone.csv.runs" \
  --out "$dir/site.yaml"
refuse 1 'amb.csv' --config "$design" --runs "$R" --ambient "$dir/amb.csv" --out "$dir/site.yaml"
# a run whose loads do not match its axles (a five-axle truck given four loads)
awk -F, 'NR == 4 { sub(/;[0-9.]*$/, "", $5) } { print }' OFS=, "$R" > "$dir/ok/loads.csv"
refuse 1 'loads.csv:4: axle_kg: 4 loads for 5 axles' --config "$design" \
  --runs "$dir/ok/loads.csv" --out "$dir/site.yaml"
# a load that is not a number, a speed out of range
sed '2s/,7000.0;/,7000x;/' "$R" > "$dir/ok/nan.csv"
refuse 1 "nan.csv:2: axle_kg: '7000x' is not a number" --config "$design" \
  --runs "$dir/ok/nan.csv" --out "$dir/site.yaml"
# too few runs
head -n 4 "$R" > "$dir/ok/three.csv"
refuse 1 'three.csv: 3 runs; commissioning needs at least 4' --config "$design" \
  --runs "$dir/ok/three.csv" --out "$dir/site.yaml"
# speeds too alike to tell the clock offset from the speed scale
refuse 1 'too alike' --config "$design" --runs "$dir/alike/RUNS.csv" --out "$dir/site.yaml"
# ... unless one of the two is held: then the set goes on (not checked here)
# runs that keep too little free vibration to identify the bridge
refuse 1 'free vibration' --config "$design" --runs "$dir/short/RUNS.csv" --out "$dir/site.yaml"
# each run's speed estimated (--speed-sd): the clock offset cannot be told
# from the mass then, and must be held
refuse 2 "speed-sd: '0.5' is not a number in" --config "$design" --runs "$R" \
  --out "$dir/site.yaml" --speed-sd 0.5
refuse 1 "cannot tell the detector's clock offset from the mass: hold clock" \
  --config "$design" --runs "$R" --out "$dir/site.yaml" --speed-sd 0.03
# speeds that scatter too much for 4 runs to fix the detector's scale (its
# random error 8 % SD; searched within 3 x 5 %: at --speed-sd 0.1 the four
# searches over 3 x 10 % took 28 s of the test's 38 under ASan, for the same
# refusal)
"$sim" --config "$design" --calibration-runs "$dir/noisy" --runs-per-truck 2 \
  --speed-error 0,0.08 --seed 3 2>/dev/null || fail "sim_publisher (speed error) exited $?"
refuse 1 "the runs' speeds scatter by .* 4 runs fix its speed scale only to" \
  --config "$design" --runs "$dir/noisy/RUNS.csv" --out "$dir/site.yaml" --speed-sd 0.05 \
  --hold clock
# a multi-channel file that lacks one of the site's sensors
cat > "$dir/two.yaml" <<EOF
sensors:
  - {id: 0, at_m: 10}
  - {id: 3, at_m: 6}
EOF
sed -n '/^sensors:/q;p' "$design" > "$dir/design2.yaml"
cat "$dir/two.yaml" >> "$dir/design2.yaml"
sed -n '/^solver:/,$p' "$design" >> "$dir/design2.yaml"
refuse 1 'run001.csv.*(sensor|channel|accel).*3' --config "$dir/design2.yaml" --runs "$R" \
  --out "$dir/site.yaml"
# multi-channel run files of a two-sensor site are read (the set is then
# refused for its speeds, after every file was read) ...
"$sim" --config "$dir/design2.yaml" --calibration-runs "$dir/two" --runs-per-truck 3 \
  --calibration-speeds 20,21 2>/dev/null || fail "sim_publisher (two sensors) exited $?"
head -1 "$dir/two/run001.csv" | grep -q '^t,accel_0,accel_3$' ||
  fail "two-sensor run file header: $(head -1 "$dir/two/run001.csv")"
refuse 1 'too alike' --config "$dir/design2.yaml" --runs "$dir/two/RUNS.csv" --out "$dir/site.yaml"
# ... and a column of no sensor of the site is named
refuse 1 'run001.csv:1: .*column\(s\) of no sensor of the site: accel_3' --config "$design" \
  --runs "$dir/two/RUNS.csv" --out "$dir/site.yaml"
echo "commission_cli: every bad input refused with one line"
