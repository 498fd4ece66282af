#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_cli.sh: amfi-report on a fixture store. The fixture is built with
# the sqlite3 program from the DDL in docs/schema.md (the same DDL the store
# creates: test_store checks that), then filled with known rows; every mode
# must print what the rows say (figures cross-checked with sqlite3 itself),
# exit 0, leave the file unchanged unless it sets a baseline, and every bad
# database or command line must fail cleanly: status 1 (data) or 2 (usage),
# never a crash, one line on stderr, nothing on stdout.
#
# usage: report_cli.sh PATH/TO/amfi-report PATH/TO/docs/schema.md [PATH/TO/json_check]
# Exit 77 (skipped) without the sqlite3 program.
set -u

bin=${1:?usage: report_cli.sh AMFI_REPORT SCHEMA_MD JSON_CHECK STORE_STAMP}
doc=${2:?usage: report_cli.sh AMFI_REPORT SCHEMA_MD}
jcheck=${3:-}
stamp=${4:?usage: report_cli.sh AMFI_REPORT SCHEMA_MD JSON_CHECK STORE_STAMP}
[ -x "$bin" ] || { echo "report_cli.sh: $bin: not executable" >&2; exit 1; }
[ -r "$doc" ] || { echo "report_cli.sh: $doc: not readable" >&2; exit 1; }
command -v sqlite3 > /dev/null || { echo "report_cli.sh: no sqlite3 program: skipped"; exit 77; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_cli.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

failures=0
cases=0
problem() { echo "FAIL $name: $*"; failures=$((failures + 1)); }

# ---- the fixture ----------------------------------------------------------
# 40 passages an hour apart from 2025-11-22 00:00 UTC (1763769600 s): every
# tenth a gap (no GVW), the others ok, GVW 15 000 + 1000·(i mod 7) kg; a truth
# row per vehicle 2 % lighter than inferred; 25 indicators; alerts: a
# mean_shift raised then cleared, a std_increase raised and still open; one
# automatic baseline.
db=$tmp/fixture.db
awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
[ -s "$tmp/ddl.sql" ] || { echo "report_cli.sh: no DDL block in $doc" >&2; exit 1; }
{
    cat "$tmp/ddl.sql"
    cat <<'EOF'
PRAGMA journal_mode = WAL;
WITH RECURSIVE k(i) AS (SELECT 0 UNION ALL SELECT i + 1 FROM k WHERE i < 11)
INSERT INTO environment (utime, deck_c, air_c, received_utime)
SELECT 1763769600000000 + i * 7200000000, -3.25 + i, -6.0 + 0.5 * i, 1763769600000000 FROM k;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 40)
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status,
                      reason, lambda, residual_rms, formulation, solve_ms, speed_given_mps)
SELECT i, 1763769600000000 + i * 3600000000, 1, 25.0, 2,
       CASE WHEN i % 10 = 0 THEN NULL ELSE 15000.0 + 1000 * (i % 7) END,
       CASE WHEN i % 10 = 0 THEN 'gap' ELSE 'ok' END,
       CASE WHEN i % 10 = 0 THEN '12 samples missing in the window' ELSE '' END,
       CASE WHEN i % 10 = 0 THEN NULL ELSE 7.94e-9 END,
       CASE WHEN i % 10 = 0 THEN NULL ELSE 0.001 END,
       CASE WHEN i % 10 = 0 THEN NULL ELSE 'paper' END, 15.0, 25.0
FROM k;
UPDATE passages SET f1_hz = 5.70 + 0.01 * (vehicle_id % 3), f1_zeta = 0.03, f1_r2 = 0.95,
       f1_comp_hz = CASE WHEN vehicle_id > 20 THEN 5.72 + 0.002 * (vehicle_id % 2) END
WHERE status = 'ok';
INSERT INTO meta (key, value) VALUES ('natfreq.short', '3'), ('natfreq.noisy', '1');
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 1, NULL, 0.4 * gvw_kg FROM passages;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg)
SELECT id, 2, 4.5, 0.6 * gvw_kg FROM passages;
INSERT INTO truth (vehicle_id, utime, gvw_kg, n_axles, speed_true_mps)
SELECT vehicle_id, utime, coalesce(gvw_kg, 15000.0) / 1.02, 2, 25.0 FROM passages;
INSERT INTO truth_axles (truth_id, idx, load_kg, mean_force_N)
SELECT id, 1, 0.4 * gvw_kg, NULL FROM truth;
INSERT INTO truth_axles (truth_id, idx, load_kg, mean_force_N)
SELECT id, 2, 0.6 * gvw_kg, NULL FROM truth;
INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
VALUES (1763769600000000, 30, 17800, 1900, 'auto', '');
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 25)
INSERT INTO indicators (utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg,
                        std_ratio, p_value, state)
