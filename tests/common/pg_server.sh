# SPDX-License-Identifier: GPL-3.0-or-later
# pg_server.sh: sourced by the fleet_* tests. pg_start DIR starts a throwaway
# PostgreSQL server (initdb into DIR/data as the unprivileged user postgres,
# or nobody; Unix socket in DIR, no TCP port) and sets PG_CONNINFO; pg_stop
# and pg_restart stop / restart it. The caller's trap runs pg_stop (pg_tmp
# sets one up).
pg_user=postgres
id "$pg_user" > /dev/null 2>&1 || pg_user=nobody
pg_as() {
    if [ "$(id -u)" = 0 ]; then runuser -u "$pg_user" -- env HOME="$PG_DIR" "$@"; else "$@"; fi
}
pg_start() {
    PG_DIR=$1
    command -v initdb > /dev/null && command -v pg_ctl > /dev/null ||
        { echo "pg_server.sh: no initdb/pg_ctl (apt-get install postgresql): skipped"; exit 77; }
    [ "$(id -u)" = 0 ] && chown "$pg_user" "$PG_DIR"
    pg_as initdb -D "$PG_DIR/data" -U postgres -A trust --no-sync > "$PG_DIR/initdb.log" 2>&1 ||
        { cat "$PG_DIR/initdb.log" >&2; exit 1; }
    pg_restart_start
    PG_CONNINFO="host=$PG_DIR dbname=postgres user=postgres"
}
pg_restart_start() {
    pg_as pg_ctl -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w \
        -o "-k $PG_DIR -c listen_addresses='' -c fsync=off" start > /dev/null ||
        { cat "$PG_DIR/server.log" >&2; exit 1; }
}
pg_stop() {
    [ -n "${PG_DIR:-}" ] && [ -f "$PG_DIR/data/postmaster.pid" ] &&
        pg_as pg_ctl -D "$PG_DIR/data" -m fast -w stop > /dev/null 2>&1
    return 0
}
# pg_tmp NAME: a new temporary directory in $tmp (NAME.XXXXXX under TMPDIR),
# removed at exit with the server stopped, and the server started in it.
pg_tmp() {
    tmp=$(mktemp -d "${TMPDIR:-/tmp}/$1.XXXXXX") || exit 1
    chmod 755 "$tmp"
    trap 'pg_stop; rm -rf "$tmp"' EXIT INT TERM
    pg_start "$tmp"
}
pg_q() { psql -X -q -At -v ON_ERROR_STOP=1 "$PG_CONNINFO" -c "$1"; }
# fleet_same DB SITE: the central rows of SITE equal the store DB's, table by
# table (count and newest id: no gap, no duplicate), axles by count; calls
# the caller's fail for each difference.
fleet_same() {
    for t in passages indicators alerts baseline runs environment scale_evals; do
        l=$(sqlite3 "$1" "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t")
        c=$(pg_q "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t WHERE site_id = '$2'")
        [ "$l" = "$c" ] || fail "$2 $t: store '$l' central '$c'"
    done
    l=$(sqlite3 "$1" "SELECT count(*) FROM axles")
    c=$(pg_q "SELECT count(*) FROM axles WHERE site_id = '$2'")
    [ "$l" = "$c" ] || fail "$2 axles: store '$l' central '$c'"
}
# fleet_synced DB SITE: 0 when the central rows of the site have the store's
# counts and last ids in every table (fleet_same's check, silent)
fleet_synced() {
    for t in passages indicators alerts baseline runs environment scale_evals; do
        [ "$(sqlite3 "$1" "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t")" = \
          "$(pg_q "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t WHERE site_id = '$2'")" ] ||
            return 1
    done
    [ "$(sqlite3 "$1" "SELECT count(*) FROM axles")" = \
      "$(pg_q "SELECT count(*) FROM axles WHERE site_id = '$2'")" ]
}
# fleet_columns_same DB SITE TABLE [WHERE]: every row of TABLE (the store's
# columns, in its order; WHERE on both sides) equal in the store and the
# central database, column by column. Both print reals with 15 significant
# digits (sqlite3's %!.15g; PostgreSQL with extra_float_digits 0), the
# store's integral reals with a ".0" that is dropped.
fleet_columns_same() {
    cols=$(sqlite3 "$1" "SELECT group_concat(name, ', ') FROM pragma_table_info('$3')")
    key=id
    [ "$3" = axles ] && key="passage_id, idx"
    sqlite3 "$1" "SELECT $cols FROM $3 ${4:+WHERE $4} ORDER BY $key" |
        sed -E 's/([0-9])\.0(\||$)/\1\2/g; s/([0-9])\.0(\||$)/\1\2/g' > "$tmp/cols.store"
    PGOPTIONS='-c extra_float_digits=0' \
        pg_q "SELECT $cols FROM $3 WHERE site_id = '$2' ${4:+AND $4} ORDER BY $key" > "$tmp/cols.central"
    [ -s "$tmp/cols.store" ] || fail "$2 $3: no rows to compare"
    cmp -s "$tmp/cols.store" "$tmp/cols.central" ||
        fail "$2 $3: central rows differ from the store's: $(diff "$tmp/cols.store" "$tmp/cols.central" | head -4)"
}
# fleet_issue14_rows DB [ID]: issue 14's data added to a site store of
# version 8: deck and air temperature readings, scale blocks and known-truck
# runs (scale_evals), and on its passages above ID (default all) a deck
# temperature, the weight the STD rule was fed, natural frequency and now
# and then a known truck's weight.
# The reals are binary fractions, printed alike by sqlite3 and psql.
fleet_issue14_rows() {
    sqlite3 "$1" <<SQL > /dev/null
PRAGMA busy_timeout = 5000;
BEGIN;
WITH RECURSIVE k(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM k WHERE i < 47)
INSERT INTO environment (utime, deck_c, air_c, received_utime)
SELECT b + i * 1800000000, -20.25 + 0.5 * i, -21.75 + 0.5 * i, b + i * 1800000000 + 250000
FROM k, (SELECT coalesce(max(utime) + 1800000000, 1763769600000000) AS b FROM environment);
UPDATE passages SET deck_c = -5.25 + 0.5 * (id % 40), gvw_comp_kg = 14999.5 + 1000 * (id % 7)
 WHERE status = 'ok' AND id > ${2:-0};
UPDATE passages SET f1_hz = 3.125 + 0.0625 * (id % 8), f1_zeta = 0.015625 * (1 + id % 3),
       f1_r2 = 0.96875, f1_comp_hz = CASE WHEN id % 2 = 0 THEN 3.140625 + 0.0625 * (id % 8) END
 WHERE status = 'ok' AND id % 3 = 0 AND id > ${2:-0};
UPDATE passages SET reference_gvw_kg = 40000.5 WHERE status = 'ok' AND id % 97 = 0 AND id > ${2:-0};
WITH RECURSIVE k(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM k WHERE i < 23)
INSERT INTO scale_evals (utime, kind, n, value, raw, deck_c, z, cusum, h, state)
SELECT 1763769600000000 + i * 3600000000, 'scale_shift', 200, 1.0078125 + 0.0009765625 * i,
       1.0234375 + 0.0009765625 * i, -4.75 + 0.5 * i, 0.25 * i - 1.125, 0.125 * i + 0.0625, 5.5,
       CASE WHEN i < 4 THEN 'baseline' WHEN i < 20 THEN 'normal' WHEN i < 23 THEN 'watch' ELSE 'alert' END
FROM k;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 6)
INSERT INTO scale_evals (utime, kind, n, value, raw, deck_c, z, cusum, h, state)
SELECT 1763769600000000 + i * 86400000000 + 1, 'known_truck', i, 0.9921875 + 0.001953125 * i,
       0.9765625 + 0.001953125 * i, 2.25 + i, 0.5 * i - 0.875, 0.0625, 4.5, 'normal' FROM k;
