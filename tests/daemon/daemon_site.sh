#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Site identity (issue 11), on LCM's UDP multicast inside a private network
# namespace: amfid writes site.id and site.name into a new store's meta
# table; every passage, indicator, alert and status message it publishes
# carries the site id; a second start under another site.id is refused with
# a message naming both ids and leaves the store as it was; a changed
# site.name is written over the stored one.
# Usage: daemon_site.sh AMFID SIM_PUBLISHER LCM_PASSAGES CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 passages=$3 config=$4
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
meta() { sqlite3 "$dir/a.db" "SELECT value FROM meta WHERE key = '$1'"; }

# The shipped file with a site section of the test's own, small indicator
# windows (so that indicators are published) and a 0.2 s heartbeat.
site() { # ID NAME
  sed -e "s/^  id: local .*/  id: $1/" -e "s/^  # name: .*/  name: \"$2\"/" \
      -e "s/^  # latitude: .*/  latitude: 46.05/" -e "s/^  # longitude: .*/  longitude: 14.51/" \
      -e "s/^    window: 500/    window: 10/" -e "s/^    every: 100/    every: 5/" \
      -e "s/^    baseline_n: 10000/    baseline_n: 10/" \
      -e "s/^  status_period_s: 1 /  status_period_s: 0.2 /" "$config"
}
site north-42 "Bridge over the Sava, km 42" > "$dir/a.yaml"
grep -q '^  id: north-42$' "$dir/a.yaml" || fail "the test's site.id did not apply"
grep -q '^  name: "Bridge over the Sava, km 42"$' "$dir/a.yaml" || fail "site.name did not apply"
grep -q '^    baseline_n: 10 ' "$dir/a.yaml" || fail "the indicator settings did not apply"
"$amfid" --config "$dir/a.yaml" --check-config > /dev/null || fail "check-config"

# 1. First start: claimed, and every output message carries the id.
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/traffic.log" --vehicles 24 --headway 2 --speedup max --seed 7 \
  2> "$dir/sim.log" || fail "sim_publisher"
lcm-logger -f "$dir/out.lcmlog" > "$dir/logger.log" 2>&1 &
pids="$pids $!"
"$amfid" --config "$dir/a.yaml" --db "$dir/a.db" 2> "$dir/amfid.log" &
apid=$!
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
lcm-logplayer -s 8 "$dir/traffic.log" > "$dir/player.log" 2>&1 || fail "lcm-logplayer"
sleep 1.5
kill -TERM $apid; wait $apid; rc=$?
[ $rc -eq 0 ] || fail "amfid exited $rc"
grep -q "first start of site 'north-42'" "$dir/amfid.log" || fail "no first-start line in the log"
[ "$(meta site.id)" = north-42 ] || fail "meta site.id is '$(meta site.id)'"
[ "$(meta site.name)" = "Bridge over the Sava, km 42" ] || fail "meta site.name is '$(meta site.name)'"
[ "$(meta site.latitude)" = 46.0500000 ] || fail "meta site.latitude is '$(meta site.latitude)'"
[ "$(meta site.longitude)" = 14.5100000 ] || fail "meta site.longitude is '$(meta site.longitude)'"
sleep 0.5
"$passages" --site "$dir/out.lcmlog" > "$dir/sites.txt" || fail "lcm_passages --site"
for ch in AMFI_PASSAGE AMFI_INDICATOR AMFI_STATUS; do
  n=$(grep -c "^$ch " "$dir/sites.txt")
  [ "$n" -ge 1 ] || fail "no $ch message recorded"
done
np=$(grep -c "^AMFI_PASSAGE " "$dir/sites.txt")
rows=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM passages")
[ "$np" -eq "$rows" ] || fail "$np passage messages, $rows rows"
others=$(grep -vc " north-42$" "$dir/sites.txt")
[ "$others" -eq 0 ] || fail "$others messages without site north-42: $(grep -v ' north-42$' "$dir/sites.txt" | head -3)"

# 2. Another site's configuration on this store: refused, store unchanged.
site south-7 "Another bridge" > "$dir/b.yaml"
runs=$(sqlite3 "$dir/a.db" "SELECT count(*) FROM runs")
"$amfid" --config "$dir/b.yaml" --db "$dir/a.db" 2> "$dir/b.log" & bpid=$!
i=0; while kill -0 $bpid 2>/dev/null; do
  i=$((i + 1)); [ $i -lt 200 ] || { kill -9 $bpid; fail "amfid with another site.id kept running"; }
  sleep 0.05; done
wait $bpid; rc=$?
[ $rc -ne 0 ] || fail "amfid with another site.id exited 0"
grep -q "belongs to site 'north-42', but .*b.yaml configures site.id 'south-7'" "$dir/b.log" ||
  fail "refusal message: $(cat "$dir/b.log")"
[ "$(meta site.id)" = north-42 ] || fail "the refused start changed site.id"
[ "$(sqlite3 "$dir/a.db" "SELECT count(*) FROM runs")" = "$runs" ] || fail "the refused start added a run"

# 3. The same site renamed: the new name is stored.
site north-42 "Sava bridge km 42 (north)" > "$dir/c.yaml"
"$amfid" --config "$dir/c.yaml" --db "$dir/a.db" 2> "$dir/c.log" & cpid=$!
wait_for running "$dir/c.log" $cpid 60 || fail "amfid did not start (renamed)"
kill -TERM $cpid; wait $cpid || fail "renamed run exited non-zero"
[ "$(meta site.name)" = "Sava bridge km 42 (north)" ] || fail "meta site.name is '$(meta site.name)'"
grep -q "site.name changed from 'Bridge over the Sava, km 42' to 'Sava bridge km 42 (north)'" \
  "$dir/c.log" || fail "no rename line in the log"
echo "daemon_site: $rows passages, $(wc -l < "$dir/sites.txt") output messages all with site north-42; other site refused; rename stored"