SELECT 1763769600000000 + i * 5400000000, 20, 17800 + i, 1900 + 20 * i, 17800, 1900,
       (1900 + 20 * i) / 1900.0, 0.5 / i, CASE WHEN i >= 22 THEN 'alert' ELSE 'normal' END
FROM k;
INSERT INTO alerts (utime, level, kind, message, indicator_id, raised) VALUES
  (1763769600000000 + 10 * 5400000000, 'info', 'mean_shift', 'mean GVW +6 % over the baseline', 10, 1),
  (1763769600000000 + 12 * 5400000000, 'info', 'mean_shift', 'mean GVW back within 3 %', 12, 0),
  (1763769600000000 + 22 * 5400000000, 'warning', 'std_increase', 'STD of GVW 1.23 x baseline (p = 0.023)', 22, 1);
EOF
} > "$tmp/fixture.sql"
# the schema version and migration rows as the store's migrations record them
if ! { sqlite3 "$db" < "$tmp/fixture.sql" && "$stamp" "$db"; } > "$tmp/fixture.log" 2>&1; then
    echo "report_cli.sh: building the fixture failed:" >&2
    cat "$tmp/fixture.log" >&2
    exit 1
fi
q() { sqlite3 "$1" "$2"; }
cp "$db" "$tmp/pristine.db" # the fixture before the baseline tests add rows

# ---- good runs ---------------------------------------------------------------

# ok NAME ARGS...: exit 0, nothing on stderr; output in $tmp/out
ok() {
    name=$1
    shift
    cases=$((cases + 1))
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    if [ "$rc" -ne 0 ]; then
        problem "status $rc, expected 0 ($(head -c 300 "$tmp/err"))"
        return 1
    fi
    [ -s "$tmp/err" ] && problem "wrote to stderr: $(head -c 300 "$tmp/err")"
    return 0
}
# has PATTERN: the output of the last run matches the grep -E pattern
has() { grep -Eq -- "$1" "$tmp/out" || problem "output lacks /$1/"; }
hasnt() { ! grep -Eq -- "$1" "$tmp/out" || problem "output has /$1/"; }

sum0=$(md5sum < "$db")

if ok default --db "$db"; then
    has '^== passages$'
    has '^== indicators \(last 20 of 25\)$'
    has '^== alerts \(last 3 of 3\)$'
    hasnt '^== errors'
    has '^Next, with sqlite3'
    has "^  sqlite3 -header -column $db \"SELECT \\* FROM daily_trend\"$"
fi

if ok summary --db "$db" --summary; then
    has '^passages +40$'
    has '^  ok +36 +90\.0 %$'
    has '^  gap +4 +10\.0 %$'
    has '^  late +0 '
    mean=$(q "$db" "SELECT printf('%.0f', avg(gvw_kg)) FROM passages WHERE status = 'ok'")
    std=$(q "$db" "SELECT printf('%.0f', sqrt(sum((gvw_kg - m) * (gvw_kg - m)) / (count(*) - 1)))
                   FROM passages, (SELECT avg(gvw_kg) AS m FROM passages WHERE status = 'ok')
                   WHERE status = 'ok'")
    has "^GVW, ok +n 36, mean $mean kg, STD $std kg, min 15000, median [0-9]+, max 21000 kg$"
    has '^time span +2025-11-22 01:00:00 \.\. 2025-11-23 16:00:00 UTC \(39\.0 h\)$'
    has '^baseline +mean 17800 kg, STD 1900 kg, n 30, auto, from 2025-11-22 00:00:00 UTC$'
    has '^temperature +deck -3\.2 \.\. 7\.8 °C, air -6\.0 \.\. -0\.5 °C, 12 readings, 2025-11-22 00:00:00 \.\. 2025-11-22 22:00:00 UTC$'
    f1=$(q "$db" "SELECT printf('%.4f', avg(f1_hz)) FROM passages")
    has "^natural f1 +n 36, raw mean $f1 Hz \\(SD 0\\.[0-9]{2} %\\), compensated n 18, mean 5\\.7211 Hz \\(SD 0\\.02 %\\); newest 36: raw $f1 Hz, compensated 5\\.7211 Hz \\(\\+0\\.00 %\\)$"
    has '^  not estimated \(amfid.s last run\): short 3, noisy 1$'
    hasnt '^== indicators'
fi

if ok trend --db "$db" --trend; then
    has '^time \(UTC\) +n +mean kg +STD kg +ratio +p +state$'
    rows=$(grep -Ec '^20[0-9]{2}-[0-9]{2}-[0-9]{2} ' "$tmp/out")
    [ "$rows" -eq 20 ] || problem "$rows indicator rows, expected 20"
    # oldest first: the 6th indicator (2025-11-22 09:00) to the 25th
    has '^2025-11-22 09:00:00 +20 +17806 +2020 +1\.063 +8\.33e-02 +normal$'
    last=$(grep -E '^20[0-9]{2}-' "$tmp/out" | tail -n 1)
    case $last in
    "2025-11-23 13:30:00"*alert) ;;
    *) problem "last trend row is '$last'" ;;
    esac
    has 'window_trend'
