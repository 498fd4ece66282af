#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Alert notices and the metrics file (issue 11), with amfid reading a
# simulated stream through file:// (no network): 60 vehicles, 30 % stiffness
# loss from the 31st, indicator windows of 10 so that the STD alert rises.
#  1. alerts.command is a script that records its environment: one call per
#     row of the alerts table, with that row's id, kind, level, raised, time
#     and message, and the site.
#  2. A script that sleeps past alerts.command_timeout_s (1 s) is killed and
#     counted; the passages after the alert were stored while it ran (the
#     notice never blocks the pipeline); amfid exits 0.
#  3. A script that fails (exit 3) is logged and counted.
#  4. A command that is missing or not executable is refused at load with
#     FILE:LINE.
#  5. The metrics file is valid text format (tests/daemon/prom_check.awk) and its
#     counters equal the store's.
#  6. A metrics file that cannot be written (a read-only mount, in a private
#     mount namespace): logged once with the reason, every passage still
#     stored, amfid exits 0.
#  7. With ALERT_PROBE (tests/daemon/alert_probe.c) as the command: it sees only
#     descriptors 0 to 2 of amfid's (not the bus's, the store's, the log's),
#     no signal ignored or blocked, its own process group; then, made to
#     hang with a grandchild (command_timeout_s 600), amfid's stop takes
#     alerts.command_stop_wait_s (2 s) + 3 s at most, kills both, counts
#     the notices never started as dropped, exits 0.
# Usage: daemon_notify.sh AMFID SIM_PUBLISHER CONFIG PROM_CHECK_AWK [ALERT_PROBE]
set -u
amfid=$1 sim=$2 config=$3 check=$4
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log" 2>/dev/null; exit 1; }
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/t.lcmlog" --vehicles 60 --headway 2 --speedup max \
  --damage 0.3 --damage-step-at 30 --seed 3 2> "$dir/sim.log" || fail "sim_publisher"
# CONF COMMAND TIMEOUT: the shipped file with small windows, the command, the metrics file
# (a simulation: the truth is read too, every message sent is counted)
conf() {
  sed -e "s/^    window: 500/    window: 10/" -e "s/^    every: 100/    every: 2/" \
      -e "s/^    baseline_n: 10000/    baseline_n: 20/" -e "s/^    raise_after: 6 /    raise_after: 1 /" \
      -e "s/^    clear_after: 6 /    clear_after: 1 /" -e "s|^  # command: .*|  command: $1|" \
      -e "s|^  command_timeout_s: 30 |  command_timeout_s: $2 |" \
      -e "s|^  # textfile: .*|  textfile: $dir/amfid.prom|" -e "s/^  id: local /  id: notify-test /" \
      -e "s/^  simulation: false .*/  simulation: true/" "$config"
}
run() { # NAME: amfid on the stream with $dir/NAME.yaml into $dir/NAME.db
  rm -f "$dir/$1.db"
  "$amfid" --config "$dir/$1.yaml" --db "$dir/$1.db" --lcm-url "file://$dir/t.lcmlog?speed=0" \
    2> "$dir/amfid.log"
}
q() { sqlite3 "$dir/$1.db" "$2"; }

# 1. one recorded call per alert row
mkdir "$dir/calls"
cat > "$dir/record.sh" <<REC
#!/bin/sh
env | grep '^AMFI_' | sort > "$dir/calls/\$AMFI_ALERT_ID.\$AMFI_ALERT_RAISED"
REC
chmod +x "$dir/record.sh"
conf "$dir/record.sh" 30 > "$dir/rec.yaml"
grep -q "^  command: $dir/record.sh" "$dir/rec.yaml" || fail "the test's alerts.command did not apply"
run rec || fail "amfid exit $? (recording)"
rows=$(q rec "SELECT count(*) FROM alerts")
[ "$rows" -ge 1 ] || fail "no alert raised: the test stream does not exercise notices"
[ "$(ls "$dir/calls" | wc -l)" -eq "$rows" ] || fail "$(ls "$dir/calls" | wc -l) calls for $rows alert rows"
q rec "SELECT id, kind, level, raised, utime, message FROM alerts" | while IFS='|' read -r id kind level raised utime msg; do
  f="$dir/calls/$id.$raised"
  [ -f "$f" ] || { echo "FAIL: no call for alert $id (raised $raised)"; exit 1; }
  for kv in "AMFI_ALERT_ID=$id" "AMFI_ALERT_KIND=$kind" "AMFI_ALERT_LEVEL=$level" \
            "AMFI_ALERT_RAISED=$raised" "AMFI_ALERT_UTIME=$utime" "AMFI_ALERT_MESSAGE=$msg" \
            "AMFI_SITE_ID=notify-test" "AMFI_DB=$dir/rec.db"; do
    grep -qxF "$kv" "$f" || { echo "FAIL: call $f lacks '$kv': $(cat "$f")"; exit 1; }
  done
  t=$(date -u -d "@$((utime / 1000000))" +%Y-%m-%dT%H:%M:%SZ)
  grep -qx "AMFI_ALERT_TIME=$t" "$f" || { echo "FAIL: call $f: time is not $t"; exit 1; }
