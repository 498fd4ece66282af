#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fleet_security.sh: what one site can do to another in the central
# PostgreSQL, TLS to a server not on this machine, the password file, and
# amfi-sync as a user that may only read the store. Inside a private network
# namespace (nothing can leave it), with a throwaway PostgreSQL
# (tests/common/pg_server.sh) that also listens on 192.0.2.10, an address given to
# the namespace's lo: not on this machine by amfi-sync's rules, yet
# reachable here.
# - roles: two sites, each with its own role (amfi-sync --init-site-role).
#   Logged in as site A's role, each attack on site B fails: a "cleared"
#   alert inserted for B, B's shipped mark raised (UPDATE and upsert), a
#   passage at B's next id (INSERT and COPY), fleet_migrations written, B's
#   rows and the fleet views read, A's role shipping B's store. B's next
#   sync still ships, and the fleet summary (amfi-report --pg as an analyst
#   of amfi_reader) still shows B's open alert.
# - upgrade: a central database of version 5 with the shared writer role
#   amfi_sync of before, which can forge another site's rows there (the
#   finding, shown); the owner migrates to 6: amfi_sync can do nothing more,
#   the site's new role ships on from the marks.
# - tls: a conninfo with sslmode=disable (or allow) to a host not on this
#   machine refused before anything is sent (exit 2), let through by
#   --allow-plaintext; the server without TLS on 192.0.2.10: refused (libpq
#   asked for TLS); with ssl=on and a self-signed certificate: shipped over
#   TLS (PQsslInUse), verify-full when a root certificate is given (a
#   certificate for another address refused); amfi-report --pg alike.
#   127.0.0.1 without TLS is local: shipped.
# - passfile: a site role with a password (scram-sha-256): shipped with
#   --passfile or PGPASSFILE (0600) and a service file without the secret;
#   a password file others may read is refused (exit 2), naming it.
# - readonly: amfi-sync as an unprivileged user who can only read the store
#   (and its -wal and -shm): shipped while a writer holds the store open
#   (WAL) and after it closed (no -wal, no -shm); the store untouched.
# Usage: fleet_security.sh AMFI_SYNC AMFI_REPORT SCHEMA_MD. Exit 77 without
# sqlite3, PostgreSQL or openssl.
set -u
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip addr add 192.0.2.10/32 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
sync=$1 report=$2 doc=$3
command -v sqlite3 > /dev/null || { echo "fleet_security.sh: no sqlite3: skipped"; exit 77; }
command -v openssl > /dev/null || { echo "fleet_security.sh: no openssl: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp fleet_security
failures=0
fail() { echo "FAIL $case: $*"; failures=$((failures + 1)); }
fleet_store_setup "$doc"
sock="host=$PG_DIR dbname=postgres"
as() { psql -X -q -At -v ON_ERROR_STOP=1 "$sock user=$1" -c "$2"; }

case=roles
"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "--init-schema"
for s in a b; do
    "$sync" --pg "$PG_CONNINFO" --init-site-role site-$s 2> "$tmp/role-$s.log" ||
        fail "--init-site-role site-$s: $(cat "$tmp/role-$s.log")"
done
grep -q "site 'site-a' ships as the role 'amfi_sync_site-a'" "$tmp/role-a.log" || fail "message: $(cat "$tmp/role-a.log")"
"$sync" --pg "$PG_CONNINFO" --init-site-role site-a --quiet || fail "--init-site-role again"
"$sync" --pg "$PG_CONNINFO" --init-site-role site-c --role amfi_sync_site-a 2> "$tmp/role-c.log"
[ $? = 2 ] || fail "a role given a second site: not refused"
grep -q "already gives the role 'amfi_sync_site-a' the site 'site-a'" "$tmp/role-c.log" || fail "$(cat "$tmp/role-c.log")"
"$sync" --pg "$PG_CONNINFO" --init-site-role site-c --role postgres 2> "$tmp/role-su.log"
[ $? = 2 ] || fail "a superuser as a site role: not refused"
# every central table with a site_id is bound (a table added by a later
# version without its policy would fail here)
unbound=$(pg_q "SELECT string_agg(c.relname, ' ' ORDER BY c.relname) FROM pg_class AS c
                WHERE c.relnamespace = current_schema()::regnamespace AND c.relkind = 'r'
                  AND EXISTS (SELECT 1 FROM pg_attribute AS a WHERE a.attrelid = c.oid AND a.attname = 'site_id')
                  AND NOT (c.relrowsecurity AND EXISTS (SELECT 1 FROM pg_policy AS p
                           WHERE p.polrelid = c.oid AND p.polname = CASE c.relname
                                 WHEN 'fleet_site_roles' THEN 'fleet_own_role' ELSE 'fleet_site' END))")
[ -z "$unbound" ] || fail "tables with a site_id and no row-level security: $unbound"
[ "$(pg_q "SELECT count(*) FROM pg_class WHERE relnamespace = current_schema()::regnamespace
           AND relkind = 'r' AND relrowsecurity")" -ge 10 ] || fail "fewer than 10 tables bound"
pg_q "CREATE ROLE analyst LOGIN IN ROLE amfi_reader"
A="$sock user=amfi_sync_site-a" B="$sock user=amfi_sync_site-b"
mkstore "$tmp/a.db" site-a 1000
mkstore "$tmp/b.db" site-b 1000
# B ends with its STD alert raised
sqlite3 "$tmp/b.db" "INSERT INTO alerts (utime, level, kind, message, indicator_id, raised)
                     VALUES (1763900000000000, 'warning', 'std_increase', 'STD up', NULL, 1)"
"$sync" --db "$tmp/a.db" --pg "$A" --once --quiet || fail "site A's role: exit $?"
"$sync" --db "$tmp/b.db" --pg "$B" --once --quiet || fail "site B's role: exit $?"
fleet_same "$tmp/a.db" site-a
fleet_same "$tmp/b.db" site-b
summary() { "$report" --pg "$sock user=analyst" | awk -v s=site-b '$1 == s { print $4, $6 }'; }
[ "$(summary)" = "normal 1" ] || fail "fleet summary of B before: '$(summary)', want 'normal 1'"
mark=$(pg_q "SELECT hwm FROM fleet_sync_state WHERE site_id = 'site-b' AND tbl = 'passages'")
next=$((mark + 1))
# attacks as A on B: each must fail
as amfi_sync_site-a "INSERT INTO alerts (site_id, id, utime, level, kind, message, raised)
    VALUES ('site-b', 100000, 1900000000000000, 'warning', 'std_increase', 'all clear', 0)" 2> /dev/null &&
    fail "A inserted a cleared alert for B"
as amfi_sync_site-a "UPDATE fleet_sync_state SET hwm = hwm + 1000 WHERE site_id = 'site-b'" 2> /dev/null
as amfi_sync_site-a "INSERT INTO fleet_sync_state (site_id, tbl, hwm, last_hash) VALUES ('site-b', 'passages', 99999, '0')
    ON CONFLICT (site_id, tbl) DO UPDATE SET hwm = 99999" 2> /dev/null && fail "A upserted B's mark"
as amfi_sync_site-a "INSERT INTO fleet_sync_state (site_id, tbl, hwm, last_hash) VALUES ('site-b', 'runs2', 1, '0')" 2> /dev/null &&
    fail "A inserted a mark for B"
[ "$(pg_q "SELECT hwm FROM fleet_sync_state WHERE site_id = 'site-b' AND tbl = 'passages'")" = "$mark" ] ||
    fail "A moved B's mark"
as amfi_sync_site-a "INSERT INTO passages (site_id, id, vehicle_id, utime, lane, n_axles, status, reason, stored_at)
    VALUES ('site-b', $next, 1, 1763769600000000, 1, 2, 'gap', '', 'x')" 2> /dev/null &&
    fail "A inserted a passage at B's next id"
printf 'site-b\t%s\t1\t1763769600000000\t1\t2\tgap\t\tx\n' $next |
    psql -X -q "$A" -c "COPY passages (site_id, id, vehicle_id, utime, lane, n_axles, status, reason, stored_at) FROM STDIN" 2> /dev/null &&
    fail "A copied a passage at B's next id"
as amfi_sync_site-a "INSERT INTO fleet_migrations (version, description) VALUES (99, 'x')" 2> /dev/null &&
    fail "A wrote fleet_migrations"
as amfi_sync_site-a "DELETE FROM fleet_migrations" 2> /dev/null && fail "A deleted fleet_migrations"
as amfi_sync_site-a "UPDATE fleet_migrations SET version = version" 2> /dev/null && fail "A updated fleet_migrations"
as amfi_sync_site-a "INSERT INTO fleet_site_roles VALUES ('amfi_sync_site-a', 'site-b')" 2> /dev/null &&
    fail "A wrote fleet_site_roles"
[ "$(as amfi_sync_site-a "SELECT count(*) FROM passages WHERE site_id = 'site-b'")" = 0 ] || fail "A reads B's passages"
[ "$(as amfi_sync_site-a "SELECT count(DISTINCT site_id) FROM alerts")" = 1 ] || fail "A reads other sites' alerts"
[ "$(as amfi_sync_site-a "SELECT string_agg(site_id, ' ') FROM fleet_site_roles")" = site-a ] || fail "A reads other sites' roles"
for v in fleet_open_alerts fleet_latest_state fleet_window_trend fleet_daily_trend fleet_summary; do
    as amfi_sync_site-a "SELECT count(*) FROM $v" > /dev/null 2>&1 && fail "A reads the view $v (every site)"
done
as amfi_sync_site-a "DELETE FROM passages" 2> /dev/null && fail "A deleted passages"
# A's role shipping B's store: refused, not retried
"$sync" --db "$tmp/b.db" --pg "$A" --once 2> "$tmp/ab.log"
rc=$?
[ $rc = 2 ] || fail "A's role shipping B's store: exit $rc, expected 2"
grep -q "the role 'amfi_sync_site-a' is the role of site 'site-a'.*not of this store's site 'site-b'" "$tmp/ab.log" ||
    fail "message: $(cat "$tmp/ab.log")"
# an analyst (amfi_reader) cannot ship
"$sync" --db "$tmp/b.db" --pg "$sock user=analyst" --once 2> "$tmp/an.log"
[ $? = 2 ] || fail "the analyst shipped"
grep -q "no site's role" "$tmp/an.log" || fail "analyst: $(cat "$tmp/an.log")"
# B's next sync still ships; the summary still shows its alert
add_rows "$tmp/b.db" 300
"$sync" --db "$tmp/b.db" --pg "$B" --once --quiet || fail "B's next sync: exit $?"
fleet_same "$tmp/b.db" site-b
[ "$(summary)" = "normal 1" ] || fail "fleet summary of B after the attacks: '$(summary)', want 'normal 1'"
[ "$(pg_q "SELECT count(*) FROM fleet_open_alerts WHERE site_id = 'site-b'")" = 1 ] || fail "B's alert not open"
# the analyst reads every site
[ "$(psql -X -At "$sock user=analyst" -c "SELECT count(DISTINCT site_id) FROM passages")" = 2 ] ||
    fail "the analyst does not read every site"
# one site's report from the central database: the analyst's of B equals
# the one from B's store; A's role does not even see that B exists
"$report" --pg "$sock user=analyst" --site site-b --summary --alerts > "$tmp/rb.central" 2> "$tmp/rb.log" ||
    fail "amfi-report --pg --site site-b as the analyst: $(cat "$tmp/rb.log")"
"$report" --db "$tmp/b.db" --summary --alerts > "$tmp/rb.store" 2>&1 || fail "amfi-report --db b.db"
sed -i '/^Next, with/,$d' "$tmp/rb.central" "$tmp/rb.store"
[ -s "$tmp/rb.central" ] && cmp -s "$tmp/rb.store" "$tmp/rb.central" ||
    fail "site-b's report from the central database differs: $(diff "$tmp/rb.store" "$tmp/rb.central" | head -6)"
"$report" --pg "$A" --site site-b --summary > /dev/null 2> "$tmp/rab.log"
rc=$?
[ $rc = 2 ] && grep -q "no site 'site-b' in the central database (sites: site-a)" "$tmp/rab.log" ||
    fail "amfi-report --site site-b as A's role: exit $rc: $(cat "$tmp/rab.log")"

case=upgrade
# version 5 as it was: the shared writer amfi_sync for every site (the
# roles block of the documentation before version 6)
pg_q "CREATE DATABASE up5"
up="host=$PG_DIR dbname=up5 user=postgres"
upw="host=$PG_DIR dbname=up5 user=amfi_sync"
"$sync" --pg "$up" --init-schema --quiet || fail "--init-schema"
mkstore "$tmp/u.db" site-u 500
mkstore "$tmp/v.db" site-v 500
sqlite3 "$tmp/v.db" "INSERT INTO alerts (utime, level, kind, message, indicator_id, raised)
                     VALUES (1763900000000000, 'warning', 'std_increase', 'STD up', NULL, 1)"
# the sites shipped (by the owner), then the database taken back to version 5
PG_CONNINFO=$up
for s in u v; do
    "$sync" --db "$tmp/$s.db" --pg "$up" --once --quiet || fail "site-$s: exit $?"
done
psql -X -q -v ON_ERROR_STOP=1 "$up" > "$tmp/up.log" 2>&1 <<'SQL' || fail "down to 5: $(cat "$tmp/up.log")"
DO $$ DECLARE t text; BEGIN
  FOREACH t IN ARRAY ARRAY['passages', 'axles', 'indicators', 'alerts', 'baseline', 'runs',
                           'environment', 'scale_evals', 'fleet_sync_state', 'fleet_site_roles'] LOOP
    EXECUTE format('DROP POLICY IF EXISTS fleet_site ON %I', t);
    EXECUTE format('DROP POLICY IF EXISTS fleet_reader ON %I', t);
    EXECUTE format('ALTER TABLE %I DISABLE ROW LEVEL SECURITY', t);
  END LOOP;
END $$;
DROP VIEW fleet_summary;
DROP TABLE fleet_sites;
DROP TABLE fleet_site_roles;
ALTER TABLE passages DROP COLUMN class, DROP COLUMN axle_groups, DROP COLUMN overload;
ALTER TABLE passages DROP COLUMN fit_ratio;
ALTER TABLE passages DROP COLUMN loads_refused;
DELETE FROM fleet_migrations WHERE version > 5;
CREATE ROLE amfi_sync LOGIN;
GRANT USAGE ON SCHEMA public TO amfi_sync;
GRANT SELECT, INSERT ON ALL TABLES IN SCHEMA public TO amfi_sync;
GRANT UPDATE ON fleet_sync_state TO amfi_sync;
SQL
# the finding at version 5: the shared writer forges another site's rows
psql -X -q -v ON_ERROR_STOP=1 "$upw" -c "INSERT INTO fleet_migrations VALUES (77, 'x');
    INSERT INTO alerts (site_id, id, utime, level, kind, message, raised)
    VALUES ('site-v', 9999, 1900000000000000, 'warning', 'std_increase', 'all clear', 0)" > "$tmp/forge.log" 2>&1 ||
    fail "at version 5, the shared writer could not forge (the test cannot see the attack): $(cat "$tmp/forge.log")"
[ "$(pg_q "SELECT count(*) FROM fleet_open_alerts WHERE site_id = 'site-v'")" = 0 ] ||
    fail "at version 5, the forged cleared alert did not close site-v's alert"
pg_q "DELETE FROM alerts WHERE site_id = 'site-v' AND id = 9999; DELETE FROM fleet_migrations WHERE version = 77"
"$sync" --pg "$up" --init-schema --quiet || fail "--init-schema 5 -> 10"
[ "$(psql -X -At "$up" -c 'SELECT max(version) FROM fleet_migrations')" = 10 ] || fail "not migrated to 10"
add_rows "$tmp/u.db" 200
"$sync" --db "$tmp/u.db" --pg "$upw" --once 2> "$tmp/upw.log"
[ $? = 2 ] || fail "the shared writer after the migration: not refused"
grep -q "not a site's role.*--init-site-role" "$tmp/upw.log" || fail "message: $(cat "$tmp/upw.log")"
for q in "SELECT count(*) FROM passages" "SELECT count(*) FROM fleet_open_alerts" \
         "INSERT INTO fleet_migrations VALUES (77, 'x')" \
         "INSERT INTO alerts (site_id, id, utime, level, kind, message, raised) VALUES ('site-v', 9999, 1, 'info', 'k', 'm', 0)" \
         "UPDATE fleet_sync_state SET hwm = 1"; do
    psql -X -q -v ON_ERROR_STOP=1 "$upw" -c "$q" > /dev/null 2>&1 && fail "the shared writer after the migration: $q"
done
"$sync" --pg "$up" --init-site-role site-u --quiet || fail "--init-site-role site-u"
"$sync" --db "$tmp/u.db" --pg "host=$PG_DIR dbname=up5 user=amfi_sync_site-u" --once --quiet ||
    fail "site-u's role after the migration: exit $?"
fleet_same "$tmp/u.db" site-u
[ "$(pg_q "SELECT count(*) FROM fleet_open_alerts WHERE site_id = 'site-v'")" = 1 ] || fail "site-v's alert"
PG_CONNINFO="host=$PG_DIR dbname=postgres user=postgres"

case=tls
# not on this machine, plain text asked for: refused before anything is sent
for m in disable allow; do
    "$sync" --db "$tmp/a.db" --pg "host=fleet.invalid dbname=fleet user=x sslmode=$m" --once 2> "$tmp/t.log"
    rc=$?
    [ $rc = 2 ] || fail "sslmode=$m to fleet.invalid: exit $rc, expected 2"
    grep -q "the server fleet.invalid is not on this machine and sslmode=$m would send" "$tmp/t.log" ||
        fail "sslmode=$m: $(cat "$tmp/t.log")"
done
"$report" --pg "host=fleet.invalid dbname=fleet sslmode=disable" 2> "$tmp/t.log"
rc=$?
[ $rc = 2 ] && grep -q "not on this machine and sslmode=disable" "$tmp/t.log" ||
    fail "amfi-report to fleet.invalid with sslmode=disable: exit $rc: $(cat "$tmp/t.log")"
# PGSSLMODE and a service file say it too
PGSSLMODE=disable "$sync" --db "$tmp/a.db" --pg "host=192.0.2.99 dbname=fleet" --once 2> /dev/null
[ $? = 2 ] || fail "PGSSLMODE=disable to 192.0.2.99: not refused"
printf '[far]\nhost=192.0.2.99\ndbname=fleet\nsslmode=disable\n' > "$tmp/svc.conf"
PGSERVICEFILE=$tmp/svc.conf "$sync" --db "$tmp/a.db" --pg "service=far" --once 2> /dev/null
[ $? = 2 ] || fail "a service with sslmode=disable to 192.0.2.99: not refused"
# --allow-plaintext lets it through: libpq tries (an address with no route here)
"$sync" --db "$tmp/a.db" --pg "host=192.0.2.99 dbname=fleet user=x sslmode=disable connect_timeout=2" \
    --allow-plaintext --once 2> "$tmp/t.log"
rc=$?
[ $rc = 1 ] && grep -q "cannot connect to PostgreSQL" "$tmp/t.log" ||
    fail "--allow-plaintext: exit $rc: $(cat "$tmp/t.log")"
# the server on 192.0.2.10 and 127.0.0.1 without TLS
port=54329
pg_stop
cat >> "$PG_DIR/data/pg_hba.conf" <<EOF
host all all 192.0.2.10/32 trust
EOF
pg_as pg_ctl -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w \
    -o "-k $PG_DIR -c listen_addresses='127.0.0.1,192.0.2.10' -p $port -c fsync=off" start > /dev/null ||
    { cat "$PG_DIR/server.log"; exit 1; }
far="host=192.0.2.10 port=$port dbname=postgres user=amfi_sync_site-a"
add_rows "$tmp/a.db" 100
"$sync" --db "$tmp/a.db" --pg "$far" --once 2> "$tmp/t.log"
rc=$?
[ $rc = 1 ] && grep -q "SSL" "$tmp/t.log" || fail "no TLS on 192.0.2.10 (default sslmode): exit $rc: $(cat "$tmp/t.log")"
"$sync" --db "$tmp/a.db" --pg "$far sslmode=prefer" --once 2> /dev/null
[ $? = 1 ] || fail "no TLS on 192.0.2.10 with sslmode=prefer: shipped"
"$report" --pg "host=192.0.2.10 port=$port dbname=postgres user=analyst" > /dev/null 2>&1 &&
    fail "amfi-report without TLS to 192.0.2.10"
"$sync" --db "$tmp/a.db" --pg "$far" --allow-plaintext --once 2> "$tmp/t.log" ||
    fail "--allow-plaintext to 192.0.2.10: $(cat "$tmp/t.log")"
grep -q "without TLS" "$tmp/t.log" || fail "--allow-plaintext: $(cat "$tmp/t.log")"
add_rows "$tmp/a.db" 100
"$sync" --db "$tmp/a.db" --pg "host=127.0.0.1 port=$port dbname=postgres user=amfi_sync_site-a" --once --quiet ||
    fail "127.0.0.1 without TLS (local): exit $?"
PG_CONNINFO="host=127.0.0.1 port=$port dbname=postgres user=postgres" fleet_same "$tmp/a.db" site-a
# ssl = on, a self-signed certificate for 192.0.2.10 (and one for another address)
pg_stop
for n in good:192.0.2.10 other:192.0.2.11; do
    openssl req -x509 -newkey rsa:2048 -nodes -days 2 -subj "/CN=${n#*:}" \
        -addext "subjectAltName=IP:${n#*:}" -keyout "$PG_DIR/${n%%:*}.key" -out "$PG_DIR/${n%%:*}.crt" \
        > /dev/null 2>&1 || fail "openssl req"
done
[ "$(id -u)" = 0 ] && chown "$pg_user" "$PG_DIR"/*.key
chmod 600 "$PG_DIR"/*.key
chmod 644 "$PG_DIR"/*.crt
pg_tls_start() {
    pg_as pg_ctl -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w \
        -o "-k $PG_DIR -c listen_addresses='127.0.0.1,192.0.2.10' -p $port -c fsync=off -c ssl=on -c ssl_cert_file=$PG_DIR/$1.crt -c ssl_key_file=$PG_DIR/$1.key" \
        start > /dev/null ||
        { cat "$PG_DIR/server.log"; exit 1; }
}
pg_tls_start good
add_rows "$tmp/a.db" 100
"$sync" --db "$tmp/a.db" --pg "$far" --once 2> "$tmp/t.log" || fail "over TLS: exit $?: $(cat "$tmp/t.log")"
grep -q "rows shipped to 192.0.2.10/postgres over TLS (TLSv1" "$tmp/t.log" || fail "over TLS: $(cat "$tmp/t.log")"
PG_CONNINFO="host=127.0.0.1 port=$port dbname=postgres user=postgres" fleet_same "$tmp/a.db" site-a
add_rows "$tmp/a.db" 100
"$sync" --db "$tmp/a.db" --pg "$far sslrootcert=$PG_DIR/good.crt" --once 2> "$tmp/t.log" ||
    fail "verify-full with the right certificate: $(cat "$tmp/t.log")"
"$report" --pg "host=192.0.2.10 port=$port dbname=postgres user=analyst sslrootcert=$PG_DIR/good.crt" > "$tmp/r.out" 2>&1 ||
    fail "amfi-report over TLS: $(cat "$tmp/r.out")"
grep -q "^site-b " "$tmp/r.out" || fail "amfi-report over TLS: $(cat "$tmp/r.out")"
pg_stop
pg_tls_start other   # a certificate valid for 192.0.2.11, not for 192.0.2.10
add_rows "$tmp/a.db" 100
"$sync" --db "$tmp/a.db" --pg "$far sslrootcert=$PG_DIR/other.crt" --once 2> "$tmp/t.log"
rc=$?
[ $rc = 1 ] && grep -q "does not match host name\|192.0.2.10" "$tmp/t.log" ||
    fail "a root certificate given, the server's for another address: exit $rc: $(cat "$tmp/t.log")"
"$sync" --db "$tmp/a.db" --pg "$far sslrootcert=$PG_DIR/other.crt sslmode=verify-ca" --once --quiet ||
    fail "verify-ca said: exit $?"
pg_stop
pg_restart_start

case=passfile
pg_q "CREATE ROLE \"amfi_sync_site-p\" LOGIN PASSWORD 'p-secret-1'"
"$sync" --pg "$PG_CONNINFO" --init-site-role site-p --quiet || fail "--init-site-role site-p"
pg_stop
{ echo "local all amfi_sync_site-p scram-sha-256"; cat "$PG_DIR/data/pg_hba.conf"; } > "$PG_DIR/hba.new"
cat "$PG_DIR/hba.new" > "$PG_DIR/data/pg_hba.conf"
pg_restart_start
mkstore "$tmp/p.db" site-p 300
echo "*:*:*:amfi_sync_site-p:p-secret-1" > "$tmp/pgpass"
chmod 600 "$tmp/pgpass"
P="$sock user=amfi_sync_site-p"
"$sync" --db "$tmp/p.db" --pg "$P" --once 2> "$tmp/p.log" < /dev/null && fail "shipped without the password"
"$sync" --db "$tmp/p.db" --pg "$P" --passfile "$tmp/pgpass" --once --quiet || fail "--passfile: exit $?"
add_rows "$tmp/p.db" 100
printf '[amfi]\nhost=%s\ndbname=postgres\nuser=amfi_sync_site-p\n' "$PG_DIR" > "$tmp/pg_service.conf"
PGSERVICEFILE=$tmp/pg_service.conf PGPASSFILE=$tmp/pgpass "$sync" --db "$tmp/p.db" --pg service=amfi --once --quiet ||
    fail "PGSERVICEFILE and PGPASSFILE: exit $?"
fleet_same "$tmp/p.db" site-p
chmod 640 "$tmp/pgpass"
"$sync" --db "$tmp/p.db" --pg "$P" --passfile "$tmp/pgpass" --once 2> "$tmp/p.log"
[ $? = 2 ] && grep -q -- "--passfile $tmp/pgpass: mode 0640 lets other users read the password" "$tmp/p.log" ||
    fail "a password file of mode 0640: $(cat "$tmp/p.log")"
PGPASSFILE=$tmp/pgpass "$sync" --db "$tmp/p.db" --pg "$P" --once 2> "$tmp/p.log"
[ $? = 2 ] && grep -q "PGPASSFILE $tmp/pgpass: mode 0640" "$tmp/p.log" || fail "PGPASSFILE of mode 0640: $(cat "$tmp/p.log")"
"$sync" --db "$tmp/p.db" --pg "$P" --passfile "$tmp/nonesuch" --once 2> "$tmp/p.log"
[ $? = 2 ] && grep -q "nonesuch: No such file" "$tmp/p.log" || fail "a missing password file: $(cat "$tmp/p.log")"
grep -q "p-secret" "$tmp/p.log" && fail "the password is in amfi-sync's messages"

case=readonly
# the store's directory and files owned by another user, readable only
reader=nobody
id "$reader" > /dev/null 2>&1 || { echo "no user nobody: readonly skipped"; reader=; }
if [ "$(id -u)" = 0 ] && [ -n "$reader" ]; then
    mkdir "$tmp/store"
    mkstore "$tmp/store/r.db" site-r 500
    chmod 755 "$tmp/store"
    chmod 644 "$tmp/store/r.db"
    "$sync" --pg "$PG_CONNINFO" --init-site-role site-r --quiet || fail "--init-site-role site-r"
    R="$sock user=amfi_sync_site-r"
    rosync() { runuser -u "$reader" -- "$sync" --db "$tmp/store/r.db" --pg "$R" --once --quiet; }
    # a writer holds the store open in WAL mode: -wal and -shm exist, read-only to the reader
    mkfifo "$tmp/w.fifo"
    sqlite3 "$tmp/store/r.db" < "$tmp/w.fifo" > /dev/null &
    wpid=$!
    exec 3> "$tmp/w.fifo"
    echo "PRAGMA journal_mode = WAL; INSERT INTO runs (version, config_path) VALUES ('0.w', '/x');" >&3
    i=0; while [ ! -f "$tmp/store/r.db-shm" ] && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
    [ -f "$tmp/store/r.db-wal" ] && [ -f "$tmp/store/r.db-shm" ] || fail "the writer left no -wal/-shm"
    chmod 644 "$tmp/store/r.db-wal" "$tmp/store/r.db-shm"
    rosync 2> "$tmp/ro.log" || fail "read-only user, writer running: exit $?: $(cat "$tmp/ro.log")"
    fleet_same "$tmp/store/r.db" site-r
    exec 3>&-
    wait $wpid
    [ ! -f "$tmp/store/r.db-wal" ] || fail "the writer's -wal is still there"
    add_rows "$tmp/store/r.db" 200
    rm -f "$tmp/store/r.db-wal" "$tmp/store/r.db-shm"
    sum=$(md5sum < "$tmp/store/r.db")
    rosync 2> "$tmp/ro.log" || fail "read-only user, no -wal/-shm: exit $?: $(cat "$tmp/ro.log")"
    fleet_same "$tmp/store/r.db" site-r
    [ "$(md5sum < "$tmp/store/r.db")" = "$sum" ] || fail "the store changed"
    [ "$(ls "$tmp/store")" = r.db ] || fail "files made beside the store: $(ls "$tmp/store")"
fi

[ $failures = 0 ] && echo "fleet_security.sh: all cases pass"
exit $((failures != 0))
