#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fleet_bench.sh: amfi-fleet-bench at a tiny scale (3 sites x 2 days x 300
# passages) against a throwaway PostgreSQL (tests/common/pg_server.sh), so the
# benchmark of docs/fleet.md cannot rot: the stores are built, shipped by the
# real amfi-sync, the central counts equal the stores' (the bench checks it)
# and every view query runs. Timings are printed, never judged.
# Usage: fleet_bench.sh AMFI_FLEET_BENCH AMFI_SYNC. Exit 77 without PostgreSQL.
set -u
bench=$1 sync=$2
here=$(cd "$(dirname "$0")" && pwd)
. "$here/../common/pg_server.sh"
pg_tmp fleet_bench
"$sync" --pg "$PG_CONNINFO" --init-schema --quiet || { echo "FAIL: --init-schema"; exit 1; }
out=$("$bench" --pg "$PG_CONNINFO" --sync "$sync" --dir "$tmp/stores" --sites 3 --days 2 \
      --per-day 300 --jobs 2) || { echo "$out"; echo "FAIL: amfi-fleet-bench exit $?"; exit 1; }
echo "$out"
failures=0
for v in fleet_latest_state fleet_open_alerts fleet_daily_trend fleet_passages_daily; do
    echo "$out" | grep -q "^  $v" || { echo "FAIL: no timing of $v"; failures=$((failures + 1)); }
done
# 3 sites x 2 days x 300: the central database holds exactly that many, each
# with two axles; each site has an indicator (a window is 500 ok passages)
# and two daily trend rows.
n=$(pg_q "SELECT count(*) FROM passages") a=$(pg_q "SELECT count(*) FROM axles")
[ "$n" = 1800 ] && [ "$a" = 3600 ] || { echo "FAIL: central passages $n axles $a, want 1800 3600"; failures=$((failures + 1)); }
l=$(pg_q "SELECT count(*) FROM fleet_latest_state")
[ "$l" = 3 ] || { echo "FAIL: fleet_latest_state has $l rows, want 3 (one per site)"; failures=$((failures + 1)); }
o=$(pg_q "SELECT string_agg(site_id, ' ') FROM fleet_open_alerts")
[ "$o" = bench-000 ] || { echo "FAIL: open alerts at '$o', want bench-000 (every tenth site)"; failures=$((failures + 1)); }
d=$(pg_q "SELECT count(*) FROM fleet_daily_trend")
[ "$d" = 6 ] || { echo "FAIL: fleet_daily_trend has $d rows, want 6"; failures=$((failures + 1)); }
# a second bench run on the same stores (--keep) ships nothing new
out=$("$bench" --pg "$PG_CONNINFO" --sync "$sync" --dir "$tmp/stores" --sites 3 --days 2 \
      --per-day 300 --keep) || { echo "$out"; echo "FAIL: --keep exit $?"; exit 1; }
echo "$out" | grep -q "shipped: .* 0 passages" ||
    { echo "$out"; echo "FAIL: --keep shipped rows again"; failures=$((failures + 1)); }
[ "$(pg_q "SELECT count(*) FROM passages")" = 1800 ] || { echo "FAIL: rows doubled"; failures=$((failures + 1)); }
[ "$failures" = 0 ] && echo "fleet_bench: ok"
exit $((failures > 0))
