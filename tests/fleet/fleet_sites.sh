#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fleet_sites.sh: the sites themselves in the central database (central
# schema version 8), against a throwaway PostgreSQL (tests/common/pg_server.sh):
# - a site's name, position and bridge type (the store's meta, as amfid
#   writes them from site.* of amfid.yaml) shipped into fleet_sites, a
#   change shipped by the next pass; a bad value refused naming the key;
# - a second store claiming the same site id refused with a message that
#   says so, since when and what to do (exit 3, nothing shipped); a copy of
#   the site's own store restored from an older backup still told so;
# - a central database of version 7 migrated: each site's row made from its
#   first run, the second store still refused;
# - the views give times as timestamptz, exact to the µs;
# - amfi-report --pg: the fleet summary with the site's name, exported as
#   CSV and JSON (parsed), and one site's plots titled by its name;
# - roles.sql (the installed file): applied again changes nothing; applied
#   to a database whose rights and policies were lost, a site's role can
#   again neither write nor read another site's rows.
# Usage: fleet_sites.sh AMFI_SYNC AMFI_REPORT SCHEMA_MD ROLES_SQL. Exit 77
# without sqlite3/PostgreSQL.
set -u
sync=$1 report=$2 doc=$3 roles=$4
command -v sqlite3 > /dev/null || { echo "fleet_sites.sh: no sqlite3: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp fleet_sites
failures=0
case=init
fail() { echo "FAIL $case: $*"; failures=$((failures + 1)); }
fleet_store_setup "$doc"
meta() { # DB KEY VALUE
    sqlite3 "$1" "INSERT INTO meta (key, value) VALUES ('$2', '$3')
                  ON CONFLICT (key) DO UPDATE SET value = excluded.value"
}
"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "--init-schema"
[ "$(pg_q 'SELECT max(version) FROM fleet_migrations')" = 10 ] || fail "schema version"

case=facts
mkstore "$tmp/a.db" a1-km12 300
meta "$tmp/a.db" site.name "Sava bridge, km 12 \"north\""
meta "$tmp/a.db" site.latitude 46.0512345
meta "$tmp/a.db" site.longitude 14.5054321
meta "$tmp/a.db" site.bridge_type "prestressed concrete slab"
mkstore "$tmp/b.db" b7-km3 200   # no name, no position
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "a: exit $?"
"$sync" --db "$tmp/b.db" --pg "$PG_CONNINFO" --once --quiet || fail "b: exit $?"
[ "$(pg_q "SELECT name || '|' || latitude || '|' || longitude || '|' || bridge_type || '|' || store_started_at
           FROM fleet_sites WHERE site_id = 'a1-km12'")" = \
  "Sava bridge, km 12 \"north\"|46.0512345|14.5054321|prestressed concrete slab|$(sqlite3 "$tmp/a.db" "SELECT started_at FROM runs WHERE id = 1")" ] ||
    fail "fleet_sites of a1-km12: $(pg_q "SELECT * FROM fleet_sites WHERE site_id = 'a1-km12'")"
[ "$(pg_q "SELECT coalesce(name, 'NULL') || coalesce(latitude::text, 'NULL') FROM fleet_sites WHERE site_id = 'b7-km3'")" = NULLNULL ] ||
    fail "b7-km3 without a name: $(pg_q "SELECT * FROM fleet_sites WHERE site_id = 'b7-km3'")"
meta "$tmp/a.db" site.name "Sava bridge, km 12"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "a again: exit $?"
[ "$(pg_q "SELECT name FROM fleet_sites WHERE site_id = 'a1-km12'")" = "Sava bridge, km 12" ] ||
    fail "a changed name was not shipped"
# values the loader would refuse: named, nothing shipped
cp "$tmp/a.db" "$tmp/bad.db"
add_rows "$tmp/bad.db" 10
before=$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'a1-km12'")
for kv in "site.latitude 91" "site.longitude east" "site.bridge_type $(printf 'a\tb')"; do
    cp "$tmp/bad.db" "$tmp/bad1.db"
    meta "$tmp/bad1.db" "${kv%% *}" "${kv#* }"
    "$sync" --db "$tmp/bad1.db" --pg "$PG_CONNINFO" --once 2> "$tmp/bad.log"
    rc=$?
    [ $rc = 3 ] && grep -q "refused: site 'a1-km12' store .*bad1.db: meta '${kv%% *}'" "$tmp/bad.log" ||
        fail "bad ${kv%% *}: exit $rc: $(cat "$tmp/bad.log")"
done
sqlite3 "$tmp/bad1.db" "DELETE FROM meta WHERE key = 'site.longitude'"
meta "$tmp/bad1.db" site.bridge_type "slab"
"$sync" --db "$tmp/bad1.db" --pg "$PG_CONNINFO" --once 2> "$tmp/bad.log"
[ $? = 3 ] && grep -q "meta 'site.latitude' without 'site.longitude'" "$tmp/bad.log" ||
    fail "half a position: $(cat "$tmp/bad.log")"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'a1-km12'")" = "$before" ] || fail "rows shipped beside a bad value"

