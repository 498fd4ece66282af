#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_golden.sh: everything amfi-report prints, against checked-in
# expected output. A fixture store is built deterministically with the
# sqlite3 program from the DDL in docs/schema.md and report_golden.sql
# (every section has rows: lanes, gaps, an overload, estimated speeds,
# truth, indicators, alerts with hostile text, scale blocks, known-truck
# runs, temperatures, natural frequencies, intake counters), plus a store
# with the schema only and one without baseline, meta, scale or f1 rows.
# Then every section in every format, with and without filters and
# --config, the default report, --check, the baseline setters, the usage
# errors, --help and, with gnuplot, --plot's listing, data files and
# script, each as stdout, stderr and exit status, concatenated into one
# text that must equal report_golden.expected (and report_golden_plot.expected
# for --plot): the values by common/num_cmp.sh (floating point may differ in
# its last bits between machines; words and integers exactly), and the
# form byte for byte with every digit read as 9 (so that a number printed
# with another precision, "24.25" for "24.250", is a difference too).
#
# The expected files were written by the amfi-report built from main
# before its sections became a table (the refactor changed no byte of
# them). To rewrite them after an intended change of the output:
#   REPORT_GOLDEN_WRITE=1 sh report_golden.sh AMFI_REPORT SCHEMA_MD NUM_CMP DIR
#
# usage: report_golden.sh PATH/TO/amfi-report PATH/TO/docs/schema.md
#                         PATH/TO/num_cmp.sh DIR_OF_EXPECTED_FILES
# Exit 77 (skipped) without the sqlite3 program.
set -u

bin=${1:?usage: report_golden.sh AMFI_REPORT SCHEMA_MD NUM_CMP DIR}
doc=${2:?usage: report_golden.sh AMFI_REPORT SCHEMA_MD NUM_CMP DIR}
numcmp=${3:?usage: report_golden.sh AMFI_REPORT SCHEMA_MD NUM_CMP DIR}
dir=${4:?usage: report_golden.sh AMFI_REPORT SCHEMA_MD NUM_CMP DIR}
[ -x "$bin" ] || { echo "report_golden.sh: $bin: not executable" >&2; exit 1; }
[ -r "$doc" ] || { echo "report_golden.sh: $doc: not readable" >&2; exit 1; }
[ -r "$dir/report_golden.sql" ] || { echo "report_golden.sh: $dir/report_golden.sql: not readable" >&2; exit 1; }
command -v sqlite3 > /dev/null || { echo "report_golden.sh: no sqlite3 program: skipped"; exit 77; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_golden.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

# ---- the fixture ----------------------------------------------------------
awk '/^<!-- ddl:begin -->/ { on = 1; next } /^<!-- ddl:end -->/ { on = 0 }
     on && !/^```/' "$doc" > "$tmp/ddl.sql"
[ -s "$tmp/ddl.sql" ] || { echo "report_golden.sh: no DDL block in $doc" >&2; exit 1; }
v=$(sed -n 's/.*PRAGMA user_version` (this document: version \([0-9]*\)).*/\1/p' "$doc")
[ -n "$v" ] || { echo "report_golden.sh: no schema version in $doc" >&2; exit 1; }
db=$tmp/golden.db
{
    cat "$tmp/ddl.sql"
    echo "PRAGMA user_version = $v;
WITH RECURSIVE k(i) AS (SELECT 1 UNION ALL SELECT i + 1 FROM k WHERE i < $v)
INSERT INTO schema_migrations (version, description) SELECT i, 'golden' FROM k;"
    cat "$dir/report_golden.sql"
} > "$tmp/fixture.sql"
if ! sqlite3 "$db" < "$tmp/fixture.sql" > "$tmp/fixture.log" 2>&1; then
    echo "report_golden.sh: building the fixture failed:" >&2
    cat "$tmp/fixture.log" >&2
    exit 1
fi
empty=$tmp/empty.db
cp "$db" "$empty"
sqlite3 "$empty" "DELETE FROM axles; DELETE FROM truth_axles; DELETE FROM truth; DELETE FROM passages;
    DELETE FROM alerts; DELETE FROM indicators; DELETE FROM baseline; DELETE FROM meta;
    DELETE FROM environment; DELETE FROM scale_evals; VACUUM" || exit 1
bare=$tmp/bare.db
cp "$db" "$bare"
sqlite3 "$bare" "DELETE FROM baseline; DELETE FROM meta; DELETE FROM scale_evals;
    DELETE FROM environment; UPDATE passages SET f1_hz = NULL, f1_comp_hz = NULL, f1_zeta = NULL,
    f1_r2 = NULL, speed_estimated = 0, gvw_comp_kg = NULL;
    DELETE FROM alerts WHERE indicator_id IS NULL" || exit 1
damaged=$tmp/damaged.db
cp "$db" "$damaged"
sqlite3 "$damaged" "UPDATE passages SET reason = 'a' || char(10) || 'b' WHERE id = 30" || exit 1
printf 'report:\n  limits:\n    gvw_kg: 30000\n    axle_kg: 7000\n  histogram_bin_kg: 2500\n' \
    > "$tmp/limits.yaml"

# ---- the runs ----------------------------------------------------------------
got=$tmp/got
: > "$got"
n=0
# run NAME ARGS...: "== NAME", stdout, "-- stderr", stderr, "-- status N"
run() {
    name=$1
    shift
    "$bin" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    { echo "== $name"; cat "$tmp/out"; echo "-- stderr"; cat "$tmp/err"; echo "-- status $rc"; } >> "$got"
    n=$((n + 1))
}
for f in table csv json; do
    for s in summary trend alerts errors passages histogram overloads speed classes class-histogram; do
        run "$s.$f" --db "$db" --$s --format $f
        run "empty-$s.$f" --db "$empty" --$s --format $f
        run "bare-$s.$f" --db "$bare" --$s --format $f
    done
    run "passages-filtered.$f" --db "$db" --passages --from 2025-11-22T06:00 --to '2025-11-22 18:30:00' --lane 2 --format $f
    run "passages-gap.$f" --db "$db" --passages --status gap --format $f
    run "histogram-lane.$f" --db "$db" --histogram --bin-kg 500 --lane 1 --format $f
    run "overloads-range.$f" --db "$db" --overloads --from 2025-11-22 --to 2025-11-22 --format $f
    run "speed-lane.$f" --db "$db" --speed --lane 2 --to 2025-11-22T12:00Z --format $f
    run "config-overloads.$f" --db "$db" --overloads --config "$tmp/limits.yaml" --format $f
    run "config-histogram.$f" --db "$db" --histogram --config "$tmp/limits.yaml" --format $f
    run "damaged-passages.$f" --db "$damaged" --summary --passages --histogram --format $f
done
run default.table --db "$db"
run default.json --db "$db" --format json
run empty-default --db "$empty"
run bare-default --db "$bare"
run all.table --db "$db" -s -t -a -e -P -H -O -C
run all.json --db "$db" -s -t -a -e -P -H -O -C -F json
run units-engineering --db "$db" -s -t -P -H -O -L -Y --units engineering
run check --db "$db" --check
run check-summary --db "$db" --check --summary --errors
run help --help
run config-missing --db "$db" --config "$tmp/missing.yaml"
run usage-none
run usage-csv-two --db "$db" --summary --trend --format csv
run usage-csv-default --db "$db" --format csv
run usage-format --db "$db" --format xml
run usage-status --db "$db" --status ok
run usage-status-bad --db "$db" --passages --status nope
run usage-from-to --db "$db" --passages --from 2025-11-23 --to 2025-11-22
run usage-time --db "$db" --passages --from 2025-13-01
run usage-lane --db "$db" --passages --lane x
run usage-bin --db "$db" --histogram --bin-kg 5
run usage-note --db "$db" --note x
run usage-both-baseline --db "$db" --set-baseline-last 3 --set-baseline 1,2,3
run usage-baseline --db "$db" --set-baseline 1,2
run usage-json-check --db "$db" --check --format json
run usage-pg-db --db "$db" --pg host=x
run usage-site --db "$db" --site x
run usage-pg-sections --pg host=x --summary
run usage-pg-baseline --pg host=x --site a --check
run usage-plaintext --db "$db" --allow-plaintext
run usage-empty --db ''
run usage-unknown --db "$db" --bogus
run usage-ambiguous --db "$db" --s
run missing-db --db "$db.missing"
cp "$db" "$tmp/copy.db"
run baseline-open-alert --db "$tmp/copy.db" --set-baseline-last 5
run usage-force --db "$db" --force
run baseline-last --db "$tmp/copy.db" --set-baseline-last 5 --note 'after "work"' --force
run baseline-given --db "$tmp/copy.db" --set-baseline 18000,1500,30 --summary --force
run baseline-too-many --db "$tmp/copy.db" --set-baseline-last 1000 --force

# --plot: the listing, every data file and the script (not the PNGs, nor
# gnuplot's log)
gotplot=$tmp/gotplot
: > "$gotplot"
plots=0
if command -v gnuplot > /dev/null; then
    plots=1
    for store in golden empty bare damaged; do
        "$bin" --db "$tmp/$store.db" --plot "$tmp/$store.d" > "$tmp/out" 2> "$tmp/err"
        rc=$?
        { echo "== plot $store"; cat "$tmp/out"; echo "-- stderr"; cat "$tmp/err"; echo "-- status $rc"; } >> "$gotplot"
        for f in "$tmp/$store.d"/data/*; do
            [ -e "$f" ] || continue
            case $f in */gnuplot.log) continue ;; esac
            { echo "== plot $store data/$(basename "$f")"; cat "$f"; } >> "$gotplot"
        done
    done
