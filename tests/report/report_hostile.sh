#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_hostile.sh: amfi-report on stores crafted by an attacker (a store
# copied from a site is a file from elsewhere). Three properties:
#   --plot: nothing from the store runs in gnuplot. Site names (and, without
#     one, the store's file name) full of backquotes, system(), $(...), quotes,
#     line breaks, set print, @macros, broken UTF-8 and 4 kB long: every plot
#     is still drawn, no file appears in the canary folder, the script holds
#     no backquote; alert kinds with blanks and line breaks add no data rows;
#     a --plot folder with a quote and backquotes works too.
#   --format csv: no text cell from the store starts a spreadsheet formula
#     (= + - @ tab CR LF, after blanks; full-width = + - @): each is written
#     with a leading single quote, numbers (negative ones too) stay numbers.
#   SQLite: a store whose view calls a function SQLite does not mark
#     innocuous, or reads a virtual table, is refused; a store
#     with a trigger (one on baseline deleting every passage) is refused by
#     --set-baseline-last and the readers, the file unchanged.
# The fixture is built with the sqlite3 program from the DDL in
# docs/schema.md, as report_cli.sh does.
#
# usage: report_hostile.sh PATH/TO/amfi-report PATH/TO/docs/schema.md
# Exit 77 (skipped) without the sqlite3 program; the --plot part is skipped
# (said on stdout) without gnuplot.
set -u

