#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# solve_multi.sh: amfi-solve --vehicle (several vehicles solved jointly).
# Two two-axle vehicles at 25 m/s, the second entering 0.5 s after the first
# (12.5 m behind), are the same axle trajectories as one four-axle vehicle
# with spacings 5, 7.5, 4: amfi-mkcase writes that case, and the joint solve
# (an event of two vehicles: weighed at λ/10, AMFI_MULTI_QUALITY_LAMBDA)
# must give the one-vehicle solve's numbers at λ/10 (every key before the timing: the
# same text, the same numbers to 1e-9 relative: the printed 10 digits may
# differ in the last one where the two paths' axle positions differ by
# round-off; a solve this ill-conditioned amplifies that, LAPACK's
# factorisation choosing its pivots by it), plus each vehicle's GVW
# (truth 18000 and 15000 kg) within 1 % and a quality figure and a
# separability >= 1, in the
# order the vehicles were given.
#
# usage: solve_multi.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR
set -u
solve=${1:?usage: solve_multi.sh AMFI_SOLVE AMFI_MKCASE CONFIG_DIR}
mkcase=${2:?usage}
confdir=${3:?usage}
tmp=$(mktemp -d "${TMPDIR:-/tmp}/solve_multi.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
fail() { echo "FAIL: $*"; exit 1; }
config="--config $confdir/paper-20m.yaml"
[ -f "$confdir/paper-20m.yaml" ] || fail "$confdir/paper-20m.yaml missing"

# shellcheck disable=SC2086
"$mkcase" $config --out "$tmp/two.csv" --speed 25 --axle-loads-kg 10400,7600,9000,6000 \
    --axle-spacing 5,7.5,4 --pre 0.5 --post 0.5 --scan-rate 1000 > "$tmp/truth" ||
    fail "amfi-mkcase: exit $?"
lambda=$(sed -n 's/^  lambda: \([0-9.eE+-]*\) .*/\1/p' "$confdir/paper-20m.yaml")
[ -n "$lambda" ] || fail "no fixed solver.lambda in $confdir/paper-20m.yaml"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/two.csv" --speed 25 --axle-spacing 5,7.5,4 \
    --entry-time 0.5 --lambda "$(awk -v l="$lambda" 'BEGIN { printf "%.17g", l / 10 }')" \
    > "$tmp/one.json" || fail "one-vehicle solve: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/two.csv" --vehicle 0.5:25:5 --vehicle 1.0:25:4 \
    > "$tmp/joint.json" || fail "joint solve: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/two.csv" --vehicle 1.0:25:4 --vehicle 0.5:25:5 \
    > "$tmp/reversed.json" || fail "reversed joint solve: exit $?"
echo "one:      $(cat "$tmp/one.json")"
echo "joint:    $(cat "$tmp/joint.json")"
echo "reversed: $(cat "$tmp/reversed.json")"

# the keys before solve_ms (the timing): the same text between the numbers,
# the same numbers to 1e-9 relative
head_of() { sed 's/,"solve_ms".*//' "$1" | tr ',:[]{}' '\n\n\n\n\n\n'; }
head_of "$tmp/one.json" > "$tmp/one.tok"
head_of "$tmp/joint.json" > "$tmp/joint.tok"
[ "$(wc -l < "$tmp/one.tok")" = "$(wc -l < "$tmp/joint.tok")" ] ||
    fail "the joint solve's keys differ from the one-vehicle solve's"
paste -d ' ' "$tmp/one.tok" "$tmp/joint.tok" | awk '
    function num(s) { return s ~ /^-?[0-9.]+([eE][-+]?[0-9]+)?$/ }
    {
        if ($1 == $2) next
        if (num($1) && num($2)) {
            d = $1 - $2; if (d < 0) d = -d
            m = $1 < 0 ? -$1 : $1
            if (d <= 1e-9 * m) next
        }
        printf "one-vehicle %s, joint %s\n", $1, $2; bad = 1
    }
    END { exit bad }' ||
    fail "the joint solve differs from the one-vehicle solve of the same axles"

# "vehicles":[{"gvw_kg":G,...,"quality":Q,...,"separability":S,...},{...}] -> "G Q S" per line
# (the keys after separability, the class and its groups, are not read)
vehicles() {
    sed 's/.*"vehicles":\[//' "$1" | tr '}' '\n' |
        sed -n 's/.*"gvw_kg":\([^,]*\),.*"quality":\([^,]*\),.*"separability":\([^,]*\).*/\1 \2 \3/p'
}
check() { # FILE TRUTH1 TRUTH2
    vehicles "$1" | awk -v t1="$2" -v t2="$3" '
        { n++; g[n] = $1; q[n] = $2; sp[n] = $3 }
        END {
            if (n != 2) { print "expected 2 vehicles, got " n; exit 1 }
            t[1] = t1; t[2] = t2
            for (i = 1; i <= 2; i++) {
                e = g[i] / t[i] - 1
                if (e < -0.01 || e > 0.01) { printf "vehicle %d: GVW %g vs %g\n", i, g[i], t[i]; exit 1 }
                if (!(q[i] >= 1)) { printf "vehicle %d: quality %s < 1\n", i, q[i]; exit 1 }
                if (!(sp[i] >= 1)) { printf "vehicle %d: separability %s < 1\n", i, sp[i]; exit 1 }
            }
        }' || fail "$1"
}
check "$tmp/joint.json" 18000 15000
check "$tmp/reversed.json" 15000 18000

# Side by side: a two-axle truck's passage declared as two vehicles at one
# entry time, speed and spacing (two lanes, the beam has no width): every
# axle coincides with the other vehicle's, so the axles are merged, both
# vehicles are one group (quality 1e6) whose weight is the one-vehicle
# solve's, at the same λ (once a numerical failure, or a solve at 10 λ,
# depending on the BLAS kernel).
"$mkcase" $config --out "$tmp/truck.csv" --speed 25 --axle-loads-kg 10400,7600 \
    --axle-spacing 5 --pre 0.5 --post 0.5 --scan-rate 1000 > /dev/null || fail "amfi-mkcase: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/truck.csv" --speed 25 --axle-spacing 5 --entry-time 0.5 \
    > "$tmp/truck.json" || fail "truck alone: exit $?"
# shellcheck disable=SC2086
"$solve" $config --accel "$tmp/truck.csv" --vehicle 0.5:25:5 --vehicle 0.5:25:5 \
    > "$tmp/pair.json" || fail "side by side: exit $?"
echo "side by side: $(sed 's/.*"vehicles"/"vehicles"/' "$tmp/pair.json")"
lam1=$(sed 's/.*"lambda_ref":\([^,]*\),.*/\1/' "$tmp/truck.json")
lam2=$(sed 's/.*"lambda_ref":\([^,]*\),.*/\1/' "$tmp/pair.json")
[ "$lam1" = "$lam2" ] || fail "side by side solved at λ $lam2, alone at $lam1"
g1=$(sed 's/^{"gvw_kg":\([^,]*\),.*/\1/' "$tmp/truck.json")
sed 's/.*"vehicles":\[//' "$tmp/pair.json" | tr '}' '\n' | awk -v g1="$g1" '
    /"gvw_kg"/ {
        n++
        if ($0 !~ /"quality":1000000\.0,/ || $0 !~ /"group":0,/ || $0 !~ /"n_merged":2,/) {
            print "vehicle " n " not marked as a group of merged axles: " $0; bad = 1
        }
        s = $0; sub(/.*"group_gvw_kg":/, "", s); g = s + 0
        d = g / g1 - 1; if (d < 0) d = -d
        if (d > 1e-6) { printf "vehicle %d: the group weighs %s, the truck alone %s\n", n, g, g1; bad = 1 }
    }
    END { if (n != 2) { print "expected 2 vehicles, got " n; bad = 1 }; exit bad }' ||
    fail "side by side"
echo "solve_multi: ok"