case=second-store
# another store (its own first run) under the same site id
sleep 0.01
mkstore "$tmp/a-other.db" a1-km12 400
"$sync" --db "$tmp/a-other.db" --pg "$PG_CONNINFO" --once 2> "$tmp/other.log"
rc=$?
cat "$tmp/other.log"
[ $rc = 3 ] || fail "a second store of a1-km12: exit $rc, expected 3"
since=$(pg_q "SELECT to_char(claimed_at AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS\"Z\"') FROM fleet_sites WHERE site_id = 'a1-km12'")
grep -q "refused: another store already claims site id 'a1-km12': the central database has shipped it since $since" "$tmp/other.log" ||
    fail "the message does not say another store claims the site since $since"
grep -q "this store .*a-other.db was first started at $(sqlite3 "$tmp/a-other.db" "SELECT started_at FROM runs WHERE id = 1")" "$tmp/other.log" ||
    fail "the message does not name this store and its first start"
grep -q "its own site.id" "$tmp/other.log" && grep -q "deletes the site's central rows" "$tmp/other.log" ||
    fail "the message does not say what to do"
grep -q "older backup" "$tmp/other.log" && fail "a second store taken for a restored backup"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'a1-km12'")" = "$before" ] || fail "rows merged"
# the same store restored from an older backup: still told so
cp "$tmp/a.db" "$tmp/a-backup.db"
add_rows "$tmp/a.db" 50
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "a: exit $?"
"$sync" --db "$tmp/a-backup.db" --pg "$PG_CONNINFO" --once 2> "$tmp/backup.log"
[ $? = 3 ] && grep -q "older backup" "$tmp/backup.log" || fail "restored backup: $(cat "$tmp/backup.log")"
# a site shipped before central version 8: its claim from its first run
pg_q "DELETE FROM fleet_sites WHERE site_id = 'a1-km12'"
"$sync" --db "$tmp/a-other.db" --pg "$PG_CONNINFO" --once 2> "$tmp/other2.log"
[ $? = 3 ] && grep -q "another store already claims site id 'a1-km12'" "$tmp/other2.log" ||
    fail "without a fleet_sites row: $(cat "$tmp/other2.log")"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "a after its row was lost: exit $?"
[ "$(pg_q "SELECT name FROM fleet_sites WHERE site_id = 'a1-km12'")" = "Sava bridge, km 12" ] || fail "the row not made again"