fi

if ok alerts --db "$db" --alerts; then
    has '^OPEN NOW +warning std_increase since 2025-11-23 09:00:00 UTC$'
    hasnt 'OPEN NOW +info mean_shift'
    has 'mean_shift +cleared +12 +mean GVW back within 3 %$'
    has '^2025-11-23 09:00:00 +warning +std_increase +raised +22 +STD of GVW 1\.23 x baseline \(p = 0\.023\)$'
fi

if ok errors --db "$db" --errors; then
    has '^== errors against the truth$'
    has '^truth rows +40; ok passages matched 36; other passages matched 4$'
    e=$(q "$db" "SELECT printf('%+.2f', avg(gvw_error_pct)) FROM passage_errors WHERE status = 'ok'" |
        sed 's/[+.]/\\&/g')
    has "^GVW error +mean $e %, STD 0\\.00 %\$"
    has '^\|GVW error\| +median 2\.00 %, 90 % 2\.00 %, 95 % 2\.00 %, 99 % 2\.00 %, max 2\.00 %$'
    has 'passage_errors ORDER BY abs\(gvw_error_pct\)'
fi

if ok check --db "$db" --check; then
    has '^integrity +ok$'
fi

sum1=$(md5sum < "$db")
name="read-only modes"
cases=$((cases + 1))
[ "$sum0" = "$sum1" ] || problem "the printing modes changed the file"

if ok baseline-last --db "$db" --set-baseline-last 10 --note "after the bearing repair" --force; then
    has '^baseline set: mean [0-9]+ kg, STD [0-9]+ kg, n 10, manual, from 2025-11-23 16:00:00 UTC$'
    got=$(q "$db" "SELECT n, source, note, utime_set FROM baseline ORDER BY id DESC LIMIT 1")
    [ "$got" = "10|manual|after the bearing repair|1763913600000000" ] || problem "newest baseline row '$got'"
    want=$(q "$db" "SELECT printf('%.6f', avg(gvw_kg)) FROM (SELECT gvw_kg FROM passages
                    WHERE status = 'ok' ORDER BY utime DESC LIMIT 10)")
    got=$(q "$db" "SELECT printf('%.6f', mean_kg) FROM baseline ORDER BY id DESC LIMIT 1")
    [ "$got" = "$want" ] || problem "baseline mean $got, expected $want"
    has 'SELECT \* FROM baseline'
fi

if ok baseline-explicit --db "$db" --set-baseline 18000,2000.5,500 --summary --force; then
    got=$(q "$db" "SELECT mean_kg, std_kg, n, source, note FROM baseline ORDER BY id DESC LIMIT 1")
    [ "$got" = "18000.0|2000.5|500|manual|" ] || problem "newest baseline row '$got'"
    has '^baseline +mean 18000 kg, STD 2000 kg, n 500, manual, from 2025-11-23 16:00:00 UTC$'
fi

if ok help --help; then
    has '^usage: amfi-report --db PATH'
fi

# ---- records and exports (issue 11) -------------------------------------------
# A copy of the fixture on two lanes (every third passage on lane 2), three
# passages made overloads (GVW 45 t; an axle of 12 t; both), and its site id.
ex=$tmp/exports.db
cp "$tmp/pristine.db" "$ex"
q "$ex" "UPDATE passages SET lane = 2 WHERE id % 3 = 0;
         UPDATE passages SET gvw_kg = 45000 WHERE id = 1;
         UPDATE axles SET load_kg = 27000 WHERE passage_id = 1 AND idx = 2;
         UPDATE axles SET load_kg = 14000 WHERE passage_id = 2 AND idx = 2;
         UPDATE passages SET gvw_kg = 50000 WHERE id = 4;
         UPDATE axles SET load_kg = 30000 WHERE passage_id = 4 AND idx = 2;
         INSERT INTO meta (key, value) VALUES ('site.id', 'fixture-1'), ('site.name', 'Fixture bridge');"
exsum0=$(md5sum < "$ex")

if ok passages-all --db "$ex" --passages; then
    has '^== passages$'
    has '^\(40 passages\)$'
    has '^2025-11-22T10:00:00Z +10 +10 +1 +25\.00 +2 +- +-/- +gap +12 samples missing in the window$'
    has '^2025-11-22T03:00:00Z +3 +3 +2 +25\.00 +2 +18000 +7200/10800 +ok'
fi
if ok passages-filtered --db "$ex" --passages --from 2025-11-22T05:00 --to 2025-11-22 --status ok --lane 2; then
    want=$(q "$ex" "SELECT count(*) FROM passages WHERE utime BETWEEN 1763787600000000 AND 1763855999999999 AND status = 'ok' AND lane = 2")
    has "^\\($want passages\\)\$"
    hasnt ' gap '
