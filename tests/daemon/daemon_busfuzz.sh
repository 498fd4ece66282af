#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Bus fuzzing of amfid (issue 9): real traffic with COUNT mutated messages
# spread through it (tests/daemon/lcm_fuzzlog.c), replayed through file:// (no
# network) or, with "live", played by lcm-logplayer on LCM's UDP multicast in
# a private network namespace. amfid must keep running and exit 0 at the end,
# and every real vehicle must have a row. (Not every one is ok: a mutated
# message can be a plausible vehicle of its own on the span at the same time,
# and the real one is then stored as `multiple`; that is what such a forged
# message does on a real bus too. The ok count is printed.)
# Prints the figures. The suite runs a short file:// version; the long runs
# are tools/bench/amfi-bus-fuzz.
# Usage: daemon_busfuzz.sh AMFID SIM_PUBLISHER LCM_FUZZLOG CONFIG COUNT [live] [VEHICLES]
set -u
if [ "${6:-}" = live ] && [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
amfid=$1 sim=$2 fuzzlog=$3 config=$4 count=$5 mode=${6:-file} nveh=${7:-10}
dir=$(mktemp -d)
pids=""
cleanup() { for p in $pids; do kill -9 "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
. "$(dirname "$0")/../common/proc.sh"
# The fuzz is aimed at the decoders and the authentication: every real
# vehicle must get its row. The mutated vehicles that pass both are signed
# and, like a broken detector's, can exceed the vehicle channel's rate
# limit, beyond which a vehicle (a real one too) is counted without a row;
# how many tokens a file:// replay refills depends on the machine's speed
# (wall or data time), so the limit is lifted here (daemon_intake tests it).
sed "s/^    vehicles_per_s: 10 .*/    vehicles_per_s: 100000/" "$config" > "$dir/fuzz.yaml"
grep -q "^    vehicles_per_s: 100000$" "$dir/fuzz.yaml" || { echo "FAIL: no daemon.intake.vehicles_per_s in $config"; exit 1; }
config=$dir/fuzz.yaml
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/clean.log" --vehicles "$nveh" --headway 3 --speedup max --seed 8 \
  2> "$dir/sim.log" || fail "sim_publisher"
"$fuzzlog" "$dir/clean.log" "$dir/fuzz.log" "$count" 11 > "$dir/fuzzlog.txt" || fail "lcm_fuzzlog"
t0=$(date +%s.%N)
if [ "$mode" = live ]; then
  "$amfid" --config "$config" --db "$dir/a.db" 2> "$dir/amfid.log" &
  apid=$!; pids="$pids $apid"
  wait_for running "$dir/amfid.log" $apid 60 || fail "no start"
  lcm-logplayer -s 1 "$dir/fuzz.log" > "$dir/player.log" 2>&1 || fail "lcm-logplayer"
  sleep 3
  kill -0 $apid 2>/dev/null || fail "amfid died"
  kill -TERM $apid; wait $apid; rc=$?
else
  "$amfid" --config "$config" --db "$dir/a.db" --lcm-url "file://$dir/fuzz.log?speed=0" \
    2> "$dir/amfid.log"; rc=$?
fi
t1=$(date +%s.%N)
[ $rc -eq 0 ] || fail "amfid exit status $rc"
# (mutated copies of a real vehicle that still pass validation get rows of
# their own, usually invalid as duplicates: count the real ids)
rows=$(sqlite3 "$dir/a.db" "SELECT count(DISTINCT vehicle_id) FROM passages WHERE vehicle_id BETWEEN 1 AND $nveh")
ok=$(sqlite3 "$dir/a.db" "SELECT count(DISTINCT vehicle_id) FROM passages WHERE status = 'ok' AND vehicle_id BETWEEN 1 AND $nveh")
refused=$(sed -n 's/.*refused since start: .*: \([0-9]*\)$/\1/p' "$dir/amfid.log" | awk '{s += $1} END {print s + 0}')
forged=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages WHERE vehicle_id NOT BETWEEN 1 AND $nveh")
drops=$(sed -n 's/.*the kernel dropped \([0-9]*\) UDP.*/\1/p' "$dir/amfid.log" | tail -1)
echo "bus fuzz ($mode): $(cat "$dir/fuzzlog.txt"); amfid exit 0 after $(echo "$t1 - $t0" | bc) s;" \
  "$refused refused; real vehicles: $rows rows, $ok ok of $nveh; rows of mutated vehicles that passed validation: $forged; kernel drops ${drops:-0};" \
  "log lines $(wc -l < "$dir/amfid.log")"
sed -n 's/.*refused since start: //p' "$dir/amfid.log" | sed 's/^/  refused: /'
got=$(sed -n 's/.*stopped: .* \([0-9]*\) messages received.*/\1/p' "$dir/amfid.log")
sent=$(sed -n 's/^\([0-9]*\) real events, \([0-9]*\) mutated.*/\1 \2/p' "$dir/fuzzlog.txt" | awk '{print $1 + $2}')
echo "  messages: $sent sent, $got reached amfid's handlers, kernel drops ${drops:-0}"
grep "stopped:" "$dir/amfid.log" | sed "s/^/  /"
echo "  real vehicles by status: $(sqlite3 "$dir/a.db" "SELECT group_concat(s, ', ') FROM (SELECT status || ' ' || count(*) || ' (' || substr(min(reason), 1, 60) || ')' s FROM passages WHERE vehicle_id BETWEEN 1 AND $nveh GROUP BY status)")"
[ "$rows" -eq "$nveh" ] || fail "$rows of $nveh real vehicles have rows"