case=migration-7-8
# a central database of version 7 with sites shipped: the migration gives
# each its fleet_sites row from its first run (claimed since that run's
# start), and the second store is still refused after it
pg_q "CREATE DATABASE up7"
U="host=$PG_DIR dbname=up7 user=postgres"
"$sync" --pg "$U" --init-schema --quiet || fail "up7: --init-schema"
"$sync" --db "$tmp/a.db" --pg "$U" --once --quiet || fail "up7: a: exit $?"
psql -X -q -v ON_ERROR_STOP=1 "$U" -c "ALTER TABLE passages DROP COLUMN loads_refused, DROP COLUMN fit_ratio;
    DROP VIEW fleet_summary; DROP TABLE fleet_sites;
    DELETE FROM fleet_migrations WHERE version >= 8" > "$tmp/up7.log" 2>&1 || fail "down to 7: $(cat "$tmp/up7.log")"
"$sync" --db "$tmp/a.db" --pg "$U" --once 2> "$tmp/up7.log"
[ $? = 0 ] || fail "up7: the owner's pass did not migrate: $(cat "$tmp/up7.log")"
started=$(sqlite3 "$tmp/a.db" "SELECT started_at FROM runs WHERE id = 1")
[ "$(psql -X -At "$U" -c "SELECT store_started_at || ' ' || (claimed_at = '$started'::timestamptz) || ' ' || name
     FROM fleet_sites WHERE site_id = 'a1-km12'")" = "$started true Sava bridge, km 12" ] ||
    fail "up7: fleet_sites after the migration: $(psql -X -At "$U" -c "SELECT * FROM fleet_sites")"
"$sync" --db "$tmp/a-other.db" --pg "$U" --once 2> "$tmp/up7.log"
[ $? = 3 ] && grep -q "another store already claims site id 'a1-km12'" "$tmp/up7.log" ||
    fail "up7: the second store after the migration: $(cat "$tmp/up7.log")"

case=timestamptz
for v in fleet_latest_state fleet_open_alerts fleet_window_trend fleet_latest_scale; do
    [ "$(pg_q "SELECT format_type(atttypid, atttypmod) FROM pg_attribute WHERE attrelid = '$v'::regclass AND attname = 'time'")" = \
      "timestamp with time zone" ] || fail "$v: no timestamptz column time"
    [ "$(pg_q "SELECT count(*) FROM pg_attribute WHERE attrelid = '$v'::regclass AND attname = 'utime'")" = 0 ] ||
        fail "$v still gives utime"
done
for c in last_passage last_shipped; do
    [ "$(pg_q "SELECT format_type(atttypid, atttypmod) FROM pg_attribute WHERE attrelid = 'fleet_summary'::regclass AND attname = '$c'")" = \
      "timestamp with time zone" ] || fail "fleet_summary.$c is not timestamptz"
done
# exact to the µs: an indicator at 2025-11-22T00:00:00.000123Z
pg_q "INSERT INTO indicators (site_id, id, utime, n, state) VALUES ('b7-km3', 999999, 1763769600000123, 1, 'watch')"
[ "$(PGTZ=UTC pg_q "SELECT time FROM fleet_latest_state WHERE site_id = 'b7-km3'")" = "2025-11-22 00:00:00.000123+00" ] ||
    fail "fleet_latest_state.time: $(PGTZ=UTC pg_q "SELECT time FROM fleet_latest_state WHERE site_id = 'b7-km3'")"

case=summary
"$report" --pg "$PG_CONNINFO" > "$tmp/sum.txt" 2>&1 || fail "summary: exit $?: $(cat "$tmp/sum.txt")"
grep -q "^a1-km12 .*  Sava bridge, km 12$" "$tmp/sum.txt" || fail "the summary does not name a1-km12: $(cat "$tmp/sum.txt")"
grep -q "^b7-km3 .*  -$" "$tmp/sum.txt" || fail "b7-km3 without a name: $(cat "$tmp/sum.txt")"
"$report" --pg "$PG_CONNINFO" --format csv > "$tmp/sum.csv" 2> "$tmp/err" || fail "csv: exit $?: $(cat "$tmp/err")"
"$report" --pg "$PG_CONNINFO" --format json > "$tmp/sum.json" 2> "$tmp/err" || fail "json: exit $?: $(cat "$tmp/err")"
cat "$tmp/sum.csv" "$tmp/sum.json"
want=$(pg_q "SELECT string_agg(site_id || ' ' || passages || ' ' || state || ' ' || open_alerts, ';' ORDER BY site_id) FROM fleet_summary")
python3 - "$tmp/sum.csv" "$tmp/sum.json" "$want" <<'PY' || fail "the exports do not parse or differ from fleet_summary"
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1], newline='')))
doc = json.load(open(sys.argv[2]))
want = sys.argv[3]
assert list(rows[0].keys()) == ["site_id", "name", "latitude", "longitude", "bridge_type", "passages",
                                "last_passage", "state", "std_ratio", "open_alerts", "last_shipped"], rows[0].keys()