fi
if ok passages-csv --db "$ex" --passages --format csv --status gap; then
    n=$(($(wc -l < "$tmp/out") - 1))
    [ "$n" -eq 4 ] || problem "$n CSV rows of gap passages, expected 4"
    hdr=$(head -1 "$tmp/out")
    [ "$(echo "$hdr" | awk -F, '{print NF}')" -eq 38 ] || problem "CSV header has $(echo "$hdr" | awk -F, '{print NF}') columns"
    echo "$hdr" | grep -q ',status,reason,speed_given_mps,speed_estimated,n_vehicles,quality,class$' || problem "CSV header: $hdr"
    bad_rows=$(awk -F, 'NR > 1 && NF != 38' "$tmp/out" | wc -l)
    [ "$bad_rows" -eq 0 ] || problem "$bad_rows CSV rows without 38 columns"
    has '^2025-11-22T10:00:00Z,1763805600000000,10,10,1,25\.000,2,,,,'
    has ',gap,12 samples missing in the window,25\.000,0,1,,$'
fi
if ok passages-csv-values --db "$ex" --passages --format csv --from 2025-11-22T03:00:00Z --to 2025-11-22T03:00:00Z; then
    row=$(sed -n 2p "$tmp/out")
    [ "$(echo "$row" | cut -d, -f8,9,10)" = "18000.0,7200.0,10800.0" ] || problem "passage 3: '$row'"
    [ "$(echo "$row" | cut -d, -f21)" = "4.500" ] || problem "passage 3 spacing: '$row'"
fi
# a vehicle weighed in an event of two (issue 13): n_vehicles and quality
# exported; its class (store version 10) as stored
cp "$ex" "$tmp/event.db"
sqlite3 "$tmp/event.db" "UPDATE passages SET n_vehicles = 2, quality = 1.25, class = 'A23' WHERE utime = 1763780400000000"
if ok passages-event-csv --db "$tmp/event.db" --passages --format csv --from 2025-11-22T03:00:00Z --to 2025-11-22T03:00:00Z; then
    row=$(sed -n 2p "$tmp/out")
    [ "$(echo "$row" | cut -d, -f36,37,38)" = "2,1.25,A23" ] || problem "event passage: '$row'"
fi
if ok passages-event-json --db "$tmp/event.db" --passages --format json --from 2025-11-22T03:00:00Z --to 2025-11-22T03:00:00Z; then
    has '"n_vehicles":2,"quality":1\.25,"class":"A23"\}'
fi
if ok passages-json --db "$ex" --passages --format json --lane 1; then
    n=$(grep -o '"passage_id":' "$tmp/out" | wc -l)
    want=$(q "$ex" "SELECT count(*) FROM passages WHERE lane = 1")
    [ "$n" -eq "$want" ] || problem "$n JSON passages on lane 1, expected $want"
    [ -z "$jcheck" ] || "$jcheck" site_id=fixture-1 < "$tmp/out" || problem "JSON does not parse, or site_id"
fi
if ok histogram --db "$ex" --histogram --bin-kg 5000; then
    has '^== GVW histogram of ok passages, 5000 kg bins$'
    has '^GVW kg +lane 1 +lane 2 +all$'
    for lane in 1 2; do
        for lo in 15000 20000 45000; do
            want=$(q "$ex" "SELECT count(*) FROM passages WHERE status = 'ok' AND lane = $lane AND gvw_kg >= $lo AND gvw_kg < $lo + 5000")
            col=$((lane + 3))
            got=$(awk -v lo="$lo" '$1 == lo && $2 == ".." {print $'$col'}' "$tmp/out")
            [ "${got:-0}" -eq "$want" ] || problem "lane $lane, bin $lo: $got, expected $want"
        done
    done
    all=$(q "$ex" "SELECT count(*) FROM passages WHERE status = 'ok'")
    has "^total +[0-9]+ +[0-9]+ +$all\$"
fi
if ok histogram-csv --db "$ex" --histogram --format csv --lane 2; then
    has '^gvw_from_kg,gvw_to_kg,lane_2,all$'
    sum=$(awk -F, 'NR > 1 {s += $3} END {print s}' "$tmp/out")
    want=$(q "$ex" "SELECT count(*) FROM passages WHERE status = 'ok' AND lane = 2")
    [ "$sum" -eq "$want" ] || problem "lane 2 histogram sums to $sum, expected $want"
