#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_publisher --as-built, --calibration-runs and --ambient-out:
#  - the calibration runs' free vibration rings at the as-built bridge's f1
#    (libamfi) within 0.5 %, not at the design's, and the design's runs at
#    the design's; weighed with the design model the as-built runs are off
#    by what the stiffer bridge says, the design's are not;
#  - the detector's clock, speed and spacing errors are in RUNS.csv,
#    meta.csv and vehicle_t, and not in RUNS.truth.csv, meta's truth
#    columns and truth_t; the sensor is where the as-built file puts it;
#  - several sensors give the header t,accel_ID,...;
#  - the ambient record's spectrum peaks at the as-built f1;
#  - bad as-built files and truck specs are refused (FILE:LINE, status 1 / 2);
#  - an as-built file equal to the design changes no value of the records.
#  - sim_publisher(1) names every key of an as-built file.
# Usage: sim_asbuilt.sh SIM_PUBLISHER ASBUILT_CHECK AMFI_SOLVE DESIGN.yaml PAGE.scd
set -u
sim=$1
chk=$2
solve=$3
design=$4
page=$5
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# The manual names every key the as-built loader reads (its last component).
keys=$("$chk" keys) || fail "asbuilt_check keys"
for k in $keys; do
  name=${k##*.}
  name=${name%%\[\]}
  grep -qE -- "[*.]$name[*:]" "$page" || fail "$page does not document the as-built key $k"
done
# same A B: the two CSV files hold the same values (fields split at ',' and
# ';', numbers equal to 1e-12 relative, text exactly), not compared as bytes
same() {
  [ "$(wc -l < "$1")" -eq "$(wc -l < "$2")" ] || return 1
  paste -d'|' "$1" "$2" | awk -F'|' '{
      na = split($1, a, /[,;]/); nb = split($2, b, /[,;]/)
      if (na != nb) exit 1
      for (i = 1; i <= na; i++) {
        if (a[i] == b[i]) continue
        if (a[i] !~ /^[-+0-9.eE]+$/ || b[i] !~ /^[-+0-9.eE]+$/) exit 1
        d = a[i] - b[i]; m = (a[i] < 0 ? -a[i] : a[i]) + (b[i] < 0 ? -b[i] : b[i])
        if ((d < 0 ? -d : d) > 1e-12 * m) exit 1
      } }'
}
# |a/b − 1| <= tol, else fail with the message
near() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { e = a / b - 1; exit !(e <= t && e >= -t) }'; }

# The as-built bridge: E +7 %, mass +5 %, damping 2 %, bearings with
# rotational springs of 0.5 EI/L, the sensor 0.5 m short of mid-span, the
# detector 10 ms late, speeds 2 % high, spacings 1 % short.
cat > "$dir/ab.yaml" <<'EOF'
bridge:
  E_pa: 3.745e10
  density_kgm3: 2520
  damping: {ratio: 0.02}
  supports:
    - {at_m: 0, type: pinned, k_theta_nmprad: 2.8e8}
    - {at_m: 20, type: roller, k_theta_nmprad: 2.8e8}
sensors:
  - {id: 0, offset_m: -0.5}
detector:
  clock_offset_s: 0.010
  speed_scale: 1.02
  spacing_scale: 0.99
EOF
f1_design=$("$chk" f1 "$design") || fail "f1 of the design"
f1_ab=$("$chk" f1 "$design" "$dir/ab.yaml") || fail "f1 of the as-built bridge"
echo "f1: design $f1_design Hz, as built $f1_ab Hz"
near "$f1_ab" "$f1_design" 0.05 && fail "the as-built f1 should differ from the design's by > 5 %"

"$sim" --config "$design" --as-built "$dir/ab.yaml" --calibration-runs "$dir/ab" \
  --runs-per-truck 2 2>/dev/null || fail "calibration runs on the as-built bridge exited $?"
"$sim" --config "$design" --calibration-runs "$dir/de" --runs-per-truck 2 2>/dev/null ||
  fail "calibration runs on the design exited $?"