for got in (';'.join(f"{r['site_id']} {r['passages']} {r['state']} {r['open_alerts']}" for r in rows),
            ';'.join(f"{s['site_id']} {s['passages']} {s['state']} {s['open_alerts']}" for s in doc["sites"])):
    assert got == want, (got, want)
a = [r for r in rows if r["site_id"] == "a1-km12"][0]
assert a["name"] == "Sava bridge, km 12" and abs(float(a["latitude"]) - 46.0512345) < 1e-9, a
assert a["bridge_type"] == "prestressed concrete slab" and a["last_passage"].endswith("Z"), a
j = [s for s in doc["sites"] if s["site_id"] == "a1-km12"][0]
assert j["name"] == a["name"] and abs(j["longitude"] - 14.5054321) < 1e-9 and isinstance(j["passages"], int), j
b = [s for s in doc["sites"] if s["site_id"] == "b7-km3"][0]
assert b["name"] is None and b["latitude"] is None, b
assert doc["fleet"]["n_sites"] == len(rows) == 2, doc["fleet"]
PY
"$report" --pg "$PG_CONNINFO" --format csv --summary > /dev/null 2>&1 && fail "csv of a section without --site accepted"
# a name the sites would never ship is refused, not printed
pg_q "UPDATE fleet_sites SET name = E'x\\ty' WHERE site_id = 'b7-km3'"
"$report" --pg "$PG_CONNINFO" --format csv > /dev/null 2> "$tmp/err"
[ $? != 0 ] && grep -q "(site 'b7-km3'): fleet_sites.name is not" "$tmp/err" || fail "a bad name: $(cat "$tmp/err")"
pg_q "UPDATE fleet_sites SET name = NULL WHERE site_id = 'b7-km3'"
# one site's plots are titled by its name, not the temporary store's file
mkstore "$tmp/p.db" p-1 200
sqlite3 "$tmp/p.db" "UPDATE passages SET reason = 'gap' WHERE reason <> ''"
meta "$tmp/p.db" site.name "Most čez Savo"
"$sync" --db "$tmp/p.db" --pg "$PG_CONNINFO" --once --quiet || fail "p: exit $?"
"$report" --pg "$PG_CONNINFO" --site p-1 --plot "$tmp/plots" > "$tmp/plot.log" 2>&1 || fail "plot: exit $?: $(tail -3 "$tmp/plot.log")"
grep -q "Most čez Savo" "$tmp/plots/data/plots.gp" || fail "the plots are not titled by the site's name"

