#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_pg.sh: amfi-report --pg against a throwaway PostgreSQL
# (tests/common/pg_server.sh). Two site stores (amfi-fleet-bench, 3 days x 400) are
# shipped with amfi-sync; then the fleet summary has one line per site with
# its counts, and the report of one site from the central database equals
# the report of its store: the default sections, the CSV and JSON exports,
# the histogram, the plots. A third site with issue 14's data (temperatures,
# scale blocks, known-truck runs, natural frequency, the weight the STD rule
# was fed) gives the same temperature, scale, known-truck, natural-frequency
# and fed-GVW lines, exports and plot data from the central database as from
# its store. An unknown site (exit 2, the sites listed), a
# central row the store schema refuses (exit 1, named), a stopped server
# (exit 1, one line, no password) and the options that make no sense
# centrally (exit 2) are refused.
# No temporary store is left behind.
# Usage: report_pg.sh AMFI_REPORT AMFI_SYNC AMFI_FLEET_BENCH. Exit 77 without PostgreSQL.
set -u
report=$1 sync=$2 bench=$3
command -v sqlite3 > /dev/null || { echo "report_pg.sh: no sqlite3: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp report_pg
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
mkdir "$tmp/t"
export TMPDIR="$tmp/t"

"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "--init-schema"
"$bench" --pg "$PG_CONNINFO" --sync "$sync" --dir "$tmp/st" --sites 2 --days 3 --per-day 400 \
    > "$tmp/bench.log" || { cat "$tmp/bench.log"; fail "amfi-fleet-bench"; exit 1; }
a=$tmp/st/bench-000.db

# the fleet summary: one line per site, passages, open alerts (site 0 has one)
"$report" --pg "$PG_CONNINFO" > "$tmp/fleet.txt" || fail "fleet summary: exit $?"
cat "$tmp/fleet.txt"
grep -q "^fleet  *2 sites" "$tmp/fleet.txt" || fail "fleet summary: no '2 sites' line"
grep -Eq "^bench-000 +1200 +2025-01-03T..:..Z +baseline +[0-9.]+ +1 " "$tmp/fleet.txt" ||
    fail "fleet summary: bench-000 line"
grep -Eq "^bench-001 +1200 .* 0 +[0-9]{4}-" "$tmp/fleet.txt" || fail "fleet summary: bench-001 line"

# one site: the same report as from its store (up to the 'Next' hints,
# which name sqlite3 and the file there, psql and the views here)
site=bench-000
same() {
    "$report" --db "$a" "$@" > "$tmp/db.out" 2>&1 || fail "--db $*: exit $?"
    "$report" --pg "$PG_CONNINFO" --site $site "$@" > "$tmp/pg.out" 2>&1 || fail "--pg $*: exit $?"
    sed '/^Next, with/,$d' "$tmp/db.out" > "$tmp/db.cut"
    sed '/^Next, with/,$d' "$tmp/pg.out" > "$tmp/pg.cut"
    cmp -s "$tmp/db.cut" "$tmp/pg.cut" || { diff "$tmp/db.cut" "$tmp/pg.cut" | head; fail "--pg differs: $*"; }
    [ -s "$tmp/pg.cut" ] || fail "--pg $*: no output"
}
same
same --passages --format csv
same --format json
same --histogram --lane 1
same --overloads --from 2025-01-02
"$report" --pg "$PG_CONNINFO" --site bench-000 > "$tmp/pg.out"
grep -q "^  psql -c \"SELECT \* FROM fleet_daily_trend WHERE site_id = 'bench-000'" "$tmp/pg.out" ||
    fail "no psql hint"
grep -q "host=\|dbname=" "$tmp/pg.out" && fail "the connection string is echoed"
if command -v gnuplot > /dev/null; then
    "$report" --db "$a" --plot "$tmp/p1" > /dev/null 2>&1 || fail "--db --plot"
    "$report" --pg "$PG_CONNINFO" --site bench-000 --plot "$tmp/p2" > /dev/null 2>&1 || fail "--pg --plot"
    [ "$(ls "$tmp/p1")" = "$(ls "$tmp/p2")" ] && [ -n "$(ls "$tmp/p2")" ] ||
        fail "plots: '$(ls "$tmp/p1" | tr '\n' ' ')' vs '$(ls "$tmp/p2" | tr '\n' ' ')'"
fi

# issue 14's data (tables environment and scale_evals, the passages' deck
# temperature, known-truck weight, natural frequency): a copy of bench-000's
# store as site-14 with them added, shipped; its report from the central
# database has the same temperature, scale, known-truck and natural-frequency
# lines and plots as from the store.
cp "$a" "$tmp/i14.db"
sqlite3 "$tmp/i14.db" "UPDATE meta SET value = 'site-14' WHERE key = 'site.id'" || fail "site-14 store"
fleet_issue14_rows "$tmp/i14.db"
"$sync" --db "$tmp/i14.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync of site-14: exit $?"
a=$tmp/i14.db site=site-14
same
same --summary
same --format json
same --summary --format csv
"$report" --pg "$PG_CONNINFO" --site site-14 --summary > "$tmp/pg14.out" 2>&1
for line in '^temperature  deck -20\.2 \.\. 3\.2 °C, air -21\.8 \.\. 1\.8 °C, 48 readings' \
            '^scale        20 blocks, newest 2025-11-22 23:00 UTC: 1\.0303 compensated' \
            '^known truck  6 runs, ratio inferred/reference' '^natural f1   n [1-9][0-9]*, raw mean 3\.' \
            '^GVW, fed     n [1-9][0-9]*, mean [0-9]* kg'; do
    grep -q "$line" "$tmp/pg14.out" || fail "site-14 --pg: no line /$line/: $(cat "$tmp/pg14.out")"
done
if command -v gnuplot > /dev/null; then
    "$report" --db "$a" --plot "$tmp/p3" > /dev/null 2>&1 || fail "site-14 --db --plot"
    "$report" --pg "$PG_CONNINFO" --site site-14 --plot "$tmp/p4" > /dev/null 2>&1 || fail "site-14 --pg --plot"
    # the plots' data (the PNGs name the source in their titles)
    for f in scale known_truck natfreq temperature; do
        [ -s "$tmp/p4/$f.png" ] && [ -s "$tmp/p4/data/$f.dat" ] &&
            cmp -s "$tmp/p3/data/$f.dat" "$tmp/p4/data/$f.dat" || fail "site-14 plots: $f differs or is missing"
    done
    [ "$(ls "$tmp/p3")" = "$(ls "$tmp/p4")" ] || fail "site-14 plots: '$(ls "$tmp/p3" | tr '\n' ' ')' vs '$(ls "$tmp/p4" | tr '\n' ' ')'"
fi
a=$tmp/st/bench-000.db site=bench-000

# refusals
"$report" --pg "$PG_CONNINFO" --site nope 2> "$tmp/e1"
rc=$?
[ $rc = 2 ] || fail "unknown site: exit $rc"
grep -q "no site 'nope' in the central database (sites: bench-000, bench-001, site-14)" "$tmp/e1" ||
    fail "unknown site: $(cat "$tmp/e1")"
for args in "--site bench-000" "--pg x --db $a" "--pg x --site bench-000 --set-baseline-last 10" \
            "--pg x --site bench-000 --check" "--pg x --summary" "--pg x --site 'bad id'"; do
    eval "\"\$report\" $args" > /dev/null 2>&1
    rc=$?
    [ $rc = 2 ] || fail "amfi-report $args: exit $rc, expected 2"
done
# a bad row in the fleet summary's sources: an error naming the site, no table
pg_q "UPDATE indicators SET state = 'wobbly' WHERE site_id = 'bench-001' AND id =
      (SELECT indicator_id FROM fleet_latest_state WHERE site_id = 'bench-001')"
"$report" --pg "$PG_CONNINFO" > "$tmp/o5" 2> "$tmp/e5"
rc=$?
[ $rc = 1 ] || fail "fleet summary, bad state: exit $rc"
grep -q "^amfi-report: --pg: fleet summary: central row 2 (site 'bench-001'): fleet_latest_state.state is not" "$tmp/e5" ||
    fail "fleet summary, bad state: $(cat "$tmp/e5")"
[ -s "$tmp/o5" ] && fail "fleet summary, bad state: printed a table"
pg_q "UPDATE indicators SET state = 'normal', std_ratio = -1 WHERE site_id = 'bench-001' AND id =
      (SELECT indicator_id FROM fleet_latest_state WHERE site_id = 'bench-001')"
"$report" --pg "$PG_CONNINFO" > /dev/null 2> "$tmp/e5"
rc=$?
[ $rc = 1 ] || fail "fleet summary, negative ratio: exit $rc"
grep -q "(site 'bench-001'): fleet_latest_state.std_ratio is not a ratio" "$tmp/e5" ||
    fail "fleet summary, negative ratio: $(cat "$tmp/e5")"
pg_q "UPDATE indicators SET std_ratio = 1 WHERE site_id = 'bench-001'"
pg_q "UPDATE fleet_sync_state SET site_id = 'bad site' || chr(10) || 'x' WHERE site_id = 'bench-001'"
"$report" --pg "$PG_CONNINFO" > /dev/null 2> "$tmp/e5"
rc=$?
[ $rc = 1 ] || fail "fleet summary, bad site id: exit $rc"
[ "$(wc -l < "$tmp/e5")" = 1 ] && grep -q "(site 'bad site?x'): site_id is not a valid site id" "$tmp/e5" ||
    fail "fleet summary, bad site id: $(cat "$tmp/e5")"
pg_q "UPDATE fleet_sync_state SET site_id = 'bench-001' WHERE site_id LIKE 'bad site%'"
"$report" --pg "$PG_CONNINFO" > /dev/null || fail "fleet summary after the repairs: exit $?"
pg_q "INSERT INTO passages (site_id, id, vehicle_id, utime, lane, n_axles, status, reason, stored_at)
      VALUES ('bench-001', 99999, 1, 1735776000000000, 99999, 2, 'gap', '', 'x')"
"$report" --pg "$PG_CONNINFO" --site bench-001 2> "$tmp/e2" > /dev/null
rc=$?
[ $rc = 1 ] || fail "a bad central row: exit $rc"
grep -q "central passages row (site 'bench-001', id 99999) refused by the store schema: CHECK" "$tmp/e2" ||
    fail "a bad central row: $(cat "$tmp/e2")"
pg_stop
"$report" --pg "$PG_CONNINFO" --site bench-000 2> "$tmp/e3" > /dev/null
rc=$?
[ $rc = 1 ] || fail "server stopped: exit $rc"
grep -q "cannot connect to PostgreSQL" "$tmp/e3" || fail "server stopped: $(cat "$tmp/e3")"
[ "$(wc -l < "$tmp/e3")" = 1 ] || fail "server stopped: not one line: $(cat "$tmp/e3")"
grep -q "Is the server running" "$tmp/e3" || fail "server stopped: libpq's hint lost: $(cat "$tmp/e3")"
"$report" --pg "$PG_CONNINFO password=sekret-pw" 2> "$tmp/e4" > "$tmp/o4"
rc=$?
[ $rc = 1 ] || fail "fleet summary, server stopped: exit $rc"
[ "$(wc -l < "$tmp/e4")" = 1 ] || fail "fleet summary, server stopped: not one line: $(cat "$tmp/e4")"
grep -q sekret "$tmp/e4" "$tmp/o4" && fail "server stopped: the password is printed"
[ -z "$(ls "$tmp/t")" ] || fail "temporary files left: $(ls "$tmp/t")"
[ $failures = 0 ] && echo "report_pg.sh: all cases pass"
exit $((failures != 0))
