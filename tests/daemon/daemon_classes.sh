#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid's class and axle groups per passage, on LCM's UDP multicast inside a
# private network namespace: sim_publisher streams a mix of heavy vehicles
# (two-axle and three- and four-axle rigid, tractors with tandem and tridem
# semi-trailers: records of the shipped EU population, amfi-population
# --traffic eu's seed 1) and amfid (its shipped classes:, the European
# scheme, groups at 2.0 m) stores each passage's class, groups and overload.
# For every vehicle: the stored class is the population record's class (the
# truth the simulator built the vehicle from), the stored groups are the
# record's spacings grouped at 2.0 m, overload is decided (0 or 1) for the
# ok passages; passage_t on the bus carries the same class and groups, and
# its group loads sum to the stored GVW. Then the same vehicles without
# their sensor data (the recorded bus, vehicle_t only, replayed through
# file://): each is stored as gap, not solved, and still gets its class and
# groups from the spacings, with overload NULL.
# Then the class filter of the STD and mean rules (daemon.indicators.classes,
# min_gvw_kg): the recorded bus replayed through a daemon that feeds the
# rules only A23 and A33 passages of at least 20 t: the passages fed and
# left out, counted in amfid's log, are those of the store's rows; after a
# restart the window is refilled with those passages only, and an automatic
# baseline collected from other passages is not applied.
# amfi-report --set-baseline-last takes the same passages (the filter amfid
# recorded in meta).
# Usage: daemon_classes.sh AMFID SIM_PUBLISHER LCM_PASSAGES LCM_INJECT CONFIG POPULATION_EU
#     AMFI_REPORT
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 listen=$3 inject=$4 config=$5 popeu=$6 report=$7
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
q() { sqlite3 "$dir/s.db" "$1"; }

# The test's population: records of each class from the shipped one (0-based
# record numbers): A33, R2, A23, A22, A32, R3, R4, R4.
{ head -1 "$popeu"
  for r in 0 1 2 8 14 20 41 49; do sed -n "$((r + 2))p" "$popeu"; done; } > "$dir/pop.csv"
N=$(($(wc -l < "$dir/pop.csv") - 1))
head -1 "$dir/pop.csv" | grep -q '^timestamp_s,lane,speed_mps,class,' ||
  fail "population header: $(head -1 "$dir/pop.csv")"
[ "$(tail -n +2 "$dir/pop.csv" | cut -d, -f4 | sort -u | wc -l)" -ge 7 ] ||
  fail "the test population has fewer than 7 classes"
# what each vehicle must be stored as: vehicle_id (first record + 1), class,
# groups (adjacent spacings <= 2.0 m join)
tail -n +2 "$dir/pop.csv" | awk -F, '{
    n = split($8, s, ";"); g = ""; k = 1
    for (i = 1; i <= n; i++) if (s[i] + 0 <= 2.0) k++; else { g = g k "-"; k = 1 }
    print NR, $4, g k }' > "$dir/want.txt"

grep -q "^  group_spacing_m: 2.0 " "$config" || fail "$config: classes.group_spacing_m is not 2.0"
grep -q "^  scheme: eu " "$config" || fail "$config: classes.scheme is not eu"
# the solver's workspace for six axles (the shipped file sizes it for two)
sed -e "s/^  max_axles: [0-9]* /  max_axles: 6 /" "$config" > "$dir/amfid.yaml"
grep -q "^  max_axles: 6 " "$dir/amfid.yaml" || fail "the test's solver.max_axles did not apply"
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null || fail "check-config"
amfid_start "$amfid" "$dir/amfid.yaml"
lcm-logger -f "$dir/passages.log" > "$dir/logger.log" 2>&1 &  # every channel
lpid=$!; pids="$pids $lpid"
sleep 0.3
timeout 240 "$sim" --allow-production-bus --population "$dir/pop.csv" --vehicles $N --headway 3 --speedup 20 \
  --dt 2.5e-4 2> "$dir/sim.log" || { cat "$dir/sim.log"; fail "sim_publisher exited $?"; }
sleep 1
amfid_stop
kill -INT $lpid; wait $lpid 2>/dev/null

# The store: one row per vehicle with its class and groups.
q "SELECT vehicle_id, class, axle_groups, status, ifnull(overload, 'NULL'), gvw_kg
   FROM passages ORDER BY vehicle_id" | tr '|' ' ' > "$dir/got.txt"
