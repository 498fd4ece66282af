#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# contrib_monitoring.sh: contrib/prometheus/amfi-alerts.yml and
# contrib/grafana/amfi-fleet.json are what they claim:
# - the YAML and the JSON parse and have the structure Prometheus and
#   Grafana read (groups/rules with alert, expr, severity, summary; a
#   dashboard with panels, each with a datasource and targets);
# - every metric their PromQL names is one amfid writes (daemon/metrics.c:
#   its HELP/TYPE heads, with _bucket/_sum/_count of histograms and
#   summaries) or node-exporter's node_textfile_mtime_seconds, and every
#   label they match on is one amfid writes;
# - promtool (Debian's prometheus) checks the rules and passes their unit
#   tests (contrib/prometheus/amfi-alerts.test.yml);
# - every SQL of the dashboard (its panels and its site variable, Grafana's
#   $__timeFilter and $site filled in) runs on a throwaway PostgreSQL with
#   the central schema and a shipped site, as an analyst (amfi_reader), and
#   the fleet, map and trend panels get rows.
# Usage: contrib_monitoring.sh AMFI_SYNC SCHEMA_MD SOURCE_DIR. Exit 77
# without sqlite3/PostgreSQL/promtool (the parts before run anyway).
set -u
sync=$1 doc=$2 src=$3
rules=$src/contrib/prometheus/amfi-alerts.yml
rtest=$src/contrib/prometheus/amfi-alerts.test.yml
dash=$src/contrib/grafana/amfi-fleet.json
failures=0
case=structure
fail() { echo "FAIL $case: $*"; failures=$((failures + 1)); }
python3 -c 'import yaml' 2> /dev/null || { echo "contrib_monitoring.sh: no python3-yaml: skipped"; exit 77; }

work=$(mktemp -d "${TMPDIR:-/tmp}/contrib_monitoring.XXXXXX")
trap 'rm -rf "$work"' EXIT
python3 - "$rules" "$dash" "$src/daemon/metrics.c" "$work/queries.sql" <<'PY' || fail "structure or metric names (above)"
import json, re, sys, yaml
rules_path, dash_path, metrics_c, out = sys.argv[1:5]
bad = []
src = open(metrics_c).read()
heads = re.findall(r'head\(f, "(amfi_[a-z_]+)", "([a-z]+)"', src)
if len(heads) < 20:
    bad.append(f"{metrics_c}: only {len(heads)} metric heads found")
exported = set()
for name, typ in heads:
    exported.add(name)
    if typ == "histogram":
        exported |= {name + "_bucket", name + "_sum", name + "_count"}
    if typ == "summary":
        exported |= {name + "_sum", name + "_count"}
external = {"node_textfile_mtime_seconds"}
labels_written = set(re.findall(r'([a-z_]+)=\\"', src)) | {"quantile", "le"}
external_labels = {"file", "instance"}
functions = {"sum", "max", "min", "avg", "count", "rate", "irate", "increase", "delta", "time",
             "abs", "absent", "histogram_quantile", "and", "or", "unless", "bool", "offset"}

def check_promql(where, expr):
    e = re.sub(r'"(?:[^"\\]|\\.)*"', '""', expr)           # strings
    for name, body in re.findall(r'([a-zA-Z_:][\w:]*)\s*\{([^}]*)\}', e):
        for lbl in re.findall(r'([a-zA-Z_]\w*)\s*(?:=~|!~|!=|=)', body):
            ok = lbl in external_labels if name in external else lbl in labels_written
            if not ok:
                bad.append(f"{where}: label {lbl} of {name} is not one amfid writes")
    e = re.sub(r'\{[^}]*\}', '', e)                         # matchers
    e = re.sub(r'\[[^\]]*\]', '', e)                        # ranges
    e = re.sub(r'\b(by|on|ignoring|without|group_left|group_right)\s*\([^)]*\)', ' ', e)
    e = re.sub(r'\b(group_left|group_right)\b', ' ', e)
    e = re.sub(r'\b\d+(\.\d+)?([eE][-+]?\d+)?\b', ' ', e)  # numbers
    names = set(re.findall(r'[a-zA-Z_:][\w:]*', e)) - functions
    if not names:
        bad.append(f"{where}: names no metric")
    for n in names:
        if n not in exported and n not in external:
            bad.append(f"{where}: {n} is not a metric amfid writes (daemon/metrics.c)")
    return names

doc = yaml.safe_load(open(rules_path))
used = set()
groups = doc.get("groups") if isinstance(doc, dict) else None
if not isinstance(groups, list) or not groups:
    bad.append(f"{rules_path}: no groups")
for g in groups or []:
    if not isinstance(g.get("name"), str) or not isinstance(g.get("rules"), list):
        bad.append(f"{rules_path}: a group without name or rules")
        continue
    for r in g["rules"]:
        a = r.get("alert")
        if not isinstance(a, str) or not isinstance(r.get("expr"), str):
            bad.append(f"{rules_path}: a rule without alert or expr: {r}")
            continue
        if r.get("labels", {}).get("severity") not in ("critical", "warning", "info"):
            bad.append(f"{rules_path}: {a}: severity not critical, warning or info")
        if not r.get("annotations", {}).get("summary"):
            bad.append(f"{rules_path}: {a}: no summary")
        used |= check_promql(f"{rules_path}: {a}", r["expr"])

