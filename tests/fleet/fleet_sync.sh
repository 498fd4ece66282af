#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fleet_sync.sh: amfi-sync against a real PostgreSQL server (tests/common/pg_server.sh):
# three sites at once; a writer appending while sync reads; kill -9 of
# amfi-sync 10 times at random moments; the server stopped and restarted while
# amfi-sync follows; a store restored from an older backup refused. After each
# case the central counts equal the sites', with no duplicate and no gap.
# Then --config (amfid's YAML: store and site from it) and follow mode under a
# stand-in systemd notification socket (READY, STATUS, WATCHDOG, STOPPING).
# The roles of docs/fleet.md (its SQL block run as written): the writer role
# syncs, the analysts' role reads the views and cannot write. Issue 14's data
# (environment, scale_evals, the passages' temperature, known-truck weight and
# natural frequency) shipped and compared column by column; values that break
# the site store's rules refused (exit 3, named, nothing shipped); a central
# database of version 4 migrated to 5 by the owner, then synced by the writer.
# Usage: fleet_sync.sh AMFI_SYNC SCHEMA_MD NOTIFY_LISTEN FLEET_MD. Exit 77
# without sqlite3/PostgreSQL.
set -u
sync=$1 doc=$2 listen=$3 fleetdoc=$4
command -v sqlite3 > /dev/null || { echo "fleet_sync.sh: no sqlite3: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp fleet_sync
failures=0
fail() { echo "FAIL $case: $*"; failures=$((failures + 1)); }

fleet_store_setup "$doc"

# same DB SITE: central rows of the site equal the store's, no gap
# (fleet_same, pg_server.sh), and text copied exactly.
same() {
    fleet_same "$1" "$2"
    l=$(sqlite3 "$1" "SELECT reason FROM passages WHERE id = 10")
    c=$(pg_q "SELECT reason FROM passages WHERE site_id = '$2' AND id = 10")
    [ "$l" = "$c" ] || fail "$2: text not copied exactly: '$l' vs '$c'"
}

case=init
"$sync" --pg "$PG_CONNINFO" --init-schema 2> "$tmp/init.log" || fail "--init-schema: $(cat "$tmp/init.log")"
[ "$(pg_q 'SELECT max(version) FROM fleet_migrations')" = 10 ] || fail "schema version"
# a central database of version 1 migrates on the next contact (the views of
# version 8 stay: each version's views are dropped and made again upward)
v10_down="ALTER TABLE passages DROP COLUMN loads_refused;"
v9_down="$v10_down ALTER TABLE passages DROP COLUMN fit_ratio;"
v8_down="$v9_down DROP VIEW fleet_summary; DROP TABLE fleet_sites;"
v7_down="$v8_down ALTER TABLE passages DROP COLUMN class, DROP COLUMN axle_groups, DROP COLUMN overload;"
v6_down="$v7_down DO \$\$ DECLARE t text; BEGIN
        FOREACH t IN ARRAY ARRAY['passages', 'axles', 'indicators', 'alerts', 'baseline', 'runs',
                                 'environment', 'scale_evals', 'fleet_sync_state'] LOOP
          EXECUTE format('DROP POLICY fleet_site ON %I', t);
          EXECUTE format('DROP POLICY fleet_reader ON %I', t);
          EXECUTE format('ALTER TABLE %I DISABLE ROW LEVEL SECURITY', t);
        END LOOP;
      END \$\$;
      DROP TABLE fleet_site_roles;"
v5_down="$v6_down DROP VIEW fleet_latest_scale; DROP TABLE environment, scale_evals;
      ALTER TABLE passages DROP COLUMN reference_gvw_kg, DROP COLUMN deck_c, DROP COLUMN f1_hz,
      DROP COLUMN f1_comp_hz, DROP COLUMN f1_zeta, DROP COLUMN f1_r2, DROP COLUMN gvw_comp_kg;"
pg_q "$v5_down DROP VIEW fleet_window_trend; ALTER TABLE passages DROP COLUMN speed_given_mps,
      DROP COLUMN speed_estimated, DROP COLUMN n_vehicles, DROP COLUMN quality;
      DELETE FROM fleet_migrations WHERE version > 1"
"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "migration 1 -> 10"
[ "$(pg_q 'SELECT max(version) FROM fleet_migrations')" = 10 ] || fail "not migrated to 10"
pg_q "SELECT count(*) FROM fleet_window_trend" > /dev/null || fail "no fleet_window_trend after migration"
grep -q password "$tmp/init.log" && fail "log mentions a password"
# docs/fleet.md's DDL of versions 5 to 10 (version 10's followed by
# fleet/roles.sql, as amfi-sync runs it) is what amfi-sync applies: a
# database migrated by it and one taken back to version 4 and given the
# document's blocks have the same schema (tables, policies, rights)
for v in 5 6 7 8 9 10; do
    awk "/^<!-- fleet-v$v:begin -->/ { on = 1; next } /^<!-- fleet-v$v:end -->/ { on = 0 }
         on && !/^\`\`\`/" "$fleetdoc" > "$tmp/v$v.sql"
    [ -s "$tmp/v$v.sql" ] || fail "no version $v block in $fleetdoc"
done
for d in docv5a docv5b; do
    pg_q "CREATE DATABASE $d"
    "$sync" --pg "host=$PG_DIR dbname=$d user=postgres" --init-schema --quiet || fail "$d: --init-schema"
done
psql -X -q -v ON_ERROR_STOP=1 "host=$PG_DIR dbname=docv5b user=postgres" -c "$v5_down" -f "$tmp/v5.sql" \
    -f "$tmp/v6.sql" -f "$tmp/v7.sql" -f "$tmp/v8.sql" -f "$tmp/v9.sql" -f "$tmp/v10.sql" -f "$(dirname "$fleetdoc")/../fleet/roles.sql" \
    > "$tmp/v5.log" 2>&1 || fail "docs/fleet.md's version 5 to 10 blocks: $(cat "$tmp/v5.log")"
for d in docv5a docv5b; do
    pg_dump -s -T fleet_migrations "host=$PG_DIR dbname=$d user=postgres" > "$tmp/$d.dump" || fail "pg_dump $d"
    grep -v "^\\\\\(un\)\?restrict " "$tmp/$d.dump" > "$tmp/$d.sql"  # a random key per dump
done
cmp -s "$tmp/docv5a.sql" "$tmp/docv5b.sql" ||
    fail "docs/fleet.md's versions 5 to 10 differ from amfi-sync's: $(diff "$tmp/docv5a.sql" "$tmp/docv5b.sql" | head -6)"

case=three-sites
for s in a b c; do mkstore "$tmp/$s.db" "site-$s" 3000; done
for s in a b c; do "$sync" --db "$tmp/$s.db" --pg "$PG_CONNINFO" --once --quiet & done
wait
for s in a b c; do same "$tmp/$s.db" "site-$s"; done
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once || fail "second --once failed"
same "$tmp/a.db" site-a

case=issue14
# issue 14's data (temperatures, scale blocks, known-truck runs, natural
# frequency) shipped: every central row equal to the store's, column by column
mkstore "$tmp/i.db" site-i 3000
fleet_issue14_rows "$tmp/i.db"
"$sync" --db "$tmp/i.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync: exit $?"
same "$tmp/i.db" site-i
for t in passages axles indicators alerts baseline runs environment scale_evals; do
    fleet_columns_same "$tmp/i.db" site-i $t
done
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-i' AND f1_hz IS NOT NULL")" = \
  "$(sqlite3 "$tmp/i.db" "SELECT count(*) FROM passages WHERE f1_hz IS NOT NULL")" ] &&
    [ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-i' AND reference_gvw_kg IS NOT NULL")" -gt 10 ] ||
    fail "natural frequencies or known trucks not shipped"
[ "$(pg_q "SELECT string_agg(kind || ' ' || state || ' ' || n, ', ' ORDER BY kind) FROM fleet_latest_scale
           WHERE site_id = 'site-i'")" = "known_truck normal 6, scale_shift alert 200" ] ||
    fail "fleet_latest_scale: $(pg_q "SELECT * FROM fleet_latest_scale WHERE site_id = 'site-i'")"
# the new tables' marks hold as the old ones: a copy whose environment or
# scale_evals row at the mark differs is refused, nothing merged
for t in environment scale_evals; do
    cp "$tmp/i.db" "$tmp/i-restored.db"
    sqlite3 "$tmp/i-restored.db" "UPDATE $t SET deck_c = deck_c + 0.5 WHERE id = (SELECT max(id) FROM $t)"
    "$sync" --db "$tmp/i-restored.db" --pg "$PG_CONNINFO" --once 2> "$tmp/i-restored.log"
    rc=$?
    [ $rc = 3 ] && grep -q "refused: site 'site-i' table $t: .* different row at that id" "$tmp/i-restored.log" ||
        fail "$t: a different row at the mark: exit $rc, $(cat "$tmp/i-restored.log")"
done
same "$tmp/i.db" site-i
# more of everything: the second pass ships only the new rows
add_rows "$tmp/i.db" 500
fleet_issue14_rows "$tmp/i.db" 3000
"$sync" --db "$tmp/i.db" --pg "$PG_CONNINFO" --once --quiet || fail "second sync: exit $?"
same "$tmp/i.db" site-i
for t in passages environment scale_evals; do fleet_columns_same "$tmp/i.db" site-i $t; done

case=bad-values
# A store that breaks its own rules (values written around amfid's checks):
# refused (exit 3) naming the table, the row and the column, and nothing of
# the pass shipped, not even the good rows of the other tables.
mkstore "$tmp/v.db" site-v 200
fleet_issue14_rows "$tmp/v.db"
"$sync" --db "$tmp/v.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync: exit $?"
add_rows "$tmp/v.db" 100
fleet_issue14_rows "$tmp/v.db" 200
counts() {
    pg_q "SELECT (SELECT count(*) FROM passages WHERE site_id = 'site-v') || ' ' ||
                 (SELECT count(*) FROM axles WHERE site_id = 'site-v') || ' ' ||
                 (SELECT count(*) FROM indicators WHERE site_id = 'site-v') || ' ' ||
                 (SELECT count(*) FROM environment WHERE site_id = 'site-v') || ' ' ||
                 (SELECT count(*) FROM scale_evals WHERE site_id = 'site-v')"
}
before=$(counts)
env_last=$(sqlite3 "$tmp/v.db" "SELECT max(id) FROM environment")
scale_last=$(sqlite3 "$tmp/v.db" "SELECT max(id) FROM scale_evals")
# bad_case WANT SQL [SQL2]: the SQL run on a copy of the store (checks off;
# SQL2 in a second session), then the copy refused with WANT in the message
bad_case() {
    cp "$tmp/v.db" "$tmp/vb.db"
    rm -f "$tmp/vb.db-wal" "$tmp/vb.db-shm"
    sqlite3 "$tmp/vb.db" "PRAGMA ignore_check_constraints = 1; $2" &&
        { [ -z "${3:-}" ] || sqlite3 "$tmp/vb.db" "PRAGMA ignore_check_constraints = 1; $3"; } ||
        fail "cannot make the bad row: $2 ${3:-}"
    "$sync" --db "$tmp/vb.db" --pg "$PG_CONNINFO" --once 2> "$tmp/bad.log"
    rc=$?
    [ $rc = 3 ] || fail "$2 ${3:-}: exit $rc, expected 3"
    grep -Fq "refused: site 'site-v' store $tmp/vb.db: $1" "$tmp/bad.log" ||
        fail "$2 ${3:-}: message: $(cat "$tmp/bad.log")"
    [ "$(counts)" = "$before" ] || fail "$2 ${3:-}: rows shipped: $before -> $(counts)"
}
bad_case "table passages, id 251, column deck_c: 1000000000 is not in [-60, 80]" \
    "UPDATE passages SET deck_c = 1e9 WHERE id = 251"
bad_case "table passages, id 252, column f1_hz: inf is not in (0, 1000]" \
    "UPDATE passages SET f1_hz = 1e999 WHERE id = 252"
# a NaN cannot be a REAL in SQLite: it comes as text, once the table is not STRICT
bad_case "table passages, id 255, column f1_hz: text, but it must be a number" \
    "PRAGMA writable_schema = ON;
     UPDATE sqlite_schema SET sql = replace(sql, ') STRICT', ')') WHERE name = 'passages'" \
    "UPDATE passages SET f1_hz = 'NaN' WHERE id = 255"
bad_case "table axles, passage_id 260, idx 2, column load_kg: 2000000 is not in [-1000000, 1000000]" \
    "UPDATE axles SET load_kg = 2e6 WHERE passage_id = 260 AND idx = 2"
bad_case "table environment, id $env_last, column air_c: -inf is not in [-60, 80]" \
    "UPDATE environment SET air_c = -1e999 WHERE id = $env_last"
bad_case "table scale_evals, id $scale_last, column kind: 'bogus' is not one of scale_shift|known_truck" \
    "UPDATE scale_evals SET kind = 'bogus' WHERE id = $scale_last"
bad_case "table alerts, id 6, column message: text that is not valid UTF-8 (or holds a NUL byte)" \
    "UPDATE alerts SET message = CAST(X'41C328' AS TEXT) WHERE id = 6"
bad_case "table passages, id 280, column status: 'fine' is not one of ok|gap|late|overload|multiple|invalid|error" \
    "UPDATE passages SET status = 'fine' WHERE id = 280"
"$sync" --db "$tmp/v.db" --pg "$PG_CONNINFO" --once --quiet || fail "the good store after the bad ones: exit $?"
same "$tmp/v.db" site-v

case=writer
( for i in 1 2 3 4 5 6 7 8; do add_rows "$tmp/b.db" 500; done ) &
w=$!
while kill -0 $w 2> /dev/null; do "$sync" --db "$tmp/b.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync during writes"; done
wait $w
"$sync" --db "$tmp/b.db" --pg "$PG_CONNINFO" --once --quiet || fail "final sync"
same "$tmp/b.db" site-b

case=kill9
# Each round appends 10 000 passages (two batches of 5000), starts amfi-sync,
# waits for its first batch to commit and kills it 0..9 ms later: the kills
# land in the middle of a sync, at varying points of the second batch (ten
# rounds: twenty took two minutes under the sanitizers, every kill mid-sync).
mkstore "$tmp/k.db" site-k 4000
i=0 mid=0
while [ $i -lt 10 ]; do
    add_rows "$tmp/k.db" 10000
    n0=$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-k'")
    "$sync" --db "$tmp/k.db" --pg "$PG_CONNINFO" --once --quiet 2> /dev/null &
    p=$!
    while kill -0 $p 2> /dev/null &&
        [ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-k'")" = "$n0" ]; do :; done
    sleep "0.00$(od -An -N1 -tu1 /dev/urandom | tr -d ' ' | cut -c1)"
    kill -9 $p 2> /dev/null
    wait $p 2> /dev/null
    [ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-k'")" -lt "$(sqlite3 "$tmp/k.db" 'SELECT count(*) FROM passages')" ] &&
        mid=$((mid + 1))
    i=$((i + 1))
done
echo "kill9: $mid of 10 kills left the site partly shipped"
[ $mid -ge 3 ] || fail "only $mid of 10 kills landed before the end of a sync"
"$sync" --db "$tmp/k.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync after the kills"
same "$tmp/k.db" site-k

case=restart
mkstore "$tmp/r.db" site-r 2000
"$sync" --db "$tmp/r.db" --pg "$PG_CONNINFO" --interval 0.2 --quiet 2> "$tmp/follow.log" &
f=$!
sleep 1
pg_stop
add_rows "$tmp/r.db" 2000
sleep 2
pg_restart_start
# follow mode retries with a capped backoff (1, 2, 4 ... 60 s): wait until it
# has shipped what was added while the server was away, every table (at most
# 90 s), not a fixed time, which a loaded machine's slow first pass outlasts;
# a pass ships the tables one after the other and SIGTERM stops it after the
# batch in flight (the passages alone were seen shipped, alerts still to come)
k=0
while [ $k -lt 900 ] && kill -0 $f 2> /dev/null && ! fleet_synced "$tmp/r.db" site-r; do
    sleep 0.1
    k=$((k + 1))
done
kill -TERM $f
wait $f || fail "follow mode did not stop cleanly on SIGTERM: $?"
same "$tmp/r.db" site-r
grep -q "cannot connect" "$tmp/follow.log" || fail "no message while the server was away"

case=restored
cp "$tmp/c.db" "$tmp/c-backup.db"
add_rows "$tmp/c.db" 100
"$sync" --db "$tmp/c.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync c"
before=$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-c'")
add_rows "$tmp/c-backup.db" 10   # fewer new rows than shipped: ids go backwards
"$sync" --db "$tmp/c-backup.db" --pg "$PG_CONNINFO" --once 2> "$tmp/restored.log"
rc=$?
[ $rc = 3 ] || fail "restored store: exit $rc, expected 3"
grep -q "refused: site 'site-c'.*older backup" "$tmp/restored.log" || fail "message: $(cat "$tmp/restored.log")"
cp "$tmp/c.db" "$tmp/c-backup2.db"
sqlite3 "$tmp/c-backup2.db" "UPDATE runs SET version = '0.other' WHERE id = 1"
"$sync" --db "$tmp/c-backup2.db" --pg "$PG_CONNINFO" --once 2> "$tmp/restored2.log"
[ $? = 3 ] || fail "a different row at a shipped id was not refused"
add_rows "$tmp/c-backup.db" 500  # ids past the mark, but the row at the mark differs
"$sync" --db "$tmp/c-backup.db" --pg "$PG_CONNINFO" --once 2> "$tmp/restored3.log"
[ $? = 3 ] || fail "restored store with more rows: not refused"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-c'")" = "$before" ] || fail "rows merged"
same "$tmp/c.db" site-c

case=old-store
# a store amfid has not migrated yet (version 3): nothing shipped, exit 1
# (retried in follow mode), the message says what to do
cp "$tmp/a.db" "$tmp/old.db"
sqlite3 "$tmp/old.db" "PRAGMA user_version = 3; UPDATE meta SET value = 'site-old' WHERE key = 'site.id'"
"$sync" --db "$tmp/old.db" --pg "$PG_CONNINFO" --once 2> "$tmp/old.log"
rc=$?
[ $rc = 1 ] || fail "a version-3 store: exit $rc, expected 1"
grep -q "store schema version 3, this amfi-sync needs" "$tmp/old.log" || fail "message: $(cat "$tmp/old.log")"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-old'")" = 0 ] || fail "a version-3 store shipped"
case=crafted-store
# a store from elsewhere whose alerts table is a view computing its rows (a
# function of an untrusted schema) and whose indicators is an fts5 virtual
# table: refused (exit 3) naming the object, nothing shipped
cp "$tmp/a.db" "$tmp/view.db"
rm -f "$tmp/view.db-wal" "$tmp/view.db-shm"
sqlite3 "$tmp/view.db" "UPDATE meta SET value = 'site-view' WHERE key = 'site.id';
ALTER TABLE alerts RENAME TO alerts_real;
CREATE VIEW alerts AS SELECT id, utime, level, json_extract('{\"k\":\"std_increase\"}', '\$.k') AS kind,
  message, indicator_id, raised FROM alerts_real;" || fail "cannot make the crafted store"
"$sync" --db "$tmp/view.db" --pg "$PG_CONNINFO" --once 2> "$tmp/view.log"
rc=$?
[ $rc = 3 ] || fail "a view in place of alerts: exit $rc, expected 3 ($(cat "$tmp/view.log"))"
grep -Fq "refused: store $tmp/view.db: 'alerts' is view, not a table" "$tmp/view.log" ||
    fail "message: $(cat "$tmp/view.log")"
cp "$tmp/a.db" "$tmp/vt.db"
rm -f "$tmp/vt.db-wal" "$tmp/vt.db-shm"
sqlite3 "$tmp/vt.db" "UPDATE meta SET value = 'site-view' WHERE key = 'site.id';
DROP TABLE indicators; CREATE VIRTUAL TABLE indicators USING fts5(x);" || fail "cannot make the fts5 store"
"$sync" --db "$tmp/vt.db" --pg "$PG_CONNINFO" --once 2> "$tmp/vt.log"
rc=$?
[ $rc = 3 ] || fail "fts5 in place of indicators: exit $rc, expected 3 ($(cat "$tmp/vt.log"))"
grep -Fq "refused: store $tmp/vt.db: 'indicators' is a virtual table, not a table" "$tmp/vt.log" ||
    fail "message: $(cat "$tmp/vt.log")"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-view'")" = 0 ] || fail "a crafted store shipped"
# the new columns ship as they are in the store
add_rows "$tmp/a.db" 20
sqlite3 "$tmp/a.db" "UPDATE passages SET speed_given_mps = 26.25, speed_estimated = 1, n_vehicles = 2, quality = 1.25 WHERE id = (SELECT max(id) FROM passages)"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync of estimated speeds"
[ "$(pg_q "SELECT speed_given_mps || ' ' || speed_estimated || ' ' || n_vehicles || ' ' || quality FROM passages WHERE site_id = 'site-a' ORDER BY id DESC LIMIT 1")" = "26.25 1 2 1.25" ] ||
    fail "speed_given_mps/speed_estimated/n_vehicles/quality not shipped"
# the class, groups and overload (store version 10, central version 7)
add_rows "$tmp/a.db" 2
sqlite3 "$tmp/a.db" "UPDATE passages SET class = 'A23', axle_groups = '1-1-3', overload = 1 WHERE id = (SELECT max(id) FROM passages)"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync of a class"
[ "$(pg_q "SELECT class || ' ' || axle_groups || ' ' || overload FROM passages WHERE site_id = 'site-a' ORDER BY id DESC LIMIT 1")" = "A23 1-1-3 1" ] ||
    fail "class/axle_groups/overload not shipped"
# the model fit (store version 12, central version 9)
add_rows "$tmp/a.db" 2
sqlite3 "$tmp/a.db" "UPDATE passages SET fit_ratio = 0.0125 WHERE id = (SELECT max(id) FROM passages)"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync of a model fit"
[ "$(pg_q "SELECT fit_ratio FROM passages WHERE site_id = 'site-a' ORDER BY id DESC LIMIT 1")" = 0.0125 ] ||
    fail "fit_ratio not shipped"
# the loads' refusal (store version 13, central version 10)
add_rows "$tmp/a.db" 2
sqlite3 "$tmp/a.db" "UPDATE passages SET loads_refused = 'group 2 (axles 2-3): load -3200 kg < 0' WHERE id = (SELECT max(id) FROM passages)"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync of a refusal"
[ "$(pg_q "SELECT loads_refused FROM passages WHERE site_id = 'site-a' ORDER BY id DESC LIMIT 1")" = "group 2 (axles 2-3): load -3200 kg < 0" ] ||
    fail "loads_refused not shipped"
same "$tmp/a.db" site-a

case=usage
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --site 'bad id' --once 2> /dev/null
[ $? = 2 ] || fail "bad --site accepted"

case=config
# amfid's configuration names the store and the site: explicit options win,
# a store of another site is refused, a bad file is named at its line.
printf 'site:\n  id: site-a\ndaemon:\n  store:\n    path: %s\n' "$tmp/a.db" > "$tmp/a.yaml"
add_rows "$tmp/a.db" 300
"$sync" --config "$tmp/a.yaml" --pg "$PG_CONNINFO" --once --quiet || fail "--config: exit $?"
same "$tmp/a.db" site-a
printf 'site:\n  id: site-zz\ndaemon:\n  store:\n    path: %s\n' "$tmp/a.db" > "$tmp/zz.yaml"
"$sync" --config "$tmp/zz.yaml" --pg "$PG_CONNINFO" --once 2> "$tmp/zz.log"
rc=$?
[ $rc = 2 ] || fail "a store of another site: exit $rc, expected 2"
grep -q "belongs to site 'site-a'.*zz.yaml: site.id gives 'site-zz'" "$tmp/zz.log" ||
    fail "message: $(cat "$tmp/zz.log")"
"$sync" --config "$tmp/zz.yaml" --site site-a --pg "$PG_CONNINFO" --once --quiet ||
    fail "--site does not win over the configuration"
printf 'site:\n  id: site-a\n  idd: x\n' > "$tmp/bad.yaml"
"$sync" --config "$tmp/bad.yaml" --pg "$PG_CONNINFO" --once 2> "$tmp/bad.log"
rc=$?
[ $rc = 2 ] || fail "bad configuration: exit $rc"
grep -q "bad.yaml:3: site.idd: unknown key" "$tmp/bad.log" || fail "message: $(cat "$tmp/bad.log")"

case=roles
# docs/fleet.md's roles block run as written: an analyst and a site's role
awk '/^<!-- roles:begin -->/ { on = 1; next } /^<!-- roles:end -->/ { on = 0 }
     on && !/^```/' "$fleetdoc" > "$tmp/roles.sql"
[ -s "$tmp/roles.sql" ] || fail "no roles block in $fleetdoc"
psql -X -q -v ON_ERROR_STOP=1 "$PG_CONNINFO" -f "$tmp/roles.sql" > "$tmp/roles.log" 2>&1 ||
    fail "the roles SQL of docs/fleet.md: $(cat "$tmp/roles.log")"
writer="host=$PG_DIR dbname=postgres user=amfi_sync_a1-km12"
reader="host=$PG_DIR dbname=postgres user=alice"
mkstore "$tmp/w.db" a1-km12 3000
"$sync" --db "$tmp/w.db" --pg "$writer" --once --quiet || fail "the site's role cannot sync"
"$sync" --db "$tmp/w.db" --pg "$writer" --once --quiet || fail "the site's role: second pass"
same "$tmp/w.db" a1-km12
[ "$(psql -X -At "$reader" -c "SELECT count(*) FROM fleet_window_trend WHERE site_id = 'a1-km12'")" = \
  "$(sqlite3 "$tmp/w.db" "SELECT count(*) FROM window_trend")" ] || fail "fleet_window_trend differs from the store's window_trend"
[ "$(psql -X -At "$reader" -c "SELECT count(*) FROM fleet_latest_state WHERE site_id = 'a1-km12'")" = 1 ] ||
    fail "the reader cannot read fleet_latest_state"
[ "$(psql -X -At "$reader" -c "SELECT count(DISTINCT site_id) FROM passages")" -gt 3 ] ||
    fail "the reader does not read every site"
psql -X -At "$reader" -c "SELECT count(*) FROM fleet_daily_trend" > /dev/null 2>&1 ||
    fail "the reader cannot read fleet_daily_trend"
psql -X -At "$reader" -c "DELETE FROM passages WHERE site_id = 'a1-km12'" > /dev/null 2>&1 &&
    fail "the reader deleted passages"
psql -X -At "$writer" -c "DELETE FROM passages WHERE site_id = 'a1-km12'" > /dev/null 2>&1 &&
    fail "the site's role deleted passages"
add_rows "$tmp/w.db" 100
"$sync" --db "$tmp/w.db" --pg "$reader" --once 2> "$tmp/reader.log" && fail "the reader role synced"
grep -q "no site's role" "$tmp/reader.log" || fail "reader sync: $(cat "$tmp/reader.log")"
"$sync" --db "$tmp/w.db" --pg "$writer" --once --quiet || fail "the site's role: after the reader"
same "$tmp/w.db" a1-km12

case=upgrade
# A central database of version 4 (as amfi-sync of version 4 left it, with
# the shared writer role amfi_sync of then) with a site shipped. The writer
# cannot migrate: it asks for --init-schema, ships nothing; the owner
# migrates to 8 (version 6 retires the shared writer: refused, exit 2); the
# owner gives the site its role, which ships the new passages with their
# new columns and every environment and scale_evals row. The passages
# shipped before keep NULL in the new columns.
pg_q "CREATE DATABASE up4"
up="host=$PG_DIR dbname=up4 user=postgres"
main_db=$PG_CONNINFO
PG_CONNINFO=$up
"$sync" --pg "$up" --init-schema --quiet || fail "--init-schema"
mkstore "$tmp/u.db" site-u 1000
fleet_issue14_rows "$tmp/u.db"
"$sync" --db "$tmp/u.db" --pg "$up" --once --quiet || fail "first sync: exit $?"
pg_q "$v5_down DELETE FROM fleet_sync_state WHERE tbl IN ('environment', 'scale_evals');
      DELETE FROM fleet_migrations WHERE version > 4;
      DO \$\$ BEGIN
        IF NOT EXISTS (SELECT 1 FROM pg_roles WHERE rolname = 'amfi_sync') THEN
          CREATE ROLE amfi_sync LOGIN;
        END IF;
      END \$\$;
      GRANT USAGE ON SCHEMA public TO amfi_sync;
      GRANT SELECT, INSERT ON ALL TABLES IN SCHEMA public TO amfi_sync;
      GRANT UPDATE ON fleet_sync_state TO amfi_sync;"
add_rows "$tmp/u.db" 500
fleet_issue14_rows "$tmp/u.db" 1000
upw="host=$PG_DIR dbname=up4 user=amfi_sync"
"$sync" --db "$tmp/u.db" --pg "$upw" --once 2> "$tmp/up.log"
rc=$?
[ $rc = 1 ] || fail "the writer role at version 4: exit $rc, expected 1"
grep -q "central schema is at version 4, this program needs 10: run 'amfi-sync --init-schema'" "$tmp/up.log" ||
    fail "the writer role at version 4: $(cat "$tmp/up.log")"
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-u'")" = 1000 ] || fail "the writer shipped at version 4"
"$sync" --pg "$up" --init-schema --quiet || fail "--init-schema 4 -> 10"
[ "$(pg_q 'SELECT max(version) FROM fleet_migrations')" = 10 ] || fail "not migrated to 10"
"$sync" --db "$tmp/u.db" --pg "$upw" --once 2> "$tmp/up.log"
rc=$?
[ $rc = 2 ] || fail "the shared writer after the migration: exit $rc, expected 2"
grep -q "not a site's role" "$tmp/up.log" || fail "the shared writer after the migration: $(cat "$tmp/up.log")"
"$sync" --pg "$up" --init-site-role site-u --quiet || fail "--init-site-role site-u"
"$sync" --db "$tmp/u.db" --pg "host=$PG_DIR dbname=up4 user=amfi_sync_site-u" --once --quiet ||
    fail "the site's role after the migration: exit $?"
same "$tmp/u.db" site-u
fleet_columns_same "$tmp/u.db" site-u passages "id > 1000"
fleet_columns_same "$tmp/u.db" site-u environment
fleet_columns_same "$tmp/u.db" site-u scale_evals
[ "$(pg_q "SELECT count(*) FROM passages WHERE site_id = 'site-u' AND id <= 1000 AND
           (deck_c IS NOT NULL OR f1_hz IS NOT NULL OR reference_gvw_kg IS NOT NULL OR
            gvw_comp_kg IS NOT NULL)")" = 0 ] ||
    fail "passages shipped before the migration have values in its columns"
[ "$(psql -X -At "host=$PG_DIR dbname=up4 user=alice" -c "SELECT count(*) FROM fleet_latest_scale")" = 2 ] ||
    fail "the reader role cannot read fleet_latest_scale"
PG_CONNINFO=$main_db

case=notify
# Follow mode with a 0.4 s watchdog and a 30 s interval: READY after the
# first pass, a STATUS line, watchdog pings while it sleeps (counted over the
# 2 s after READY: the first pass's length depends on the machine's load),
# STOPPING after SIGTERM, and the rows shipped.
add_rows "$tmp/a.db" 200
"$listen" "$tmp/notify.sock" 120 > "$tmp/notify.log" &
l=$!
sleep 0.3
NOTIFY_SOCKET=$tmp/notify.sock WATCHDOG_USEC=400000 \
    "$sync" --config "$tmp/a.yaml" --pg "$PG_CONNINFO" --interval 30 --quiet &
f=$!
k=0
while [ $k -lt 600 ] && kill -0 $f 2> /dev/null && ! grep -q " READY=1$" "$tmp/notify.log"; do
    sleep 0.1
    k=$((k + 1))
done
sleep 2
kill -TERM $f
wait $f || fail "follow mode under systemd: exit $?"
sleep 0.3
kill $l 2> /dev/null
wait $l 2> /dev/null
same "$tmp/a.db" site-a
grep -q " READY=1$" "$tmp/notify.log" || fail "no READY=1: $(cat "$tmp/notify.log")"
grep -q " STATUS=.*rows shipped" "$tmp/notify.log" || fail "no STATUS: $(cat "$tmp/notify.log")"
grep -q " STOPPING=1$" "$tmp/notify.log" || fail "no STOPPING=1"
pings=$(awk '/ READY=1$/ && !r { r = $1 } / WATCHDOG=1$/ && r && $1 >= r && $1 <= r + 2 { n++ }
             END { print n + 0 }' "$tmp/notify.log")
[ "$pings" -ge 5 ] || fail "$pings watchdog pings in the 2 s after READY with a 0.4 s watchdog"

[ $failures = 0 ] && echo "fleet_sync.sh: all cases pass"
exit $((failures != 0))
