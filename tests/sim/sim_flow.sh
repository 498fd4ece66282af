#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_flow.sh: sim_publisher --flow (issue 13): Poisson arrivals on one and
# two lanes into an LCM log; vehicles share the span (overlapping windows),
# both lanes are used, no vehicle overtakes another of its lane on the span,
# the vehicle_t come in entry order, every vehicle gets its truth_t; bad
# values are refused.
#   sim_flow.sh SIM_PUBLISHER LCM_FLOW
set -eu
sim=$1
chk=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 40 vehicles, 2 lanes at 1200 veh/h each (mean headway 3 s per lane); a
# coarser integration step keeps it quick under ASan
"$sim" --lcm-url none --log "$work/two.log" --speedup max --vehicles 40 --flow 1200 \
  --lanes 2 --min-headway 1 --dt 2.5e-4 2>"$work/two.err" ||
  { cat "$work/two.err" >&2; fail "two-lane run"; }
"$chk" "$work/two.log" 20 >"$work/two.txt"
cat "$work/two.txt"
set -- $(cat "$work/two.txt")
[ "$2" = 40 ] || fail "$2 vehicle_t, expected 40"
[ "$4" -ge 5 ] && [ "$5" -ge 5 ] || fail "lanes used $4 and $5 times"
[ "$7" -ge 10 ] || fail "only $7 vehicles share the span"
[ "$9" = 0 ] || fail "$9 overtakes within a lane"
[ "${11}" = 0 ] || fail "${11} vehicle_t out of entry order"
[ "${13}" -ge 999 ] || fail "entries ${13} ms apart within a lane (minimum 1 s)"

# one lane at a 3 s mean headway, 0.3 s minimum: still overlaps, all in lane 1, no overtakes
"$sim" --lcm-url none --log "$work/one.log" --speedup max --vehicles 30 --flow 1200 \
  --min-headway 0.3 --dt 2.5e-4 2>"$work/one.err" ||
  { cat "$work/one.err" >&2; fail "one-lane run"; }
set -- $("$chk" "$work/one.log" 20)
echo "one lane: $*"
[ "$2" = 30 ] && [ "$4" = 30 ] && [ "$5" = 0 ] || fail "one lane: $*"
[ "$7" -ge 2 ] || fail "one lane: only $7 vehicles share the span"
[ "$9" = 0 ] || fail "one lane: $9 overtakes"
[ "${13}" -ge 299 ] || fail "one lane: entries ${13} ms apart (minimum 0.3 s)"

# refused: three lanes, a minimum headway above the mean
"$sim" --lcm-url none --log "$work/bad.log" --vehicles 2 --flow 1200 --lanes 3 2>/dev/null && fail "--lanes 3 accepted"
"$sim" --lcm-url none --log "$work/bad.log" --vehicles 2 --flow 1200 --min-headway 5 2>"$work/bad.err" &&
  fail "--min-headway above the mean accepted"
grep -q 'min-headway' "$work/bad.err" || fail "message: $(cat "$work/bad.err")"
echo "sim_flow: ok"