cat "$dir/got.txt"
[ "$(wc -l < "$dir/got.txt")" -eq "$N" ] || fail "expected $N passages, got $(wc -l < "$dir/got.txt")"
awk 'NR == FNR { cls[$1] = $2; grp[$1] = $3; next }
     { if (!($1 in cls)) { print "vehicle " $1 ": not in the population"; bad++; next }
       if ($2 != cls[$1]) { print "vehicle " $1 ": class " $2 ", truth " cls[$1]; bad++ }
       if ($3 != grp[$1]) { print "vehicle " $1 ": groups " $3 ", truth " grp[$1]; bad++ }
       seen[$1] = 1 }
     END { for (v in cls) if (!(v in seen)) { print "vehicle " v ": no passage"; bad++ }
           exit bad > 0 }' "$dir/want.txt" "$dir/got.txt" || fail "stored class or groups wrong"
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
[ "$ok" -ge $((N - 1)) ] || fail "only $ok of $N passages ok"
q "SELECT count(*) FROM passages WHERE status = 'ok' AND overload IS NULL" | grep -qx 0 ||
  fail "an ok passage without its overload decided"
q "SELECT count(*) FROM passages WHERE status != 'ok' AND gvw_kg IS NULL AND overload IS NOT NULL" |
  grep -qx 0 || fail "overload decided for a passage that was not solved"

# The bus: passage_t with the same class and groups; the groups' loads sum to the GVW.
"$listen" --class "$dir/passages.log" > "$dir/bus.txt" || fail "lcm_passages --class"
[ "$(wc -l < "$dir/bus.txt")" -eq "$N" ] || fail "expected $N passage_t, got $(wc -l < "$dir/bus.txt")"
awk 'NR == FNR { cls[$1] = $2; grp[$1] = $3; st[$1] = $4; ov[$1] = $5; gvw[$1] = $6; next }
     { v = $2
       if ($4 != cls[v] || $5 != grp[v]) { print "passage_t of " v ": " $4 " " $5 ", stored " cls[v] " " grp[v]; bad++ }
       if (st[v] == "ok") {
         d = $6 - gvw[v]; if (d < 0) d = -d
         if (d > 1e-6 * gvw[v] + 1e-3) { print "passage_t of " v ": group loads " $6 ", gvw " gvw[v]; bad++ }
         if ($7 != ov[v]) { print "passage_t of " v ": overload " $7 ", stored " ov[v]; bad++ }
       } }
     END { exit bad > 0 }' "$dir/got.txt" "$dir/bus.txt" || { cat "$dir/bus.txt"; fail "passage_t class or groups"; }
echo "daemon_classes: $N vehicles of $(cut -d' ' -f2 "$dir/want.txt" | sort -u | tr '\n' ' ')stored and published with their class and groups"

# Not solved: the vehicles without their sensor data, stored as gap with
# their class and groups, overload NULL.
"$inject" --vehicles-only "$dir/passages.log" "$dir/novdata.log" || fail "lcm_inject --vehicles-only"
"$amfid" --config "$dir/amfid.yaml" --db "$dir/gap.db" --lcm-url "file://$dir/novdata.log?speed=0" \
  2> "$dir/amfid.log" || fail "amfid on vehicles without data: exit status $?"
sqlite3 "$dir/gap.db" "SELECT vehicle_id, class, axle_groups, status, ifnull(overload, 'NULL')
   FROM passages ORDER BY vehicle_id" | tr '|' ' ' > "$dir/gap.txt"
cat "$dir/gap.txt"
[ "$(wc -l < "$dir/gap.txt")" -eq "$N" ] || fail "without data: $(wc -l < "$dir/gap.txt") passages"
awk 'NR == FNR { cls[$1] = $2; grp[$1] = $3; next }
     { if ($2 != cls[$1] || $3 != grp[$1]) { print "vehicle " $1 " not solved: " $2 " " $3 ", truth " cls[$1] " " grp[$1]; bad++ }
       if ($4 != "gap" || $5 != "NULL") { print "vehicle " $1 ": status " $4 ", overload " $5 ", expected gap NULL"; bad++ } }
     END { exit bad > 0 }' "$dir/want.txt" "$dir/gap.txt" || fail "passages not solved: class or groups wrong"
echo "daemon_classes: the same $N vehicles without sensor data stored as gap with their class and groups"

# The class filter of the STD and mean rules: the recorded bus (every channel)
# replayed with daemon.indicators.classes A23,A33 and min_gvw_kg 20000.
sed -e 's/^    classes: "" /    classes: A23,A33 /' -e 's/^    min_gvw_kg: 0 /    min_gvw_kg: 20000 /' \
  "$dir/amfid.yaml" > "$dir/cls.yaml"
grep -q '^    classes: A23,A33 ' "$dir/cls.yaml" && grep -q '^    min_gvw_kg: 20000 ' "$dir/cls.yaml" ||
  fail "the test's daemon.indicators.classes / min_gvw_kg did not apply"
