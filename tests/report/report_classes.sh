#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_classes.sh: amfi-report's statistics per vehicle class
# (--classes, --class-histogram) and --overloads by class and axle group, on
# a fixture store of four classes on two lanes (report_classes.sql on
# docs/schema.md's DDL). The expected figures are computed from the same
# file with SQL (counts, means, nearest-rank percentiles, histogram bins),
# not written by hand; the overloaded A23 must be reported with the limits
# it exceeds (its class's 40 t and its tridem's) and nothing else; passages
# whose loads were refused (a stored reason, or one recomputed for a row
# written before store version 13) are listed apart, never as overloads.
#
# usage: report_classes.sh AMFI_REPORT SCHEMA_MD DIR_OF_report_classes.sql
# Exit 77 (skipped) without the sqlite3 program.
set -u
bin=${1:?usage: report_classes.sh AMFI_REPORT SCHEMA_MD DIR}
doc=${2:?usage: report_classes.sh AMFI_REPORT SCHEMA_MD DIR}
dir=${3:?usage: report_classes.sh AMFI_REPORT SCHEMA_MD DIR}
command -v sqlite3 > /dev/null || { echo "report_classes.sh: no sqlite3 program: skipped"; exit 77; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_classes.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
v=$(sed -n 's/.*PRAGMA user_version` (this document: version \([0-9]*\)).*/\1/p' "$doc")
[ -n "$v" ] || { echo "report_classes.sh: no schema version in $doc" >&2; exit 1; }
db=$tmp/classes.db
{
    cat "$tmp/ddl.sql"
    echo "PRAGMA user_version = $v;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $v)
INSERT INTO schema_migrations (version, description) SELECT i, 'fixture' FROM k;"
    cat "$dir/report_classes.sql"
} > "$tmp/fixture.sql"
sqlite3 "$db" < "$tmp/fixture.sql" > "$tmp/fixture.log" 2>&1 ||
    { echo "report_classes.sh: building the fixture failed:" >&2; cat "$tmp/fixture.log" >&2; exit 1; }

fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
run() { "$bin" "$@" > "$tmp/out" 2> "$tmp/err"; rc=$?; }
q() { sqlite3 -separator ' ' "$db" "$1"; }

# ---- --classes: every row against SQL -------------------------------------------
# WHERE of the selection: $1 ('' or 'AND lane = N' ...)
oracle() {
    sel="status = 'ok' AND gvw_kg IS NOT NULL $1"
    # class lane n mean p50 p95 max overloaded ("all" lanes as an empty lane)
    q "WITH s AS (SELECT class, lane, gvw_kg, overload FROM passages WHERE $sel),
         r AS (SELECT class, lane, gvw_kg, overload,
                 row_number() OVER (PARTITION BY class ORDER BY gvw_kg) AS ra,
                 count(*) OVER (PARTITION BY class) AS na,
                 row_number() OVER (PARTITION BY class, lane ORDER BY gvw_kg) AS rl,
                 count(*) OVER (PARTITION BY class, lane) AS nl FROM s)
       SELECT * FROM (
         SELECT class, '-' AS l, count(*), printf('%.1f', avg(gvw_kg)),
           max(CASE WHEN ra = (na * 50 + 99) / 100 THEN gvw_kg END),
           max(CASE WHEN ra = (na * 95 + 99) / 100 THEN gvw_kg END), max(gvw_kg), sum(overload)
         FROM r GROUP BY class
         UNION ALL
         SELECT class, lane AS l, count(*), printf('%.1f', avg(gvw_kg)),
           max(CASE WHEN rl = (nl * 50 + 99) / 100 THEN gvw_kg END),
           max(CASE WHEN rl = (nl * 95 + 99) / 100 THEN gvw_kg END), max(gvw_kg), sum(overload)
         FROM r GROUP BY class, lane)
       ORDER BY 1, l <> '-', l"
}
check_classes() { # WHERE ARGS...
    where=$1
    shift
    oracle "$where" > "$tmp/want"
    run --db "$db" --classes --format csv "$@"
    [ "$rc" = 0 ] || { fail "--classes $*: status $rc: $(cat "$tmp/err")"; return; }
    # class,lane,passages,share_pct,mean,std,p5,p50,p95,max,overloaded
    awk -F, 'NR > 1 { printf "%s %s %s %.1f %.1f %.1f %.1f %s\n", $1, $2 == "" ? "-" : $2, $3, $5,
             $8, $9, $10, $11 }' "$tmp/out" > "$tmp/got"
    awk '{ printf "%s %s %s %.1f %.1f %.1f %.1f %s\n", $1, $2, $3, $4, $5, $6, $7, $8 }' \
        "$tmp/want" > "$tmp/want.f"
    # one lane: the per-lane rows are left out (the "all" row is the lane)
    case $where in *lane*) grep ' - ' "$tmp/want.f" > "$tmp/want.a" && mv "$tmp/want.a" "$tmp/want.f" ;; esac
    cmp -s "$tmp/want.f" "$tmp/got" ||
        { fail "--classes $*: rows differ from SQL (- want + got):"; diff "$tmp/want.f" "$tmp/got"; }
}
check_classes ""
check_classes "AND lane = 2" --lane 2
check_classes "AND utime >= 1763773200000000 AND utime <= 1763783999999999" \
    --from 2025-11-22T01:00 --to 2025-11-22T03:59