COMMIT;
SQL
}
# fleet_store_setup SCHEMA_MD: site stores made from docs/schema.md's DDL
# block at its version, with the functions below (fleet_sync.sh,
# fleet_security.sh).
fleet_store_setup() {
    awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
         on && !/^```/' "$1" > "$tmp/ddl.sql"
    [ -s "$tmp/ddl.sql" ] || { echo "pg_server.sh: no DDL block in $1" >&2; exit 1; }
    store_version=$(sed -n 's/.*PRAGMA user_version` (this document: version \([0-9]*\)).*/\1/p' "$1")
    [ -n "$store_version" ] || { echo "pg_server.sh: no schema version in $1" >&2; exit 1; }
}
# add_rows DB N: N passages (2 axles each), an indicator per 10, an alert per 50.
add_rows() {
    sqlite3 "$1" <<SQL > /dev/null
PRAGMA busy_timeout = 5000;
BEGIN;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $2)
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      lambda, residual_rms, formulation, solve_ms)
SELECT i, 1763769600000000 + ((SELECT count(*) FROM passages) + i) * 40000000, 1, 25.0, 2,
       CASE WHEN i % 10 = 0 THEN NULL ELSE 15000.0 + 1000 * (i % 7) + 0.1 END,
       CASE WHEN i % 10 = 0 THEN 'gap' ELSE 'ok' END,
       CASE WHEN i % 10 = 0 THEN 'tab	and "quote" \\ back' ELSE '' END,
       7.94e-9, 0.001, 'paper', 15.0 FROM k;
INSERT INTO axles SELECT id, 1, NULL, 0.4 * gvw_kg FROM passages WHERE id NOT IN (SELECT passage_id FROM axles);
INSERT INTO axles SELECT id, 2, 4.5, 0.6 * gvw_kg FROM passages p WHERE NOT EXISTS
  (SELECT 1 FROM axles a WHERE a.passage_id = p.id AND a.idx = 2);
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $2 / 10)
INSERT INTO indicators (utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg, std_ratio, p_value, state)
SELECT 1763769600000000 + i, 20, 17800, 1900, 17800, 1900, 1.0, 0.5, 'normal' FROM k;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $2 / 50)
INSERT INTO alerts (utime, level, kind, message, indicator_id, raised)
SELECT 1763769600000000 + i, 'warning', 'std_increase', 'STD up
two lines', NULL, i % 2 FROM k;
COMMIT;
SQL
}
# mkstore DB SITE N
mkstore() {
    { cat "$tmp/ddl.sql"; echo "PRAGMA journal_mode = WAL;
PRAGMA user_version = $store_version;
INSERT INTO meta (key, value) VALUES ('site.id', '$2');
INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note) VALUES (0, 30, 17800, 1900, 'auto', '');
INSERT INTO runs (version, config_path) VALUES ('0.test', '/etc/amfi/amfid.yaml');"; } |
        sqlite3 "$1" > /dev/null
    add_rows "$1" "$3"
}