for set in ab de; do
  [ "$(head -1 "$dir/$set/RUNS.csv")" = "file,speed_mps,axle_spacings_m,entry_time_s,axle_kg" ] ||
    fail "$set: RUNS.csv header: $(head -1 "$dir/$set/RUNS.csv")"
  [ "$(wc -l < "$dir/$set/RUNS.csv")" -eq 5 ] || fail "$set: RUNS.csv has not 4 runs"
  [ "$(wc -l < "$dir/$set/RUNS.truth.csv")" -eq 5 ] || fail "$set: RUNS.truth.csv has not 4 runs"
  head -1 "$dir/$set/run001.csv" | grep -qx 't,accel' || fail "$set: run001.csv header"
done

# The free vibration after the last axle left: f1 of the bridge crossed.
for set in ab de; do
  [ $set = ab ] && f1=$f1_ab other=$f1_design || f1=$f1_design other=$f1_ab
  tail -n +2 "$dir/$set/RUNS.truth.csv" | awk -F, '{
      n = split($6, s, ";"); L = 0; for (i = 1; i <= n; i++) L += s[i];
      printf "%s %.6f\n", $1, $5 + (20 + L) / $4 + 0.1 }' > "$dir/$set.tails"
  while read -r f from; do
    m=$("$chk" freq "$dir/$set/$f" 1 "$from" 2 15) || fail "$set/$f: no frequency"
    echo "$set/$f: free vibration at $m Hz (bridge f1 $f1 Hz)"
    near "$m" "$f1" 0.005 || fail "$set/$f: $m Hz is not within 0.5 % of $f1 Hz"
    near "$m" "$other" 0.02 && fail "$set/$f: $m Hz is close to the other bridge's $other Hz"
  done < "$dir/$set.tails"
done

# A key the as-built file leaves out keeps the design's value (a design of
# another modulus); segments and elastic bearings of the as-built bridge
# ring at its libamfi f1 too.
printf 'bridge: {E_pa: 3.0e10}\n' > "$dir/soft.yaml"
printf 'detector: {clock_offset_s: 0.001}\n' > "$dir/keep.yaml"
[ "$("$chk" f1 "$dir/soft.yaml" "$dir/keep.yaml")" = "$("$chk" f1 "$dir/soft.yaml")" ] ||
  fail "an as-built file without bridge keys did not keep the design's bridge"
near "$("$chk" f1 "$dir/soft.yaml")" "$f1_design" 0.01 && fail "the soft design has the paper's f1"
cat > "$dir/seg.yaml" <<'EOF'
bridge:
  supports:
    - {at_m: 0, type: elastic, k_w_npm: 2.0e9}
    - {at_m: 20, type: elastic, k_w_npm: 2.0e9}
  segments:
    - {from_m: 0, to_m: 4, EI_nm2: 2.0e10, mass_kgpm: 3000}
    - {from_m: 16, to_m: 20, EI_nm2: 2.0e10, mass_kgpm: 3000}
EOF
f1_seg=$("$chk" f1 "$design" "$dir/seg.yaml") || fail "f1 of the segmented bridge"
near "$f1_seg" "$f1_design" 0.02 && fail "the segmented bridge has the design's f1"
"$sim" --config "$design" --as-built "$dir/seg.yaml" --calibration-runs "$dir/seg" \
  --runs-per-truck 1 2>/dev/null || fail "calibration runs on the segmented bridge exited $?"
for r in 2 3; do
  set -- $(sed -n ${r}p "$dir/seg/RUNS.truth.csv" | awk -F, '{
      n = split($6, s, ";"); L = 0; for (i = 1; i <= n; i++) L += s[i];
      printf "%s %.6f\n", $1, $5 + (20 + L) / $4 + 0.1 }')
  m=$("$chk" freq "$dir/seg/$1" 1 "$2" 2 15) || fail "seg/$1: no frequency"
  echo "seg/$1: free vibration at $m Hz (bridge f1 $f1_seg Hz)"
  near "$m" "$f1_seg" 0.005 || fail "seg/$1: $m Hz is not within 0.5 % of $f1_seg Hz"
done