n=$(grep -c '^A23 \|^CAR \|^R2 \|^R3 ' "$tmp/got" 2>/dev/null)
[ "$n" -ge 4 ] || fail "--classes with a range: only $n class rows"

run --db "$db" --classes
[ "$rc" = 0 ] || fail "--classes (table): status $rc: $(cat "$tmp/err")"
for cls in A23 CAR R2 R3; do
    grep -q "^$cls  *all  *$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND class = '$cls'") " "$tmp/out" ||
        fail "--classes table: no 'all' row of $cls with its count"
done
run --db "$db" --classes --format json
[ "$rc" = 0 ] && [ "$(grep -o '"class":' "$tmp/out" | wc -l)" = 12 ] ||
    fail "--classes json: status $rc, $(grep -o '"class":' "$tmp/out" | wc -l) rows, want 12"

# ---- --class-histogram ------------------------------------------------------------
q "SELECT class, CAST(gvw_kg / 5000 AS INTEGER) * 5000, count(*) FROM passages
   WHERE status = 'ok' AND gvw_kg IS NOT NULL GROUP BY 1, 2 ORDER BY 1, 2" > "$tmp/want"
run --db "$db" --class-histogram --bin-kg 5000 --format csv
[ "$rc" = 0 ] || fail "--class-histogram: status $rc: $(cat "$tmp/err")"
awk -F, 'NR > 1 { print $1, $2, $4 }' "$tmp/out" > "$tmp/got"
cmp -s "$tmp/want" "$tmp/got" ||
    { fail "--class-histogram csv differs from SQL (- want + got):"; diff "$tmp/want" "$tmp/got"; }
run --db "$db" --class-histogram --bin-kg 5000
grep -q '^total  *10  *9  *10  *10  *39$' "$tmp/out" || fail "--class-histogram table: totals: $(tail -1 "$tmp/out")"
run --db "$db" --class-histogram --bin-kg 5000 --format json
[ "$(grep -o '"passages":' "$tmp/out" | wc -l)" = "$(wc -l < "$tmp/want")" ] ||
    fail "--class-histogram json: not one object per non-empty bin"

# ---- --overloads by class and group --------------------------------------------------
run --db "$db" --overloads --format csv
[ "$rc" = 0 ] || fail "--overloads: status $rc: $(cat "$tmp/err")"
head -1 "$tmp/out" | grep -q '^time_utc,utime,passage_id,vehicle_id,lane,class,gvw_kg,gvw_limit_kg,limit,axles,kind,load_kg,limit_kg,over_pct,loads_refused$' ||
    fail "--overloads csv header: $(head -1 "$tmp/out")"
cut -d, -f3,6,8,9,10,11,12,13 "$tmp/out" | tail -n +2 > "$tmp/got"
printf '%s\n' '8,A23,40000.0,gvw,,gross,46000.0,40000.0' '8,A23,40000.0,group,3-5,tridem,27600.0,21000.0' > "$tmp/want"
cmp -s "$tmp/want" "$tmp/got" ||
    { fail "--overloads csv: not the A23's gross weight and tridem (- want + got):"; diff "$tmp/want" "$tmp/got"; }
run --db "$db" --overloads
grep -q '^A23  *10  *1  *1  *1  *10.00  *0$' "$tmp/out" || fail "--overloads table: no A23 line by class"
grep -q 'axles 3-5 tridem 27600 > 21000 kg' "$tmp/out" || fail "--overloads table: the tridem not named"
for cls in CAR R2 R3; do
    grep -q "^$cls  *$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND class = '$cls'")  *0  *0  *0 " "$tmp/out" ||
        fail "--overloads table: $cls not checked without an overload"
