#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid corrects every vehicle as the site file's detector: section says
# (detector.clock_offset_s, detector.speed_scale: what commissioning found),
# where the vehicle message is admitted, as amfi-solve does. On the bus in a
# private network namespace, sim_publisher simulating a detector as built
# (--as-built):
#  1. its clock 20 ms late; amfid without a detector: section weighs the
#     passages about 30 % light; the same traffic with
#     detector: {clock_offset_s: 0.02} within 2 % of the truth;
#  2. its clock 20 ms late and its speeds and spacings 3 % high; amfid with
#     detector: {clock_offset_s: 0.02, speed_scale: 1.03} within 2 % of the
#     truth, the stored row weighed with the true speed (speed_mps) and
#     keeping the detector's (speed_given_mps), the stored entry time on the
#     accelerometers' clock (the truth's utime).
# Usage: daemon_detector.sh AMFID SIM_PUBLISHER CONFIG
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -20 "$f"; done; exit 1; }
N=4

sed -e "s/^  simulation: false .*/  simulation: true/" "$config" > "$dir/design.yaml"
grep -q "^  simulation: true$" "$dir/design.yaml" || fail "daemon.simulation did not apply"
grep -q "^detector:" "$dir/design.yaml" && fail "the example configuration has a detector: section"
printf 'detector:\n  clock_offset_s: 0.02\n' > "$dir/late.yaml"
printf 'detector:\n  clock_offset_s: 0.02\n  speed_scale: 1.03\n  spacing_scale: 1.03\n' \
  > "$dir/late_fast.yaml"
{ cat "$dir/design.yaml"; printf 'detector:\n  clock_offset_s: 0.02\n'; } > "$dir/site_late.yaml"
{ cat "$dir/design.yaml"; printf 'detector:\n  clock_offset_s: 0.02\n  speed_scale: 1.03\n'; } \
  > "$dir/site_late_fast.yaml"

# run NAME SITE AS_BUILT: amfid on SITE, sim_publisher's traffic through the
# AS_BUILT detector (the same vehicles each run); the store kept as NAME.db
run() {
  amfid_start "$amfid" "$2"
  timeout 120 "$sim" --dt 2.5e-4 --allow-production-bus --config "$dir/design.yaml" --as-built "$3" --vehicles $N --headway 3 \
    --speedup 10 --seed 7 2> "$dir/sim_$1.log" || fail "$1: sim_publisher exited $?"
  sleep 1
  amfid_stop
  grep -q "runtime error\|AddressSanitizer\|LeakSanitizer" "$dir/amfid.log" &&
    fail "$1: a sanitizer reported"
  cp "$dir/amfid.log" "$dir/amfid_$1.log"
  mv "$dir/s.db" "$dir/$1.db"
  rm -f "$dir/s.db-wal" "$dir/s.db-shm"
  rows=$(q "$1" "SELECT count(*) FROM passages")
  [ "$rows" -eq $N ] || fail "$1: expected $N passage rows, got $rows"
  ok=$(q "$1" "SELECT count(*) FROM passages WHERE status = 'ok'")
  [ "$ok" -eq $N ] || fail "$1: only $ok of $N passages ok"
}
q() { sqlite3 "$dir/$1.db" "$2"; }
# err NAME AGG: AGG over the ok passages of the GVW error against the truth
err() { q "$1" "SELECT $2(p.gvw_kg / t.gvw_kg - 1) FROM passages p JOIN truth t USING (vehicle_id)
                WHERE p.status = 'ok'"; }
pct() { awk -v e="$1" 'BEGIN { printf "%+.2f %%", 100 * e }'; }

run none "$dir/design.yaml" "$dir/late.yaml"
run late "$dir/site_late.yaml" "$dir/late.yaml"
run late_fast "$dir/site_late_fast.yaml" "$dir/late_fast.yaml"
grep -q "detector: entry times corrected by detector.clock_offset_s 0.02 s" "$dir/amfid_late.log" ||
  fail "amfid does not log the detector's corrections in force"

n_mean=$(err none avg) n_lo=$(err none min) n_hi=$(err none max)
l_lo=$(err late min) l_hi=$(err late max)
f_lo=$(err late_fast min) f_hi=$(err late_fast max)
echo "detector 20 ms late, no detector: section: GVW error mean $(pct "$n_mean"), $(pct "$n_lo") .. $(pct "$n_hi")"
echo "detector 20 ms late, clock_offset_s 0.02: $(pct "$l_lo") .. $(pct "$l_hi")"
echo "detector 20 ms late and 3 % fast, clock_offset_s 0.02, speed_scale 1.03: $(pct "$f_lo") .. $(pct "$f_hi")"
awk -v a="$n_lo" -v b="$n_hi" 'BEGIN { exit !(a > -0.45 && b < -0.15) }' ||
  fail "uncorrected, the 20 ms late detector should weigh about 30 % light ($(pct "$n_lo") .. $(pct "$n_hi"))"
for r in "$l_lo $l_hi" "$f_lo $f_hi"; do
  set -- $r
  awk -v a="$1" -v b="$2" 'BEGIN { exit !(a > -0.02 && b < 0.02) }' ||
    fail "corrected passages off the truth by more than 2 % ($(pct "$1") .. $(pct "$2"))"
done
# the stored row of the 3 % fast detector: weighed with the true speed, the
# detector's own speed kept, the entry time on the accelerometers' clock
given=$(q late_fast "SELECT max(abs(p.speed_given_mps / t.speed_true_mps - 1.03)) FROM passages p
                     JOIN truth t USING (vehicle_id)")
used=$(q late_fast "SELECT max(abs(p.speed_mps / t.speed_true_mps - 1)) FROM passages p
                    JOIN truth t USING (vehicle_id)")
entry=$(q late_fast "SELECT max(abs(p.utime - t.utime)) FROM passages p JOIN truth t USING (vehicle_id)")
raw=$(q none "SELECT min(p.utime - t.utime) FROM passages p JOIN truth t USING (vehicle_id)")
echo "stored: speed_given_mps / truth - 1.03 <= $given, speed_mps / truth - 1 <= $used, |utime - truth| <= $entry µs (uncorrected: $raw µs late)"
awk -v e="$given" 'BEGIN { exit !(e < 1e-6) }' || fail "speed_given_mps is not the detector's speed (off by $given)"
awk -v e="$used" 'BEGIN { exit !(e < 1e-6) }' || fail "speed_mps is not the corrected speed (off by $used)"
[ "$entry" -le 1 ] || fail "the stored entry time is $entry µs off the truth's"
[ "$raw" -ge 19999 ] || fail "uncorrected, the stored entry should be the detector's, 20 ms late ($raw µs)"
echo "daemon_detector: ok"