# RUNS.csv holds what the detector said, RUNS.truth.csv what happened.
paste -d, "$dir/ab/RUNS.csv" "$dir/ab/RUNS.truth.csv" | tail -n +2 | awk -F, '
  function first(s) { split(s, a, ";"); return a[1] }
  { # runs: 1 file 2 speed 3 spacings 4 entry 5 kg; truth: 6 file 7 truck 8 model
    # 9 speed 10 entry 11 spacings 12 kg 13 forces 14 sensor_x
    if ($1 != $6) { print "row order: " $1 " " $6; bad = 1 }
    if (($4 - $10 - 0.010)^2 > 1e-12) { print $1 ": entry " $4 " vs true " $10; bad = 1 }
    if (($2 / $9 - 1.02)^2 > 1e-12) { print $1 ": speed " $2 " vs true " $9; bad = 1 }
    if ((first($3) / first($11) - 0.99)^2 > 1e-8) { print $1 ": spacing " $3 " vs " $11; bad = 1 }
    if ($5 != $12) { print $1 ": axle_kg " $5 " vs " $12; bad = 1 }
    if ($14 != "9.5000") { print $1 ": true sensor at " $14; bad = 1 }
    if ($10 != "0.500000") { print $1 ": true entry " $10; bad = 1 }
  } END { exit bad }' || fail "the detector's errors in RUNS.csv against the truth"
grep -q ',0.510000,' "$dir/ab/RUNS.csv" || fail "RUNS.csv: the 10 ms late entry"
cut -d, -f4,5 "$dir/ab/RUNS.truth.csv" | tail -n +2 | tr '\n' ' ' |
  grep -q '^15.000000,0.500000 25.000000,0.500000 15.000000,0.500000 25.000000,0.500000 $' ||
  fail "truth speeds and entries: $(cut -d, -f4,5 "$dir/ab/RUNS.truth.csv" | tr '\n' ' ')"
# the five-axle truck, the default second truck, front to back: its class
# model (A23), the tridem's static loads equalised (their sum kept)
sed -n 4p "$dir/ab/RUNS.truth.csv" | grep -q ',A23,.*,3.6000;5.5000;1.3000;1.3000,7000.0;11000.0;7333.3;7333.3;7333.3,' ||
  fail "default five-axle truck: $(sed -n 4p "$dir/ab/RUNS.truth.csv")"

# Weighed with the design model (amfi-solve, the detector's values): the
# design's runs within 2 %, the as-built runs' GVW off by more than 5 %.
for set in de ab; do
  tail -n +2 "$dir/$set/RUNS.csv" | while IFS=, read -r f v sp entry kg; do
    gvw=$(printf '%s\n' "$kg" | tr ';' '\n' | awk '{ s += $1 } END { print s }')
    out=$("$solve" --config "$design" --accel "$dir/$set/$f" \
            --vehicle "$entry:$v:$(printf '%s' "$sp" | tr ';' ',')") || fail "amfi-solve $set/$f"
    got=$(printf '%s' "$out" | sed 's/.*"gvw_kg":\([-0-9.e+]*\).*/\1/')
    echo "$set/$f: GVW $got kg, weighed $gvw kg"
    if [ $set = de ]; then near "$got" "$gvw" 0.02 || fail "$set/$f: design runs weighed off"
    elif near "$got" "$gvw" 0.05; then fail "$set/$f: the as-built bridge weighed like the design"; fi
  done || exit 1
done

# Without spacing_scale, the spacings (measured from the speed) scale alike.
printf 'detector: {speed_scale: 0.97}\n' > "$dir/slow.yaml"
"$sim" --config "$design" --as-built "$dir/slow.yaml" --calibration-runs "$dir/slow" \
  --runs-per-truck 1 --truck 4.0/6000,9000 --calibration-speeds 20,20 2>/dev/null ||
  fail "speed_scale alone exited $?"
sed -n 2p "$dir/slow/RUNS.csv" | grep -q '^run001.csv,19.400000,3.8800,0.500000,6000.0;9000.0$' ||
  fail "speed_scale 0.97 alone: $(sed -n 2p "$dir/slow/RUNS.csv")"

# Several sensors: the header names them by id, each sensor at its place.
cat > "$dir/two.yaml" <<'EOF'
sensors:
  - {id: 3, at_m: 10}
  - {id: 7, at_m: 5}
EOF
printf 'sensors:\n  - {id: 7, at_m: 6}\n' > "$dir/ab2.yaml"
"$sim" --config "$dir/two.yaml" --as-built "$dir/ab2.yaml" --calibration-runs "$dir/two" \
  --runs-per-truck 1 --truck 4.0/6000,9000 2>/dev/null || fail "two sensors exited $?"
