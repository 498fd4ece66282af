#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# natfreq-continuous.sh: amfid's natural frequency and its natfreq alert on
# a continuous bridge (docs/results/continuous-sensors.md, "The natural
# frequency on a continuous bridge"). sim_publisher streams the EU mix's 2-,
# 3- and 5-axle vehicles (one at a time, 8 s entry to entry, road class A,
# no noise, seed 1, no climate) over the bridge into an LCM log (no bus:
# --lcm-url none); amfid weighs the same log once per MODE
# (daemon.natural_frequency.mode: 0 the strongest peak in [f_lo_hz,
# f_hi_hz], 1 the site model's first mode in its band), the model exact.
#
# usage: natfreq-continuous.sh BUILD OUT VEHICLES BRIDGE "SENSORS" [MODE ...]
#   BUILD     the build tree (build/rel)
#   OUT       a scratch folder (kept: site files, stores, logs, f1-MODE.csv)
#   VEHICLES  vehicles streamed
#   BRIDGE    single (20 m), two (20 + 20 m), three (15 + 20 + 15 m)
#   SENSORS   sensor positions, m ("10")
#   MODE      daemon.natural_frequency.mode values (default: 0 1)
# Environment: DAMAGE and STEP (sim_publisher --damage DAMAGE
# --damage-step-at STEP; default none), BASELINE_N (baseline_n, default
# 200), FIT_MODES (daemon.natural_frequency.modes, default 3 as amfid's;
# 2 was amfid's before it followed a mode), SOLVER_RATE
# (solver.calc_rate_hz, default 5000: the weighing's rate; the natural
# frequency is estimated from the samples of the free vibration and does
# not depend on it: the same estimates per passage at 1000, which costs
# far less). The model fit
# (alerts.model_fit) is off: it does not touch the natural frequency and
# would double amfid's CPU.
# Prints per MODE: estimates (of ok passages), mean, SD, min, max of f1 per
# state (before STEP, from STEP on), how many within 3 % of each of the
# model's first frequencies, and every natfreq alert with the vehicle
# it came at. CPU: about 1 s of amfid per vehicle on 20 + 20 m at 5000
# Hz, a tenth of it at 1000.
set -u
[ $# -ge 5 ] || { echo "usage: $0 BUILD OUT VEHICLES single|two|three \"SENSORS\" [MODE ...]" >&2; exit 2; }
bin=$1 out=$2 nveh=$3 bridge=$4 sensors=$5
shift 5
[ $# -gt 0 ] || set -- 0 1
src=$(cd "$(dirname "$0")/../.." && pwd)
die() { echo "natfreq-continuous: $*" >&2; exit 1; }
mkdir -p "$out" || die "cannot create $out"
out=$(cd "$out" && pwd)
. "$src/tools/research/continuous-bridge.sh"
pop="$out/population-235.csv"
continuous_traffic "$src" "$pop" || die "cannot write $pop"
# the model's first natural frequencies (amfi_bridge_omega of the site
# model; healthy), for the counts near each
case $bridge in
  single) model_f="5.7338 22.935" ;;
  two) model_f="5.7338 8.9573" ;;
  three) model_f="7.5954 12.433 14.915" ;;