fi
# overloads by class and axle group: every passage here has two axles and
# more than 3.5 t, class R2 of the European scheme (96/53/EC: GVW 18 t, the
# steer axle a single axle of 10 t, the rear a driving axle of 11.5 t);
# report.limits apply only where no class limit does (not here)
printf 'report:\n  limits:\n    gvw_kg: 40000\n    axle_kg: 13000\n' > "$tmp/limits.yaml"
r2_over() { # the SQL of "passage p is over": $1 gvw, $2 steer, $3 driving
    echo "(gvw_kg > $1 OR EXISTS (SELECT 1 FROM axles a WHERE a.passage_id = p.id AND
          ((a.idx = 1 AND a.load_kg > $2) OR (a.idx = 2 AND a.load_kg > $3))))"
}
if ok overloads --db "$ex" --overloads --config "$tmp/limits.yaml"; then
    og=$(q "$ex" "SELECT count(*) FROM passages p WHERE status = 'ok' AND gvw_kg > 18000")
    ogr=$(q "$ex" "SELECT count(*) FROM passages p WHERE status = 'ok' AND $(r2_over 1e9 10000 11500)")
    oa=$(q "$ex" "SELECT count(*) FROM passages p WHERE status = 'ok' AND $(r2_over 18000 10000 11500)")
    [ "$oa" -gt 3 ] || problem "fixture: $oa overloads in sqlite3, expected more than 3"
    has "^checked 36 ok passages: $og over their class's GVW limit, $ogr with an axle group over its limit, $oa overloaded in all"
    has '^2025-11-22T01:00:00Z +1 +1 +1 +R2 +45000 +18000 +GVW \+150\.0 %; axle 2 driving 27000 > 11500 kg \(\+134\.8 %\)$'
    has '^2025-11-22T02:00:00Z +2 +2 +1 +R2 +17000 +18000 +axle 2 driving 14000 > 11500 kg \(\+21\.7 %\)$'
    has "^R2 +36 +$og +$ogr +$oa "
fi
# the limits of --config's classes: section
printf 'classes:\n  gvw_limit_kg:\n    R2: 48000\n  single_axle_kg: 30000\n  driving_axle_kg: 30000\n' > "$tmp/limits2.yaml"
if ok overloads-json --db "$ex" --overloads --format json --config "$tmp/limits2.yaml"; then
    has '"over_gvw":1,'
    has '"over_group":0,'
    has '"overloaded":1,'
    has '"passage_id":4,'
    has '"exceeded":\[\{"limit":"gvw","axles":null,"kind":"gross","load_kg":50000\.0,"limit_kg":48000\.0,'
    [ -z "$jcheck" ] || "$jcheck" < "$tmp/out" || problem "JSON does not parse"
fi
for sec in summary trend alerts errors; do
    if ok "$sec-csv" --db "$ex" --$sec --format csv; then
        bad_rows=$(awk -F, -v h="$(head -1 "$tmp/out" | awk -F, '{print NF}')" 'NR > 1 && NF < h' "$tmp/out" | wc -l)
        [ "$bad_rows" -eq 0 ] || problem "$bad_rows CSV rows with fewer columns than the header"
        [ "$(wc -l < "$tmp/out")" -ge 2 ] || problem "no CSV rows"
    fi
done
if ok trend-csv-rows --db "$ex" --trend --format csv; then
    [ "$(($(wc -l < "$tmp/out") - 1))" -eq 25 ] || problem "$(($(wc -l < "$tmp/out") - 1)) indicator rows, expected all 25"
fi
if ok alerts-csv-quoted --db "$ex" --alerts --format csv; then
    has '^3,2025-11-23T09:00:00Z,[0-9]+,warning,std_increase,raised,22,STD of GVW 1\.23 x baseline \(p = 0\.023\)$'
fi
if ok summary-csv-values --db "$ex" --summary --format csv; then
    has '^passages,40$'
    has '^passages_gap,4$'
    has '^baseline_n,30$'
    has '^f1_n,36$'
    has '^f1_comp_n,18$'
    has '^f1_comp_mean_hz,5\.721111$'
fi
if ok all-json --db "$ex" --summary --trend --alerts --errors --histogram --format json; then
    [ -z "$jcheck" ] || "$jcheck" site_id=fixture-1 < "$tmp/out" || problem "JSON does not parse"
    for k in summary trend alerts errors histogram; do has "\"$k\":"; done
    has '"by_status":\{"ok":36,"gap":4,'
    has '"natural_frequency":\{"n":36,"mean_hz":5\.7[0-9]*,"sd_hz":0\.0[0-9]*,"compensated_n":18,"compensated_mean_hz":5\.72111'
    has '"ok_matched":36,'
fi
# --passages in JSON is streamed as the document's last key, after the others
if ok passages-json-mixed --db "$ex" --summary --overloads --passages --format json --status gap; then
    [ -z "$jcheck" ] || "$jcheck" site_id=fixture-1 < "$tmp/out" || problem "JSON does not parse"
    want=$(q "$ex" "SELECT (SELECT count(*) FROM passages WHERE status = 'gap') + (SELECT count(*)
                    FROM passages p WHERE status = 'ok' AND $(r2_over 18000 10000 11500))")
    n=$(grep -o '"passage_id":' "$tmp/out" | wc -l)
    [ "$n" -eq "$want" ] || problem "$n passage objects, expected $want (gap passages + overloads at the 96/53/EC defaults)"
    has '"by_status":\{"ok":36,"gap":4,'
    has '"natural_frequency":\{"n":36,"mean_hz":5\.7[0-9]*,"sd_hz":0\.0[0-9]*,"compensated_n":18,"compensated_mean_hz":5\.72111'
    has ',"passages":\[\{"time_utc":"2025-11-22T10:00:00Z",.*"reason":"12 samples missing in the window","speed_given_mps":25\.0,"speed_estimated":false,"n_vehicles":1,"quality":null,"class":null\}.*\]\}$'