done
run --db "$db" --overloads --format json
grep -q '"by_class":\[{"class":"A23","checked":10,"over_gvw":1,"over_group":1,"overloaded":1,"refused":0}' "$tmp/out" ||
    fail "--overloads json: by_class"
grep -q '"exceeded":\[{"limit":"gvw","axles":null,"kind":"gross","load_kg":46000.0,"limit_kg":40000.0' "$tmp/out" ||
    fail "--overloads json: exceeded"

# ---- loads refused: never an overload, listed apart with the reason ---------------
# 41: an A23 whose tridem carries 276 t (over 10 x the 24 t any tridem may
# carry), with the reason amfid stored (store version 13); 42: an R3 whose
# tandem sums to -5 t, without a stored reason (a row written before version
# 13): the report refuses it again with the same classification. Neither is
# an overload nor checked; the overloads stay the A23 #8's two lines.
cp "$db" "$tmp/refused.db"
why41='group 3: load 276000 kg, over 10 x any legal load of 3 axles (24000 kg)'
why42='group 2 (axles 2-3): load -5000 kg < 0'
sqlite3 "$tmp/refused.db" "
INSERT INTO passages (id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      lambda, residual_rms, formulation, solve_ms, speed_given_mps,
                      speed_estimated, n_vehicles, quality, class, axle_groups, overload,
                      loads_refused)
VALUES (41, 1041, 1763769600000000 + 41 * 600000000, 1, 24.0, 5, 300000.0, 'ok', '', 1e-8, 0.001,
        'paper', 10.0, 24.0, 0, 1, 1.5, 'A23', '1-1-3', NULL, '$why41'),
       (42, 1042, 1763769600000000 + 42 * 600000000, 2, 24.0, 3, 10000.0, 'ok', '', 1e-8, 0.001,
        'paper', 10.0, 24.0, 0, 1, 1.5, 'R3', '1-2', NULL, NULL);
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
VALUES (41, 1, NULL, 8000), (41, 2, 3.6, 16000), (41, 3, 6.0, 92000), (41, 4, 1.3, 92000),
       (41, 5, 1.3, 92000), (42, 1, NULL, 15000), (42, 2, 4.5, -2000), (42, 3, 1.35, -3000);" || exit 1
run --db "$tmp/refused.db" --overloads --format csv
[ "$rc" = 0 ] || fail "--overloads with refused loads: status $rc: $(cat "$tmp/err")"
grep -v ',refused,' "$tmp/out" | cut -d, -f3,6,8,9,10,11,12,13 | tail -n +2 > "$tmp/got"
printf '%s\n' '8,A23,40000.0,gvw,,gross,46000.0,40000.0' '8,A23,40000.0,group,3-5,tridem,27600.0,21000.0' > "$tmp/want"
cmp -s "$tmp/want" "$tmp/got" ||
    { fail "--overloads csv: refused loads counted as overloads (- want + got):"; diff "$tmp/want" "$tmp/got"; }
grep -q "^[^,]*,[0-9]*,41,1041,1,A23,300000.0,40000.0,refused,,,,,,\"$why41\"\$" "$tmp/out" ||
    fail "--overloads csv: no refused line of passage 41 with its stored reason: $(grep ',41,' "$tmp/out")"
grep -q "^[^,]*,[0-9]*,42,1042,2,R3,[0-9.]*,26000.0,refused,,,,,,$why42\$" "$tmp/out" ||
    fail "--overloads csv: no refused line of passage 42 with the recomputed reason: $(grep ',42,' "$tmp/out")"
run --db "$tmp/refused.db" --overloads
grep -q '^checked 39 ok passages: 1 over .*, 1 overloaded in all' "$tmp/out" ||
    fail "--overloads table: refused passages counted as checked: $(grep '^checked' "$tmp/out")"
grep -q '^(2 ok passages not checked: their loads were refused, below)$' "$tmp/out" ||
    fail "--overloads table: the refused passages not counted"
grep -q '^A23  *10  *1  *1  *1  *10.00  *1$' "$tmp/out" || fail "--overloads table: A23's refused column"
grep -q '^R3  *10  *0  *0  *0  *0.00  *1$' "$tmp/out" || fail "--overloads table: R3's refused column"
grep -q '^== loads refused (2 ok passages' "$tmp/out" || fail "--overloads table: no section of refused loads"
grep -q " 41  *1041  *1  A23  .* loads refused: $why41\$" "$tmp/out" ||
    fail "--overloads table: passage 41 not listed refused with its reason: $(grep ' 41 ' "$tmp/out")"
grep -q " 42  *1042  *2  R3  .* loads refused: $why42 (recomputed: no reason stored)\$" "$tmp/out" ||
    fail "--overloads table: passage 42 not listed refused with the recomputed reason: $(grep ' 42 ' "$tmp/out")"
