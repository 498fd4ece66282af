#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid when its store cannot be written (issue 9, finding 5), in a private
# mount namespace on a small tmpfs (nothing is mounted outside it):
# (1) the disk fills while amfid writes (a log replayed at 4x through
#     file://), then space returns: the passages are held and retried, the
#     store_degraded alert is raised and cleared, every vehicle ends as a row,
#     integrity_check ok, exit 0;
# (2) a store left with its WAL (amfid killed with -9) on a mount that is now
#     read-only: amfid refuses to start (non-zero exit, never "running");
# (3) the disk stays full until SIGTERM: after up to 20 s of retries every
#     held passage is logged as NOT STORED and amfid exits 1 (it used to
#     give up silently, exit 0, when its retry wait ran past the 20 s).
# Usage: daemon_store_full.sh AMFID SIM_PUBLISHER CONFIG
set -u
amfid=$1 sim=$2 config=$3
command -v unshare >/dev/null || { echo "no unshare"; exit 1; }
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
"$sim" --dt 2.5e-4 --lcm-url none --log "$dir/traffic.log" --vehicles 16 --headway 2 --speedup max --seed 4 \
  2> "$dir/sim.log" || { echo "FAIL: sim_publisher"; exit 1; }
unshare --mount sh -s "$amfid" "$config" "$dir" <<'INNER'
set -u
amfid=$1 config=$2 dir=$3
fail() { echo "FAIL: $*"; tail -25 "$dir/amfid.log" 2>/dev/null; exit 1; }
mount --make-rprivate / 2>/dev/null
mkdir -p "$dir/mnt" && mount -t tmpfs -o size=3m tmpfs "$dir/mnt" || fail "tmpfs"
# (1) fill and free while amfid writes
"$amfid" --config "$config" --db "$dir/mnt/a.db" --lcm-url "file://$dir/traffic.log?speed=4" \
  2> "$dir/amfid.log" &
pid=$!
for i in $(seq 100); do grep -q running "$dir/amfid.log" && break; sleep 0.1; done
sleep 2
dd if=/dev/zero of="$dir/mnt/filler" bs=64k 2>/dev/null   # until the disk is full
full=$(df -k "$dir/mnt" | awk 'NR == 2 {print $4}')
sleep 3
rm -f "$dir/mnt/filler"
wait $pid; rc=$?
[ "$rc" -eq 0 ] || fail "amfid exit status $rc"
grep -q "ALERT store_degraded" "$dir/amfid.log" || fail "no store_degraded alert (disk free $full kB when full)"
grep -q "alert cleared store_degraded" "$dir/amfid.log" || fail "the store_degraded alert was not cleared"
al=$(sqlite3 "$dir/mnt/a.db" "SELECT group_concat(raised, '') FROM (SELECT raised FROM alerts WHERE kind = 'store_degraded' ORDER BY id)")
[ "$al" = 10 ] || fail "the alerts table should hold the store_degraded raise and clear (raised column '10'), got '$al'"
n=$(sqlite3 "$dir/mnt/a.db" "SELECT count(*) FROM passages")
[ "$n" -eq 16 ] || fail "$n of 16 vehicles stored"
[ "$(sqlite3 "$dir/mnt/a.db" "PRAGMA integrity_check")" = ok ] || fail "integrity_check"
grep -q "LOST:\|NOT STORED" "$dir/amfid.log" && fail "a passage was lost"
peak=$(sed -n 's/.*the held passages are stored (peak \([0-9]*\)).*/\1/p' "$dir/amfid.log" | sort -n | tail -1)
echo "disk full then freed: degraded and recovered, 16 of 16 stored (held at most ${peak:-?}), integrity ok"
# (2) a leftover WAL on a read-only mount: refuse to start
"$amfid" --config "$config" --db "$dir/mnt/b.db" --lcm-url "file://$dir/traffic.log?speed=1" \
  2> "$dir/b.log" &
pid=$!
for i in $(seq 100); do grep -q running "$dir/b.log" && break; sleep 0.1; done
sleep 1
kill -9 $pid; wait $pid 2>/dev/null
[ -s "$dir/mnt/b.db-wal" ] || fail "no WAL left by kill -9 (test set-up)"
mount -o remount,ro "$dir/mnt" || fail "remount read-only"
"$amfid" --config "$config" --db "$dir/mnt/b.db" --lcm-url "file://$dir/traffic.log?speed=0" \
  2> "$dir/amfid.log"; rc=$?
[ "$rc" -ne 0 ] || fail "amfid started on a store it cannot write (exit 0)"
grep -q running "$dir/amfid.log" && fail "amfid reported running on a read-only store"
echo "read-only store with a leftover WAL: refused (exit $rc): $(grep -m1 store "$dir/amfid.log" | sed 's/^<[0-9]>//')"
mount -o remount,rw "$dir/mnt" || fail "remount read-write"
rm -f "$dir/mnt/b.db"*
# (3) full until the end
"$amfid" --config "$config" --db "$dir/mnt/c.db" --lcm-url "file://$dir/traffic.log?speed=4" \
  2> "$dir/c.log" &
pid=$!
for i in $(seq 100); do grep -q running "$dir/c.log" && break; sleep 0.1; done
sleep 2
dd if=/dev/zero of="$dir/mnt/filler" bs=64k 2>/dev/null
for i in $(seq 200); do grep -q "ALERT store_degraded" "$dir/c.log" && break; sleep 0.1; done
grep -q "ALERT store_degraded" "$dir/c.log" || { kill -9 $pid; fail "(3) the store never refused"; }
t0=$(date +%s)
kill -TERM $pid; wait $pid; rc=$?
t1=$(date +%s)
[ "$rc" -eq 1 ] || fail "(3) amfid exit status $rc with passages it could not store, expected 1"
stored=$(sqlite3 "$dir/mnt/c.db" "SELECT count(*) FROM passages" 2>/dev/null || echo 0)
lost=$(grep -c "NOT STORED" "$dir/c.log")
[ "$lost" -ge 1 ] || fail "(3) no NOT STORED line"
lostc=$(sed -n 's/.*stopped: .* \([0-9]*\) not stored,.*/\1/p' "$dir/c.log")
[ "$lostc" = "$lost" ] || fail "(3) $lost NOT STORED lines, stop line says '$lostc'"
[ $((t1 - t0)) -le 40 ] || fail "(3) the stop took $((t1 - t0)) s"
echo "disk full until SIGTERM: $stored stored, $lost logged NOT STORED and counted, exit 1 after $((t1 - t0)) s"
rm -f "$dir/mnt/filler"
umount "$dir/mnt"
INNER
