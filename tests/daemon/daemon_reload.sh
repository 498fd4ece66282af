#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# daemon_reload.sh: reload the configuration with a different λ while
# passages are being solved. sim_publisher writes a log (no network); amfid
# replays it through LCM's file:// provider as fast as its solver threads
# go, while this script rewrites the configuration file, alternating the
# fixed λ between two values, and sends SIGHUP every 0.1 s. Checks: amfid
# exits 0, every vehicle is a stored passage, every reload is applied, both
# λ values were used by the solvers (the reload reaches the solver threads
# through the jobs), and no sanitizer reported anything.
#
# Built with -DAMFI_TSAN=ON (scripts/test.sh builds such a tree and runs
# this test there) it is the ThreadSanitizer test of the daemon's threads:
# TSAN_OPTIONS=halt_on_error=1 and any "ThreadSanitizer" line in amfid's
# output fails it. In the other trees it checks the same behaviour.
#
# Usage: daemon_reload.sh AMFID SIM_PUBLISHER CONFIG
set -u
amfid=$1 sim=$2 config=$3
dir=$(mktemp -d)
apid=""
cleanup() { [ -n "$apid" ] && kill -9 "$apid" 2>/dev/null; rm -rf "$dir"; }
trap cleanup EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
. "$(dirname "$0")/../common/proc.sh"
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -30 "$f"; done; exit 1; }
N=${AMFI_RELOAD_VEHICLES:-120}
L1=7.94e-9 L2=2.5e-8
export TSAN_OPTIONS="halt_on_error=1 exitcode=66 ${TSAN_OPTIONS:-}"
export OPENBLAS_NUM_THREADS=1

"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/traffic.lcmlog" --vehicles $N --headway 2 --speedup max \
  --seed 17 2> "$dir/sim.log" || fail "sim_publisher exited $?"
grep -q "^  lambda: $L1 " "$config" || fail "$config: no '  lambda: $L1' line to rewrite"
# A queue of 2: the replay waits for the solvers, so the log lasts as long
# as the solving and every SIGHUP lands while passages are being solved.
sed -e "s/^  queue_size: 256/  queue_size: 2/" "$config" > "$dir/base.yaml"
grep -q "^  queue_size: 2 " "$dir/base.yaml" || fail "the test's queue size did not apply"
cp "$dir/base.yaml" "$dir/amfid.yaml"

"$amfid" --config "$dir/amfid.yaml" --db "$dir/reload.db" \
  --lcm-url "file://$dir/traffic.lcmlog?speed=0" 2> "$dir/amfid.log" &
apid=$!
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
k=0
while kill -0 $apid 2>/dev/null; do
  sleep 0.1
  k=$((k + 1))
  if [ $((k % 2)) -eq 1 ]; then l=$L2; else l=$L1; fi
  # rewrite through a temporary file: amfid never reads half a file
  sed -e "s/^  lambda: $L1 /  lambda: $l /" "$dir/base.yaml" > "$dir/amfid.yaml.tmp" &&
    mv "$dir/amfid.yaml.tmp" "$dir/amfid.yaml"
  grep -q "^  lambda: $l " "$dir/amfid.yaml" || fail "the rewrite to lambda $l did not apply"
  kill -HUP $apid 2>/dev/null || break
done
wait $apid; rc=$?
apid=""
grep -q "ThreadSanitizer" "$dir/amfid.log" && fail "ThreadSanitizer reported (above)"
grep -q "runtime error\|AddressSanitizer\|LeakSanitizer" "$dir/amfid.log" && fail "a sanitizer reported (above)"
[ $rc -eq 0 ] || fail "amfid exit status $rc"
applied=$(grep -c "reload: configuration .* applied" "$dir/amfid.log")
rows=$(sqlite3 "$dir/reload.db" "SELECT count(*) FROM passages")
ok=$(sqlite3 "$dir/reload.db" "SELECT count(*) FROM passages WHERE status = 'ok'")
lambdas=$(sqlite3 "$dir/reload.db" "SELECT group_concat(l || ': ' || n, ', ') FROM
  (SELECT printf('%.3g', lambda) AS l, count(*) AS n FROM passages WHERE status = 'ok' GROUP BY 1)")
echo "daemon_reload: $rows passages ($ok ok) for $N vehicles, $applied reloads applied; lambda used: $lambdas"
[ "$rows" -eq $N ] || fail "expected $N passage rows, got $rows"
[ "$ok" -eq $N ] || fail "only $ok of $N passages ok"
[ "$applied" -ge 3 ] || fail "only $applied reloads applied while solving"
echo "$lambdas" | grep -q "7.94e-09: " || fail "lambda $L1 never used"
echo "$lambdas" | grep -q "2.5e-08: " || fail "lambda $L2 never used after a reload"
runs=$(sqlite3 "$dir/reload.db" "SELECT count(*) || ' ' || version FROM runs")
[ "$runs" = "1 $("$amfid" --version | sed 's/^amfid //')" ] || fail "runs table: '$runs'"
exit 0
