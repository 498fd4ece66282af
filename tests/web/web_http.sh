#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# web_http.sh: amfi-web on a fixture store (web_fixture), on 127.0.0.1 and
# a port it picks, checked over HTTP by web_http (the JSON API, headers,
# 400/404/405, traversal, escaping, fuzzing); then its start-up refusals and
# a clean stop on SIGTERM. Usage: web_http.sh AMFI_WEB WEB_FIXTURE WEB_HTTP
set -u
web=$1 fixture=$2 client=$3
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/proc.sh"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/web_http.XXXXXX") || exit 1
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; rm -rf "$tmp"' EXIT INT TERM
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

"$fixture" "$tmp/s.db" || { echo "FAIL: web_fixture"; exit 1; }
"$web" --db "$tmp/s.db" --listen 127.0.0.1:0 > "$tmp/out" 2> "$tmp/err" &
pid=$!
wait_for "serving store" "$tmp/err" "$pid" 60 || { cat "$tmp/err"; exit 1; }
port=$(sed -n 's|.*http://127\.0\.0\.1:\([0-9]*\)/$|\1|p' "$tmp/err")
[ -n "$port" ] || { cat "$tmp/err"; exit 1; }
"$client" "$port" || fail "web_http"
stop_pid "$pid" 60 || fail "amfi-web: exit $? on SIGTERM"
pid=
grep -q "AddressSanitizer\|runtime error" "$tmp/err" && { cat "$tmp/err"; fail "sanitizer"; }

# refusals at start: exit 2 with the option named, 1 for a store it cannot open
refuse() {
    want=$1 pattern=$2
    shift 2
    "$web" "$@" > "$tmp/o" 2> "$tmp/e"
    rc=$?
    [ "$rc" = "$want" ] || fail "amfi-web $*: exit $rc, expected $want"
    grep -q -- "$pattern" "$tmp/e" || { cat "$tmp/e"; fail "amfi-web $*: no '$pattern'"; }
}
refuse 2 "--listen.*not a loopback" --db "$tmp/s.db" --listen 0.0.0.0:8080
refuse 2 "--listen.*not ADDR:PORT" --db "$tmp/s.db" --listen 127.0.0.1
refuse 2 "--listen.*not ADDR:PORT" --db "$tmp/s.db" --listen 127.0.0.1:70000
refuse 2 "one of them" --listen 127.0.0.1:0
refuse 2 "one of them" --db "$tmp/s.db" --pg "host=/nonexistent"
refuse 2 "needs --site" --pg "host=/nonexistent"
refuse 2 "--site.*only with --pg" --db "$tmp/s.db" --site x
refuse 1 "no-such.db" --db "$tmp/no-such.db" --listen 127.0.0.1:0
echo "not sqlite" > "$tmp/bad.db"
refuse 1 "bad.db" --db "$tmp/bad.db" --listen 127.0.0.1:0
# the store is opened read-only: its bytes are unchanged after serving
sum1=$(md5sum < "$tmp/s.db")
"$web" --db "$tmp/s.db" --listen 127.0.0.1:0 2> "$tmp/err2" &
pid=$!
wait_for "serving store" "$tmp/err2" "$pid" 60 || fail "second start"
stop_pid "$pid" 60 || fail "second stop"
pid=
[ "$sum1" = "$(md5sum < "$tmp/s.db")" ] || fail "the store changed while served"
[ "$failures" = 0 ] || { echo "web_http.sh: $failures failures"; exit 1; }
echo "web_http.sh: ok"