done || exit 1
# 5. the metrics file of that run
awk -f "$check" "$dir/amfid.prom" > "$dir/check.txt" || fail "$(cat "$dir/check.txt")"
metric() { sed -n "s/^$1 //p" "$dir/amfid.prom"; }
[ "$(metric 'amfi_passages_total{status="ok"}')" = "$(q rec "SELECT count(*) FROM passages WHERE status = 'ok'")" ] ||
  fail "metrics: ok passages $(metric 'amfi_passages_total{status="ok"}')"
sent=$(sed -n 's/.* in \([0-9]*\) messages.*/\1/p' "$dir/sim.log")
[ "$(metric amfi_messages_received_total)" = "$sent" ] || fail "metrics: messages $(metric amfi_messages_received_total) of $sent"
[ "$(metric 'amfi_notices_total{result="ok"}')" = "$rows" ] || fail "metrics: notices ok $(metric 'amfi_notices_total{result="ok"}')"
[ "$(metric 'amfi_solve_seconds_count')" = "$(q rec "SELECT count(*) FROM passages WHERE gvw_kg IS NOT NULL")" ] ||
  fail "metrics: solve count"
[ "$(metric 'amfi_alert_open{kind="std_increase"}')" = "$(q rec "SELECT raised FROM alerts WHERE kind = 'std_increase' ORDER BY id DESC LIMIT 1")" ] ||
  fail "metrics: std_increase open"
echo "notices: $rows alert rows, $rows calls with matching environments; metrics: $(cat "$dir/check.txt"), counters equal the store's"

# 2. a notice that outlives its timeout
cat > "$dir/slow.sh" <<SLOW
#!/bin/sh
date +%s.%N > "$dir/slow.start"
exec sleep 30
SLOW
chmod +x "$dir/slow.sh"
conf "$dir/slow.sh" 1 > "$dir/slow.yaml"
t0=$(date +%s)
run slow || fail "amfid exit $? (slow notice)"
t1=$(date +%s)
grep -q "alert notice: .*slow.sh killed after 1 s" "$dir/amfid.log" || fail "no kill logged"
[ "$(metric 'amfi_notices_total{result="timeout"}')" -ge 1 ] || fail "metrics: no timeout counted"
[ "$(q slow "SELECT count(*) FROM passages")" -eq 60 ] || fail "$(q slow "SELECT count(*) FROM passages") of 60 passages"
[ $((t1 - t0)) -lt 20 ] || fail "amfid took $((t1 - t0)) s with a 1 s notice timeout"
# every passage was stored before the notice ended (1 s after it began)
start=$(cat "$dir/slow.start")
late=$(q slow "SELECT count(*) FROM passages WHERE CAST(strftime('%s', stored_at) AS REAL) + (strftime('%f', stored_at) - CAST(strftime('%S', stored_at) AS INTEGER)) > $start + 1.0")
[ "$late" -eq 0 ] || fail "$late passages stored after the slow notice was killed: the pipeline waited"
echo "slow notice: killed after 1 s and counted; all 60 passages stored while it ran; amfid took $((t1 - t0)) s"

# 3. a failing notice
printf '#!/bin/sh\nexit 3\n' > "$dir/fails.sh"
chmod +x "$dir/fails.sh"
conf "$dir/fails.sh" 30 > "$dir/fails.yaml"
run fails || fail "amfid exit $? (failing notice)"
grep -q "alert notice: .*fails.sh exited 3" "$dir/amfid.log" || fail "exit status 3 not logged"
[ "$(metric 'amfi_notices_total{result="failed"}')" -ge 1 ] || fail "metrics: failure not counted"
echo "failing notice: exit status 3 logged and counted"

# 4. refused at load
printf 'x' > "$dir/plain.txt"
for c in "$dir/missing.sh" "$dir/plain.txt" "relative/notify.sh"; do
  conf "$c" 30 > "$dir/bad.yaml"
  line=$(grep -n "^  command: " "$dir/bad.yaml" | cut -d: -f1)
  "$amfid" --config "$dir/bad.yaml" --check-config > /dev/null 2> "$dir/bad.log" && fail "$c accepted"
  grep -q "^amfid: $dir/bad.yaml:$line: alerts.command: " "$dir/bad.log" || fail "refusal of $c: $(cat "$dir/bad.log")"
done
echo "missing, not executable and relative commands refused with FILE:LINE"

