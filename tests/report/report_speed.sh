#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_speed.sh: amfi-report --speed (issue 12): the speed corrections of
# the passages whose speed amfid estimated, on a fixture store built with the
# sqlite3 program from the DDL in docs/schema.md and filled with known
# corrections c = speed_mps / speed_given_mps - 1:
#   2025-11-22: 10 passages on lane 1, c = +0.10 % + (2i - 11) * 0.16 %, i = 1 .. 10
#   2025-11-23: the same around -2.00 %, 2025-11-24 around -4.00 %,
#   2025-11-24: 2 more on lane 2 with c = +5.20 %;
# besides, passages that were not estimated (their speeds differ by 10 %) and
# an estimated one whose speed is unknown, neither of which may count. The
# expected figures were computed apart from amfi-report (nearest-rank
# percentiles, sample STD) and are compared as exact output, in the table,
# CSV and JSON formats, with the time and lane filters; the section appears
# by default only when the store has estimated speeds; a damaged speed is an
# error naming its row.
#
# usage: report_speed.sh PATH/TO/amfi-report PATH/TO/docs/schema.md PATH/TO/json_check
# Exit 77 (skipped) without the sqlite3 program.
set -u

bin=${1:?usage: report_speed.sh AMFI_REPORT SCHEMA_MD JSON_CHECK}
doc=${2:?usage: report_speed.sh AMFI_REPORT SCHEMA_MD JSON_CHECK}
jcheck=${3:?usage: report_speed.sh AMFI_REPORT SCHEMA_MD JSON_CHECK}
command -v sqlite3 > /dev/null || { echo "report_speed.sh: no sqlite3 program: skipped"; exit 77; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_speed.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
failures=0
cases=0
problem() { echo "FAIL $name: $*"; failures=$((failures + 1)); }

awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
[ -s "$tmp/ddl.sql" ] || { echo "report_speed.sh: no DDL block in $doc" >&2; exit 1; }
# the fixture is at the document's schema version, with its migration rows
v=$(sed -n 's/.*PRAGMA user_version` (this document: version \([0-9]*\)).*/\1/p' "$doc")
[ -n "$v" ] || { echo "report_speed.sh: no schema version in $doc" >&2; exit 1; }
migrations="PRAGMA user_version = $v;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $v)
INSERT INTO schema_migrations (version, description) SELECT i, 'report_speed fixture' FROM k;"
db=$tmp/speed.db
{
    cat "$tmp/ddl.sql"
    echo "$migrations"
    cat <<'EOF'
PRAGMA journal_mode = WAL;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 10),
     d(day, base) AS (VALUES (0, 1.001), (1, 0.98), (2, 0.96))
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      speed_given_mps, speed_estimated)
SELECT 100 * day + i, 1763769600000000 + day * 86400000000 + i * 3600000000, 1,
       25.0 * base + 0.04 * (2 * i - 11), 2, 20000.0, 'ok', '', 25.0, 1
FROM k, d;
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      speed_given_mps, speed_estimated) VALUES
  (901, 1763769600000000 + 2 * 86400000000 + 11 * 3600000000, 2, 26.3, 2, 20000.0, 'ok', '', 25.0, 1),
  (902, 1763769600000000 + 2 * 86400000000 + 12 * 3600000000, 2, 26.3, 2, 20000.0, 'ok', '', 25.0, 1),
  (903, 1763769600000000 + 86400000000 + 13 * 3600000000, 1, NULL, 0, NULL, 'error',
   'speed search failed', 25.0, 1);
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 5)
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      speed_given_mps, speed_estimated)
SELECT 800 + i, 1763769600000000 + i * 3600000000 + 1800000000, 1, 27.5, 2, 20000.0, 'ok', '',
       25.0, 0 FROM k;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 1, NULL, 8000.0 FROM passages WHERE n_axles = 2;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 2, 4.5, 12000.0 FROM passages WHERE n_axles = 2;
EOF
} > "$tmp/fixture.sql"
if ! sqlite3 "$db" < "$tmp/fixture.sql" > "$tmp/fixture.log" 2>&1; then
    echo "report_speed.sh: building the fixture failed:" >&2
    cat "$tmp/fixture.log" >&2
    exit 1
fi
sum0=$(md5sum < "$db")

# same NAME EXPECTED-FILE ARGS...: exit 0, nothing on stderr, stdout EXPECTED:
# the words and integers exactly, the figures as numbers within one unit of
# the table's last digit (tests/common/num_cmp.sh; floating point is not compared
# byte for byte: a value on a rounding boundary may print either way)
same() {
    name=$1 want=$2
    shift 2
    cases=$((cases + 1))
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    [ "$rc" -eq 0 ] || { problem "status $rc, expected 0 ($(head -c 300 "$tmp/err"))"; return; }
    [ -s "$tmp/err" ] && problem "wrote to stderr: $(head -c 300 "$tmp/err")"
    sh "$(dirname "$0")/../common/num_cmp.sh" -r 0 -a 0.0101 "$want" "$tmp/out" > "$tmp/why" ||
        problem "output differs: $(cat "$tmp/why"); $(diff "$want" "$tmp/out" | head -20)"
}

