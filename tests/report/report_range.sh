#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_range.sh: amfi-report's --from/--to in every section (honoured, or
# refused with a message naming the section), --help saying which honour
# it, and --plot's gnuplot script (the threshold lines inside each panel's
# y range, hourly buckets on the per-hour plot, no legend entry for a
# series without a point, the range honoured by the data files). The
# fixture is report_golden's (docs/schema.md's DDL and report_golden.sql).
#
# usage: report_range.sh AMFI_REPORT SCHEMA_MD DIR_OF_report_golden.sql
# Exit 77 (skipped) without the sqlite3 program or gnuplot.
set -u
bin=${1:?usage: report_range.sh AMFI_REPORT SCHEMA_MD DIR}
doc=${2:?usage: report_range.sh AMFI_REPORT SCHEMA_MD DIR}
dir=${3:?usage: report_range.sh AMFI_REPORT SCHEMA_MD DIR}
command -v sqlite3 > /dev/null || { echo "report_range.sh: no sqlite3 program: skipped"; exit 77; }
command -v gnuplot > /dev/null || { echo "report_range.sh: no gnuplot: skipped"; exit 77; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_range.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
v=$(sed -n 's/.*PRAGMA user_version` (this document: version \([0-9]*\)).*/\1/p' "$doc")
[ -n "$v" ] || { echo "report_range.sh: no schema version in $doc" >&2; exit 1; }
db=$tmp/golden.db
{
    cat "$tmp/ddl.sql"
    echo "PRAGMA user_version = $v;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $v)
INSERT INTO schema_migrations (version, description) SELECT i, 'golden' FROM k;"
    cat "$dir/report_golden.sql"
} > "$tmp/fixture.sql"
sqlite3 "$db" < "$tmp/fixture.sql" > "$tmp/fixture.log" 2>&1 ||
    { echo "report_range.sh: building the fixture failed:" >&2; cat "$tmp/fixture.log" >&2; exit 1; }

fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
# run ARGS...: stdout in $tmp/out, stderr in $tmp/err, status in $rc
run() { "$bin" "$@" > "$tmp/out" 2> "$tmp/err"; rc=$?; }

# ---- sections that report the whole store refuse the range ------------------
for s in summary errors; do
    for opt in "--from 2025-11-22" "--to 2025-11-22T12:00"; do
        # shellcheck disable=SC2086
        run --db "$db" --$s $opt
        [ "$rc" = 2 ] || fail "--$s $opt: status $rc, want 2 (refused)"
        grep -q -- "--$s reports the whole store and does not honour --from/--to" "$tmp/err" ||
            fail "--$s $opt: no message naming --$s: $(cat "$tmp/err")"
    done
done
run --db "$db" --from 2025-11-22
[ "$rc" = 2 ] || fail "no section, --from: status $rc, want 2"
grep -q -- "--from: --summary (shown with no section asked for) reports the whole store" "$tmp/err" ||
    fail "no section, --from: $(cat "$tmp/err")"
run --db "$db" --set-baseline-last 3 --to 2025-11-22
[ "$rc" = 2 ] && grep -q -- "--set-baseline-last works on the whole store" "$tmp/err" ||
    fail "--set-baseline-last --to: status $rc: $(cat "$tmp/err")"

# --lane likewise: the sections that cover every lane refuse it
for s in summary trend alerts errors; do
    run --db "$db" --$s --lane 2
    [ "$rc" = 2 ] && grep -q -- "--lane: --$s covers every lane and does not honour --lane" "$tmp/err" ||
        fail "--$s --lane 2: status $rc: $(cat "$tmp/err")"
done
run --db "$db" --passages --lane 2 --plot "$tmp/pl"
[ "$rc" = 2 ] && grep -q -- "--lane: --check, --set-baseline\* and --plot cover every lane" "$tmp/err" ||
    fail "--plot --lane 2: status $rc: $(cat "$tmp/err")"
run --db "$db" --classes --lane 2
[ "$rc" = 0 ] || fail "--classes --lane 2: status $rc"

# ---- --trend and --alerts honour it ------------------------------------------
# indicators hourly from 01:00 to 24:00; alerts at 10:00, 12:00, 20:00, 21:00
for f in csv json table; do
    run --db "$db" --trend --from 2025-11-22T20:00 --to 2025-11-22T22:00 --format $f
    [ "$rc" = 0 ] || fail "--trend range $f: status $rc: $(cat "$tmp/err")"
    case $f in
    csv) n=$(($(wc -l < "$tmp/out") - 1)) ;;
    json) n=$(grep -o '"indicator_id"' "$tmp/out" | wc -l) ;;
    table) n=$(grep -c '^2025-11-2' "$tmp/out") ;;
    esac
    [ "$n" = 3 ] || fail "--trend 20:00 .. 22:00 --format $f: $n rows, want 3"
    run --db "$db" --alerts --from 2025-11-22T11:00 --to 2025-11-22T20:30 --format $f
    [ "$rc" = 0 ] || fail "--alerts range $f: status $rc: $(cat "$tmp/err")"
    case $f in
    csv) n=$(grep -c '^[0-9]' "$tmp/out") ;;
    json) n=$(grep -o '"alert_id"' "$tmp/out" | wc -l) ;;
    table) n=$(grep -c '^2025-11-2' "$tmp/out") ;;
    esac
    [ "$n" = 2 ] || fail "--alerts 11:00 .. 20:30 --format $f: $n rows, want 2"
