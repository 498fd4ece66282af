#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# daemon_reload_keys.sh: every configuration key the key tables mark live
# (amfi_config_key.live: amfid.yaml(5) "applies at once on SIGHUP") takes
# effect on SIGHUP without a restart. One amfid on LCM's UDP multicast inside
# a private network namespace (tests/common/bus_prologue.sh); for each live
# key, in turn: the key alone changed in the site file, SIGHUP, the reload
# acknowledged in the log, then bus messages (lcm_reload, lcm-logplayer) that
# only the new value treats as seen:
#   solver.lambda, .lambda_ref_rate_hz, .lcurve.*: the same vehicle's data
#       replayed (later in data time) is solved to another λ or GVW, where
#       two replays before any change gave the same
#   detector.*: the same vehicle's data replayed is weighed otherwise (its
#       entry time or speed corrected by the new value)
#   daemon.channels.*: passages, indicators, alerts, status on the new
#       channel (lcm-logger's record)
#   daemon.status_period_s: status messages at the new period
#   daemon.max_wait_s: a window whose data has a hole is stored as gap once
#       the data time is the new wait past its end
#   daemon.environment_max_skew_s, daemon.intake.*: a message only the new
#       bound refuses is refused (the store's refusal summaries or the
#       passage row name the new value), a rate or burst counted at the new
#       one, readings thinned at the new interval, summaries at the new period
# The keys come from the loader's table (test_config_man --print): a live key
# without a case here fails by name, and so does a case whose key is not live.
# Usage: daemon_reload_keys.sh AMFID SIM_PUBLISHER LCM_RELOAD TEST_CONFIG_MAN
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
amfid=$1 sim=$2 tool=$3 keys=$4
key=""
fail() {
  echo "FAIL: ${key:+$key: }$*"
  for f in "$dir"/amfid.log "$dir"/player.log; do [ -f "$f" ] && { echo "--- $f"; tail -25 "$f"; }; done
  exit 1
}
q() { sqlite3 "$dir/s.db" "PRAGMA busy_timeout = 5000; $1" | tail -n +2; }
# wait_until DESCRIPTION COMMAND...: until COMMAND succeeds (up to 30 s)
wait_until() {
  _what=$1; shift
  _i=0; until "$@"; do
    _i=$((_i + 1)); [ $_i -lt 300 ] || fail "not seen within 30 s: $_what"
    kill -0 $apid 2>/dev/null || fail "amfid exited"
    sleep 0.1
  done
}
nonzero() { r=$(q "$1"); [ -n "$r" ] && [ "$r" != 0 ]; }

# ---- the live keys: the loader's table against this script's cases --------
"$keys" --print > "$dir/keys.txt" || fail "test_config_man --print"
sed -n 's/^\*\([^*]*\)\* (.*; applies at once on SIGHUP)$/\1/p' "$dir/keys.txt" > "$dir/live.txt"
[ -s "$dir/live.txt" ] || fail "no live key in the key table"
# The order of the cases (traffic first: the indicator needs its baseline;
# max_wait_s last: on a tracker that ignores it, its window blocks the rest).
ORDER="daemon.channels.passage daemon.channels.indicator daemon.channels.alert
  solver.lambda solver.lambda_ref_rate_hz solver.lcurve.lo solver.lcurve.hi
  solver.lcurve.per_decade solver.lcurve.refine detector.clock_offset_s detector.speed_scale
  daemon.status_period_s daemon.channels.status
  daemon.intake.summary_period_s daemon.intake.vehicle_ahead_s daemon.intake.min_speed_mps
  daemon.intake.max_length_m daemon.intake.calibration_sources daemon.intake.calibration_max_kg
  daemon.intake.calibration_min_kg daemon.intake.burst_s daemon.intake.vehicles_per_s
  daemon.intake.truth_per_s daemon.intake.accel_margin
  daemon.intake.environment_min_interval_s daemon.intake.deck_max_rate_c_per_min
  daemon.environment_max_skew_s daemon.intake.environment_per_s daemon.max_wait_s"
missing=""
for k in $(cat "$dir/live.txt"); do
  case " $(echo $ORDER) " in *" $k "*) ;; *) missing="$missing $k" ;; esac
