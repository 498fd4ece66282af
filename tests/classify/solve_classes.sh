#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# solve_classes.sh: amfi-solve's class and axle groups on a simulated
# five-axle A23 (tractor and tridem semi-trailer, 38.5 t, 25 m/s; sim_publisher
# with its coupled vehicle model on a class A road, no noise, amfi-solve
# given every spacing): class A23, groups [0], [1], [2,3,4] with the
# tridem's load within 7 % of its static truth (COST 323 B+(7), a group of
# axles; measured +3.3 %), the limits of 96/53/EC (40 t, 24 t tridem), the
# same through --vehicle; the passage 25 times as strong refused for the
# limits (a 150 t steer axle is no overload); the FHWA scheme from the site file
# (FHWA9); a bad classes: section refused with FILE:LINE.
#   solve_classes.sh SIM_PUBLISHER AMFI_SOLVE CONFIG_DIR
set -u
sim=${1:?usage: solve_classes.sh SIM_PUBLISHER AMFI_SOLVE CONFIG_DIR}
solve=${2:?usage}
confdir=${3:?usage}
work=$(mktemp -d "${TMPDIR:-/tmp}/solve_classes.XXXXXX") || exit 1
trap 'rm -rf "$work"' EXIT INT TERM
fail() { echo "FAIL: $*"; exit 1; }

printf '%s\n' 'timestamp_s,lane,speed_mps,class,gvw_kg,n_axles,axle_kg,spacings_m' \
  '5.0,1,25.0,A23,38500,5,6200;10700;7200;7200;7200,3.75;5.67;1.31;1.31' >"$work/pop.csv"
"$sim" --population "$work/pop.csv" --out "$work/out" --vehicles 1 --first 0 --profile A \
  --dt 2.5e-4 2>"$work/sim.err" || { cat "$work/sim.err"; fail "sim_publisher --out"; }
meta=$(tail -n 1 "$work/out/meta.csv")
entry=$(printf '%s' "$meta" | cut -d, -f5)
kgs=$(printf '%s' "$meta" | cut -d, -f21)
truth=$(printf '%s' "$kgs" | awk -F';' '{ printf "%.3f", $3 + $4 + $5 }')
cfg="--config $confdir/paper-20m.yaml"

# shellcheck disable=SC2086
out=$("$solve" $cfg --accel "$work/out/v00001.csv" --speed 25 --axle-spacing 3.75,5.67,1.31,1.31 \
      --entry-time "$entry") || fail "amfi-solve exited $?"
echo "$out"
printf '%s' "$out" | grep -q '"class":"A23"' || fail "class is not A23"
groups=$(printf '%s' "$out" | grep -o '"axles":\[[0-9,]*\]' | tr '\n' ' ')
[ "$groups" = '"axles":[0] "axles":[1] "axles":[2,3,4] ' ] || fail "groups: $groups"
# every existing field still there, before the new ones
printf '%s' "$out" | grep -q '^{"gvw_kg":[-0-9.e+]*,"axle_kg":\[' || fail "gvw_kg, axle_kg first"
printf '%s' "$out" | grep -q '"sensor_ids":\[0\],"class":"A23","groups":' || fail "field order"
tridem=$(printf '%s' "$out" | sed 's/.*"axles":\[2,3,4\],"load_kg":\([-0-9.e+]*\).*/\1/')
awk -v g="$tridem" -v t="$truth" 'BEGIN { e = (g - t) / t;
  printf "tridem: truth %.0f kg, inferred %.0f kg (%+.2f %%)\n", t, g, 100 * e;
  exit (e > 0.07 || e < -0.07) }' || fail "tridem load error above 7 %"
printf '%s' "$out" | grep -q '"kind":"tridem","limit_kg":24000.0}' || fail "tridem limit"
printf '%s' "$out" | grep -q '"gvw_limit_kg":40000.0,"overload":false' || fail "GVW limit"

# the same vehicle through --vehicle: its class and groups in its object
# shellcheck disable=SC2086
outv=$("$solve" $cfg --accel "$work/out/v00001.csv" --vehicle "$entry:25:3.75,5.67,1.31,1.31") ||
  fail "amfi-solve --vehicle exited $?"
printf '%s' "$outv" | grep -q '"vehicles":\[{.*"class":"A23","groups":\[{"axles":\[0\]' ||
  { echo "$outv"; fail "--vehicle: no class A23 with its groups"; }

# the FHWA scheme from the site file
{ cat "$confdir/paper-20m.yaml"; printf 'classes:\n  scheme: fhwa13\n'; } >"$work/fhwa.yaml"
outf=$("$solve" --config "$work/fhwa.yaml" --accel "$work/out/v00001.csv" --speed 25 \
       --axle-spacing 3.75,5.67,1.31,1.31 --entry-time "$entry") || fail "fhwa13: exit $?"
printf '%s' "$outf" | grep -q '"class":"FHWA9"' || fail "fhwa13: not FHWA9"

# the same passage 25 times as strong: a 150 t steer axle (and a 540 t
# tridem) is no overload but a load no vehicle carries (over 10 x the
# largest legal single axle, 11.5 t): the loads refused with the first such
# axle or group named, the class and groups still given, exit 0 and one
# line on stderr
awk -F, 'NR == 1 { print; next } { printf "%s,%.9g\n", $1, 25 * $2 }' "$work/out/v00001.csv" \
  >"$work/strong.csv" || fail "strong.csv"
# shellcheck disable=SC2086
outs=$("$solve" $cfg --accel "$work/strong.csv" --speed 25 --axle-spacing 3.75,5.67,1.31,1.31 \
       --entry-time "$entry" 2>"$work/strong.err") || fail "implausible loads: exit $?"
printf '%s' "$outs" | grep -q '"class":"A23".*"overload":null,.*"loads_refused":"single axle 1: load [0-9]* kg, over 10 x any legal load of 1 axle (11500 kg)"' ||
  { echo "$outs"; fail "implausible loads: not refused"; }
[ "$(wc -l <"$work/strong.err")" -eq 1 ] && grep -q "loads refused for the limits: single axle 1: " "$work/strong.err" ||
  { cat "$work/strong.err"; fail "implausible loads: stderr"; }

# a bad classes: section: refused at its line
{ cat "$confdir/paper-20m.yaml"; printf 'classes:\n  group_spacing_m: 4\n'; } >"$work/bad.yaml"
line=$(($(wc -l <"$work/bad.yaml")))
"$solve" --config "$work/bad.yaml" --accel "$work/out/v00001.csv" --speed 25 \
  --axle-spacing 3.75,5.67,1.31,1.31 --entry-time "$entry" >"$work/bad.out" 2>"$work/bad.err"
rc=$?
[ "$rc" -eq 1 ] || fail "bad classes: exit $rc, want 1"
grep -q "$work/bad.yaml:$line: classes.group_spacing_m: " "$work/bad.err" ||
  { cat "$work/bad.err"; fail "bad classes: no FILE:LINE"; }
echo "ok"