# 6. the metrics file on a read-only mount
mkdir "$dir/ro"
conf "$dir/fails.sh" 30 | sed "s|^  textfile: .*|  textfile: $dir/ro/amfid.prom|" > "$dir/ro.yaml"
grep -q "^  textfile: $dir/ro/amfid.prom" "$dir/ro.yaml" || fail "the test's metrics path did not apply"
unshare --mount sh -c 'mount --make-rprivate / 2>/dev/null; mount -t tmpfs -o ro,size=64k tmpfs "$1/ro" &&
  "$2" --config "$1/ro.yaml" --db "$1/ro.db" --lcm-url "file://$1/t.lcmlog?speed=0" 2> "$1/amfid.log"' \
  sh "$dir" "$amfid" || fail "amfid exit $? (metrics on a read-only mount)"
n=$(grep -c "metrics: cannot write $dir/ro/amfid.prom: Read-only file system" "$dir/amfid.log")
[ "$n" -eq 1 ] || fail "the write error logged $n times, not once"
[ "$(q ro "SELECT count(*) FROM passages")" -eq 60 ] || fail "$(q ro "SELECT count(*) FROM passages") of 60 passages"
[ ! -e "$dir/ro/amfid.prom" ] || fail "a metrics file outside the namespace's mount"
echo "metrics on a read-only mount: the write error logged once, all 60 passages stored, exit 0"

# 7. what the command inherits of amfid's, and a stop with notices hanging
[ -n "${5:-}" ] || { echo "no ALERT_PROBE: case 7 skipped"; exit 0; }
probe=$5
conf "$probe" 600 | sed "s/^  command_stop_wait_s: 10 /  command_stop_wait_s: 2 /" > "$dir/probe.yaml"
grep -q "^  command_stop_wait_s: 2 " "$dir/probe.yaml" || fail "the test's command_stop_wait_s did not apply"
run probe || fail "amfid exit $? (probe)"
n=0
for f in "$dir"/probe.db.probe.*; do
  [ -f "$f" ] || fail "the probe never ran"
  n=$((n + 1))
  grep -qx "fds 0 1 2" "$f" || fail "the alert command inherited amfid's descriptors: $(head -1 "$f")"
  ign=$(sed -n 's/^sigign //p' "$f") blk=$(sed -n 's/^sigblk //p' "$f")
  # signals 32 and 33 are glibc's own: posix_spawn leaves them ignored
  [ $((0x$ign & ~(3 << 31))) -eq 0 ] || fail "the alert command starts with signals ignored (SigIgn $ign; SIGPIPE is 0x1000)"
  [ $((0x$blk)) -eq 0 ] || fail "the alert command starts with signals blocked (SigBlk $blk)"
  set -- $(sed -n 's/^pid \([0-9]*\) pgrp \([0-9]*\)$/\1 \2/p' "$f")
  [ "${1:-x}" = "${2:-y}" ] || fail "the alert command does not lead its process group: $(grep '^pid' "$f")"
done
rm -f "$dir"/probe.db.probe.*
touch "$dir/probe.db.hang" # the probe now hangs, with a grandchild ignoring SIGTERM
t0=$(date +%s)
rm -f "$dir/probe.db"
timeout 120 "$amfid" --config "$dir/probe.yaml" --db "$dir/probe.db" \
  --lcm-url "file://$dir/t.lcmlog?speed=0" 2> "$dir/amfid.log" || fail "amfid exit $? (hanging notices)"
t1=$(date +%s)
grep -q "still running after 2 s (alerts.command_stop_wait_s), killed" "$dir/amfid.log" ||
  fail "no kill at stop logged"
[ "$(q probe "SELECT count(*) FROM passages")" -eq 60 ] || fail "$(q probe "SELECT count(*) FROM passages") of 60 passages"
[ $((t1 - t0)) -lt 30 ] || fail "amfid took $((t1 - t0)) s to run and stop with notices hanging"
g=0
for f in "$dir"/probe.db.probe.*; do
  p=$(sed -n 's/^grandchild //p' "$f")
  [ -n "$p" ] || continue
  g=$((g + 1))
  i=0
  while kill -0 "$p" 2> /dev/null && [ "$(awk '{ print $3 }' "/proc/$p/stat" 2> /dev/null)" != Z ]; do
    i=$((i + 1)); [ $i -lt 100 ] || { kill -9 "$p"; fail "grandchild $p outlived amfid's stop"; }; sleep 0.05
  done
done
[ "$g" -ge 1 ] || fail "no hanging probe started a grandchild"
echo "probe: $n notices saw descriptors 0-2 only, no ignored or blocked signal, their own group; with notices hanging amfid ran and stopped in $((t1 - t0)) s, $g grandchildren killed"

