#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# kill -9 of amfid at random moments while traffic streams (issue 9), on
# LCM's UDP multicast inside a private network namespace: lcm-logplayer
# plays a recorded stream, lcm-logger records every AMFI_PASSAGE amfid
# publishes (it publishes a passage only after its commit: acknowledged),
# and amfid is killed with SIGKILL KILLS times at random and restarted on the
# same store. Then: the store opens, integrity_check is ok, and every
# acknowledged passage is in it with the same id, vehicle and status.
# Usage: daemon_kill9.sh AMFID SIM_PUBLISHER LCM_PASSAGES CONFIG [KILLS]
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 passages=$3 config=$4 kills=${5:-20}
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
# 120 vehicles, one every 2 s of data: 240 s played at 8x = 30 s of wall time
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/traffic.log" --vehicles 120 --headway 2 --speedup max --seed 5 \
  2> "$dir/sim.log" || fail "sim_publisher"
lcm-logger -c AMFI_PASSAGE -f "$dir/acked.log" > "$dir/logger.log" 2>&1 &
pids="$pids $!"
start() {
  "$amfid" --config "$config" --db "$dir/a.db" 2>> "$dir/amfid.log" &
  apid=$!
  i=0; until [ "$(grep -c running "$dir/amfid.log")" -ge "$1" ]; do
    i=$((i + 1)); [ $i -lt 200 ] || fail "amfid did not start (run $1)"; sleep 0.05; done
}
start 1
lcm-logplayer -s 8 "$dir/traffic.log" > "$dir/player.log" 2>&1 &
ppid=$!; pids="$pids $ppid"
k=0
while [ $k -lt "$kills" ]; do
  sleep "$(awk -v s="$k$$" 'BEGIN {srand(s); printf "%.2f", 0.2 + 1.0 * rand()}')"
  kill -9 $apid; wait $apid 2>/dev/null
  k=$((k + 1))
  start $((k + 1))
done
wait $ppid
sleep 2
kill -TERM $apid; wait $apid; rc=$?
[ $rc -eq 0 ] || fail "the last amfid exited $rc"
sleep 0.5
kill -INT $(echo $pids | awk '{print $1}') 2>/dev/null; sleep 0.5
[ "$(sqlite3 "$dir/a.db" "PRAGMA integrity_check")" = ok ] || fail "integrity_check"
"$passages" "$dir/acked.log" > "$dir/acked.txt" || fail "lcm_passages"
acked=$(wc -l < "$dir/acked.txt")
[ "$acked" -ge 20 ] || fail "only $acked passages acknowledged: the test did not exercise amfid"
missing=0
while read -r pid vid status; do
  got=$(sqlite3 "$dir/a.db" "SELECT vehicle_id || ' ' || status FROM passages WHERE id = $pid")
  [ "$got" = "$vid $status" ] || { echo "acknowledged passage $pid (vehicle $vid, $status) stored as '$got'"; missing=$((missing + 1)); }
done < "$dir/acked.txt"
[ $missing -eq 0 ] || fail "$missing of $acked acknowledged passages missing or different"
rows=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages")
echo "kill -9: $kills kills while streaming; $acked passages acknowledged, all $acked present; $rows rows in the store; integrity ok"