esac
continuous_bridge_yaml "$bridge" x "" > /dev/null || die "unknown bridge $bridge"
# site MODE -> OUT/site-MODE.yaml
site() {
  {
    echo "# SPDX-License-Identifier: GPL-3.0-or-later"
    echo "# natfreq-continuous.sh: bridge $bridge, sensors $sensors, mode $1"
    continuous_bridge_yaml "$bridge" "natfreq-$bridge" "$sensors"
    echo "solver:"
    echo "  calc_rate_hz: ${SOLVER_RATE:-5000}"
    echo "daemon:"
    echo "  simulation: true"
    echo "  natural_frequency:"
    echo "    mode: $1"
    echo "    modes: ${FIT_MODES:-3}"
    echo "    baseline_n: ${BASELINE_N:-200}"
    echo "alerts:"
    echo "  model_fit:"
    echo "    enabled: off"
    echo "    calc_rate_hz: ${SOLVER_RATE:-2000}"
    echo "simulation:"
    echo "  population: $pop"
  } > "$out/site-$1.yaml"
}
site 0
rm -f "$out/bus.key"
"$bin/daemon/amfid" --make-bus-key "$out/bus.key" > /dev/null 2>&1 || die "amfid --make-bus-key"
dmg=""
[ -n "${DAMAGE:-}" ] && dmg="--damage $DAMAGE --damage-step-at ${STEP:-1}"
# shellcheck disable=SC2086
"$bin/sim_publisher/sim_publisher" --config "$out/site-0.yaml" --vehicles "$nveh" --seed 1 \
  --profile A --headway 8 --speedup max --bus-key "$out/bus.key" --lcm-url none $dmg \
  --log "$out/s.lcmlog" > "$out/sim.log" 2>&1 || die "sim_publisher: $(tail -2 "$out/sim.log")"
for m in "$@"; do
  site "$m"
  rm -f "$out/a-$m.db"*
  "$bin/daemon/amfid" --config "$out/site-$m.yaml" --db "$out/a-$m.db" --bus-key "$out/bus.key" \
    --lcm-url "file://$out/s.lcmlog?speed=0" > "$out/amfid-$m.log" 2>&1 &
done
wait
step=${STEP:-999999999}
[ -n "${DAMAGE:-}" ] || step=999999999
for m in "$@"; do
  db="$out/a-$m.db"
  [ -f "$db" ] || die "mode $m: no store: $(tail -2 "$out/amfid-$m.log")"
  f1m=$(sed -n 's/.*following the site model.s mode [0-9]* (\([0-9.]*\) Hz).*/\1/p' "$out/amfid-$m.log")
  sqlite3 -separator , "$db" "SELECT vehicle_id, printf('%.5f', f1_hz) FROM passages
     WHERE status = 'ok' AND f1_hz IS NOT NULL ORDER BY vehicle_id" > "$out/f1-$m.csv"
  ok=$(sqlite3 "$db" "SELECT count(*) FROM passages WHERE status = 'ok'")
  echo "mode=$m model_f=${f1m:-none} ok_passages=$ok"
  awk -F, -v step="$step" -v d="${DAMAGE:-0}" -v fm="$model_f" '
    BEGIN { nm = split(fm, f, " ") }
    { s = $1 >= step; n[s]++; x[s] += $2; xx[s] += $2 * $2
      if (!(s in lo) || $2 < lo[s]) lo[s] = $2; if (!(s in hi) || $2 > hi[s]) hi[s] = $2
      # the model'"'"'s first modes, healthy and damaged (sqrt(1 - d)): within 3 %
      k = s ? sqrt(1 - d) : 1
      for (j = 1; j <= nm; j++) if ($2 > f[j] * k * 0.97 && $2 < f[j] * k * 1.03) c[s, j]++ }
    END { for (s = 0; s <= 1; s++) if (n[s]) {
            mu = x[s] / n[s]; sd = n[s] > 1 ? sqrt((xx[s] - n[s] * mu * mu) / (n[s] - 1)) : 0
            printf "  %s: estimates=%d mean=%.4f sd=%.4f (%.2f %%) min=%.4f max=%.4f",
              s ? "damaged" : "healthy", n[s], mu, sd, 100 * sd / mu, lo[s], hi[s]
            for (j = 1; j <= nm; j++) printf " near_%s=%d", f[j], c[s, j] + 0
            printf "\n" } }' \
    "$out/f1-$m.csv"
  sqlite3 -separator ' ' "$db" "SELECT a.raised, (SELECT max(p.vehicle_id) FROM passages p
      WHERE p.utime <= a.utime), a.message FROM alerts a WHERE a.kind = 'natfreq' ORDER BY a.id" |
    while read -r r v msg; do echo "  natfreq alert raised=$r at vehicle $v: $msg"; done
  grep "natfreq alert:\|natural frequency: [0-9]* passages" "$out/amfid-$m.log" | sed 's/^/  log: /'
done