head -1 "$dir/two/run001.csv" | grep -qx 't,accel_3,accel_7' ||
  fail "two sensors: header $(head -1 "$dir/two/run001.csv")"
sed -n 2p "$dir/two/RUNS.truth.csv" | grep -q ',10.0000;6.0000,' ||
  fail "two sensors: true positions $(sed -n 2p "$dir/two/RUNS.truth.csv")"
[ "$(wc -l < "$dir/two/RUNS.csv")" -eq 2 ] || fail "--truck did not replace the default trucks"

# The ambient record: the spectrum's peak at the as-built f1 (Welch, 10 s).
"$sim" --config "$design" --as-built "$dir/ab.yaml" --ambient-out "$dir/amb.csv" \
  --ambient-duration 120 2>/dev/null || fail "ambient exited $?"
[ "$(wc -l < "$dir/amb.csv")" -eq 120001 ] || fail "ambient: $(wc -l < "$dir/amb.csv") lines"
m=$("$chk" welch "$dir/amb.csv" 1 10 2 15) || fail "ambient: no frequency"
echo "ambient: peak at $m Hz (as built $f1_ab Hz)"
near "$m" "$f1_ab" 0.03 || fail "ambient: $m Hz is not within 3 % of $f1_ab Hz"

# --out with the as-built file: the detector's values in meta.csv's first
# columns, the truth appended; vNNNNN.csv from the as-built bridge.
"$sim" --config "$design" --out "$dir/o_ab" --vehicles 2 --as-built "$dir/ab.yaml" ||
  fail "--out --as-built exited $?"
for c in entry_time_true_s axle_spacing_true_m sensor_x_true_m; do
  head -1 "$dir/o_ab/meta.csv" | tr ',' '\n' | grep -qx $c || fail "meta.csv with --as-built: no $c"
done
# columns by name (other columns may come and go)
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  function v(n) { return $(c[n]) }
  {
    if ((v("speed_mps") / v("speed_true_mps") - 1.02)^2 > 1e-12) { print "speed " v("speed_mps"); bad = 1 }
    if ((v("entry_time_s") - v("entry_time_true_s") - 0.010)^2 > 1e-12) { print "entry " v("entry_time_s"); bad = 1 }
    if ((v("axle_spacing_m") / v("axle_spacing_true_m") - 0.99)^2 > 1e-12) { print "spacing " v("axle_spacing_m"); bad = 1 }
    if (v("sensor_x_m") != 10 || v("sensor_x_true_m") != 9.5) { print "sensor " v("sensor_x_m"); bad = 1 }
  } END { exit bad || NR != 3 }' "$dir/o_ab/meta.csv" || fail "meta.csv: the detector against the truth"

# The stream: vehicle_t late and fast, truth_t true.
"$sim" --config "$design" --as-built "$dir/ab.yaml" --lcm-url none --log "$dir/s.log" \
  --speedup max --vehicles 3 2>/dev/null || fail "streaming with --as-built exited $?"
"$chk" log "$dir/s.log" > "$dir/s.txt" || fail "reading the log"
awk '$1 == "V" { u[$2] = $3; v[$2] = $4 } $1 == "T" { n++
      if (u[$2] - $3 != 10000) { print "vehicle " $2 ": utime " u[$2] " truth " $3; bad = 1 }
      if ((v[$2] / $4 - 1.02)^2 > 1e-12) { print "vehicle " $2 ": speed " v[$2] " truth " $4; bad = 1 } }
     END { exit bad || n != 3 }' "$dir/s.txt" || fail "vehicle_t against truth_t: $(cat "$dir/s.txt")"

# Bad as-built files: one line naming FILE:LINE (status 1).
bad() { # name, expected message part, file body
  printf '%s\n' "$3" > "$dir/$1.yaml"
  msg=$("$sim" --config "$design" --as-built "$dir/$1.yaml" --calibration-runs "$dir/x" 2>&1 >/dev/null)
  rc=$?
  [ $rc -eq 1 ] || fail "$1: exit $rc, not 1 ($msg)"
  printf '%s\n' "$msg" | grep -qF "$dir/$1.yaml:$2" || fail "$1: message '$msg', wanted '$2'"
  [ -e "$dir/x" ] && fail "$1: wrote $dir/x"
  echo "refused: $msg"
}
bad unknown "2: bridge.E: unknown key" 'bridge:
  E: 3e10'
