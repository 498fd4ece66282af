#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# solve_sensors.sh: amfi-solve on a site of several sensors. The shipped
# paper-20m.yaml with three sensors (ids 3, 7, 12 at 10, 5 and 15 m);
# amfi-mkcase writes their passage as 't,accel_3,accel_7,accel_12' (2 %
# noise). amfi-solve must use all three, each column by its sensor's id:
# GVW within 2 % of the truth (measured -0.65 %), "sensor_ids" [3,7,12],
# the same numbers with the columns in another order. It must refuse
# (exit 1, one line naming them) a file without a column for a site
# sensor, a column of no site sensor, a repeated column, and the one-sensor
# format 't,accel' for this site (before, it solved with the first sensor
# alone and exited 0). A site of one sensor still takes 't,accel', and
# 't,accel_0' gives the same numbers.
#
# usage: solve_sensors.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR
set -u
solve=${1:?usage: solve_sensors.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR}
mkcase=${2:?usage}
confdir=${3:?usage}
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/solve_sensors.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
fail() { echo "FAIL: $*"; exit 1; }
[ -f "$confdir/paper-20m.yaml" ] || fail "$confdir/paper-20m.yaml missing"
site=$tmp/three.yaml
sed '/^sensors:/,/^$/c\
sensors:\
  - {id: 3, at_m: 10, weight: 1}\
  - {id: 7, at_m: 5, weight: 1}\
  - {id: 12, at_m: 15, weight: 1}\
' "$confdir/paper-20m.yaml" > "$site"
[ "$(grep -c '^  - {id: ' "$site")" -eq 3 ] || fail "could not give $site three sensors"
pass="--speed 25 --axle-spacing 5 --entry-time 0.5"

"$mkcase" --config "$site" --out "$tmp/three.csv" --speed 25 --axle-loads-kg 10400,7600 \
    --axle-spacing 5 --noise 0.02 --seed 3 > "$tmp/truth" || fail "amfi-mkcase: exit $?"
[ "$(head -1 "$tmp/three.csv")" = "t,accel_3,accel_7,accel_12" ] ||
    fail "amfi-mkcase's header: $(head -1 "$tmp/three.csv")"
truth=$(sed 's/.*"gvw_kg":\([^,}]*\).*/\1/' "$tmp/truth")

# shellcheck disable=SC2086
"$solve" --config "$site" --accel "$tmp/three.csv" $pass > "$tmp/three.json" ||
    fail "three sensors: exit $?"
echo "three sensors: $(cat "$tmp/three.json")"
grep -q '"sensor_ids":\[3,7,12\]' "$tmp/three.json" || fail "sensor_ids is not [3,7,12]"
gvw=$(sed 's/^{"gvw_kg":\([^,]*\),.*/\1/' "$tmp/three.json")
awk -v g="$gvw" -v t="$truth" 'BEGIN { e = g / t - 1; printf "GVW %s kg, truth %s kg: %+.2f %%\n", g, t, 100 * e
    exit !(e > -0.02 && e < 0.02) }' || fail "three sensors: GVW off by more than 2 %"

# the columns in another order: the same solve (the numbers before the timing)
awk -F, 'BEGIN { OFS = "," } { print $1, $4, $2, $3 }' "$tmp/three.csv" > "$tmp/perm.csv"
# shellcheck disable=SC2086
"$solve" --config "$site" --accel "$tmp/perm.csv" $pass > "$tmp/perm.json" ||
    fail "columns reordered: exit $?"
before_timing() { sed 's/,"solve_ms".*//' "$1" > "$1.head"; }
before_timing "$tmp/three.json"
before_timing "$tmp/perm.json"
sh "$here/../common/num_cmp.sh" "$tmp/three.json.head" "$tmp/perm.json.head" ||
    fail "the columns' order changed the solve"

# refused, exit 1, one line on stderr naming what is wrong
refused() { # NAME FILE TEXT...: the solve of FILE on the three-sensor site
    name=$1 file=$2
    shift 2
    # shellcheck disable=SC2086
    "$solve" --config "$site" --accel "$file" $pass > "$tmp/out" 2> "$tmp/err"
    rc=$?
    echo "$name: exit $rc: $(cat "$tmp/err")"
    [ "$rc" -eq 1 ] || fail "$name: exit $rc, expected 1"
    [ -s "$tmp/out" ] && fail "$name: printed a result"
    [ "$(wc -l < "$tmp/err")" -eq 1 ] || fail "$name: stderr is not one line"
    for text in "$@"; do
        grep -qF -- "$text" "$tmp/err" || fail "$name: stderr does not say '$text'"
    done
}
cut -d, -f1,2 "$tmp/three.csv" | sed '1s/.*/t,accel/' > "$tmp/one.csv"
refused "one column for three sensors" "$tmp/one.csv" "$tmp/one.csv:1:" "3 sensors (ids 3, 7, 12)"
cut -d, -f1,2,4 "$tmp/three.csv" > "$tmp/no7.csv"
refused "sensor 7 missing" "$tmp/no7.csv" "$tmp/no7.csv:1:" "no column for sensor(s) 7"
cut -d, -f1,2 "$tmp/three.csv" > "$tmp/only3.csv"
refused "sensors 7 and 12 missing" "$tmp/only3.csv" "no column for sensor(s) 7, 12"
sed '1s/accel_7/accel_9/' "$tmp/three.csv" > "$tmp/unknown.csv"
refused "unknown column" "$tmp/unknown.csv" "no column for sensor(s) 7" \
    "column(s) of no sensor of the site: accel_9"
sed '1s/accel_7/accel_3/' "$tmp/three.csv" > "$tmp/dup.csv"
refused "repeated column" "$tmp/dup.csv" "$tmp/dup.csv:1:" "column 3 repeats sensor 3 (column 2)"

# a site of one sensor (id 0): 't,accel' as before, 't,accel_0' the same
"$mkcase" --config "$confdir/paper-20m.yaml" --out "$tmp/single.csv" --speed 25 \
    --axle-loads-kg 10400,7600 --axle-spacing 5 --noise 0.02 --seed 3 > /dev/null ||
    fail "amfi-mkcase, one sensor: exit $?"
[ "$(head -1 "$tmp/single.csv")" = "t,accel" ] || fail "one sensor: header $(head -1 "$tmp/single.csv")"
sed '1s/.*/t,accel_0/' "$tmp/single.csv" > "$tmp/single0.csv"
for f in single single0; do
    # shellcheck disable=SC2086
    "$solve" --config "$confdir/paper-20m.yaml" --accel "$tmp/$f.csv" $pass > "$tmp/$f.json" ||
        fail "one sensor, $f.csv: exit $?"
    grep -q '"sensor_ids":\[0\]' "$tmp/$f.json" || fail "$f: sensor_ids is not [0]"
    before_timing "$tmp/$f.json"
done
sh "$here/../common/num_cmp.sh" "$tmp/single.json.head" "$tmp/single0.json.head" ||
    fail "'t,accel_0' and 't,accel' differ on a one-sensor site"
echo "solve_sensors: ok"
