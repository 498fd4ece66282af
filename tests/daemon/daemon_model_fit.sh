#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid's model_mismatch and natfreq alerts (docs/indicators.md section 10)
# on LCM's UDP multicast inside a private network namespace, the shipped
# amfid.yaml with test sizes (calc_rate_hz 1000, the natural frequency's
# baseline of 30 estimates):
#   1. the design bridge itself, the site's climate from mid-January
#      (sim_publisher --environment site, 1 s of data 2000 s of site time:
#      12 site days of frost and thaw, the modulus following the deck),
#      130 vehicles 4 s apart, 10 % stiffness lost from vehicle 100: every
#      passage has a model fit; before the loss the model fits (median fit
#      ratio below 0.05) and neither alert is raised, although the deck
#      moves the raw f1 and the weights; after it the natfreq alert is raised
#      within 20 passages and model_mismatch within 40 (the damage);
#   2. the main job's scenario shortened (scripts/main.sh: no climate, so
#      nothing compensated: the natfreq alert on the raw f1 against the mean
#      of the first 30 estimates; vehicles 2 s apart, 20 % stiffness lost
#      from vehicle 50 of 75): natfreq raised within 15 passages of the
#      loss, neither alert before it;
#   3. an as-built bridge whose bearings hold 2 EI/L of rotation (seized:
#      f1 +30 %, GVW −38 % uncommissioned), 60 vehicles, no climate:
#      model_mismatch (warning) raised once within them, logged, stored,
#      published on the alert channel; the restart after finds it open and
#      does not raise it again.
# Usage: daemon_model_fit.sh AMFID SIM_PUBLISHER CONFIG AS_BUILT_DIR
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 config=$3 cases=$4
fail() { echo "FAIL: $*"; tail -20 "$dir/amfid.log"; exit 1; }
q() { sqlite3 "$dir/s.db" "$1"; }

sed -e "s|^    baseline_n: 200 .*|    baseline_n: 30|" \
    -e "s|^  calc_rate_hz: 5000 .*|  calc_rate_hz: 1000|" \
    -e "s/^    deck_max_rate_c_per_min: 2 /    deck_max_rate_c_per_min: 1000000 /" "$config" > "$dir/amfid.yaml"
grep -q "^    baseline_n: 30" "$dir/amfid.yaml" || fail "no natural_frequency.baseline_n in $config"
grep -q "^  calc_rate_hz: 1000" "$dir/amfid.yaml" || fail "no solver.calc_rate_hz in $config"