done
run --db "$db" --trend --format csv
[ "$(($(wc -l < "$tmp/out") - 1))" = 24 ] || fail "--trend without a range: not every row"
run --db "$db" --trend --from 2025-11-22T20:00 --to 2025-11-22T22:00
grep -q '^== indicators (last 3 of 3 from 2025-11-22 20:00:00 to 2025-11-22 22:00:59 UTC)' "$tmp/out" ||
    fail "--trend range: header: $(head -1 "$tmp/out")"

# ---- --help says, per section, whether it honours the range --------------------
run --help
awk '/^  -[a-zA-Z], --[a-z]/ { sec = $2 } /honours --from --to/ { print sec, "honours" }
     /refuses --from and --to/ { print sec, "refuses" }' "$tmp/out" > "$tmp/help"
for s in summary:refuses errors:refuses trend:honours alerts:honours passages:honours \
         histogram:honours overloads:honours speed:honours plot:honours; do
    grep -q "^--${s%%:*} ${s#*:}\$" "$tmp/help" || fail "--help: --${s%%:*} does not say it ${s#*:} --from/--to"
done

# ---- --plot honours the range ------------------------------------------------
run --db "$db" --plot "$tmp/p1" --from 2025-11-22T06:00 --to 2025-11-22T11:59
[ "$rc" = 0 ] || fail "--plot range: status $rc: $(cat "$tmp/err")"
# passages every 30 min from 00:30: 06:00 .. 11:30 is 12 of them
n=$(grep -vc '^#' "$tmp/p1/data/passages.dat")
[ "$n" = 12 ] || fail "--plot 06:00 .. 11:59: passages.dat has $n rows, want 12"
n=$(grep -vc '^#' "$tmp/p1/data/indicators.dat")
[ "$n" = 6 ] || fail "--plot 06:00 .. 11:59: indicators.dat has $n rows, want 6"
n=$(grep -vc '^#' "$tmp/p1/data/alerts.dat")
[ "$n" = 1 ] || fail "--plot 06:00 .. 11:59: alerts.dat has $n rows, want 1"
awk 'NR > 1 && ($1 < 1763791200 || $1 > 1763812799) { bad = 1 } END { exit bad }' \
    "$tmp/p1/data/temperature.dat" || fail "--plot range: temperature.dat outside the range"