fi
if ok passages-json-none --db "$ex" --passages --format json --lane 7; then
    [ -z "$jcheck" ] || "$jcheck" site_id=fixture-1 < "$tmp/out" || problem "JSON does not parse"
    has '^\{"site_id":"fixture-1","passages":\[\]\}$'
fi
if ok passages-lane-sql --db "$ex" --passages --format csv --lane 2 --from 2025-11-22T01:00 --to 2025-11-22T20:00; then
    want=$(q "$ex" "SELECT count(*) FROM passages WHERE lane = 2 AND utime BETWEEN 1763773200000000 AND 1763841659999999")
    [ "$(($(wc -l < "$tmp/out") - 1))" -eq "$want" ] || problem "$(($(wc -l < "$tmp/out") - 1)) lane-2 rows, expected $want"
    bad_lane=$(awk -F, 'NR > 1 && $5 != 2' "$tmp/out" | wc -l)
    [ "$bad_lane" -eq 0 ] || problem "$bad_lane rows not on lane 2"
fi
# ISO 8601 forms: fractions of a second, a zero offset; --to a minute is its last µs
if ok time-forms --db "$ex" --passages --format csv --from 2025-11-22T03:00:00.000000Z --to 2025-11-22T03:00:00+00:00; then
    [ "$(($(wc -l < "$tmp/out") - 1))" -eq 1 ] || problem "not exactly passage 3"
    has '^2025-11-22T03:00:00Z,1763780400000000,3,'
fi
if ok time-to-minute --db "$ex" --passages --format csv --from '2025-11-22 02:59:59.999999' --to 2025-11-22T03:00; then
    [ "$(($(wc -l < "$tmp/out") - 1))" -eq 1 ] || problem "--to HH:MM is not the whole minute"
fi
if ok time-after --db "$ex" --passages --format csv --from 2025-11-22T03:00:00.000001; then
    hasnt ',1763780400000000,3,'
fi
name="exports are read-only"
cases=$((cases + 1))
[ "$exsum0" = "$(md5sum < "$ex")" ] || problem "the export modes changed the file"

# ---- failures -------------------------------------------------------------

# bad NAME WANT_STATUS PATTERN ARGS...: one stderr line matching PATTERN
bad() {
    name=$1 want=$2 pattern=$3
    shift 3
    cases=$((cases + 1))
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    lines=$(wc -l < "$tmp/err")
    if [ "$rc" -ge 128 ]; then
        problem "crashed (status $rc)"
    elif [ "$rc" -ne "$want" ]; then
        problem "status $rc, expected $want"
    elif [ "$lines" -ne 1 ]; then
        problem "stderr has $lines lines, expected 1: $(head -c 300 "$tmp/err")"
    elif ! grep -Eq -- "$pattern" "$tmp/err"; then
        problem "stderr '$(cat "$tmp/err")' does not match /$pattern/"
    elif [ -s "$tmp/out" ]; then
        problem "wrote to stdout: $(head -c 200 "$tmp/out")"
    fi
}

