#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# make_corpus.sh: (re)writes the committed seed corpora of the fuzz targets,
# fuzz/corpus/NAME/, small valid and invalid examples (docs/fuzzing.md).
#   sh fuzz/make_corpus.sh BUILD [OUT]
#       BUILD: a configured and built tree (any flavour) holding
#       tests/test_msg_check; OUT: where to write (default fuzz/corpus)
# Deterministic: the same sources give the same files (the intake seeds,
# simulator output, the same to the last bits on one CPU and BLAS kernel,
# to about 1e-9 relative on another), so the fuzz_corpus test
# (tests/fuzz/fuzz_corpus.sh) can tell a committed corpus that a changed .lcm or
# config/*.yaml left stale (a message seed with the old fingerprint seeds
# nothing).
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
build=${1:?usage: make_corpus.sh BUILD [OUT]}
c=${2:-$top/fuzz/corpus}
rm -rf "$c"
mkdir -p "$c/config" "$c/accel_csv" "$c/traffic"

# --- config: the shipped files and a few broken ones ---
for f in "$top"/config/*.yaml; do cp "$f" "$c/config/"; done
printf 'bridge:\n  span_m: 20\n  elements: 40\nsolver:\n  lamda: 1\n' >"$c/config/unknown-key.yaml"
printf 'bridge: [1, 2\n' >"$c/config/syntax.yaml"
printf 'bridge:\n  span_m: -5\n' >"$c/config/negative-span.yaml"
printf 'sensors:\n  - {id: 0, x_m: 10}\n  - {id: 0, x_m: 12}\n' >"$c/config/duplicate-sensor.yaml"
printf 'bridge: &a\n  span_m: *a\n' >"$c/config/alias.yaml"

# --- accel_csv: a 20-row passage at 1 kHz, plain and gzip, and broken ones ---
{
  echo "t,accel"
  i=0
  while [ $i -lt 20 ]; do printf '%d.%03d,%d.5e-3\n' $((i / 1000)) $((i % 1000)) $((i % 7 - 3)); i=$((i + 1)); done
} >"$c/accel_csv/valid.csv"
gzip -9 -n -c "$c/accel_csv/valid.csv" >"$c/accel_csv/valid.csv.gz"
sed 's/\r*$/\r/' "$c/accel_csv/valid.csv" >"$c/accel_csv/crlf.csv"
head -5 "$c/accel_csv/valid.csv" >"$c/accel_csv/too-short.csv"
sed '8s/.*/0.007,nan/' "$c/accel_csv/valid.csv" >"$c/accel_csv/nan.csv"
sed '8s/.*/0.001,1/' "$c/accel_csv/valid.csv" >"$c/accel_csv/time-back.csv"
sed '1s/.*/time,acc/' "$c/accel_csv/valid.csv" >"$c/accel_csv/bad-header.csv"
head -c 30 "$c/accel_csv/valid.csv.gz" >"$c/accel_csv/gzip-cut.gz"
# several sensors: a column per sensor id, and a repeated id
sed -e '1s/.*/t,accel_3,accel_7,accel_12/' -e '2,$s/$/,1e-3,-2e-3/' "$c/accel_csv/valid.csv" \
  >"$c/accel_csv/three-sensors.csv"
sed '1s/accel_7/accel_3/' "$c/accel_csv/three-sensors.csv" >"$c/accel_csv/repeated-sensor.csv"

# --- traffic: the shipped population's first vehicles, 12 axles, broken ones ---
head -6 "$top/sim_publisher/data/population.csv" >"$c/traffic/valid.csv"
{
  h="timestamp_s,lane,speed_mps,gvw_kg"; r="1.5,1,20,60000"
  a=1; while [ $a -le 12 ]; do h="$h,axle${a}_kg"; r="$r,5000"; a=$((a + 1)); done
  a=1; while [ $a -le 11 ]; do h="$h,spacing${a}_m"; r="$r,1.5"; a=$((a + 1)); done
  echo "$h"; echo "$r"
} >"$c/traffic/twelve-axles.csv"
sed '3s/,[0-9.]*$/,-1/' "$c/traffic/valid.csv" >"$c/traffic/negative-spacing.csv"
sed '2s/8003/9000/' "$c/traffic/valid.csv" >"$c/traffic/gvw-mismatch.csv"
head -1 "$c/traffic/valid.csv" >"$c/traffic/header-only.csv"
sed '1s/axle2_kg/axle3_kg/' "$c/traffic/valid.csv" >"$c/traffic/axle-hole.csv"
# the class format: heavy traffic by class, an unknown class, a short list
head -6 "$top/sim_publisher/data/population-eu.csv" >"$c/traffic/classes.csv"
sed '2s/,A33,/,A99,/' "$c/traffic/classes.csv" >"$c/traffic/class-unknown.csv"
sed '3s/;[0-9]*,/,/' "$c/traffic/classes.csv" >"$c/traffic/class-short-list.csv"

# --- intake: sim_publisher traffic as fuzz_intake records (tests/lcm_intake_seed) ---
mkdir -p "$c/intake"
tmpd=$(mktemp -d)
trap 'rm -rf "$tmpd"' EXIT
sim="$build/sim_publisher/sim_publisher"
export AMFI_DATA_DIR="${AMFI_DATA_DIR:-$top/sim_publisher/data}"
# two vehicles at 1000 Hz, blocks of 160 samples
"$sim" --lcm-url none --log "$tmpd/a.lcmlog" --vehicles 2 --headway 2.5 --speedup max --seed 3 \
  --block 160 2>/dev/null
"$build/tests/lcm_intake_seed" "$tmpd/a.lcmlog" "$c/intake/two-vehicles"
# the same cut after its first 12 events (vehicles whose data never comes)
"$build/tests/lcm_intake_seed" "$tmpd/a.lcmlog" "$c/intake/cut-short" 12
# its vehicles without any sensor data (found by fuzz_intake: amfid crashed at shutdown)
"$build/tests/lcm_inject" --vehicles-only "$tmpd/a.lcmlog" "$tmpd/v.lcmlog"
"$build/tests/lcm_intake_seed" "$tmpd/v.lcmlog" "$c/intake/vehicles-without-data"
# a dozen vehicles sampled at 200 Hz: enough for the baseline and a window
"$sim" --lcm-url none --log "$tmpd/b.lcmlog" --vehicles 12 --headway 2.5 --speedup max --seed 4 \
  --block 160 --scan-rate 200 2>/dev/null
"$build/tests/lcm_intake_seed" "$tmpd/b.lcmlog" "$c/intake/twelve-at-200hz"

# --- msg_TYPE: encoded by lcm-gen (test_msg_check --corpus) ---
"$build/tests/test_msg_check" --corpus "$c"
echo "make_corpus: $(find "$c" -type f | wc -l) files, $(du -sk "$c" | cut -f1) kB in $c"