# ---- the gnuplot script --------------------------------------------------------
run --db "$db" --plot "$tmp/p2"
[ "$rc" = 0 ] || fail "--plot: status $rc: $(cat "$tmp/err")"
gp=$tmp/p2/data/plots.gp
# the y range set for the panel of each ylabel: "LO HI"
yr() { awk -v l="$1" 'index($0, "set ylabel '\''" l) == 1 { on = 1; next }
       on && /^set yrange \[/ { s = $3; gsub(/[][]/, "", s); split(s, a, ":"); print a[1], a[2]; exit }
       on && /^plot/ { exit }' "$gp"; }
# the thresholds, read from the legend titles
read -r raise clear <<EOT
$(sed -n "s/.*title 'raise at >= \([0-9.e+-]*\)'.*title 'clear below \([0-9.e+-]*\)'.*/\1 \2/p" "$gp")
EOT
read -r mean_r <<EOT
$(sed -n "s/.*title 'mean alert \([0-9.e+-]*\) and 1\/.*/\1/p" "$gp")
EOT
[ -n "$raise" ] && [ -n "$clear" ] && [ -n "$mean_r" ] || fail "plots.gp: no threshold titles"
read -r lo hi <<EOT
$(yr 'STD ratio')
EOT
[ -n "$lo" ] || fail "plots.gp: no y range on the STD ratio panel"
awk -v lo="${lo:-0}" -v hi="${hi:-0}" -v a="$raise" -v c="$clear" \
    'BEGIN { m = 0.02 * (a - c); exit !(lo < c - m && lo < a - m && hi > a + m && hi > c + m) }' ||
    fail "STD ratio panel: y range [$lo:$hi] does not hold $clear and $raise inside the frame"
read -r lo hi <<EOT
$(yr 'mean ratio')
EOT
[ -n "$lo" ] || fail "plots.gp: no y range on the mean ratio panel"
awk -v lo="${lo:-0}" -v hi="${hi:-0}" -v r="$mean_r" \
    'BEGIN { m = 0.02 * (r - 1 / r); exit !(lo < 1 / r - m && hi > r + m) }' ||
    fail "mean ratio panel: y range [$lo:$hi] does not hold 1/$mean_r and $mean_r inside the frame"
# passages per hour: one-hour buckets
grep -q '(bucket 3600 s)' "$tmp/p2/data/hourly.dat" || fail "hourly.dat: $(head -1 "$tmp/p2/data/hourly.dat")"
grep -A8 "passages_per_hour.png" "$gp" | grep -q 'set boxwidth 3240$' ||
    fail "passages_per_hour.png: boxes not one hour wide"
# the thresholds amfid ran with (meta daemon.indicators), not the defaults
# nor --config's
cp "$db" "$tmp/rec.db"
sqlite3 "$tmp/rec.db" "INSERT INTO meta (key, value) VALUES ('daemon.indicators',
  'window=500 every=100 baseline_n=10000 std_alert_ratio=1.5 std_alert_p=0.05 std_clear_ratio=1.25 raise_after=6 clear_after=6 mean_shift=1 mean_alert_ratio=1.125 mean_alert_p=0.01 mean_clear_ratio=1.0625')" || exit 1
printf 'daemon:\n  indicators:\n    std_alert_ratio: 1.75\n    std_clear_ratio: 1.5\n' > "$tmp/other.yaml"
run --db "$tmp/rec.db" --plot "$tmp/p4" --config "$tmp/other.yaml"
[ "$rc" = 0 ] || fail "--plot (recorded thresholds): status $rc: $(cat "$tmp/err")"
gp4=$tmp/p4/data/plots.gp
grep -q "title 'raise at >= 1.5', .* title 'clear below 1.25'" "$gp4" ||
    fail "trend.png: not the recorded STD thresholds 1.5 / 1.25: $(grep -o "title 'raise at[^,]*" "$gp4")"
grep -q "title 'mean alert 1.125 and 1/1.125'" "$gp4" || fail "trend.png: not the recorded mean threshold 1.125"
grep -q "thresholds: amfid's, from the store" "$gp4" || fail "trend.png: the title does not say where the thresholds come from"
read -r lo hi <<EOT
$(gp=$gp4; yr 'STD ratio')
EOT
awk -v lo="${lo:-0}" -v hi="${hi:-0}" 'BEGIN { exit !(lo < 1.24 && hi > 1.51) }' ||
    fail "STD ratio panel: y range [$lo:$hi] does not hold the recorded 1.25 and 1.5"
sqlite3 "$tmp/rec.db" "UPDATE meta SET value = 'window=500 std_alert_ratio=x' WHERE key = 'daemon.indicators'" || exit 1
run --db "$tmp/rec.db" --plot "$tmp/p5"
[ "$rc" = 1 ] && grep -q "rec.db: meta daemon.indicators: std_alert_ratio: not a number" "$tmp/err" ||
    fail "a damaged daemon.indicators: status $rc: $(cat "$tmp/err")"

# natural frequency without a compensated value: no 'compensated' legend entry
sqlite3 "$db" "UPDATE passages SET f1_comp_hz = NULL" || exit 1
run --db "$db" --plot "$tmp/p3"
[ "$rc" = 0 ] || fail "--plot (no compensated f1): status $rc: $(cat "$tmp/err")"
awk '/natfreq.png/ { on = 1 } on && /^plot/ { p = 1 } p && /^set output/ { exit } p' \
    "$tmp/p3/data/plots.gp" | grep -q "title 'compensated'" &&
    fail "natfreq.png: a 'compensated' legend entry with no compensated value"

# ---- the solver's residual: a summary line and residual.png ---------------------
# the fixture's 41 ok passages at 0.001 m/s², then 100 more at 0.01 (tenfold)
cp "$tmp/golden.db" "$tmp/res.db" 2> /dev/null || sqlite3 "$tmp/res.db" < "$tmp/fixture.sql"
sqlite3 "$tmp/res.db" "UPDATE passages SET f1_comp_hz = 5.75 WHERE status = 'ok';
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 100)
INSERT INTO passages (id, vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status, reason,
                      lambda, residual_rms, formulation, solve_ms, speed_given_mps,
                      speed_estimated, n_vehicles, quality)
