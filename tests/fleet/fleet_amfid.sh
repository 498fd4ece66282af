#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fleet_amfid.sh: amfi-sync follows the store while amfid writes it. Inside a
# private network namespace (LCM multicast on lo only): a throwaway
# PostgreSQL (tests/common/pg_server.sh), amfid fed live by sim_publisher, and
# amfi-sync in follow mode every 0.2 s on amfid's own configuration. amfid
# is never blocked (every vehicle the simulator sent is stored), amfi-sync
# ships while the rows arrive, and after both stop the central rows equal
# the store's: no gap, no duplicate. The simulator's site climate is on:
# the temperature readings, the passages' deck temperatures and natural
# frequencies are shipped too, and the site's name, position and bridge
# type of amfid.yaml (through amfid's meta) reach fleet_sites.
# Usage: fleet_amfid.sh AMFI_SYNC AMFID SIM_PUBLISHER CONFIG. Exit 77 without
# sqlite3/PostgreSQL.
set -u
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
sync=$1 amfid=$2 sim=$3 config=$4
command -v sqlite3 > /dev/null || { echo "fleet_amfid.sh: no sqlite3: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp fleet_amfid
dir=$tmp; . "$here/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
. "$(dirname "$0")/../common/proc.sh"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
die() { echo "FAIL: $*"; tail -n 5 "$tmp/amfid.log" "$tmp/sync.log" "$tmp/sim.log"; exit 1; }

# the shipped amfid.yaml with this test's site, store and small windows
sed -e "s/^  id: local .*/  id: live-1/" -e "s|^    path: amfi.db .*|    path: $tmp/live.db|" \
    -e "s/^    window: 500/    window: 10/" -e "s/^    every: 100/    every: 5/" \
    -e "s/^    baseline_n: 10000/    baseline_n: 10/" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" \
    -e "s/^  # name: .*/  name: \"Live bridge, km 1\"/" -e "s/^  # latitude: .*/  latitude: 46.05/" \
    -e "s/^  # longitude: .*/  longitude: 14.51/" -e "s/^  # bridge_type: .*/  bridge_type: \"box girder\"/" \
    "$config" > "$tmp/live.yaml"
grep -q "^  id: live-1$" "$tmp/live.yaml" && grep -q "path: $tmp/live.db" "$tmp/live.yaml" &&
    grep -q '^  bridge_type: "box girder"$' "$tmp/live.yaml" ||
    die "the test's site and store did not apply"
"$amfid" --config "$tmp/live.yaml" 2> "$tmp/amfid.log" &
apid=$!
wait_for running "$tmp/amfid.log" $apid 60 || die "amfid did not start"
"$sync" --config "$tmp/live.yaml" --pg "$PG_CONNINFO" --interval 0.2 2> "$tmp/sync.log" &
spid=$!
# 120 vehicles 2 s apart, 12 times faster than real time: about 20 s; the
# site's climate (issue 14) on, time-compressed, a reading every second
"$sim" --dt 2.5e-4 --allow-production-bus --vehicles 120 --headway 2 --speedup 12 --seed 11 \
    --environment site --time-compression 73000 --environment-period 1 2> "$tmp/sim.log" || die "sim_publisher"
sleep 2
mid=$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'live-1'")
kill -TERM $apid; wait $apid; rc=$?
[ $rc = 0 ] || fail "amfid exited $rc"
sleep 1
kill -TERM $spid; wait $spid; rc=$?
[ $rc = 0 ] || fail "amfi-sync exited $rc on SIGTERM"
"$sync" --config "$tmp/live.yaml" --pg "$PG_CONNINFO" --once --quiet || fail "last --once"
stored=$(sqlite3 "$tmp/live.db" "SELECT count(*) FROM passages")
[ "$stored" = 120 ] || fail "amfid stored $stored of 120 vehicles"
[ "$mid" -gt 0 ] || fail "nothing shipped while amfid was writing"
passes=$(grep -c "rows shipped" "$tmp/sync.log")
[ "$passes" -ge 3 ] || fail "amfi-sync shipped in $passes passes while amfid wrote, expected several"
fleet_same "$tmp/live.db" live-1
# the site's facts, from amfid.yaml through amfid's meta to fleet_sites
f=$(pg_q "SELECT name || '|' || latitude || '|' || longitude || '|' || bridge_type FROM fleet_sites WHERE site_id = 'live-1'")
[ "$f" = "Live bridge, km 1|46.05|14.51|box girder" ] || fail "fleet_sites of live-1: '$f'"
# issue 14's data as amfid wrote it: temperature readings, the passages'
# deck temperature and natural frequency, all of it in the central rows
env=$(sqlite3 "$tmp/live.db" "SELECT count(*) FROM environment")
[ "$env" -ge 10 ] || fail "amfid stored $env environment readings"
n14="count(deck_c) || ' ' || count(f1_hz) || ' ' || count(f1_r2) || ' ' || count(gvw_comp_kg)"
l=$(sqlite3 "$tmp/live.db" "SELECT $n14 FROM passages")
c=$(pg_q "SELECT $n14 FROM passages WHERE site_id = 'live-1'")
[ "$l" = "$c" ] || fail "deck_c, f1_hz, f1_r2, gvw_comp_kg values: store $l, central $c"
[ "${l%% *}" -gt 0 ] || fail "no passage with a deck temperature: $l"
echo "fleet_amfid: amfid stored $stored, $mid shipped before amfid stopped, in $passes passes; $env temperature readings, passages with deck_c, f1_hz, f1_r2, gvw_comp_kg: $l"
[ $failures = 0 ] && echo "fleet_amfid.sh: all cases pass"
exit $((failures != 0))