bad no-db 2 '^amfi-report: --db: missing' --summary
bad from-bad 2 "^amfi-report: --from: '2025-13-01' is not a UTC time" --db "$db" --passages --from 2025-13-01
bad to-bad 2 "^amfi-report: --to: 'yesterday' is not a UTC time" --db "$db" --passages --to yesterday
bad from-month 2 "^amfi-report: --from: '2025-13-01' is not a UTC time \\(month 13 is not in 1 \\.\\. 12\\)" --db "$db" --passages --from 2025-13-01
bad from-hour 2 "^amfi-report: --from: '2025-11-22T25:00' is not a UTC time \\(hour 25 " --db "$db" --passages --from 2025-11-22T25:00
bad from-offset 2 "^amfi-report: --from: '2025-11-22T10:00\\+02:00' is not a UTC time \\(offset \\+02:00: only UTC" --db "$db" --passages --from 2025-11-22T10:00+02:00
bad to-trailing 2 "^amfi-report: --to: '2025-11-22x' is not a UTC time \\(unexpected 'x'\\)" --db "$db" --passages --to 2025-11-22x
bad to-no-minutes 2 "^amfi-report: --to: '2025-11-22T10' is not a UTC time \\(no time HH:MM" --db "$db" --passages --to 2025-11-22T10
bad feb30 2 "^amfi-report: --from: '2025-02-30' is not a UTC time" --db "$db" --passages --from 2025-02-30
bad from-after-to 2 '^amfi-report: --from: after --to' --db "$db" --passages --from 2025-11-23 --to 2025-11-22
bad status-bad 2 "^amfi-report: --status: 'fine' is not a status" --db "$db" --passages --status fine
bad status-alone 2 '^amfi-report: --status: only with --passages' --db "$db" --histogram --status ok
bad lane-bad 2 "^amfi-report: --lane: 'x' is not a lane number" --db "$db" --passages --lane x
bad bin-bad 2 "^amfi-report: --bin-kg: '10' is not a bin width" --db "$db" --histogram --bin-kg 10
bad format-bad 2 "^amfi-report: --format: 'xml' is not table, csv or json" --db "$db" --summary --format xml
bad csv-two 2 '^amfi-report: --format: csv takes one section at a time \(2 given\)' --db "$db" --summary --trend --format csv
bad csv-check 2 '^amfi-report: --format: csv and json are for the report sections' --db "$db" --check --format json
bad empty-db 2 '^amfi-report: --db: empty value' --db ''
bad unknown 2 '^amfi-report: --bogus: unknown option' --db "$db" --bogus
bad stray 2 '^amfi-report: stray: unexpected argument' --db "$db" stray
bad last-1 2 '^amfi-report: --set-baseline-last: .1. is not an integer in \[2,' --db "$db" --set-baseline-last 1
bad both 2 'not both' --db "$db" --set-baseline-last 5 --set-baseline 1,2,3
bad two-fields 2 '^amfi-report: --set-baseline: .18000,2000.: expected MEAN_KG,STD_KG,N' --db "$db" --set-baseline 18000,2000
bad neg-std 2 '^amfi-report: --set-baseline: STD .-1. is not in' --db "$db" --set-baseline 18000,-1,10
bad note-alone 2 '^amfi-report: --note: only with' --db "$db" --note hello

bad missing 1 "^amfi-report: $tmp/missing\\.db: No such file or directory\$" --db "$tmp/missing.db"
name=missing-not-created
cases=$((cases + 1))
[ ! -e "$tmp/missing.db" ] || problem "amfi-report created $tmp/missing.db"
bad missing-set 1 'No such file or directory$' --db "$tmp/missing.db" --set-baseline 1,2,3
[ ! -e "$tmp/missing.db" ] || problem "--set-baseline created $tmp/missing.db"

i=0
while [ $i -lt 100 ]; do echo "t,accel"; i=$((i + 1)); done > "$tmp/text.db"
bad not-sqlite 1 "^amfi-report: $tmp/text\\.db: not an SQLite database" --db "$tmp/text.db"
bad not-sqlite-check 1 'not an SQLite database' --db "$tmp/text.db" --check
: > "$tmp/empty.db"
bad empty-file 1 'empty database, not an amfi store' --db "$tmp/empty.db"
bad directory 1 'not a regular file' --db "$tmp"

sqlite3 "$tmp/recipes.db" "CREATE TABLE recipes (name TEXT)"
bad foreign 1 'not an amfi store' --db "$tmp/recipes.db"

cp "$tmp/pristine.db" "$tmp/newer.db"
sqlite3 "$tmp/newer.db" "PRAGMA user_version = 99"
bad newer 1 'schema version 99 is newer than this program.s [0-9]' --db "$tmp/newer.db"

# the fixture's std_increase alert is open: refused without --force, and
# the store unchanged
n0=$(q "$db" "SELECT count(*) FROM baseline")
bad baseline-open-alert 1 "^amfi-report: $tmp/fixture\\.db: 1 alert is open: warning std_increase \\(since 2025-11-23 09:00:00 UTC\\); .* give --force\$" \
    --db "$db" --set-baseline-last 10
[ "$(q "$db" "SELECT count(*) FROM baseline")" = "$n0" ] || problem "a refused baseline was stored"
cp "$tmp/pristine.db" "$tmp/damaged.db"
sqlite3 "$tmp/damaged.db" "PRAGMA ignore_check_constraints = ON; UPDATE passages SET gvw_kg = -1 WHERE id = 3"
bad damaged-row 1 "^amfi-report: $tmp/damaged\\.db: passages row 3: gvw_kg is out of range" --db "$tmp/damaged.db" --summary
cp "$tmp/pristine.db" "$tmp/damaged2.db"
sqlite3 "$tmp/damaged2.db" "PRAGMA ignore_check_constraints = ON; UPDATE baseline SET std_kg = -5 WHERE id = 1"
bad damaged-baseline 1 'baseline row 1: std_kg: -5 kg is out of range \(0, 1e\+06\] kg$' --db "$tmp/damaged2.db" --summary
# the damaged row is not read to set a new baseline, which then is in force
ok baseline-over-damaged --db "$tmp/damaged2.db" --set-baseline 18000,2000,100 --summary --force
cp "$tmp/pristine.db" "$tmp/damaged3.db"
sqlite3 "$tmp/damaged3.db" "PRAGMA ignore_check_constraints = ON; UPDATE indicators SET state = 'panic' WHERE id = 24"
bad damaged-indicator 1 'indicators row 24: state is not a known state' --db "$tmp/damaged3.db" --trend