done
[ -z "$missing" ] || fail "live key(s) without a reload case in $0:$missing"
for k in $ORDER; do
  grep -qx "$k" "$dir/live.txt" || fail "$k has a reload case but the key table does not mark it live"
done

# ---- the site file: every live key from a variable -------------------------
var() { echo "v_$1" | tr '.' '_'; }
set_key() { eval "$(var "$1")=\$2"; }
get_key() { eval "echo \"\$$(var "$1")\""; }
set_key solver.lambda 7.94e-9
set_key solver.lambda_ref_rate_hz 5000
set_key solver.lcurve.lo 1e-12
set_key solver.lcurve.hi 1e-10
set_key solver.lcurve.per_decade 2
set_key solver.lcurve.refine 2
set_key detector.clock_offset_s 0
set_key detector.speed_scale 1
set_key daemon.channels.passage RL_PASSAGE
set_key daemon.channels.indicator RL_INDICATOR
set_key daemon.channels.alert RL_ALERT
set_key daemon.channels.status RL_STATUS
set_key daemon.status_period_s 2
set_key daemon.max_wait_s 3600
set_key daemon.environment_max_skew_s 864000
set_key daemon.intake.vehicle_ahead_s 120
set_key daemon.intake.min_speed_mps 2
set_key daemon.intake.max_length_m 360
set_key daemon.intake.accel_margin 4
set_key daemon.intake.vehicles_per_s 5
set_key daemon.intake.environment_per_s 10
set_key daemon.intake.truth_per_s 50
set_key daemon.intake.burst_s 30
set_key daemon.intake.summary_period_s 3600
set_key daemon.intake.environment_min_interval_s 0
set_key daemon.intake.deck_max_rate_c_per_min 2
set_key daemon.intake.calibration_sources "sim_publisher,rig"
set_key daemon.intake.calibration_min_kg 3500
set_key daemon.intake.calibration_max_kg 60000
write_config() {
  cat > "$dir/amfid.yaml.tmp" <<EOF
site:
  id: reload-keys
sensors: # two: one may fall silent while the other sends (daemon.max_wait_s)
  - {id: 0, at_m: 7}
  - {id: 1, at_m: 13}
solver:
  calc_rate_hz: 1000 # the solves (an L-curve for each λ case) cheap
  lambda: $v_solver_lambda
  lambda_ref_rate_hz: $v_solver_lambda_ref_rate_hz
  lcurve:
    lo: $v_solver_lcurve_lo
    hi: $v_solver_lcurve_hi
    per_decade: $v_solver_lcurve_per_decade
    refine: $v_solver_lcurve_refine
detector:
  clock_offset_s: $v_detector_clock_offset_s
  speed_scale: $v_detector_speed_scale
daemon:
  channels:
    passage: $v_daemon_channels_passage
    indicator: $v_daemon_channels_indicator
    alert: $v_daemon_channels_alert
    status: $v_daemon_channels_status
  workers: 2
  simulation: true # the truth channel is subscribed (daemon.intake.truth_per_s)
  status_period_s: $v_daemon_status_period_s
  max_wait_s: $v_daemon_max_wait_s
  environment_max_skew_s: $v_daemon_environment_max_skew_s
  indicators:
    window: 10
    every: 5
    baseline_n: 10
    mean_shift: on
    mean_alert_ratio: 1.3
    mean_alert_p: 1
    raise_after: 1
  intake:
    vehicle_ahead_s: $v_daemon_intake_vehicle_ahead_s
    min_speed_mps: $v_daemon_intake_min_speed_mps
    max_length_m: $v_daemon_intake_max_length_m
    accel_margin: $v_daemon_intake_accel_margin
    vehicles_per_s: $v_daemon_intake_vehicles_per_s
    environment_per_s: $v_daemon_intake_environment_per_s
    truth_per_s: $v_daemon_intake_truth_per_s
    burst_s: $v_daemon_intake_burst_s
    summary_period_s: $v_daemon_intake_summary_period_s
    environment_min_interval_s: $v_daemon_intake_environment_min_interval_s
    deck_max_rate_c_per_min: $v_daemon_intake_deck_max_rate_c_per_min
    calibration_sources: $v_daemon_intake_calibration_sources
    calibration_min_kg: $v_daemon_intake_calibration_min_kg
    calibration_max_kg: $v_daemon_intake_calibration_max_kg
EOF
  # whole, never half a file (amfid may read it any time)
  mv "$dir/amfid.yaml.tmp" "$dir/amfid.yaml"
}
# reload KEY VALUE: the one key changed in the file, SIGHUP, acknowledged
applied=0
reload() {
  key=$1
  [ "$(get_key "$1")" != "$2" ] || fail "the case does not change the value ($2)"
  set_key "$1" "$2"
  write_config
  grep -q "^ *$(echo "$1" | sed 's/.*\.//'): $2\$" "$dir/amfid.yaml" || fail "$2 not written"
  applied=$((applied + 1))
  kill -HUP $apid
  wait_until "reload $applied applied" sh -c \
    "[ \$(grep -c 'reload: configuration .* applied' '$dir/amfid.log') -ge $applied ]"
  ! grep -q "reload: the new configuration is refused" "$dir/amfid.log" ||
    fail "the new configuration was refused: $(grep -B2 refused "$dir/amfid.log" | head -3)"
  done_keys="$done_keys $1"
}
done_keys=""

