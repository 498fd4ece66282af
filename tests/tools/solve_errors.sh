#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# solve_errors.sh: amfi-solve on bad input. Every case must fail cleanly:
# exit status 1 (data) or 2 (usage), never a crash (status >= 128), exactly
# one line on stderr, naming the file and line or the option at fault.
#
# usage: solve_errors.sh PATH/TO/amfi-solve CONFIG_DIR
set -u

bin=${1:?usage: solve_errors.sh AMFI_SOLVE CONFIG_DIR}
confdir=${2:?usage: solve_errors.sh AMFI_SOLVE CONFIG_DIR}
[ -x "$bin" ] || { echo "solve_errors.sh: $bin: not executable" >&2; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/solve_errors.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

# the shipped configuration when it is there, else amfi-solve's defaults
config=
if [ -f "$confdir/paper-20m.yaml" ]; then
    config="--config $confdir/paper-20m.yaml"
fi

failures=0
cases=0

# csv NAME ROWS [BADLINE TEXT]: "t,accel" and ROWS rows at 1000 Hz, accel 0;
# line BADLINE (the header is line 1) replaced by TEXT
csv() {
    awk -v rows="$2" -v bad="${3:-0}" -v text="${4:-}" 'BEGIN {
        print "t,accel"
        for (k = 0; k < rows; k++) {
            if (k + 2 == bad) print text
            else printf "%.3f,0\n", k / 1000
        }
    }' > "$tmp/$1"
    echo "$tmp/$1"
}

# run NAME WANT_STATUS PATTERN ARGS...: PATTERN is a grep -E pattern that the
# single stderr line must match
run() {
    name=$1 want=$2 pattern=$3
    shift 3
    cases=$((cases + 1))
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    lines=$(wc -l < "$tmp/err")
    problem=
    if [ "$rc" -ge 128 ]; then
        problem="crashed (status $rc)"
    elif [ "$rc" -eq 0 ]; then
        problem="accepted (status 0)"
    elif [ "$rc" -ne "$want" ]; then
        problem="status $rc, expected $want"
    elif [ "$lines" -ne 1 ] || [ "$(wc -c < "$tmp/err")" -lt 2 ]; then
        problem="stderr has $lines lines, expected exactly 1"
    elif ! grep -Eq -- "$pattern" "$tmp/err"; then
        problem="stderr does not match '$pattern'"
    elif [ -s "$tmp/out" ]; then
        problem="wrote to stdout on error"
    fi
    if [ -n "$problem" ]; then
        failures=$((failures + 1))
        echo "FAIL $name: $problem"
        sed 's/^/    stderr: /' "$tmp/err"
    else
        echo "ok   $name: $(cat "$tmp/err")"
    fi
}

# the usual arguments around a file
solve() {
    # shellcheck disable=SC2086
    run "$1" "$2" "$3" $config --accel "$4" --speed 25 --axle-spacing 4
}

f=$(csv missing_column.csv 40 5 "0.003"); solve missing_column 1 "^$f:5: .*missing column" "$f"
f=$(csv extra_column.csv 40 5 "0.003,0,1"); solve extra_column 1 "^$f:5: .*extra column" "$f"
f=$(csv text.csv 40 7 "0.005,abc"); solve non_numeric 1 "^$f:7: .*not a number" "$f"
f=$(csv garbage.csv 40 7 "0.005,1.5e"); solve trailing_garbage 1 "^$f:7: .*not a number" "$f"
f=$(csv nan.csv 40 8 "0.006,nan"); solve nan 1 "^$f:8: .*NaN" "$f"
f=$(csv inf.csv 40 8 "0.006,inf"); solve inf 1 "^$f:8: .*infinite" "$f"
f=$(csv decreasing.csv 40 9 "0.001,0"); solve non_increasing 1 "^$f:9: .*not increasing" "$f"
f=$(csv nonuniform.csv 40 9 "0.0075,0"); solve non_uniform 1 "^$f:9: .*non-uniform" "$f"
f=$(csv few.csv 10); solve too_few_samples 1 "^$f:11: .*too few samples" "$f"

# valid file, but 0.5 s cannot hold (20 m + 4 m) / 25 m/s = 0.96 s
f=$(csv short.csv 501); solve not_covered 1 "^$f: passage not covered: the data spans \[.*\] s but the window needs \[.*\] s$" "$f"

good=$(csv good.csv 2000)
for s in 0 -3 500 nan abc; do
    # shellcheck disable=SC2086
    run "speed_$s" 2 "--speed" $config --accel "$good" --speed "$s" --axle-spacing 4