cat > "$tmp/want.table" <<'EOF'
== speed corrections (c = speed weighed with / detector's speed - 1)
estimated    32 passages, 2025-11-22 .. 2025-11-24
c            median -1.84 %, mean -1.52 %, STD 2.58 %
percentiles  p5 -5.12 %, p25 -3.44 %, p75 -0.38 %, p95 +5.20 %
|c| > 1 %    75.0 % of them; |c| > 3 %: 37.5 %
day (UTC)        n     median         p5        p95
2025-11-22      10    -0.06 %    -1.34 %    +1.54 %
2025-11-23      10    -2.16 %    -3.44 %    -0.56 %
2025-11-24      12    -3.84 %    -5.44 %    +5.20 %
EOF
same table "$tmp/want.table" --db "$db" --speed

cat > "$tmp/want.lane1" <<'EOF'
== speed corrections (c = speed weighed with / detector's speed - 1)
estimated    30 passages, 2025-11-22 .. 2025-11-24
c            median -2.16 %, mean -1.97 %, STD 1.94 %
percentiles  p5 -5.12 %, p25 -3.44 %, p75 -0.56 %, p95 +1.22 %
|c| > 1 %    73.3 % of them; |c| > 3 %: 33.3 %
day (UTC)        n     median         p5        p95
2025-11-22      10    -0.06 %    -1.34 %    +1.54 %
2025-11-23      10    -2.16 %    -3.44 %    -0.56 %
2025-11-24      10    -4.16 %    -5.44 %    -2.56 %
EOF
same lane1 "$tmp/want.lane1" --db "$db" --speed --lane 1

cat > "$tmp/want.csv" <<'EOF'
day,n,median_pct,p5_pct,p25_pct,p75_pct,p95_pct,mean_pct,std_pct,over_1pct_share_pct,over_3pct_share_pct
all,32,-1.8400,-5.1200,-3.4400,-0.3800,5.2000,-1.5188,2.5760,75.0000,37.5000
2025-11-22,10,-0.0600,-1.3400,-0.7000,0.9000,1.5400,0.1000,0.9688,40.0000,0.0000
2025-11-23,10,-2.1600,-3.4400,-2.8000,-1.2000,-0.5600,-2.0000,0.9688,80.0000,20.0000
2025-11-24,12,-3.8400,-5.4400,-4.8000,-2.8800,5.2000,-2.4667,3.6868,100.0000,83.3333
EOF
same csv "$tmp/want.csv" --db "$db" --speed --format csv

cat > "$tmp/want.day2" <<'EOF'
day,n,median_pct,p5_pct,p25_pct,p75_pct,p95_pct,mean_pct,std_pct,over_1pct_share_pct,over_3pct_share_pct
all,10,-2.1600,-3.4400,-2.8000,-1.2000,-0.5600,-2.0000,0.9688,80.0000,20.0000
2025-11-23,10,-2.1600,-3.4400,-2.8000,-1.2000,-0.5600,-2.0000,0.9688,80.0000,20.0000
EOF
same csv-one-day "$tmp/want.day2" --db "$db" --speed --format csv --from 2025-11-23 --to 2025-11-23

# JSON: one document; the figures under "speed"
name=json
cases=$((cases + 1))
if "$bin" --db "$db" --speed --format json > "$tmp/out" 2> "$tmp/err"; then
    "$jcheck" < "$tmp/out" || problem "not one JSON document"
    for want in '"speed":{"n":32,"median_pct":-1.84' '"p25_pct":-3.44' '"p75_pct":-0.38' \
        '"p95_pct":5.2' '"over_1pct_share_pct":75' '"over_3pct_share_pct":37.5' \
        '"days":[{"day":"2025-11-22","n":10,"median_pct":-0.06' \
        '{"day":"2025-11-24","n":12,"median_pct":-3.84,"p5_pct":-5.44,"p95_pct":5.2'; do
        grep -qF -- "$want" "$tmp/out" || problem "lacks $want: $(head -c 400 "$tmp/out")"
    done
else
    problem "status $?: $(cat "$tmp/err")"
fi

# by default (no section asked for) the section follows the alerts, here
name=default
cases=$((cases + 1))
"$bin" --db "$db" > "$tmp/out" 2> "$tmp/err" || problem "status $?: $(cat "$tmp/err")"
grep -q '^== alerts' "$tmp/out" || problem "no alerts section"
grep -q '^estimated    32 passages' "$tmp/out" || problem "no speed section by default"
name=default-json
cases=$((cases + 1))
"$bin" --db "$db" --format json > "$tmp/out" 2> "$tmp/err" || problem "status $?: $(cat "$tmp/err")"
grep -qF '"speed":{"n":32' "$tmp/out" || problem "no speed object by default"

# a store without estimated speeds: not by default, and said so when asked
sqlite3 "$tmp/plain.db" < "$tmp/ddl.sql"
sqlite3 "$tmp/plain.db" "$migrations"
sqlite3 "$tmp/plain.db" "INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg,
    status, speed_given_mps, speed_estimated) VALUES (1, 1763769600000000, 1, 27.5, 0, NULL, 'gap',
    25.0, 0)"
name=plain-default
cases=$((cases + 1))
"$bin" --db "$tmp/plain.db" > "$tmp/out" 2> "$tmp/err" || problem "status $?: $(cat "$tmp/err")"
grep -q 'speed corrections' "$tmp/out" && problem "a speed section without estimated speeds"
printf '%s\n' "== speed corrections (c = speed weighed with / detector's speed - 1)" \
    "(no estimated passages in the selection: amfid estimates the speed with solver.speed: estimate)" \
    > "$tmp/want.none"
same plain-asked "$tmp/want.none" --db "$tmp/plain.db" --speed
cat > "$tmp/want.nonecsv" <<'EOF'
day,n,median_pct,p5_pct,p25_pct,p75_pct,p95_pct,mean_pct,std_pct,over_1pct_share_pct,over_3pct_share_pct
all,0,,,,,,,,,
EOF
same plain-csv "$tmp/want.nonecsv" --db "$tmp/plain.db" --speed --format csv

name=read-only
cases=$((cases + 1))
[ "$(md5sum < "$db")" = "$sum0" ] || problem "the report changed the store"

# bad: one line on stderr, the status, nothing on stdout
bad() {
    name=$1 want=$2 pattern=$3
    shift 3
    cases=$((cases + 1))
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    [ "$rc" -eq "$want" ] || problem "status $rc, expected $want"
    [ "$(wc -l < "$tmp/err")" -eq 1 ] || problem "stderr: $(cat "$tmp/err")"
    grep -Eq -- "$pattern" "$tmp/err" || problem "stderr lacks /$pattern/: $(cat "$tmp/err")"
    [ -s "$tmp/out" ] && problem "wrote to stdout: $(head -c 200 "$tmp/out")"
}
bad csv-two 2 '^amfi-report: --format: csv takes one section at a time \(2 given\)$' \
    --db "$db" --speed --summary --format csv
cp "$db" "$tmp/damaged.db"
sqlite3 "$tmp/damaged.db" "PRAGMA ignore_check_constraints = ON;
    UPDATE passages SET speed_given_mps = 500 WHERE vehicle_id = 105"
bad damaged 1 "^amfi-report: $tmp/damaged\\.db: passages row [0-9]+: speed_given_mps.* out of range" \
    --db "$tmp/damaged.db" --speed

# --plot: speed_correction.png from one line per day (day, n, median, p5, p95)
if command -v gnuplot > /dev/null; then
    name=plot
    cases=$((cases + 1))
    if "$bin" --db "$db" --plot "$tmp/plots" > "$tmp/out" 2> "$tmp/err"; then
        grep -q "^plot  $tmp/plots/speed_correction\\.png  daily median speed correction" "$tmp/out" ||
            problem "no speed_correction.png line: $(cat "$tmp/out")"
        [ -s "$tmp/plots/speed_correction.png" ] || problem "no speed_correction.png"
        printf '%s\n' '1763769600 10 -0.0600 -1.3400 1.5400' '1763856000 10 -2.1600 -3.4400 -0.5600' \
            '1763942400 12 -3.8400 -5.4400 5.2000' > "$tmp/want.dat"
        grep -v '^#' "$tmp/plots/data/speed_correction.dat" | cmp -s "$tmp/want.dat" - ||
            problem "speed_correction.dat: $(cat "$tmp/plots/data/speed_correction.dat")"
    else
        problem "status $?: $(cat "$tmp/err")"
    fi
    name=plot-plain
    cases=$((cases + 1))
    "$bin" --db "$tmp/plain.db" --plot "$tmp/plots-plain" > "$tmp/out" 2> "$tmp/err" ||
        problem "status $?: $(cat "$tmp/err")"
    grep -q speed_correction "$tmp/out" && problem "speed_correction.png without estimated speeds"
else
    echo "report_speed.sh: no gnuplot: --plot skipped"
fi

echo "report_speed.sh: $cases cases, $failures failed"
[ "$failures" -eq 0 ]