case=roles
A="host=$PG_DIR dbname=postgres user=amfi_sync_a1-km12"
as_a() { psql -X -q -At -v ON_ERROR_STOP=1 "$A" -c "$1"; }
"$sync" --pg "$PG_CONNINFO" --init-site-role a1-km12 --quiet || fail "--init-site-role a1-km12"
"$sync" --db "$tmp/a.db" --pg "$A" --once --quiet || fail "a1-km12's own role: exit $?"
attacks() { # 0 when every attack of A on b7-km3 failed
    ok=0
    as_a "INSERT INTO passages (site_id, id, vehicle_id, utime, lane, n_axles, status, reason, stored_at)
          VALUES ('b7-km3', 900000, 1, 1763769600000000, 1, 2, 'gap', '', 'x')" 2> /dev/null && ok=1
    as_a "UPDATE fleet_sites SET name = 'forged' WHERE site_id = 'b7-km3'" 2> /dev/null
    [ "$(pg_q "SELECT coalesce(name, '') FROM fleet_sites WHERE site_id = 'b7-km3'")" = forged ] && ok=1
    as_a "INSERT INTO fleet_sites (site_id, name) VALUES ('c9-new', 'forged')" 2> /dev/null && ok=1
    [ "$(as_a "SELECT count(*) FROM fleet_sites WHERE site_id <> 'a1-km12'" 2> /dev/null || echo 0)" = 0 ] || ok=1
    [ "$(as_a "SELECT count(*) FROM passages WHERE site_id = 'b7-km3'" 2> /dev/null || echo 0)" = 0 ] || ok=1
    as_a "SELECT count(*) FROM fleet_summary" > /dev/null 2>&1 && ok=1
    return $ok
}
attacks || fail "a site's role wrote or read another site's rows after the migration"
psql -X -q -v ON_ERROR_STOP=1 "$PG_CONNINFO" -f "$roles" > "$tmp/roles.log" 2>&1 || fail "roles.sql again: $(cat "$tmp/roles.log")"
pg_dump -s "$PG_CONNINFO" | grep -v '^\\\(un\)\?restrict ' > "$tmp/before.sql"
psql -X -q -v ON_ERROR_STOP=1 "$PG_CONNINFO" -f "$roles" > "$tmp/roles.log" 2>&1 || fail "roles.sql a third time"
pg_dump -s "$PG_CONNINFO" | grep -v '^\\\(un\)\?restrict ' > "$tmp/after.sql"
cmp -s "$tmp/before.sql" "$tmp/after.sql" || fail "roles.sql run again changed the schema: $(diff "$tmp/before.sql" "$tmp/after.sql" | head -5)"
# the rights and policies lost (every table open to the sites' group)
pg_q "DO \$\$ DECLARE t text; BEGIN
        FOREACH t IN ARRAY ARRAY['passages', 'axles', 'indicators', 'alerts', 'baseline', 'runs',
                                 'environment', 'scale_evals', 'fleet_sync_state', 'fleet_sites'] LOOP
          EXECUTE format('DROP POLICY fleet_site ON %I', t);
          EXECUTE format('ALTER TABLE %I DISABLE ROW LEVEL SECURITY', t);
          EXECUTE format('GRANT ALL ON %I TO amfi_site', t);
        END LOOP;
      END \$\$; GRANT ALL ON fleet_summary TO amfi_site"
attacks && fail "the test's loss of the rights did not open the tables"
pg_q "DELETE FROM passages WHERE id = 900000; DELETE FROM fleet_sites WHERE site_id = 'c9-new';
      UPDATE fleet_sites SET name = NULL WHERE site_id = 'b7-km3'"
psql -X -q -v ON_ERROR_STOP=1 "$PG_CONNINFO" -f "$roles" > "$tmp/roles.log" 2>&1 || fail "roles.sql: $(cat "$tmp/roles.log")"
# roles.sql binds again what it grants; the extra rights given above stay
# the owner's business (roles.sql grants, it does not revoke what it never gave)
pg_q "REVOKE ALL ON passages, axles, indicators, alerts, baseline, runs, environment, scale_evals,
        fleet_sync_state, fleet_sites, fleet_summary FROM amfi_site"
psql -X -q -v ON_ERROR_STOP=1 "$PG_CONNINFO" -f "$roles" > "$tmp/roles.log" 2>&1 || fail "roles.sql: $(cat "$tmp/roles.log")"
attacks || fail "after roles.sql a site's role writes or reads another site's rows"
"$sync" --db "$tmp/a.db" --pg "$A" --once --quiet || fail "a1-km12's own role after roles.sql: exit $?"
fleet_same "$tmp/a.db" a1-km12

[ $failures = 0 ] || { echo "fleet_sites: $failures failure(s)"; exit 1; }
echo "fleet_sites: ok"