SELECT 1000 + i, 5000 + i, 1763856000000000 + i * 60000000, 1, 24.0, 2, 18000.0, 'ok', '',
       1e-8, 0.01, 'paper', 10.0, 24.0, 0, 1, 2.5 FROM k;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg) SELECT id, 1, NULL, 7200 FROM passages WHERE id > 1000;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg) SELECT id, 2, 4.5, 10800 FROM passages WHERE id > 1000;" || exit 1
run --db "$tmp/res.db" --summary
grep -q '^residual     n 141, median 0.01 m/s², p95 0.01 m/s²; oldest 50 median 0.001, newest 50 median 0.01 (x 10.00); quality median 2.5$' "$tmp/out" ||
    fail "--summary: no residual line showing the tenfold rise: $(grep '^residual' "$tmp/out")"
run --db "$tmp/res.db" --summary --format csv
grep -q '^residual_growth,10$' "$tmp/out" || fail "--summary csv: residual_growth: $(grep residual_growth "$tmp/out")"
run --db "$tmp/res.db" --summary --format json
grep -q '"residual":{"n":141,"median_mps2":0.01,"p95_mps2":0.01,"oldest_median_mps2":0.001,"newest_median_mps2":0.01,"newest_over_oldest":10' "$tmp/out" ||
    fail "--summary json: no residual object"
run --db "$tmp/res.db" --plot "$tmp/p6"
[ "$rc" = 0 ] || fail "--plot (residual): status $rc: $(cat "$tmp/err")"
grep -q 'residual.png  solver residual' "$tmp/out" || fail "--plot: residual.png not listed: $(cat "$tmp/out")"
[ "$(grep -vc '^#' "$tmp/p6/data/residual.dat")" = 141 ] || fail "residual.dat: not one row per ok passage"
tail -1 "$tmp/p6/data/residual.dat" | awk '{ exit !($4 == 0.01) }' || fail "residual.dat: running median at the end not 0.01"
run --db "$tmp/res.db" --plot "$tmp/p7" --from 2025-11-23T00:01
[ "$(grep -vc '^#' "$tmp/p7/data/residual.dat")" = 100 ] || fail "residual.dat with --from: not the range's 100 passages"

# ---- the model fit: fit_ratio.png with the thresholds amfid ran with -------------
# the 41 fixture passages fit (0.003), the 100 after them do not (0.3); amfid
# recorded a rule of its own (meta alerts.model_fit)
sqlite3 "$tmp/res.db" "UPDATE passages SET fit_ratio = CASE WHEN id > 1000 THEN 0.3 ELSE 0.003 END
  WHERE status = 'ok';