fi

# the temporary paths as words
for f in "$got" "$gotplot"; do
    sed "s|$tmp/|TMP/|g" "$f" > "$f.s" && mv "$f.s" "$f"
done

if [ "${REPORT_GOLDEN_WRITE:-0}" = 1 ]; then
    cp "$got" "$dir/report_golden.expected"
    [ "$plots" = 1 ] && cp "$gotplot" "$dir/report_golden_plot.expected"
    echo "report_golden.sh: wrote the expected output of $n runs into $dir"
    exit 0
fi
status=0
# same WANT GOT: the values within num_cmp's tolerance, the form exactly
same() {
    sh "$numcmp" "$1" "$2" || return 1
    sed 's/[0-9]/9/g' "$1" > "$tmp/form.want"
    sed 's/[0-9]/9/g' "$2" > "$tmp/form.got"
    cmp -s "$tmp/form.want" "$tmp/form.got" ||
        { echo "the form of the numbers or text differs"; return 1; }
}
if ! same "$dir/report_golden.expected" "$got"; then
    echo "FAIL: amfi-report's output differs from report_golden.expected (diff - expected + got):"
    diff "$dir/report_golden.expected" "$got" | head -40
    status=1
fi
if [ "$plots" = 1 ] && ! same "$dir/report_golden_plot.expected" "$gotplot"; then
    echo "FAIL: --plot's output differs from report_golden_plot.expected (diff - expected + got):"
    diff "$dir/report_golden_plot.expected" "$gotplot" | head -40
    status=1
fi
[ "$plots" = 1 ] || echo "report_golden.sh: no gnuplot: --plot not compared"
[ "$status" -eq 0 ] && echo "ok: $n runs (and --plot: $plots) as expected"
exit "$status"
