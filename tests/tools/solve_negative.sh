#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# solve_negative.sh: amfi-solve when the solve gives an axle below zero.
# amfi-mkcase writes two noisy passages (seeded) with a nearly unloaded
# axle (1 kg), whose solved load comes out below zero:
#  1. an A23 (5 axles, the tridem's middle axle 1 kg): the axle inside the
#     tridem is not separable, its group's sum is what is classified and
#     judged, so the result is printed (exit 0, nothing on stderr) with the
#     class, axle_separable false for the tridem's axles, overload decided
#     (true: the truth's 41 t gross weight is above the A23's 40 t) and
#     loads_refused null;
#  2. a two-axle vehicle (second axle 1 kg, a single axle): printed too
#     (exit 0) with its class and groups, overload null, loads_refused
#     naming the axle, and that reason once on stderr (no "stdout: ...").
#
# usage: solve_negative.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR
set -u
solve=${1:?usage: solve_negative.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR}
mkcase=${2:?usage}
confdir=${3:?usage}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/solve_negative.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
fail() { echo "FAIL: $*"; exit 1; }
config="--config $confdir/paper-20m.yaml"
[ -f "$confdir/paper-20m.yaml" ] || fail "$confdir/paper-20m.yaml missing"
# axle N's (1-based) load from the JSON's axle_kg
axle() { sed 's/.*"axle_kg":\[\([^]]*\)\].*/\1/' "$1" | cut -d, -f"$2"; }

# 1. a negative axle inside the tridem
# shellcheck disable=SC2086
"$mkcase" $config --out "$tmp/a23.csv" --speed 25 --axle-loads-kg 7000,10000,12000,1,12000 \
    --axle-spacing 3.6,5.5,1.3,1.3 --noise 0.1 --seed 4 > /dev/null || fail "amfi-mkcase: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/a23.csv" --speed 25 --axle-spacing 3.6,5.5,1.3,1.3 \
    --entry-time 0.5 > "$tmp/a23.json" 2> "$tmp/a23.err"
rc=$?
echo "A23: exit $rc: $(cat "$tmp/a23.json")"
cat "$tmp/a23.err"
[ "$rc" = 0 ] || fail "A23 with a negative axle in its tridem: exit $rc"
[ -s "$tmp/a23.err" ] && fail "A23: stderr not empty"
a4=$(axle "$tmp/a23.json" 4)
awk -v a="$a4" 'BEGIN { exit !(a < 0) }' ||
    fail "the case no longer gives a negative axle 4 ($a4 kg): it tests nothing"
for want in '"class":"A23"' '"kind":"tridem"' '"overload":true' \
    '"axle_separable":[true,true,false,false,false]' '"loads_refused":null'; do
    grep -qF "$want" "$tmp/a23.json" || fail "A23: no $want"
done

# 2. a negative single axle
# shellcheck disable=SC2086
"$mkcase" $config --out "$tmp/r2.csv" --speed 25 --axle-loads-kg 9000,1 \
    --axle-spacing 4.5 --noise 0.15 --seed 2 > /dev/null || fail "amfi-mkcase: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/r2.csv" --speed 25 --axle-spacing 4.5 \
    --entry-time 0.5 > "$tmp/r2.json" 2> "$tmp/r2.err"
rc=$?
echo "R2: exit $rc: $(cat "$tmp/r2.json")"
cat "$tmp/r2.err"
[ "$rc" = 0 ] || fail "a negative single axle: exit $rc"
a2=$(axle "$tmp/r2.json" 2)
awk -v a="$a2" 'BEGIN { exit !(a < 0) }' ||
    fail "the case no longer gives a negative axle 2 ($a2 kg): it tests nothing"
for want in '"class":"R2"' '"overload":null' '"loads_refused":"axle 2: load ' \
    '"axle_separable":[true,true]'; do
    grep -qF "$want" "$tmp/r2.json" || fail "R2: no $want"
done
[ "$(wc -l < "$tmp/r2.err")" = 1 ] || fail "R2: not one line on stderr"
grep -q 'axle 2: load .* (a single axle)' "$tmp/r2.err" || fail "R2: stderr does not name the axle"
grep -q 'stdout' "$tmp/r2.err" && fail "R2: a bogus stdout error"
echo "a negative axle in a tridem judged by its group; a negative single axle refused, named: ok"