INSERT INTO meta (key, value) VALUES ('alerts.model_fit',
  'enabled=1 window=5 raise=0.2 clear=0.1 raise_after=3 clear_after=4')" || exit 1
printf 'alerts:\n  model_fit:\n    raise: 0.4\n    clear: 0.25\n' > "$tmp/mf.yaml"
run --db "$tmp/res.db" --plot "$tmp/p8" --config "$tmp/mf.yaml"
[ "$rc" = 0 ] || fail "--plot (fit ratio): status $rc: $(cat "$tmp/err")"
grep -q 'fit_ratio.png  model fit ratio per passage' "$tmp/out" || fail "--plot: fit_ratio.png not listed: $(cat "$tmp/out")"
[ -s "$tmp/p8/fit_ratio.png" ] || fail "fit_ratio.png not drawn"
[ "$(grep -vc '^#' "$tmp/p8/data/fit_ratio.dat")" = 141 ] || fail "fit_ratio.dat: not one row per fitted passage"
awk '!/^#/ { n++; if (n == 4 && $3 != "nan") bad = 1; if (n == 5 && $3 != 0.003) bad = 1 }
     END { if ($3 != 0.3) bad = 1; exit bad }' "$tmp/p8/data/fit_ratio.dat" ||
    fail "fit_ratio.dat: not the median of the last 5 once 5 are there: $(sed -n '2,7p;$p' "$tmp/p8/data/fit_ratio.dat")"
gp8=$tmp/p8/data/plots.gp
awk '/fit_ratio.png/ { on = 1 } on && /^plot/ { p = 1 } p && /^set output/ { exit } p' "$gp8" > "$tmp/fit.gp"
grep -q "title 'median of the last 5'" "$tmp/fit.gp" || fail "fit_ratio.png: not the recorded window: $(cat "$tmp/fit.gp")"
grep -q "^     0.2 with lines .* title 'raise at >= 0.2 (3 in a row)'" "$tmp/fit.gp" ||
    fail "fit_ratio.png: not the recorded raise level 0.2: $(cat "$tmp/fit.gp")"
grep -q "^     0.1 with lines .* title 'clear below 0.1 (4 in a row)'" "$tmp/fit.gp" ||
    fail "fit_ratio.png: not the recorded clear level 0.1"
grep -q "model_mismatch; thresholds: amfid's, from the store" "$gp8" || fail "fit_ratio.png: the title does not say where the thresholds come from"
# the y range (log) holds every value and both levels inside the frame
read -r lo hi <<EOT
$(awk '/fit_ratio.png/ { on = 1 } on && /^set yrange/ { gsub(/\[|\]|:/, " "); print $3, $4; exit }' "$gp8")
EOT
awk -v lo="${lo:-0}" -v hi="${hi:-0}" 'BEGIN { exit !(lo > 0 && lo < 0.003 && hi > 0.3) }' ||
    fail "fit_ratio.png: y range [$lo:$hi] does not hold 0.003 .. 0.3"
grep -A6 "fit_ratio.png" "$gp8" | grep -q "set logscale y" || fail "fit_ratio.png: not on a log axis"
# without amfid's record: --config's levels; without either: the defaults
sqlite3 "$tmp/res.db" "DELETE FROM meta WHERE key = 'alerts.model_fit'" || exit 1
run --db "$tmp/res.db" --plot "$tmp/p9" --config "$tmp/mf.yaml"
grep -q "title 'raise at >= 0.4 (10 in a row)'" "$tmp/p9/data/plots.gp" &&
  grep -q "thresholds: --config" "$tmp/p9/data/plots.gp" || fail "fit_ratio.png: not --config's levels"
run --db "$tmp/res.db" --plot "$tmp/p9" --from 2025-11-23T00:01
grep -q "title 'raise at >= 0.1 (10 in a row)', .*" "$tmp/p9/data/plots.gp" &&
  grep -q "title 'clear below 0.05 (25 in a row)'" "$tmp/p9/data/plots.gp" ||
  fail "fit_ratio.png: not the default levels"
