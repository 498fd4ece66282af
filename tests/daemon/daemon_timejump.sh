#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid when the data's time jumps (issue 9, finding 2), through file:// logs:
# (1) an accel block dated an hour ahead arrives first: the real stream
#     confirms the jump back, and the real vehicles are weighed (they used to
#     be stored as late, every one);
# (2) an outage of two hours after the 4th vehicle (data and detector): the
#     ring restarts when the stream resumes, and the vehicles after the hole
#     are weighed (they used to be stored as gap until amfid was restarted).
# Every vehicle ends as a row in both cases.
# Usage: daemon_timejump.sh AMFID SIM_PUBLISHER LCM_TIMESHIFT CONFIG
set -u
amfid=$1 sim=$2 shift_=$3 config=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
q() { sqlite3 "$dir/$1" "$2"; }
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/clean.log" --vehicles 8 --headway 4 --speedup max --seed 3 \
  2> "$dir/sim.log" || fail "sim_publisher"

"$shift_" poison "$dir/clean.log" "$dir/poison.log" || fail "lcm_timeshift poison"
"$amfid" --config "$config" --db "$dir/p.db" --lcm-url "file://$dir/poison.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid on the poisoned log"
grep -q "time jumped by -3599" "$dir/amfid.log" || fail "no confirmed jump back logged"
[ "$(q p.db "SELECT count(*) FROM passages")" -eq 8 ] || fail "poison: not every vehicle has a row"
ok=$(q p.db "SELECT count(*) FROM passages WHERE status = 'ok'")
[ "$ok" -eq 8 ] || fail "poison: $ok of 8 ok ($(q p.db "SELECT status, reason FROM passages WHERE status <> 'ok'"))"
echo "poisoned first block: jump back confirmed, 8 of 8 vehicles ok"

"$shift_" outage "$dir/clean.log" "$dir/outage.log" 4 || fail "lcm_timeshift outage"
"$amfid" --config "$config" --db "$dir/o.db" --lcm-url "file://$dir/outage.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid on the outage log"
grep -q "time jumped by +7" "$dir/amfid.log" || fail "no confirmed jump forward logged"
[ "$(q o.db "SELECT count(*) FROM passages")" -eq 8 ] || fail "outage: not every vehicle has a row"
[ "$(q o.db "SELECT count(*) FROM passages WHERE status = 'late'")" -eq 0 ] || fail "outage: late rows"
after=$(q o.db "SELECT count(*) FROM passages WHERE status = 'ok' AND vehicle_id > 4")
[ "$after" -ge 3 ] || fail "outage: $after of the 4 vehicles after the hole ok ($(q o.db "SELECT vehicle_id, status, reason FROM passages"))"
echo "outage of 2 h: ring restarted, $after of 4 vehicles after the hole ok," \
  "$(q o.db "SELECT count(*) FROM passages WHERE status = 'ok'") of 8 in all"
