#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# web_browser.sh: amfi-web's pages in headless Chromium, on the fixture store
# (web_fixture) and on the same rows in a throwaway central PostgreSQL
# (tests/common/pg_server.sh, shipped with amfi-sync; amfi-web --pg). Each
# page loads without a console message (errors, CSP refusals: the script
# logs nothing itself) and its drawn DOM is checked: the table rows carry
# the fixture's passage and alert ids, each chart's canvas was drawn
# (data-drawn) with the expected number of points (data-points), the
# hostile reason and alert text appear as text, never as elements; the
# vehicle page draws a passage's raw signal (one chart per sensor). Chromium
# gets a fresh profile in the test's directory and a timeout; everything on
# 127.0.0.1. Usage: web_browser.sh AMFI_WEB WEB_FIXTURE AMFI_SYNC.
# Exit 77 without chromium (the PostgreSQL half is skipped without its
# server programs).
set -u
web=$1 fixture=$2 sync=$3
command -v chromium > /dev/null || { echo "web_browser.sh: no chromium: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/proc.sh"
. "$here/../common/pg_server.sh"
tmp=$(mktemp -d "${TMPDIR:-/tmp}/web_browser.XXXXXX") || exit 1
chmod 755 "$tmp"
pid=
trap '[ -n "$pid" ] && kill "$pid" 2>/dev/null; pg_stop; rm -rf "$tmp"' EXIT INT TERM
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# page URL NAME: the DOM after the scripts ran into $tmp/NAME.html, Chromium's
# log into $tmp/NAME.log; a console line there is a failure unless NAME
# ends in -error.
page() {
    timeout 120 chromium --headless=new --no-sandbox --disable-gpu --no-first-run \
        --user-data-dir="$tmp/profile" --enable-logging=stderr --v=0 \
        --virtual-time-budget=10000 --dump-dom "$1" > "$tmp/$2.html" 2> "$tmp/$2.log"
    rc=$?
    [ "$rc" = 0 ] || fail "$2: chromium exit $rc"
    case $2 in
    *-error) ;;
    *) if grep -q ":CONSOLE" "$tmp/$2.log"; then
           grep ":CONSOLE" "$tmp/$2.log" | head -5
           fail "$2: console messages"
       fi ;;
    esac
}
# has NAME PATTERN [COUNT]: the DOM of NAME holds PATTERN (grep -E, -o
# counted: exactly COUNT times when given)
has() {
    n=$(grep -oE -- "$2" "$tmp/$1.html" | wc -l)
    if [ $# -ge 3 ]; then
        [ "$n" = "$3" ] || fail "$1: '$2' $n times, expected $3"
    else
        [ "$n" -ge 1 ] || fail "$1: no '$2'"
    fi
}
# ids NAME TABLE: the data-id values of TABLE's rows, space-separated
ids() {
    sed -n "s/.*<table id=\"$2\">\(.*\)/\1/p" "$tmp/$1.html" | sed 's|</table>.*||' |
        grep -o 'data-id="[0-9]*"' | tr -dc '0-9\n' | tr '\n' ' ' | sed 's/ $//'
}
canvas() { # canvas NAME ID POINTS: drawn, with POINTS points
    grep -oE "<canvas id=\"$2\"[^>]*>" "$tmp/$1.html" > "$tmp/c" || { fail "$1: no canvas $2"; return; }
    grep -q "data-points=\"$3\"" "$tmp/c" || fail "$1: canvas $2: $(cat "$tmp/c"), expected $3 points"
    grep -q 'data-drawn="1"' "$tmp/c" || fail "$1: canvas $2 not drawn"
}

# The console check sees errors at all (this Chromium's log format).
timeout 120 chromium --headless=new --no-sandbox --disable-gpu --no-first-run \
    --user-data-dir="$tmp/profile" --enable-logging=stderr --v=0 --virtual-time-budget=2000 \
    --dump-dom 'data:text/html,<script>console.error("web-probe");undefinedFunction()</script>' \
    > /dev/null 2> "$tmp/probe.log"
grep -q ':CONSOLE.*web-probe' "$tmp/probe.log" && grep -q ':CONSOLE.*Uncaught' "$tmp/probe.log" ||
    { cat "$tmp/probe.log"; fail "console messages are not seen in Chromium's log"; }

# all pages of the server at $base ($1: store or central)
pages() {
    k=$1
    page "$base/" "$k-status"
    [ "$(ids "$k-status" passages)" = "40 39 38 37 36 35 34 33 32 31" ] ||
        fail "$k-status: latest passages '$(ids "$k-status" passages)'"
    has "$k-status" '<td>web-test</td>' 1
    has "$k-status" 'STD up &lt;img src=x onerror="window.__xss=1"&gt;' 1
    has "$k-status" '<td class="num">16</td>'   # ok passages of the newest day

    page "$base/passages" "$k-passages"
    [ "$(ids "$k-passages" passages)" = "$(seq 40 -1 1 | tr '\n' ' ' | sed 's/ $//')" ] ||
        fail "$k-passages: '$(ids "$k-passages" passages)'"
    has "$k-passages" 'solver: &lt;img src=x onerror="window.__xss=1"&gt;' 1
    has "$k-passages" '<td>loads refused: group 2: &lt;img src=x onerror="window.__xss=1"&gt;' 1
    page "$base/passages?status=invalid&limit=3" "$k-invalid"
    [ "$(ids "$k-invalid" passages)" = "33 23 13" ] || fail "$k-invalid: '$(ids "$k-invalid" passages)'"
    page "$base/passages?status=bogus" "$k-passages-error"
    has "$k-passages-error" 'id="error">Could not load: .bogus. is not a status' 1

    page "$base/vehicle?id=7" "$k-vehicle"
    has "$k-vehicle" '<table id="axles">' 1
    has "$k-vehicle" '<td class="num">7500</td>' 1
    has "$k-vehicle" '<td class="num">22200</td>' 1      # the group 3-4-5
    has "$k-vehicle" 'solver: &lt;img src=x onerror="window.__xss=1"&gt;' 1
    has "$k-vehicle" 'id="raw-reason"' 1
    canvas "$k-vehicle" chart-axles 5
    # the raw signal: one chart per sensor, every sample or 4000 points
    # (decimated), the entry marked; none from the central database
    page "$base/vehicle?id=5" "$k-signal"
    if [ "$k" = store ]; then
        page "$base/vehicle?id=11" "$k-signal-long"
        page "$base/vehicle?id=15" "$k-signal-event"
        page "$base/vehicle?id=17" "$k-signal-damaged"
        canvas "$k-signal" chart-signal-0 1500
        canvas "$k-signal" chart-signal-1 1500
        has "$k-signal" '<canvas id="chart-signal-' 2
        has "$k-signal" 'id="raw-info"' 1
        for c in 0 1 2; do canvas "$k-signal-long" chart-signal-$c 4000; done
        has "$k-signal-long" 'min and max of every 15 samples' 1
        canvas "$k-signal-event" chart-signal-0 2000
        has "$k-signal-event" 'data-entry-s="1.7"' 2
        has "$k-signal-event" '2 vehicle\(s\) in the window' 1
        has "$k-signal-damaged" 'id="raw-reason"[^>]*>the raw samples are damaged: passage 17' 1
    else # one page: the central database has no raw samples for any passage
        has "$k-signal" 'id="raw-reason"[^>]*>the central database does not ship raw samples' 1
        has "$k-signal" 'chart-signal' 0
    fi
    page "$base/vehicle?id=41" "$k-vehicle-error"
    has "$k-vehicle-error" 'id="error">Could not load: no passage 41' 1

    page "$base/trends" "$k-trends"
    canvas "$k-trends" chart-gvw 35
    canvas "$k-trends" chart-indicator 8
    canvas "$k-trends" chart-natfreq 20
    canvas "$k-trends" chart-residual 36
    canvas "$k-trends" chart-temperature 12
    # the model fit with the model_mismatch levels as two flat lines: amfid's
    # (meta alerts.model_fit) from the store, the defaults from the central
    # database (which does not ship meta)
    canvas "$k-trends" chart-fit_ratio 15
    if [ "$k" = store ]; then
        lv="raise at (&gt;|>)= 0.2 \(median of 5, 3 in a row; amfid's\)\|clear below 0.1 \(4 in a row\)"
    else
        lv="raise at (&gt;|>)= 0.1 \(median of 25, 10 in a row; defaults\)\|clear below 0.05 \(25 in a row\)"
    fi
    has "$k-trends" "<canvas id=\"chart-fit_ratio\"[^>]*data-series=\"mean\|min\|max\|$lv\"" 1
    has "$k-trends" 'data-series="mean\|min\|max"' 5

    page "$base/alerts" "$k-alerts"
    [ "$(ids "$k-alerts" open-alerts)" = "1" ] || fail "$k-alerts: open '$(ids "$k-alerts" open-alerts)'"
    [ "$(ids "$k-alerts" alerts)" = "3 2 1" ] || fail "$k-alerts: events '$(ids "$k-alerts" alerts)'"

    page "$base/classes" "$k-classes"
    has "$k-classes" '<td>FHWA9</td><td class="num">11</td><td class="num">11</td><td class="num">1</td><td class="num">1</td>' 1
    canvas "$k-classes" chart-classes 4

    # the hostile text never became an element, on any page
    for f in "$tmp/$k"-*.html; do
        grep -q '<img\|<script>window\|onerror="window.__xss=1">' "$f" && fail "$(basename "$f"): hostile text parsed as HTML"
    done
}

serve() { # serve ARGS...: amfi-web started, $base its address
    # emptied here, not only by the background child's redirection: the
    # wait below must not see the previous server's "serving" and port (the
    # central pass once failed with "no fetch line" that way, under load)
    : > "$tmp/web.err"
    "$web" "$@" --listen 127.0.0.1:0 2> "$tmp/web.err" &
    pid=$!
    wait_for "serving" "$tmp/web.err" "$pid" 120 || { cat "$tmp/web.err"; exit 1; }
    base=http://127.0.0.1:$(sed -n 's|.*http://127\.0\.0\.1:\([0-9]*\)/$|\1|p' "$tmp/web.err")
}
stop() {
    stop_pid "$pid" 60 || fail "amfi-web: exit $? on SIGTERM"
    pid=
    grep -q "AddressSanitizer\|runtime error" "$tmp/web.err" && { cat "$tmp/web.err"; fail "sanitizer"; }
}

"$fixture" "$tmp/s.db" || { echo "FAIL: web_fixture"; exit 1; }
serve --db "$tmp/s.db"
pages store
stop

# the central database: the fixture's rows shipped by amfi-sync
if command -v initdb > /dev/null && command -v pg_ctl > /dev/null; then
    mkdir "$tmp/pg" && chmod 755 "$tmp/pg"
    pg_start "$tmp/pg"
    "$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "amfi-sync --init-schema"
    "$sync" --db "$tmp/s.db" --pg "$PG_CONNINFO" --once --quiet || fail "amfi-sync --once"
    serve --pg "$PG_CONNINFO" --site web-test
    grep -q "site web-test: [0-9]* rows fetched" "$tmp/web.err" || fail "central: no fetch line"
    pages central
    stop
    # an unknown site: exit 2, the sites named
    "$web" --pg "$PG_CONNINFO" --site nope --listen 127.0.0.1:0 2> "$tmp/e"
    rc=$?
    [ "$rc" = 2 ] && grep -q "no site 'nope'.*web-test" "$tmp/e" || { cat "$tmp/e"; fail "unknown site: exit $rc"; }
    pg_stop
    ls "$tmp"/t 2> /dev/null
else
    echo "web_browser.sh: no PostgreSQL server programs: the central half skipped"
fi
[ "$failures" = 0 ] || { echo "web_browser.sh: $failures failures"; exit 1; }
echo "web_browser.sh: ok"
