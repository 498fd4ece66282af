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
    for t in passages indicators alerts baseline runs; do
        l=$(sqlite3 "$1" "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t")
        c=$(pg_q "SELECT count(*) || ' ' || coalesce(max(id), 0) FROM $t WHERE site_id = '$2'")
        [ "$l" = "$c" ] || fail "$2 $t: store '$l' central '$c'"
    done
    l=$(sqlite3 "$1" "SELECT count(*) FROM axles")
    c=$(pg_q "SELECT count(*) FROM axles WHERE site_id = '$2'")
    [ "$l" = "$c" ] || fail "$2 axles: store '$l' central '$c'"
}