# ---- the bus messages -------------------------------------------------------
# Traffic: 40 vehicles 4 s apart (vehicle k enters at t0 + 4 k + 1.58 s), the
# bridge half as stiff from vehicle 28 on (the indicator's mean-shift alert).
write_config
"$sim" --dt 2.5e-4 --config "$dir/amfid.yaml" --lcm-url none --log "$dir/sim.log" --vehicles 40 --headway 4 --speedup max --seed 5 \
  --damage 0.5 --damage-step-at 27 2> "$dir/sim.err" || fail "sim_publisher: $(tail -2 "$dir/sim.err")"
t0=$("$tool" t0 "$dir/sim.log") || fail "lcm_reload t0"
# seconds (data time after t0) and µs, in awk's doubles (exact below 2^53)
fcalc() { awk "BEGIN { printf \"%.6f\", $1 }"; }
icalc() { awk "BEGIN { printf \"%.0f\", $1 }"; }
n=0 # logs written, each by its own producer (a signer's sequence is its own)
play() { lcm-logplayer -s 20 "$1" >> "$dir/player.log" 2>&1 || fail "lcm-logplayer $1"; }
cur=0 # seconds after t0 up to which data time was sent
# traffic_to B: the simulator's stream up to vehicle B's window end (4 B + 5.5 s)
traffic_to() {
  n=$((n + 1)); end=$(fcalc "4 * $1 + 5.5")
  [ "$1" -lt 40 ] || end=166.1
  "$tool" segment "$dir/sim.log" "$dir/m$n.log" "reload.$n" "$cur" "$end" 0 0 || fail "segment"
  play "$dir/m$n.log"; cur=$end
  wait_until "passages of vehicles 1 .. $1 stored" nonzero \
    "SELECT count(*) = $1 FROM passages WHERE vehicle_id BETWEEN 1 AND $1"
}
# replay K ID_ADD [HOLE_AFTER_ENTRY_S HOLE_LEN_S]: vehicle K's 5.5 s of data
# (from 1.58 s before it enters) again at the current data time, its id +
# ID_ADD; sensor 1 silent over the hole
replay() {
  n=$((n + 1)); from=$((4 * $1)); shift_s=$(fcalc "$cur - $from")
  hole=""; [ $# -ge 4 ] && hole="$(fcalc "$from + 1.58 + $3") $4"
  "$tool" segment "$dir/sim.log" "$dir/m$n.log" "reload.$n" $from "$(fcalc "$from + 5.5")" \
    "$shift_s" "$2" $hole || fail "segment"
  play "$dir/m$n.log"; cur=$(fcalc "$cur + 5.5")
}
now_us() { icalc "$t0 + $cur * 1000000"; }
seq_now() { icalc "$cur * 10"; } # 100-sample blocks at 1000 Hz
# (advance and the accel probe: sensor 0 only)
probe() { # MODE ARGS...: one of lcm_reload's messages, played
  n=$((n + 1)); _m=$1; shift
  "$tool" "$_m" "$dir/m$n.log" "reload.$n" "$@" || fail "lcm_reload $_m"
  play "$dir/m$n.log"
}
# advance S: S seconds of (quiet) accel data of sensor 0 at the current data time
advance() { probe accel "$(now_us)" "$(seq_now)" "$(icalc "$1 * 10")" 1000
  cur=$(fcalc "$cur + $1"); }
on_channel() { # CHANNEL [AFTER_US]: messages recorded on CHANNEL (after AFTER_US)
  "$tool" list "$dir/out.log" 2>/dev/null | awk -v c="$1" -v t="${2:-0}" '$2 == c && $1 > t' | wc -l
}
seen_on() { [ "$(on_channel "$@")" -gt 0 ]; }
row() { q "SELECT status || ' ' || printf('%.17g', lambda) || ' ' || printf('%.17g', gvw_kg) FROM passages WHERE vehicle_id = $1"; }
refused() { # INPUT PATTERN: a refusal summary of INPUT whose example is LIKE %PATTERN%
  nonzero "SELECT count(*) FROM refusals WHERE input = '$1' AND example LIKE '%$2%'"; }
refused_count() { q "SELECT coalesce(sum(count), 0) FROM refusals WHERE input = '$1' AND reason = '$2'"; }

# ---- amfid ------------------------------------------------------------------
write_config
"$amfid" --config "$dir/amfid.yaml" --check-config > /dev/null 2> "$dir/check.log" ||
  fail "check-config: $(cat "$dir/check.log")"
lcm-logger -f "$dir/out.log" > "$dir/logger.log" 2>&1 &
pids="$pids $!"
amfid_start "$amfid" "$dir/amfid.yaml"
start=$(date +%s)

# ---- the cases ----------------------------------------------------------------
traffic_to 19
for key in $ORDER; do
  case $key in
  daemon.channels.passage)
    reload $key RL_PASSAGE2
    traffic_to 21
    wait_until "a passage on RL_PASSAGE2" seen_on RL_PASSAGE2 ;;
  daemon.channels.indicator)
    [ "$(on_channel RL_INDICATOR)" -gt 0 ] || fail "no indicator on the first channel before the change"
    reload $key RL_INDICATOR2
    traffic_to 26
    wait_until "an indicator on RL_INDICATOR2" seen_on RL_INDICATOR2 ;;
  daemon.channels.alert)
    [ "$(on_channel RL_ALERT)" -eq 0 ] || fail "an alert before the damage (the test's premise)"
    reload $key RL_ALERT2
    traffic_to 40
    wait_until "an alert on RL_ALERT2" seen_on RL_ALERT2 ;;
  solver.lambda)
    # two replays of vehicle 5 before any change: the same result
    replay 5 1000; replay 5 2000
    wait_until "replays stored" nonzero "SELECT count(*) = 2 FROM passages WHERE vehicle_id IN (1005, 2005)"
    [ "$(row 1005)" = "$(row 2005)" ] || fail "one vehicle's data solved twice differs: $(row 1005) / $(row 2005)"
    case "$(row 1005)" in "ok "*) ;; *) fail "the replay is not solved: $(row 1005)" ;; esac
    prev=2005; id=3000
    reload $key auto ;; # the L-curve: the lcurve keys below act on it
  solver.lcurve.lo)
    reload $key 3e-12 ;;
  solver.lambda_ref_rate_hz)
    reload $key 2500 ;;
  solver.lcurve.hi)
    reload $key 6e-11 ;; # the grid spacing then changes (lo .. hi no whole decades)
  solver.lcurve.per_decade)
    reload $key 3 ;;
  solver.lcurve.refine)
    reload $key 3 ;;
  detector.clock_offset_s)
    reload $key 0.01 ;; # the replays below enter 10 ms earlier on the data's clock
  detector.speed_scale)
    reload $key 1.02 ;;
  daemon.status_period_s)
    t=$(date +%s%6N)
    [ "$(on_channel RL_STATUS)" -gt 0 ] || fail "no status message before the change"
    reload $key 0.2
    t=$(date +%s%6N)
    wait_until "status messages every 0.2 s" sh -c \
      "[ \$('$tool' list '$dir/out.log' | awk -v t=$t '\$2 == \"RL_STATUS\" && \$1 > t && \$1 < t + 2000000' | wc -l) -ge 5 ]" ;;
  daemon.channels.status)
    reload $key RL_STATUS2
    wait_until "a status message on RL_STATUS2" seen_on RL_STATUS2 ;;
  daemon.intake.summary_period_s)
    probe vehicles "$(now_us)" 500000 1 -3 4 sim_publisher 0
    sleep 1.5
    [ "$(q "SELECT count(*) FROM refusals")" -eq 0 ] || fail "a refusal summarised before the change"
    reload $key 1
    wait_until "a refusal summary within the new period" nonzero "SELECT count(*) FROM refusals" ;;
  daemon.intake.vehicle_ahead_s)
    reload $key 10
    probe vehicles "$(($(now_us) + 50000000))" 510000 1 20 4 sim_publisher 0
    wait_until "vehicle 50 s ahead refused at 10 s" nonzero \
      "SELECT count(*) FROM passages WHERE vehicle_id = 510000 AND status = 'invalid' AND reason LIKE '%daemon.intake.vehicle_ahead_s 10 s%'" ;;
  daemon.intake.min_speed_mps)
    reload $key 5
    probe vehicles "$(now_us)" 520000 1 3 4 sim_publisher 0
    wait_until "a 3 m/s vehicle refused below 5 m/s" nonzero \
      "SELECT count(*) FROM passages WHERE vehicle_id = 520000 AND status = 'invalid' AND reason LIKE '%min_speed_mps (5 m/s)%'" ;;
  daemon.intake.max_length_m)
    reload $key 20
    probe vehicles "$(now_us)" 530000 1 20 30 sim_publisher 0
    wait_until "a 30 m vehicle refused above 20 m" nonzero \
      "SELECT count(*) FROM passages WHERE vehicle_id = 530000 AND status = 'invalid' AND reason LIKE '%max_length_m (20 m)%'" ;;
  daemon.intake.burst_s)
    # vehicles_per_s 5: a burst of 30 s allows 150 at once, of 1 s five
    before=$(refused_count vehicle rate_limited)
    reload $key 1
    probe vehicles "$(now_us)" 540000 12 -3 4 sim_publisher 0
    wait_until "12 vehicles at once over a burst of 5" sh -c \
      "[ \$(sqlite3 '$dir/s.db' \"SELECT coalesce(sum(count), 0) FROM refusals WHERE input = 'vehicle' AND reason = 'rate_limited'\") -ge $((before + 6)) ]" ;;
  daemon.intake.vehicles_per_s)
    reload $key 0.1
    probe vehicles "$(now_us)" 550000 3 -3 4 sim_publisher 0
    wait_until "vehicles refused at 0.1 a second" refused vehicle "daemon.intake.vehicles_per_s 0.1)"
    reload $key 5 ;; # the vehicles below pass
  daemon.intake.truth_per_s)
    reload $key 0.1
    probe truth "$(now_us)" 560000 3
    wait_until "truth refused at 0.1 a second" refused truth "daemon.intake.truth_per_s 0.1)" ;;
  daemon.intake.accel_margin)
    # a burst of 1 s: at a margin of 4, 8000 samples at once; of 1, 2000. 3000
    # sent, dated 10 s back (the allowance also refills with the data time)
    reload $key 1
    probe accel "$(($(now_us) - 10000000))" "$(($(seq_now) - 100))" 30 1000
    wait_until "accel refused at a margin of 1" refused accel "daemon.intake.accel_margin 1 "
    reload $key 4 ;; # the data time advances below
  daemon.intake.environment_min_interval_s)
    u=$(now_us)
    probe env "$(($u - 40000000))" 10.0 2 10000000 # 10.0 °C, 10 s apart: both kept
    wait_until "two readings 10 s apart stored" nonzero \
      "SELECT count(*) = 2 FROM environment WHERE deck_c = 10.0"
    reload $key 100
    probe env "$(($u - 20000000))" 10.2 2 10000000 # within 100 s of the last kept
    probe env "$(($u + 75000000))" 10.4 1 0        # 105 s after it: kept
    wait_until "a reading 105 s after the last kept" nonzero \
      "SELECT count(*) FROM environment WHERE deck_c = 10.4"
    [ "$(q "SELECT count(*) FROM environment WHERE deck_c = 10.2")" -eq 0 ] ||
      fail "readings within 100 s of the last kept one were stored" ;;
  daemon.intake.deck_max_rate_c_per_min)
    reload $key 0.5
    probe env "$(($(now_us) + 76000000))" 11.9 1 0 # 1.5 °C in a minute
    wait_until "a 1.5 °C step refused at 0.5 °C/min" refused environment "deck_max_rate_c_per_min 0.5 " ;;
  daemon.environment_max_skew_s)
    reload $key 60
    probe env "$(($(now_us) - 200000000))" 10.4 1 0
    wait_until "a reading 200 s old refused at 60 s" refused environment "daemon.environment_max_skew_s 60 s)" ;;
  daemon.intake.environment_per_s)
    reload $key 0.1
    probe env "$(now_us)" 10.4 3 1000
    wait_until "readings refused at 0.1 a second" refused environment "daemon.intake.environment_per_s 0.1)" ;;
  daemon.intake.calibration_sources)
    reload $key sim_publisher
    probe vehicles "$(now_us)" 570000 1 20 4 rig 10000
    wait_until "a reference from rig refused" refused vehicle \
      "vehicle_t 570000: reference_gvw_kg 10000 not taken: source _rig_ is not in daemon.intake.calibration_sources" ;;
  daemon.intake.calibration_max_kg)
    reload $key 9000
    probe vehicles "$(now_us)" 580000 1 20 4 sim_publisher 10000
    wait_until "a 10000 kg reference refused above 9000 kg" refused vehicle "3500 .. 9000 kg" ;;
  daemon.intake.calibration_min_kg)
    reload $key 8000
    probe vehicles "$(now_us)" 590000 1 20 4 sim_publisher 7000
    wait_until "a 7000 kg reference refused below 8000 kg" refused vehicle "8000 .. 9000 kg" ;;
  daemon.max_wait_s)
    advance 3 # the probes' vehicles behind, in data time (they wait for sensor 1)
    # vehicle 7 again without sensor 1's data: the window waits for it
    replay 7 7000 -1.58 5.5
    advance 3
    sleep 1
    [ -z "$(row 7007)" ] || fail "the window with a hole was stored before the change: $(row 7007)"
    reload $key 1
    advance 3
    wait_until "the window with a hole stored 1 s after its end" nonzero \
      "SELECT count(*) FROM passages WHERE vehicle_id = 7007" ;;
  esac
  # the λ policy or the detector's corrections: the same data solved
  # again, to another λ or force
  case $key in solver.* | detector.*)
    id=$((id + 1000)); replay 5 $((id - 5))
    wait_until "the replay after the change stored" nonzero "SELECT count(*) FROM passages WHERE vehicle_id = $id"
    [ "$(row $id)" != "$(row $prev)" ] || fail "the same data solved to the same result after the change: $(row $id)"
    case "$(row $id)" in "ok "*) ;; *) fail "the replay is not solved: $(row $id)" ;; esac
    echo "$key $(get_key $key): $(row $prev) -> $(row $id)"
    prev=$id ;;
  esac
done
key=""
for k in $(cat "$dir/live.txt"); do
  case " $done_keys " in *" $k "*) ;; *) fail "$k: no SIGHUP case ran" ;; esac
done
amfid_stop
grep -q "runtime error\|AddressSanitizer\|LeakSanitizer" "$dir/amfid.log" && fail "a sanitizer reported"
echo "daemon_reload_keys: $(wc -l < "$dir/live.txt") live keys, each applied on SIGHUP without a restart ($(( $(date +%s) - start )) s)"