cp "$tmp/pristine.db" "$tmp/orphan.db"
sqlite3 "$tmp/orphan.db" "INSERT INTO axles (passage_id, idx, spacing_m, load_kg) VALUES (999, 1, NULL, 1)"
name=orphan
cases=$((cases + 1))
"$bin" --db "$tmp/orphan.db" --check > "$tmp/out" 2> "$tmp/err"
rc=$?
[ "$rc" -eq 1 ] || problem "status $rc, expected 1"
grep -q 'foreign key: a axles row refers to a missing passages row' "$tmp/out" || problem "stdout: $(cat "$tmp/out")"
[ "$(wc -l < "$tmp/err")" -eq 1 ] || problem "stderr: $(cat "$tmp/err")"

# ---- --plot DIR: five valid PNGs, one alert marker per alerts row -----------
# png_ok FILE: PNG magic, IHDR width/height in [200, 4000], size in
# [5 kB, 2 MB] (a blank or failed render is smaller, a runaway larger).
png_ok() {
    [ -f "$1" ] || { problem "$1: missing"; return; }
    magic=$(od -An -tx1 -N8 "$1" | tr -d ' \n')
    [ "$magic" = 89504e470d0a1a0a ] || problem "$1: not a PNG (magic $magic)"
    ihdr=$(od -An -c -j12 -N4 "$1" | tr -d ' \n')
    [ "$ihdr" = IHDR ] || problem "$1: no IHDR chunk first ($ihdr)"
    w=$(od -An -tu1 -j16 -N4 "$1" | awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4 }')
    h=$(od -An -tu1 -j20 -N4 "$1" | awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4 }')
    { [ "$w" -ge 200 ] && [ "$w" -le 4000 ] && [ "$h" -ge 200 ] && [ "$h" -le 4000 ]; } ||
        problem "$1: IHDR size ${w}x$h"
    sz=$(wc -c < "$1")
    { [ "$sz" -ge 5000 ] && [ "$sz" -le 2000000 ]; } || problem "$1: $sz bytes"
}
if command -v gnuplot > /dev/null; then
    cp "$tmp/pristine.db" "$tmp/plot.db"
    if ok plot --db "$tmp/plot.db" --plot "$tmp/plots"; then
        for p in gvw trend gvw_histogram passages_per_hour speed natfreq; do
            png_ok "$tmp/plots/$p.png"
            has "^plot  $tmp/plots/$p\\.png  "
        done
        # the markers drawn on trend.png are the rows of alerts.dat, which
        # must be the alerts table: id, time, raised, level, kind, in order
        sqlite3 -separator ' ' "$tmp/plot.db" \
            "SELECT id, printf('%.3f', utime / 1e6), raised, level, kind FROM alerts ORDER BY id" > "$tmp/alerts.want"
        grep -v '^#' "$tmp/plots/data/alerts.dat" > "$tmp/alerts.got"
        cmp -s "$tmp/alerts.want" "$tmp/alerts.got" ||
            problem "alerts.dat differs from the alerts table: $(diff "$tmp/alerts.want" "$tmp/alerts.got" | head -5)"
        [ "$(wc -l < "$tmp/alerts.got")" -eq 3 ] || problem "alerts.dat: $(wc -l < "$tmp/alerts.got") markers, expected 3"
        grep -c 'set arrow from' "$tmp/plots/data/plots.gp" | grep -qx 3 ||
            problem "plots.gp: not one arrow per alert"
        [ -s "$tmp/plots/data/gnuplot.log" ] && problem "gnuplot said: $(head -c 300 "$tmp/plots/data/gnuplot.log")"
        cmp -s "$tmp/pristine.db" "$tmp/plot.db" || problem "--plot changed the store"
    fi
    # an empty store still draws (empty plots saying so), a missing dir parent fails
    sqlite3 "$tmp/empty.db" < "$tmp/ddl.sql"
    "$stamp" "$tmp/empty.db"
    if ok plot-empty --db "$tmp/empty.db" --plot "$tmp/plots-empty"; then
        for p in gvw trend gvw_histogram passages_per_hour speed; do png_ok "$tmp/plots-empty/$p.png"; done
    fi
    bad plot-nodir 1 '^amfi-report: .*/no/such/dir' --db "$db" --plot "$tmp/no/such/dir"
else
    echo "report_cli.sh: no gnuplot: --plot cases skipped"
fi

echo "report_cli.sh: $cases cases, $failures failed"
[ "$failures" -eq 0 ]