bin=${1:?usage: report_hostile.sh AMFI_REPORT SCHEMA_MD}
doc=${2:?usage: report_hostile.sh AMFI_REPORT SCHEMA_MD STORE_STAMP}
stamp=${3:?usage: report_hostile.sh AMFI_REPORT SCHEMA_MD STORE_STAMP}
[ -x "$bin" ] || { echo "report_hostile.sh: $bin: not executable" >&2; exit 1; }
[ -r "$doc" ] || { echo "report_hostile.sh: $doc: not readable" >&2; exit 1; }
command -v sqlite3 > /dev/null || { echo "report_hostile.sh: no sqlite3 program: skipped"; exit 77; }
case $bin in /*) ;; *) bin=$PWD/$bin ;; esac # run from the canary folder

tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_hostile.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
canary=$tmp/canary # where the hostile commands would create files
mkdir "$canary"

failures=0
cases=0
name=setup
problem() { echo "FAIL $name: $*"; failures=$((failures + 1)); }

# ---- the fixture: 20 passages, 5 indicators, 4 alerts ----------------------
db=$tmp/base.db
awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
[ -s "$tmp/ddl.sql" ] || { echo "report_hostile.sh: no DDL block in $doc" >&2; exit 1; }
{
    cat "$tmp/ddl.sql"
    cat <<'EOF'
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 20)
INSERT INTO passages (vehicle_id, utime, lane, speed_mps, n_axles, gvw_kg, status,
                      reason, lambda, residual_rms, formulation, solve_ms, speed_given_mps)
SELECT i, 1763769600000000 + i * 3600000000, 1, 25.0, 2,
       CASE WHEN i % 5 = 0 THEN NULL ELSE 15000.0 + 1000 * (i % 7) END,
       CASE WHEN i % 5 = 0 THEN 'gap' ELSE 'ok' END,
       CASE WHEN i = 5 THEN '=cmd|'' /C calc''!A0'
            WHEN i = 10 THEN ' @SUM(1+1)*cmd|'' /C calc''!A0'
            WHEN i = 15 THEN '  -1+1'
            WHEN i = 20 THEN 'samples missing, =2+2'
            ELSE '' END,
       CASE WHEN i % 5 = 0 THEN NULL ELSE 7.94e-9 END,
       CASE WHEN i % 5 = 0 THEN NULL ELSE 0.001 END,
       CASE WHEN i % 5 = 0 THEN NULL ELSE 'paper' END, 15.0, 25.0
FROM k;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg) SELECT id, 1, NULL, 0.4 * gvw_kg FROM passages;
INSERT INTO axles (passage_id, idx, spacing_m, load_kg) SELECT id, 2, 4.5, 0.6 * gvw_kg FROM passages;
INSERT INTO baseline (utime_set, n, mean_kg, std_kg, source, note)
VALUES (1763769600000000, 10, 17800, 1900, 'auto', '');
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < 5)
INSERT INTO indicators (utime, n, mean_kg, std_kg, baseline_mean_kg, baseline_std_kg,
                        std_ratio, p_value, state)
SELECT 1763769600000000 + i * 14400000000, 20, CASE WHEN i = 3 THEN -1234.5 ELSE 17800 + i END,
       1900 + 20 * i, 17800, 1900, (1900 + 20 * i) / 1900.0, 0.5 / i, 'normal'
FROM k;
INSERT INTO alerts (utime, level, kind, message, indicator_id, raised) VALUES
  (1763769600000000 + 1 * 14400000000, 'info', '=HYPERLINK("http://x.io","c")', '+1+2', 1, 1),
  (1763769600000000 + 2 * 14400000000, 'warning', '-1+1', '-2+3', 2, 1),
  (1763769600000000 + 3 * 14400000000, 'info', 'a b 9 9 9 x', '＝1+1', 3, 0),
  (1763769600000000 + 4 * 14400000000, 'info', '@SUM(A1:A9)', 'mean GVW -6 %, fine', 4, 1);
INSERT INTO meta (key, value) VALUES ('intake.as_of', '=1+1'), ('intake.run', '1'),
  ('intake.messages_received', '5'), ('intake.messages_refused', '0'), ('intake.datagrams_dropped', '0'),
  ('intake.samples_missing', '0'), ('intake.passages_lost', '0');
EOF
} > "$tmp/fixture.sql"
# the schema version and migration rows as the store's migrations record them
if ! { sqlite3 "$db" < "$tmp/fixture.sql" && "$stamp" "$db"; } > "$tmp/fixture.log" 2>&1; then
    echo "report_hostile.sh: building the fixture failed:" >&2
    cat "$tmp/fixture.log" >&2
    exit 1
fi

# run NAME ARGS...: amfi-report; status in $rc, output in $tmp/out, $tmp/err
run() {
    name=$1
    shift
    cases=$((cases + 1))
    # in the canary folder: a relative `touch NAME` would land there
    (cd "$canary" && exec "$bin" "$@") > "$tmp/out" 2> "$tmp/err"
    rc=$?
}
ok() {
    run "$@"
    [ "$rc" -eq 0 ] || { problem "status $rc, expected 0 ($(head -c 300 "$tmp/err"))"; return 1; }
    return 0
}
canary_empty() {
    if [ -n "$(ls -A "$canary")" ]; then
        problem "the store ran commands: $(ls -A "$canary" | tr '\n' ' ')"
        rm -f "$canary"/* "$canary"/.[!.]* 2> /dev/null
    fi
}

# ---- --plot: hostile site names ----------------------------------------------
# sql_str TEXT: TEXT as an SQL string literal
sql_str() { printf "'%s'" "$(printf '%s' "$1" | sed "s/'/''/g")"; }
long=$(printf '%04000d' 0 | tr 0 A)
if command -v gnuplot > /dev/null; then
    k=0
    # the site names, one SQL expression a line
    cat > "$tmp/names" <<EOF
$(sql_str "Bridge \`touch $canary/bq\`")
$(sql_str "x\" . system(\"touch $canary/system\") . \"")
$(sql_str "\$(touch $canary/dollar) \${IFS}")
$(sql_str "it's \\\`touch $canary/bs\\\` \\\\")
$(sql_str "@b \`touch $canary/macro\`")
$(sql_str "\`touch long\`$long")
$(sql_str "｀touch $canary/fullwidth｀ \`touch utf\`")
$(sql_str "Pont de l’Île (Brücke)")
EOF
    while IFS= read -r expr; do
        k=$((k + 1))
        cp "$db" "$tmp/site$k.db"
        sqlite3 "$tmp/site$k.db" "INSERT INTO meta (key, value) VALUES ('site.name', $expr)" ||
            { name=site$k; problem "fixture: cannot set the name $expr"; continue; }
        if ok "plot-site$k" --db "$tmp/site$k.db" --plot "$tmp/plot$k"; then
            for p in gvw trend gvw_histogram passages_per_hour speed; do
                [ -s "$tmp/plot$k/$p.png" ] || problem "$p.png not drawn"
            done
            [ -s "$tmp/plot$k/data/gnuplot.log" ] &&
                problem "gnuplot said: $(head -c 300 "$tmp/plot$k/data/gnuplot.log")"
        fi
        grep -n '`' "$tmp/plot$k/data/plots.gp" > "$tmp/bq" 2> /dev/null &&
            problem "plots.gp holds a backquote: $(head -c 200 "$tmp/bq")"
        canary_empty
    done < "$tmp/names"
    # a site name with line breaks (set print, print) is refused by the
    # store's reader: a clean message, nothing run
    cp "$db" "$tmp/nl.db"
    sqlite3 "$tmp/nl.db" "INSERT INTO meta (key, value) VALUES ('site.name', 'a\"' || char(10) ||
        'set print \"$canary/print\"' || char(10) || 'print \"x\"' || char(10) || '#')"
    run plot-site-newline --db "$tmp/nl.db" --plot "$tmp/plotnl"
    [ "$rc" -eq 1 ] || problem "status $rc, expected 1"
    grep -q 'meta row [0-9]*: value holds a control character' "$tmp/err" || problem "stderr: $(cat "$tmp/err")"
    canary_empty
    # a legitimate name keeps its letters (UTF-8 included)
    grep -q 'Pont de l’Île (Brücke)' "$tmp/plot$k/data/plots.gp" ||
        problem "the site name 'Pont de l’Île (Brücke)' is not in the titles"
    # the alert kind with a blank and a line break stays one token of one row
    name=alerts-dat
    [ "$(grep -vc '^#' "$tmp/plot1/data/alerts.dat")" -eq 4 ] ||
        problem "alerts.dat: $(grep -vc '^#' "$tmp/plot1/data/alerts.dat") rows, expected 4"
    awk '!/^#/ && NF != 5 { bad = 1 } END { exit bad }' "$tmp/plot1/data/alerts.dat" ||
        problem "alerts.dat: a row without 5 fields: $(cat "$tmp/plot1/data/alerts.dat")"

    # no site name: the file name titles the plots
    bad_file="$tmp/b\`touch file\`\$(touch file2)'\".db"
    cp "$db" "$bad_file"
    if ok plot-filename --db "$bad_file" --plot "$tmp/plotf"; then
        [ -s "$tmp/plotf/gvw.png" ] || problem "gvw.png not drawn"
    fi
    canary_empty
    # a --plot folder with a quote and backquotes (the operator's, but the
    # script must still be right)
    bad_dir="$tmp/it's \`touch dir\` dir"
    if ok plot-dir --db "$db" --plot "$bad_dir"; then
        [ -s "$bad_dir/trend.png" ] || problem "trend.png not drawn in $bad_dir"
    fi
    canary_empty
    nl_dir="$tmp/a
set print 'nl'"
    run plot-dir-newline --db "$db" --plot "$nl_dir"
    [ "$rc" -eq 1 ] || problem "status $rc, expected 1"
    grep -q 'control character' "$tmp/err" || problem "stderr: $(cat "$tmp/err")"
    canary_empty
else
    echo "report_hostile.sh: no gnuplot: --plot cases skipped"
fi

# ---- --format csv: no text cell starts a formula -------------------------
# csv_cells FILE: every field of an RFC 4180 file, one a line, quotes
# removed ("" as "), a line break in a field as \n; a cell that is a number
# is printed as "NUM value".
csv_cells() {
    awk 'BEGIN { rec = "" }
    {
        rec = rec (rec == "" && !open ? "" : "\\n") $0
        n = gsub(/"/, "\"", $0)
        if (n % 2) open = !open
        if (open) next
        line = rec; rec = ""
        while (length(line) > 0 || last_comma) {
            last_comma = 0
            if (substr(line, 1, 1) == "\"") {
                v = ""; i = 2
                while (i <= length(line)) {
                    c = substr(line, i, 1)
                    if (c == "\"") {
                        if (substr(line, i + 1, 1) == "\"") { v = v "\""; i += 2; continue }
                        i++; break
                    }
                    v = v c; i++
                }
                line = substr(line, i)
            } else {
                j = index(line, ",")
                v = j ? substr(line, 1, j - 1) : line
                line = j ? substr(line, j) : ""
            }
            if (substr(line, 1, 1) == ",") { line = substr(line, 2); if (line == "") last_comma = 1 }
            if (v ~ /^-?[0-9]+(\.[0-9]+)?([eE][-+]?[0-9]+)?$/) print "NUM " v
            else print v
            if (line == "" && !last_comma) break
        }
    }' "$1"
}
# formula_cells: the cells of csv_cells output a spreadsheet would evaluate
formula_cells() {
    grep -v '^NUM ' | LC_ALL=C grep -E "^[ ]*([=+@-]|$(printf '\t')|$(printf '\r')|\\\\n|＝|＋|－|＠)"
}
for what in summary trend alerts passages errors; do
    run "csv-$what" --db "$db" "--$what" --format csv
    [ "$rc" -eq 0 ] || [ "$what" = errors ] || { problem "status $rc: $(head -c 300 "$tmp/err")"; continue; }
    csv_cells "$tmp/out" > "$tmp/cells"
    if formula_cells < "$tmp/cells" > "$tmp/formulas"; then
        problem "cells that start a formula: $(head -5 "$tmp/formulas" | tr '\n' '|')"
    fi
done
# the text is all there behind the quote, the numbers are numbers
run csv-alerts --db "$db" --alerts --format csv
grep -qF "\"'=HYPERLINK(\"\"http://x.io\"\",\"\"c\"\")\"" "$tmp/out" || problem "kind: $(cat "$tmp/out")"
grep -qF ",'+1+2" "$tmp/out" || problem "message +1+2: $(cat "$tmp/out")"
grep -qF ",'-2+3" "$tmp/out" || problem "message -2+3: $(cat "$tmp/out")"
grep -qF ",'＝1+1" "$tmp/out" || problem "message ＝1+1: $(cat "$tmp/out")"
grep -qF ",'@SUM(A1:A9)," "$tmp/out" || problem "kind @SUM: $(cat "$tmp/out")"
grep -qF ",mean GVW -6 %, fine" "$tmp/out" && problem "message with a comma not quoted"
grep -qF ",\"mean GVW -6 %, fine\"" "$tmp/out" || problem "message: $(cat "$tmp/out")"
run csv-trend --db "$db" --trend --format csv
grep -qE '^3,[^,]+,[0-9]+,20,-1234\.5,' "$tmp/out" || problem "negative mean_kg not a number: $(sed -n 4p "$tmp/out")"
run csv-summary --db "$db" --summary --format csv
grep -qx "intake_as_of,'=1+1" "$tmp/out" || problem "intake_as_of: $(grep as_of "$tmp/out")"
run csv-passages --db "$db" --passages --format csv
grep -qF ",\"'=cmd|' /C calc'!A0\"," "$tmp/out" || grep -qF ",'=cmd|' /C calc'!A0," "$tmp/out" ||
    problem "reason =cmd: $(grep calc "$tmp/out" | head -2)"

# ---- SQLite: views and triggers from elsewhere ---------------------------
# views that SQLite refuses from an untrusted schema: one calling a
# function not marked innocuous (json_extract), one reading a virtual table
# (fts5: a parser of its own shadow tables, which the file controls); the
# view is prepared when the store is opened, so every mode refuses the store
k=0
for use in "json_extract('{\"a\":1}', '\$.a')" "(SELECT count(*) FROM notes)"; do
    k=$((k + 1))
    cp "$db" "$tmp/view$k.db"
    sqlite3 "$tmp/view$k.db" "CREATE VIRTUAL TABLE notes USING fts5(x); INSERT INTO notes VALUES ('x');
DROP VIEW passage_errors;
CREATE VIEW passage_errors AS SELECT 1 AS passage_id, 'ok' AS status, $use AS gvw_error_pct,
  1 AS vehicle_id, 0 AS utime, 0.0 AS gvw_kg, 0.0 AS true_gvw_kg, 0.0 AS speed_mps,
  0.0 AS speed_true_mps, 2 AS n_axles, 2 AS true_n_axles, 1 AS truth_id;" ||
        problem "fixture: the view $use"
    sum0=$(md5sum < "$tmp/view$k.db")
    for mode in --summary --errors; do
        run "view$k$mode" --db "$tmp/view$k.db" $mode
        [ "$rc" -eq 1 ] || problem "status $rc, expected 1 (refused): $(head -c 300 "$tmp/out")"
        grep -q 'unsafe use of' "$tmp/err" || problem "stderr: $(cat "$tmp/err")"
    done
    [ "$(md5sum < "$tmp/view$k.db")" = "$sum0" ] || problem "the file changed"
done

# a trigger on baseline that empties passages: --set-baseline-last refuses
# the store, the readers too, and nothing is deleted
cp "$db" "$tmp/trigger.db"
sqlite3 "$tmp/trigger.db" "CREATE TRIGGER wipe AFTER INSERT ON baseline BEGIN DELETE FROM axles; DELETE FROM passages; END;" ||
    problem "fixture: the trigger"
sum0=$(md5sum < "$tmp/trigger.db")
run trigger-set-baseline --db "$tmp/trigger.db" --set-baseline-last 5
[ "$rc" -eq 1 ] || problem "status $rc, expected 1 (refused): $(head -c 300 "$tmp/out")"
grep -q "holds trigger 'wipe'" "$tmp/err" || problem "stderr: $(cat "$tmp/err")"
n=$(sqlite3 "$tmp/trigger.db" "SELECT count(*) FROM passages")
[ "$n" -eq 20 ] || problem "the trigger ran: $n passages left of 20"
[ "$(md5sum < "$tmp/trigger.db")" = "$sum0" ] || problem "the file changed"
run trigger-reader --db "$tmp/trigger.db" --summary
[ "$rc" -eq 1 ] || problem "status $rc, expected 1 (refused)"
grep -q "holds trigger 'wipe'" "$tmp/err" || problem "stderr: $(cat "$tmp/err")"
# the same store without the trigger: --set-baseline-last works
cp "$db" "$tmp/clean.db"
ok clean-set-baseline --db "$tmp/clean.db" --set-baseline-last 5 --force &&
    [ "$(sqlite3 "$tmp/clean.db" "SELECT count(*) FROM baseline")" -eq 2 ] ||
    problem "no baseline row added"

echo "report_hostile.sh: $cases cases, $failures failed"
[ "$failures" -eq 0 ]