"$amfid" --config "$dir/cls.yaml" --db "$dir/cls.db" --lcm-url "file://$dir/passages.log?speed=0" \
  2> "$dir/cls.log" || { cat "$dir/cls.log"; fail "amfid with a class filter: exit status $?"; }
qc() { sqlite3 "$dir/cls.db" "$1"; }
fed=$(qc "SELECT count(*) FROM passages WHERE status = 'ok' AND class IN ('A23', 'A33')
          AND gvw_comp_kg >= 20000")
other=$(qc "SELECT count(*) FROM passages WHERE status = 'ok' AND ifnull(class, '') NOT IN ('A23', 'A33')")
light=$(qc "SELECT count(*) FROM passages WHERE status = 'ok' AND class IN ('A23', 'A33')
            AND gvw_comp_kg < 20000")
qc "SELECT vehicle_id, class, status, round(gvw_comp_kg) FROM passages ORDER BY vehicle_id" | tr '|' ' '
# the test population: one A23 of 34 t and one A33 of 16 t, six of other classes
[ "$fed" -ge 1 ] && [ "$light" -ge 1 ] && [ "$other" -ge 5 ] ||
  fail "class filter: $fed passages to feed, $light light, $other of other classes (expected >= 1, 1, 5)"
want="STD and mean rules: $fed passages fed of classes A23,A33 from 20000 kg, $other of other classes or none, $light below 20000 kg left out"
grep -qF "$want" "$dir/cls.log" || { grep "STD and mean" "$dir/cls.log"; fail "class filter: expected '$want'"; }
sqlite3 "$dir/cls.db" "SELECT value FROM meta WHERE key = 'daemon.indicators.classes'" |
  grep -qx 'classes=A23,A33 min_gvw_kg=20000' || fail "meta daemon.indicators.classes"
# amfi-report's baseline from the newest passages takes the filter's only
"$report" --db "$dir/cls.db" --set-baseline-last $((fed + 1)) > "$dir/report.txt" 2>&1 &&
  fail "amfi-report --set-baseline-last $((fed + 1)) found more than the filter's $fed passages"
grep -q "only $fed ok passages stored" "$dir/report.txt" ||
  { cat "$dir/report.txt"; fail "amfi-report --set-baseline-last: not the filter's $fed passages"; }
# a restart (vehicles only: nothing more feeds) with a manual baseline: the
# window is refilled with the filter's passages only
qc "INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
    VALUES (0, 100, 30000, 3000, 'manual', 'test')"
"$amfid" --config "$dir/cls.yaml" --db "$dir/cls.db" --lcm-url "file://$dir/novdata.log?speed=0" \
  2> "$dir/cls2.log" || { cat "$dir/cls2.log"; fail "amfid restarted with a class filter: exit status $?"; }
grep -qF "window refilled from the store: $fed ok passages of classes A23,A33 from 20000 kg" "$dir/cls2.log" ||
  { grep -i "window\|baseline" "$dir/cls2.log"; fail "class filter: the window refill is not $fed passages"; }
# an automatic baseline collected from every passage is not applied under the filter
qc "INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
    VALUES (0, 100, 20000, 5000, 'auto', 'first 100 ok passages')"
"$amfid" --config "$dir/cls.yaml" --db "$dir/cls.db" --lcm-url "file://$dir/novdata.log?speed=0" \
  2> "$dir/cls3.log" || { cat "$dir/cls3.log"; fail "amfid restarted again: exit status $?"; }
grep -qF "(auto: first 100 ok passages) was not collected from the passages that feed the rules now" "$dir/cls3.log" &&
  ! grep -q "window refilled" "$dir/cls3.log" ||
  { grep -i "window\|baseline" "$dir/cls3.log"; fail "class filter: a pooled automatic baseline was applied"; }
# and pooled again, a baseline collected under a filter is not applied either
qc "INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
    VALUES (0, 100, 30000, 3000, 'auto', 'first 100 ok passages of classes A23,A33 from 20000 kg')"
"$amfid" --config "$dir/amfid.yaml" --db "$dir/cls.db" --lcm-url "file://$dir/novdata.log?speed=0" \
  2> "$dir/cls4.log" || { cat "$dir/cls4.log"; fail "amfid restarted pooled: exit status $?"; }
grep -qF "(auto: first 100 ok passages of classes A23,A33 from 20000 kg) was not collected" "$dir/cls4.log" &&
  ! grep -q "window refilled" "$dir/cls4.log" ||
  { grep -i "window\|baseline" "$dir/cls4.log"; fail "pooled: a filtered automatic baseline was applied"; }
echo "daemon_classes: the STD and mean rules fed $fed of the $((fed + other + light)) ok passages (classes A23,A33 from 20 t), refilled with them after a restart"
