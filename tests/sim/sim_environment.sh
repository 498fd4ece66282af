#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_environment.sh: sim_publisher --environment site (issue 14) into an LCM
# log: environment_t every --environment-period of data time, a compressed
# year spanning frost and summer on the deck, the mix drawing other vehicles
# than the population in order; --environment none publishes no
# environment_t and is the default; bad values are refused.
#   sim_environment.sh SIM_PUBLISHER LCM_ENVIRONMENT
set -eu
sim=$1
sum=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# 100 vehicles 4 s apart (about 406 s of data) at compression 73000: 340 site
# days; a coarser integration step (4 per sample) keeps it quick under ASan
"$sim" --lcm-url none --log "$work/site.log" --speedup max --vehicles 100 --headway 4 \
  --dt 2.5e-4 --environment site --time-compression 73000 --environment-period 15 \
  2>"$work/site.err" ||
  { cat "$work/site.err" >&2; fail "site run"; }
grep -q 'environment site: deck' "$work/site.err" || fail "no environment summary"
"$sum" "$work/site.log" >"$work/site.txt"
cat "$work/site.txt"
set -- $(sed -n 's/^env //p' "$work/site.txt")
n=$1 first=$2 last=$3 smin=$4 smax=$5 amin=$6 amax=$7 dmin=$8 dmax=$9
# one every 15 s of data from the start (2026-01-01T00:00Z) to the end
[ "$first" = 1767225600000000 ] || fail "first environment_t at $first"
[ "$smin" = 15000000 ] && [ "$smax" = 15000000 ] || fail "steps $smin .. $smax µs, not 15 s"
want=$(( (last - first) / 15000000 + 1 ))
[ "$n" -eq "$want" ] && [ "$n" -ge 26 ] || fail "$n environment_t, expected $want (>= 26)"
# a year of seasons: frost and summer on the deck and in the air
awk -v a="$amin" -v b="$amax" -v c="$dmin" -v d="$dmax" 'BEGIN {
  exit !(c < -2 && d > 18 && a < 0 && b > 18 && a > -40 && b < 45) }' ||
  fail "deck $dmin .. $dmax, air $amin .. $amax °C: not a year's range"
set -- $(sed -n 's/^truth //p' "$work/site.txt")
[ "$1" = 100 ] || fail "$1 truth messages, expected 100"
gsite=$2

# none (the default): no environment_t, the population in order
"$sim" --lcm-url none --log "$work/none.log" --speedup max --vehicles 100 --headway 4 \
  --dt 2.5e-4 2>"$work/none.err" || { cat "$work/none.err" >&2; fail "none run"; }
"$sum" "$work/none.log" >"$work/none.txt"
grep -q '^env 0 ' "$work/none.txt" || fail "environment_t without --environment site"
set -- $(sed -n 's/^truth //p' "$work/none.txt")
[ "$1" = 100 ] || fail "$1 truth messages (none), expected 100"
[ "$2" != "$gsite" ] || fail "the mix drew the same vehicles as the population in order"
grep -q 'environment' "$work/none.err" && fail "environment summary without site"

# refused values, with the flag named
for bad in "--environment winter" "--time-compression 0.5" "--environment-period 0"; do
  if "$sim" --lcm-url none --log "$work/x.log" --vehicles 1 $bad 2>"$work/bad.err"; then
    fail "$bad accepted"
  fi
  grep -q -- "${bad%% *}" "$work/bad.err" || fail "$bad: message does not name the flag"
done
echo "sim_environment: ok ($n environment_t, deck $dmin .. $dmax °C)"