[ "$(grep -c '^[0-9-]*T[0-9:]*Z  *4[12] ' "$tmp/out")" = 2 ] ||
    fail "--overloads table: passages 41 and 42 listed more than once (as overloads?)"
run --db "$tmp/refused.db" --overloads --format json
grep -q '"overloaded":1,"unclassified":0,"refused":2,"refused_recomputed":1' "$tmp/out" ||
    fail "--overloads json: the refused counts"
grep -q '{"class":"R3","checked":10,"over_gvw":0,"over_group":0,"overloaded":0,"refused":1}' "$tmp/out" ||
    fail "--overloads json: R3's refused count"
grep -q "\"passage_id\":41,\"vehicle_id\":1041,\"lane\":1,\"class\":\"A23\",\"gvw_kg\":300000.0,\"loads_refused\":\"$why41\",\"reason_from\":\"stored\"}" "$tmp/out" ||
    fail "--overloads json: refused_passages: 41"
grep -q "\"passage_id\":42,.*\"loads_refused\":\"$why42\",\"reason_from\":\"recomputed\"}" "$tmp/out" ||
    fail "--overloads json: refused_passages: 42"
# --classes counts the refusals stored (41's), not the recomputed ones (42's)
run --db "$tmp/refused.db" --classes --format csv
[ "$(head -1 "$tmp/out" | cut -d, -f11,12)" = "overloaded,loads_refused" ] ||
    fail "--classes csv: no loads_refused column: $(head -1 "$tmp/out")"
[ "$(awk -F, '$2 == "" && ($1 == "A23" || $1 == "R3") { printf "%s=%s ", $1, $12 }' "$tmp/out")" = "A23=1 R3=0 " ] ||
    fail "--classes csv: the stored refusals by class: $(grep '^A23,,\|^R3,,' "$tmp/out")"
# a reason the store holds is checked when read: a control character is refused
sqlite3 "$tmp/refused.db" "UPDATE passages SET loads_refused = 'bad' || char(10) || 'reason' WHERE id = 41" || exit 1
run --db "$tmp/refused.db" --overloads
[ "$rc" != 0 ] && grep -q "passages.*41.*loads_refused.*control character" "$tmp/err" ||
    fail "a stored reason with a control character: status $rc: $(cat "$tmp/err")"

# the classes and limits amfid ran with (meta daemon.classes) rule, not
# --config's nor the defaults: the A23's 46 t under a recorded 48 t limit
cp "$db" "$tmp/rec.db"
sqlite3 "$tmp/rec.db" "INSERT INTO meta (key, value) VALUES ('daemon.classes', 'scheme=eu group_spacing_m=2 light_max_kg=3500 container_44t=0 gvw_limit_kg.CAR=0 gvw_limit_kg.R2=18000 gvw_limit_kg.R3=26000 gvw_limit_kg.R4=32000 gvw_limit_kg.A22=36000 gvw_limit_kg.A23=48000 gvw_limit_kg.A32=40000 gvw_limit_kg.A33=40000 single_axle_kg=10000 driving_axle_kg=11500 motor_tandem_air=1')" || exit 1
printf 'classes:\n  gvw_limit_kg:\n    A23: 30000\n' > "$tmp/other.yaml"
run --db "$tmp/rec.db" --overloads --format csv --config "$tmp/other.yaml"
cut -d, -f3,6,8,9,10,11 "$tmp/out" | tail -n +2 > "$tmp/got"
printf '%s\n' '8,A23,48000.0,group,3-5,tridem' > "$tmp/want"
cmp -s "$tmp/want" "$tmp/got" ||
    { fail "--overloads with daemon.classes: (- want + got):"; diff "$tmp/want" "$tmp/got"; }
run --db "$tmp/rec.db" --overloads
grep -q "scheme eu, amfid's, from the store;" "$tmp/out" || fail "--overloads: does not say the limits are amfid's: $(head -1 "$tmp/out")"
sqlite3 "$tmp/rec.db" "UPDATE meta SET value = 'scheme=xx' WHERE key = 'daemon.classes'" || exit 1
run --db "$tmp/rec.db" --overloads
[ "$rc" = 1 ] && grep -q "rec.db: meta daemon.classes: scheme: 'xx' is not eu or fhwa13" "$tmp/err" ||
    fail "a damaged daemon.classes: status $rc: $(cat "$tmp/err")"

[ "$fails" = 0 ] && echo "ok: report_classes"
exit $((fails > 0))