done
for s in 0 -2 4,0 4,-1 31 4,x 4,,3; do
    # shellcheck disable=SC2086
    run "spacing_$s" 2 "--axle-spacing" $config --accel "$good" --speed 25 --axle-spacing "$s"
done

# random bytes named .gz; a real .gz cut in half; a gzip header and junk
f="$tmp/random.csv.gz"
head -c 4096 /dev/urandom > "$f"
solve gzip_random 1 "^$f:[0-9]+: " "$f"
csv big.csv 20000 > /dev/null
gzip -c "$tmp/big.csv" > "$tmp/whole.csv.gz"
size=$(wc -c < "$tmp/whole.csv.gz")
f="$tmp/truncated.csv.gz"
head -c $((size / 2)) "$tmp/whole.csv.gz" > "$f"
solve gzip_truncated 1 "^$f:[0-9]+: .*truncated gzip" "$f"
f="$tmp/trailer.csv.gz"
head -c $((size - 4)) "$tmp/whole.csv.gz" > "$f"
solve gzip_no_trailer 1 "^$f:[0-9]+: .*truncated gzip" "$f"
f="$tmp/junk.csv.gz"
{ printf '\037\213\010\000\000\000\000\000\000\003'; head -c 2000 /dev/urandom; } > "$f"
solve gzip_junk 1 "^$f:[0-9]+: " "$f"

solve missing_file 1 "^$tmp/nope.csv: cannot open" "$tmp/nope.csv"

# shellcheck disable=SC2086
run unknown_option 2 "--bogus" $config --accel "$good" --speed 25 --axle-spacing 4 --bogus 1
run missing_accel 2 "--accel" --speed 25 --axle-spacing 4
run missing_speed 2 "--speed" --accel "$good" --axle-spacing 4
run missing_spacing 2 "--axle-spacing" --accel "$good" --speed 25
run speed_no_value 2 "--speed" --accel "$good" --axle-spacing 4 --speed
for l in fast 0 -1e-9; do
    # shellcheck disable=SC2086
    run "lambda_$l" 2 "--lambda" $config --accel "$good" --speed 25 --axle-spacing 4 --lambda "$l"
done
# shellcheck disable=SC2086
run bad_formulation 2 "--formulation" $config --accel "$good" --speed 25 --axle-spacing 4 --formulation nope
# shellcheck disable=SC2086
run lcurve_fixed 2 "--lcurve needs --lambda auto" $config --accel "$good" --speed 25 --axle-spacing 4 --lambda 1e-9 --lcurve "$tmp/l.csv"
run bad_config 1 "^$tmp/nope.yaml" --config "$tmp/nope.yaml" --accel "$good" --speed 25 --axle-spacing 4
# shellcheck disable=SC2086
run forces_unwritable 1 "--forces" $config --accel "$good" --speed 25 --axle-spacing 4 --entry-time 0.5 --forces "$tmp/no/such/dir/f.csv"

# --vehicle ENTRY_S:SPEED_MPS:S1[,S2,...] (several vehicles solved jointly)
for v in "0:25" "0:25:" "x:25:4" "0:0:4" "0:99:4" "0:25:4,,3" "0:25:-1" "::4"; do
    # shellcheck disable=SC2086
    run "vehicle_$v" 2 "--vehicle" $config --accel "$good" --vehicle "$v"
done
# shellcheck disable=SC2086
run vehicle_and_speed 2 "--vehicle: not with" $config --accel "$good" --vehicle 0:25:4 --speed 25
# shellcheck disable=SC2086
run vehicle_and_entry 2 "--vehicle: not with" $config --accel "$good" --vehicle 0:25:4 --entry-time 0
# shellcheck disable=SC2086
# 17 vehicles (at most AMFI_MAX_VEHICLES, 16); 9 six-axle vehicles, 54 axles
# (at most AMFI_MAX_EVENT_AXLES, 48)
many=$(for _ in $(seq 17); do printf ' --vehicle 0:25:4'; done)
heavy=$(for _ in $(seq 9); do printf ' --vehicle 0:25:1,1,1,1,1'; done)
# shellcheck disable=SC2086
run vehicle_too_many 2 "--vehicle: more than 16" $config --accel "$good" $many
# shellcheck disable=SC2086
run vehicle_axles 2 "--vehicle: 54 axles in all .at most 48." $config --accel "$good" $heavy
# the second vehicle leaves after the data ends (2 s of data)
f=$(csv two_s.csv 2000)
# shellcheck disable=SC2086
run vehicle_not_covered 1 "passage not covered" $config --accel "$f" --vehicle 0:25:4 --vehicle 1.5:25:4

echo "solve_errors: $cases cases, $failures failed"
[ "$failures" -eq 0 ]