bad top "1: solver: unknown key" 'solver: {calc_rate_hz: 1000}'
bad id "4: sensors[1].id: the design has no sensor with id 4" 'sensors:
  - id: 0
    offset_m: 1
  - {id: 4, at_m: 3}' 
bad both "2: sensors[0]: give exactly one of at_m" 'sensors:
  - {id: 0, at_m: 9, offset_m: 1}'
bad off_span "2: sensors[id 0]: at 25 m, off the as-built span" 'sensors:
  - {id: 0, offset_m: 15}'
bad clock "2: detector.clock_offset_s: must be in [-1, 1]" 'detector:
  clock_offset_s: 1.5'
bad scale "3: detector.speed_scale: must be in [0.5, 2]" 'detector:
  clock_offset_s: 0.01
  speed_scale: 0.4'
bad elastic "3: bridge.supports[0]: an elastic support needs k_w_npm" 'bridge:
  supports:
    - {at_m: 0, type: elastic}
    - {at_m: 20, type: roller}'
bad mechanism "2: bridge.supports: a single support without a held or sprung rotation" 'bridge:
  supports:
    - {at_m: 0, type: elastic, k_w_npm: 1e8}'
bad number "2: bridge.E_pa" 'bridge:
  E_pa: ten'
bad syntax "2: YAML syntax error" 'bridge: {E_pa: 3e10
detector: ]'
"$sim" --config "$design" --as-built "$dir/none.yaml" --out "$dir/x" 2>/dev/null
[ $? -eq 1 ] || fail "a missing as-built file not refused"

# Bad truck specs and modes on the command line: status 2.
for t in 5.0/7000 5/7000,0 5,0/1,2,3 x/1,2 5.0,3/7000,9000; do
  "$sim" --calibration-runs "$dir/x" --truck "$t" 2>/dev/null; [ $? -eq 2 ] || fail "--truck $t not refused"
done
"$sim" --out "$dir/x" --calibration-runs "$dir/y" 2>/dev/null; [ $? -eq 2 ] || fail "--out with --calibration-runs not refused"
"$sim" --calibration-runs "$dir/x" --calibration-speeds 25,15 2>/dev/null; [ $? -eq 2 ] || fail "speeds HI < LO not refused"

# An as-built file equal to the design: the same values as without it.
printf 'detector: {clock_offset_s: 0}\nsensors: [{id: 0, offset_m: 0}]\n' > "$dir/same.yaml"
"$sim" --config "$design" --calibration-runs "$dir/same" --runs-per-truck 2 --as-built "$dir/same.yaml" 2>/dev/null ||
  fail "identity as-built exited $?"
for f in RUNS.csv RUNS.truth.csv run001.csv run002.csv run003.csv run004.csv; do
  same "$dir/de/$f" "$dir/same/$f" || fail "an as-built equal to the design changed $f"
done
"$sim" --config "$design" --out "$dir/o_de" --vehicles 2 || fail "--out exited $?"
"$sim" --config "$design" --out "$dir/o_same" --vehicles 2 --as-built "$dir/same.yaml" || fail "--out same exited $?"
for f in v00001.csv v00002.csv; do
  same "$dir/o_de/$f" "$dir/o_same/$f" || fail "an as-built equal to the design changed $f"
done
# meta.csv without the as-built file's truth columns
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) drop[i] = $i ~ /^(entry_time_true_s|axle_spacing_true_m|sensor_x_true_m)$/ }
  { out = ""; for (i = 1; i <= NF; i++) if (!drop[i]) out = out (out == "" ? "" : ",") $i; print out }' \
  "$dir/o_same/meta.csv" > "$dir/o_same/meta-design.csv"
same "$dir/o_same/meta-design.csv" "$dir/o_de/meta.csv" ||
  fail "an as-built equal to the design changed meta.csv's columns"
same "$dir/o_de/v00001.csv" "$dir/o_ab/v00001.csv" && fail "the as-built bridge gave the design's record"
echo "sim_publisher --as-built: ok"