[ "$(grep -vc '^#' "$tmp/p9/data/fit_ratio.dat")" = 100 ] || fail "fit_ratio.dat with --from: not the range's 100 passages"
# a damaged record is an error naming it
sqlite3 "$tmp/res.db" "INSERT INTO meta (key, value) VALUES ('alerts.model_fit', 'enabled=1 window=5 raise=0.1 clear=0.2 raise_after=3 clear_after=4')" || exit 1
run --db "$tmp/res.db" --plot "$tmp/p9"
[ "$rc" = 1 ] && grep -q "res.db: meta alerts.model_fit: the clear level (0.2) must be below the raise level (0.1)" "$tmp/err" ||
    fail "a damaged alerts.model_fit: status $rc: $(cat "$tmp/err")"

# ---- one unit system per output: --units and report.units ---------------------
# si (the default): tables and plots in kg and m/s
run --db "$db" --summary --passages --plot "$tmp/u1"
[ "$rc" = 0 ] || fail "--plot (si): status $rc: $(cat "$tmp/err")"
grep -q '^GVW, ok      n 41, mean 18634 kg' "$tmp/out" || fail "si: the summary not in kg"
grep -q "set ylabel 'GVW (kg)'" "$tmp/u1/data/plots.gp" || fail "si: gvw.png not in kg"
grep -q "set xlabel 'speed (m/s), bins of 0.5 m/s'" "$tmp/u1/data/plots.gp" || fail "si: speed.png not in m/s"
grep -q "xlabel 'GVW (kg), bins of" "$tmp/u1/data/plots.gp" || fail "si: gvw_histogram.png not in kg"
grep -q "(t)\|km/h" "$tmp/u1/data/plots.gp" && fail "si: a plot in t or km/h"
# engineering, by option and by report.units: tables and plots in t and km/h
printf 'report:\n  units: engineering\n' > "$tmp/eng.yaml"
for how in "--units engineering" "--config $tmp/eng.yaml"; do
    # shellcheck disable=SC2086
    run --db "$db" --summary --passages --plot "$tmp/u2" $how
    [ "$rc" = 0 ] || { fail "$how: status $rc: $(cat "$tmp/err")"; continue; }
    grep -q '^GVW, ok      n 41, mean 18.63 t, STD 4.60 t' "$tmp/out" || fail "$how: the summary not in t"
    grep -q '^time (UTC) .* km/h  ax     GVW t  axle loads t ' "$tmp/out" || fail "$how: --passages not in t and km/h"
    grep -q "set ylabel 'GVW (t)'" "$tmp/u2/data/plots.gp" || fail "$how: gvw.png not in t"
    grep -q "set xlabel 'speed (km/h), bins of 2 km/h'" "$tmp/u2/data/plots.gp" || fail "$how: speed.png not in km/h"
    grep -q "(kg)\|(m/s)" "$tmp/u2/data/plots.gp" && fail "$how: a plot in kg or m/s"
    awk '!/^#/ && $2 ~ /^[0-9.]+$/ && $2 > 100 { bad = 1 } END { exit bad }' "$tmp/u2/data/passages.dat" || fail "$how: passages.dat not in t"
done
# the exports stay in kg and m/s
run --db "$db" --passages --format csv --units engineering
awk -F, 'NR == 2 { exit !($8 > 1000) }' "$tmp/out" || fail "--units engineering changed the CSV's gvw_kg"
run --db "$db" --summary --units furlongs
[ "$rc" = 2 ] && grep -q -- "--units: 'furlongs' is not si or engineering" "$tmp/err" || fail "--units furlongs: status $rc: $(cat "$tmp/err")"
printf 'report:\n  units: imperial\n' > "$tmp/bad.yaml"
run --db "$db" --summary --config "$tmp/bad.yaml"
[ "$rc" = 1 ] && grep -q "bad.yaml:2" "$tmp/err" || fail "report.units: imperial: status $rc: $(cat "$tmp/err")"

[ "$fails" = 0 ] && echo "ok: report_range"
exit $((fails > 0))
