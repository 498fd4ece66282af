#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid on the hostile datagrams of issue 9 (an LCM log through file://, no
# network): the vehicle_t (56 bytes then, 64 with reference_gvw_kg) with a negative string length that crashed
# amfid inside lcm-gen's decoder, negative array counts on accel, vehicle and
# truth, a vehicle dated after year 9999, and 40 000 more refused messages.
# amfid must keep running, weigh the real vehicles, store the far-future
# vehicle as invalid (a row, not lost), count every refusal by channel and
# reason, and keep its log short (rate limit).
# Usage: daemon_hostile.sh AMFID SIM_PUBLISHER LCM_HOSTILE ISSUE9_VEHICLE CONFIG
set -u
amfid=$1 sim=$2 hostile=$3 issue9=$4 config=$5
extra=40000
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
# a simulation: the truth channel is subscribed (and its decoder exercised)
sed "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/sim.yaml"
grep -q "^  simulation: true$" "$dir/sim.yaml" || { echo "FAIL: daemon.simulation did not apply"; exit 1; }
config=$dir/sim.yaml
fail() { echo "FAIL: $*"; tail -30 "$dir/amfid.log"; exit 1; }
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/clean.log" --vehicles 3 --headway 4 --speedup max --seed 2 \
  2> "$dir/sim.log" || fail "sim_publisher"
"$hostile" "$dir/clean.log" "$dir/bad.log" "$issue9" $extra || fail "lcm_hostile"
"$amfid" --config "$config" --db "$dir/a.db" --lcm-url "file://$dir/bad.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ $rc -eq 0 ] || fail "amfid exit status $rc (the hostile datagrams stopped it)"
grep -q "malformed vehicle_t (64 bytes) rejected: vehicle_t.source: string length -16" "$dir/amfid.log" ||
  fail "the issue 9 datagram is not refused by name"
for what in "malformed accel_block_t .* negative" "malformed vehicle_t .* negative" \
            "malformed truth_t .* negative"; do
  grep -q "$what" "$dir/amfid.log" || fail "no log line for: $what"
done
[ "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages WHERE status = 'ok'")" -eq 3 ] ||
  fail "the three real vehicles are not all ok"
sqlite3 "$dir/a.db" "SELECT status, reason FROM passages WHERE vehicle_id = 777001" |
  grep -q "^invalid|.*utime out of" || fail "the vehicle after year 9999 has no invalid row"
# Every refusal counted: the totals at stop, by channel and reason.
n=$(sed -n 's/.*refused since start: .* negative_count: \([0-9]*\)$/\1/p' "$dir/amfid.log" |
    awk '{s += $1} END {print s + 0}')
[ "$n" -eq $((extra + 4)) ] || fail "negative_count refusals counted $n, sent $((extra + 4))"
lines=$(wc -l < "$dir/amfid.log")
[ "$lines" -le 100 ] || fail "$lines log lines for $((extra + 5)) refused messages (no rate limit)"
echo "hostile input: amfid kept running, $n negative-count refusals counted, 3 vehicles ok," \
  "the year-10000 vehicle stored as invalid, $lines log lines"