d = json.load(open(dash_path))
for k in ("title", "uid", "panels", "templating", "__inputs", "schemaVersion"):
    if k not in d:
        bad.append(f"{dash_path}: no {k}")
inputs = {i["name"] for i in d.get("__inputs", [])}
queries = []
ids = set()
for p in d.get("panels", []):
    t = p.get("title", "?")
    if p.get("id") in ids:
        bad.append(f"{dash_path}: panel id {p.get('id')} twice")
    ids.add(p.get("id"))
    if not isinstance(p.get("gridPos"), dict) or not p.get("type"):
        bad.append(f"{dash_path}: panel {t}: no type or gridPos")
    ds = p.get("datasource", {})
    if ds.get("uid", "").strip("${}") not in inputs:
        bad.append(f"{dash_path}: panel {t}: datasource {ds} is not one of the inputs {inputs}")
    if not p.get("targets"):
        bad.append(f"{dash_path}: panel {t}: no targets")
    for q in p.get("targets", []):
        if ds.get("type") == "prometheus":
            used |= check_promql(f"{dash_path}: panel {t}", q.get("expr", ""))
        elif "rawSql" in q:
            queries.append((t, q["rawSql"]))
        else:
            bad.append(f"{dash_path}: panel {t}: a target with neither expr nor rawSql")
for v in d.get("templating", {}).get("list", []):
    queries.append(("variable " + v["name"], v["query"]))
if len(queries) < 8:
    bad.append(f"{dash_path}: only {len(queries)} SQL queries")
unused = sorted(n for n in exported if n.startswith("amfi_") and not any(u.startswith(n) for u in used))
print(f"metrics used: {len(used)}; amfid's metrics in no rule or panel: {', '.join(unused) or 'none'}")
# the SQL for psql: Grafana's macros filled in, one query a file
with open(out, "w") as f:
    for t, q in queries:
        q = re.sub(r"\$__timeFilter\(([^()]*(?:\([^()]*\))?[^()]*)\)",
                   r"(\1 BETWEEN now() - interval '20 years' AND now() + interval '20 years')", q)
        q = q.replace("$site", "a1-km12")
        if "$" in q.replace("$$", ""):
            bad.append(f"{dash_path}: {t}: a macro the test does not know: {q}")
        f.write(f"\\echo -- {t}\n{q};\n")
for b in bad:
    print("FAIL", b)
sys.exit(1 if bad else 0)
PY

case=promtool
have_promtool=1
if command -v promtool > /dev/null; then
    promtool check rules "$rules" > "$work/check.log" 2>&1 || fail "promtool check rules: $(cat "$work/check.log")"
    (cd "$(dirname "$rtest")" && promtool test rules "$(basename "$rtest")") > "$work/test.log" 2>&1 ||
        fail "promtool test rules: $(cat "$work/test.log")"
else
    echo "contrib_monitoring.sh: no promtool (apt-get install prometheus): its checks skipped"
    have_promtool=0
fi

case=sql
command -v sqlite3 > /dev/null || { echo "contrib_monitoring.sh: no sqlite3: skipped"; exit 77; }
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp contrib_monitoring   # its trap removes $tmp; $work goes now
cp "$work/queries.sql" "$tmp/queries.sql"
rm -rf "$work"
fleet_store_setup "$doc"
"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || fail "--init-schema"
mkstore "$tmp/a.db" a1-km12 400
fleet_issue14_rows "$tmp/a.db"
sqlite3 "$tmp/a.db" "INSERT INTO meta (key, value) VALUES ('site.name', 'Sava bridge, km 12'),
                     ('site.latitude', '46.05'), ('site.longitude', '14.51')"
sqlite3 "$tmp/a.db" "INSERT INTO alerts (utime, level, kind, message, indicator_id, raised)
                     VALUES (1763900000000000, 'warning', 'std_increase', 'STD up', NULL, 1)"
"$sync" --db "$tmp/a.db" --pg "$PG_CONNINFO" --once --quiet || fail "sync: exit $?"
pg_q "CREATE ROLE grafana LOGIN IN ROLE amfi_reader"
psql -X -q -A -F '|' -v ON_ERROR_STOP=1 "host=$PG_DIR dbname=postgres user=grafana" -f "$tmp/queries.sql" \
    > "$tmp/sql.out" 2>&1 || fail "the dashboard's SQL as an analyst: $(tail -5 "$tmp/sql.out")"
# rows where there must be some
rows() { awk -v t="-- $1" '$0 == t { on = 1; next } /^-- / { on = 0 } on && /\|/ && !/^\(/' "$tmp/sql.out" | sed 1d | wc -l; }
for t in Fleet Sites "Open alerts" 'Passages a day ($site)' 'Mean GVW a day ($site)' 'STD ratio ($site)' 'Scale indicator ($site)'; do
    n=$(rows "$t")
    [ "$n" -gt 0 ] || fail "the panel '$t' got no rows: $(cat "$tmp/sql.out" | head -40)"
done
grep -q "^a1-km12|Sava bridge, km 12|" "$tmp/sql.out" || fail "the fleet panel does not show the site's name"
[ $failures = 0 ] || { echo "contrib_monitoring: $failures failure(s)"; exit 1; }
[ $have_promtool = 1 ] || exit 77
echo "contrib_monitoring: ok"