# ---- 1. the design bridge, a climate, then a 10 % loss ---------------------
amfid_start "$amfid" "$dir/amfid.yaml"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 130 --headway 4 --speedup 40 --seed 3 \
  --environment site --time-compression 2000 --environment-period 0.5 \
  --damage 0.1 --damage-step-at 100 2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop
ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok'")
[ "$ok" -ge 125 ] || fail "$ok ok passages of 130"
fitted=$(q "SELECT count(*) FROM passages WHERE fit_ratio IS NOT NULL")
[ "$fitted" -ge 120 ] || fail "$fitted passages with a model fit"
# before the loss (vehicles 1 .. 97: the simulator switches the bridge during
# vehicle 99's approach)
step=$(q "SELECT utime FROM passages WHERE vehicle_id = 98")
med=$(q "SELECT fit_ratio FROM passages WHERE fit_ratio IS NOT NULL AND utime < $step
         ORDER BY fit_ratio LIMIT 1 OFFSET (SELECT count(*) / 2 FROM passages
         WHERE fit_ratio IS NOT NULL AND utime < $step)")
echo "median fit ratio before the loss: $med; deck $(q "SELECT printf('%.1f .. %.1f', min(deck_c), max(deck_c)) FROM passages WHERE utime < $step") °C"
awk -v m="$med" 'BEGIN { exit !(m < 0.05) }' || fail "the design model does not fit its own bridge: median $med"
comp=$(q "SELECT count(*) FROM passages WHERE f1_comp_hz IS NOT NULL AND utime < $step")
[ "$comp" -ge 40 ] || fail "$comp compensated frequencies before the loss"
early=$(q "SELECT count(*) FROM alerts WHERE raised = 1 AND kind IN ('model_mismatch', 'natfreq') AND utime < $step")
[ "$early" = 0 ] || fail "raised before the loss: $(q "SELECT kind, message FROM alerts")"
after() { # ok passages from vehicle 98 on up to the first raise of $1; empty if none
  q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime >= $step AND utime <=
     (SELECT min(utime) FROM alerts WHERE kind = '$1' AND raised = 1)
     HAVING EXISTS (SELECT 1 FROM alerts WHERE kind = '$1' AND raised = 1)"
}
nf=$(after natfreq); mm=$(after model_mismatch)
echo "after the loss: natfreq raised at passage ${nf:-none}, model_mismatch at ${mm:-none}"
[ -n "$nf" ] && [ "$nf" -le 20 ] || fail "natfreq not raised within 20 passages of the loss"
[ -n "$mm" ] && [ "$mm" -le 40 ] || fail "model_mismatch not raised within 40 passages of the loss"
[ "$(q "SELECT level FROM alerts WHERE kind = 'natfreq'")" = warning ] || fail "natfreq not a warning"
grep -q "ALERT natfreq (warning)" "$dir/amfid.log" || fail "natfreq not in the journal"

# ---- 2. the main job's scenario, shortened: no deck temperature -------------
rm -f "$dir"/s.db*
amfid_start "$amfid" "$dir/amfid.yaml"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 75 --headway 2 --speedup 25 --seed 1 \
  --damage 0.2 --damage-step-at 50 2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop
step=$(q "SELECT utime FROM passages WHERE vehicle_id = 48")
[ -n "$step" ] || fail "no passage of vehicle 48"
early=$(q "SELECT count(*) FROM alerts WHERE raised = 1 AND kind IN ('model_mismatch', 'natfreq') AND utime < $step")
[ "$early" = 0 ] || fail "main job: raised before the loss: $(q "SELECT kind, message FROM alerts")"
nf=$(after natfreq)
echo "main job, shortened: natfreq raised at passage ${nf:-none} after the loss" \
     "($(q "SELECT count(*) FROM passages WHERE f1_hz IS NOT NULL") of 75 with an f1, none compensated:" \
     "$(q "SELECT count(*) FROM passages WHERE f1_comp_hz IS NOT NULL"))"
[ -n "$nf" ] && [ "$nf" -le 15 ] || fail "main job: natfreq not raised within 15 passages of the loss"
grep -q "uncompensated (no deck temperature)" "$dir/amfid.log" || fail "main job: not the raw mode"

# ---- 3. seized bearings, uncommissioned -------------------------------------
rm -f "$dir"/s.db*
amfid_start "$amfid" "$dir/amfid.yaml"
lcm-logger -c AMFI_ALERT -f "$dir/alerts.log" > "$dir/logger.log" 2>&1 &
lpid=$!; pids="$pids $lpid"
sleep 0.3
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 60 --headway 4 --speedup 40 --seed 4 \
  --as-built "$cases/bearings-2.yaml" 2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop
kill -INT $lpid; wait $lpid
mm=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime <=
        (SELECT min(utime) FROM alerts WHERE kind = 'model_mismatch' AND raised = 1)
        HAVING EXISTS (SELECT 1 FROM alerts WHERE kind = 'model_mismatch' AND raised = 1)")
echo "seized bearings: model_mismatch raised at ok passage ${mm:-none} (mean fit ratio" \
     "$(q "SELECT printf('%.3f', avg(fit_ratio)) FROM passages"))"
[ -n "$mm" ] && [ "$mm" -le 60 ] || fail "model_mismatch not raised within 60 passages"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'model_mismatch'")" = 1 ] || fail "not one model_mismatch event"
[ "$(q "SELECT level FROM alerts WHERE kind = 'model_mismatch'")" = warning ] || fail "not a warning"
grep -q "ALERT model_mismatch (warning)" "$dir/amfid.log" || fail "model_mismatch not in the journal"
[ -s "$dir/alerts.log" ] || fail "nothing published on AMFI_ALERT"
grep -a -q model_mismatch "$dir/alerts.log" || fail "model_mismatch not published"
# a restart: the alert stays open, not raised twice
amfid_start "$amfid" "$dir/amfid.yaml"
timeout 300 "$sim" --dt 2.5e-4 --allow-production-bus --vehicles 15 --headway 4 --speedup 40 --seed 6 \
  --start-utime $(( $(q "SELECT max(utime) FROM passages") + 10000000 )) \
  --as-built "$cases/bearings-2.yaml" 2> "$dir/sim.log" || fail "sim_publisher exited $?"
sleep 1
amfid_stop
grep -q "model fit: 25 passages from the store; the model_mismatch alert is open" "$dir/amfid.log" ||
  fail "the restart did not restore the model fit"
[ "$(q "SELECT count(*) FROM alerts WHERE kind = 'model_mismatch'")" = 1 ] || fail "the restart raised again"
echo "daemon_model_fit: ok"
