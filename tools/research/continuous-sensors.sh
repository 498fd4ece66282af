#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# continuous-sensors.sh: where the accelerometers go on a continuous bridge
# (docs/results/continuous-sensors.md). For every sensor layout of a bridge,
# sim_publisher streams the same traffic into an LCM log (no bus: --lcm-url
# none) on that bridge with those sensors, amfid weighs it from the log with
# the same site file (the model exact, class A road, no noise, the
# detector's speed exact), and the store is read back against the truth.
#
# usage: continuous-sensors.sh BUILD OUT VEHICLES [BRIDGE ...]
#   BUILD     the build tree (build/rel)
#   OUT       a scratch folder (one sub-folder per run, kept)
#   VEHICLES  vehicles per layout: the first VEHICLES 2-, 3- and 5-axle
#             vehicles of sim_publisher/data/population-eu.csv
#   BRIDGE    single (20 m, the reference), two (20 + 20 m), three
#             (15 + 20 + 15 m); default: single two
# Environment: JOBS (default 1) layouts simulated and weighed at once;
# LAYOUTS (default all) only the layouts named (e.g. "mid1 per-span");
# SUMMARY_ONLY=1 only reads the runs already in OUT back, over their first
# VEHICLES vehicles (the same seed gives the same vehicles whatever the
# count, so a longer run read over fewer vehicles is the shorter run).
#
# Prints one line per layout (key=value): bridge, layout, sensors (m),
# weighed (ok passages) of passages, GVW error inferred / true − 1 in %:
# mean, mean abs (mae), worst (largest |error|, signed), mae2 / mae3 / mae5
# by axle count, p90abs, the COST 323 gross class (amfi-accuracy, r1,
# environment I) and its delta, and the worst vehicle (axles, speed, true GVW).
# Per run OUT/BRIDGE-LAYOUT/ holds site.yaml, errors.csv (vehicle_id,
# n_axles, speed_mps, true_kg, inferred_kg, err_pct) and accuracy.json.
# CPU: about 1 s of amfid per vehicle on the two-span bridge at 5000 Hz;
# run under nice.
set -u
[ $# -ge 3 ] || { echo "usage: $0 BUILD OUT VEHICLES [single|two|three ...]" >&2; exit 2; }
bin=$1 out=$2 nveh=$3
shift 3
[ $# -gt 0 ] || set -- single two
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
die() { echo "continuous-sensors: $*" >&2; exit 1; }
mkdir -p "$out" || die "cannot create $out"
out=$(cd "$out" && pwd)

. "$src/tools/research/continuous-bridge.sh"
# the traffic: 2-, 3- and 5-axle vehicles of the EU mix, in their order
pop="$out/population-235.csv"
continuous_traffic "$src" "$pop" || die "cannot write $pop"

# site BRIDGE LAYOUT "POS ..." -> OUT/BRIDGE-LAYOUT/site.yaml
site() {
  d="$out/$1-$2"
  rm -rf "$d" && mkdir -p "$d" || die "cannot create $d"
  {
    echo "# SPDX-License-Identifier: GPL-3.0-or-later"
    echo "# continuous-sensors.sh: bridge $1, layout $2"
    continuous_bridge_yaml "$1" "continuous-$1-$2" "$3" || die "unknown bridge $1"
    echo "daemon:"
    echo "  simulation: true"
    echo "simulation:"
    echo "  population: $pop"
  } > "$d/site.yaml" || exit 1
}

# weigh BRIDGE LAYOUT "POS ...": simulate and weigh into OUT/BRIDGE-LAYOUT
weigh() {
  site "$1" "$2" "$3"
  d="$out/$1-$2"
  "$bin/daemon/amfid" --make-bus-key "$d/bus.key" > /dev/null 2>&1 || die "amfid --make-bus-key"
  # one vehicle at a time: 8 s entry to entry (3 % damping: the free
  # vibration has decayed to e^-5 of itself before the next vehicle)
  "$bin/sim_publisher/sim_publisher" --config "$d/site.yaml" --vehicles "$nveh" --seed 1 \
    --profile A --headway 8 --speedup max --bus-key "$d/bus.key" --lcm-url none \
    --log "$d/s.lcmlog" > "$d/sim.log" 2>&1 || die "$1-$2: sim_publisher: $(tail -2 "$d/sim.log")"
  "$bin/daemon/amfid" --config "$d/site.yaml" --db "$d/a.db" --bus-key "$d/bus.key" \
    --lcm-url "file://$d/s.lcmlog?speed=0" > "$d/amfid.log" 2>&1 \
    || die "$1-$2: amfid: $(tail -2 "$d/amfid.log")"
  rm -f "$d/s.lcmlog"
}

# summary BRIDGE LAYOUT "POS ...": the line of OUT/BRIDGE-LAYOUT over its
# first VEHICLES vehicles
summary() {
  d="$out/$1-$2"
  [ -f "$d/a.db" ] || { echo "bridge=$1 layout=$2 not weighed"; return; }
  q() { sqlite3 -separator , "$d/a.db" "$1"; }
  n=$(q "SELECT count(*) FROM passages WHERE vehicle_id <= $nveh")
  ok=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND vehicle_id <= $nveh")
  {
    echo "vehicle_id,n_axles,speed_mps,true_kg,inferred_kg,err_pct"
    q "SELECT p.vehicle_id, p.n_axles, printf('%.2f', p.speed_mps), printf('%.0f', t.gvw_kg),
              printf('%.0f', p.gvw_kg), printf('%.3f', 100 * (p.gvw_kg / t.gvw_kg - 1))
       FROM passages p JOIN truth t USING (vehicle_id) WHERE p.status = 'ok'
       AND p.vehicle_id <= $nveh ORDER BY p.vehicle_id"
  } > "$d/errors.csv"
  {
    echo "criterion,measured_kg,reference_kg"
    awk -F, 'NR > 1 { print "gross," $5 "," $4 }' "$d/errors.csv"
  } > "$d/accuracy.csv"
  "$bin/tools/ops/amfi-accuracy" --input "$d/accuracy.csv" --condition r1 --environment I \
    > "$d/accuracy.json" 2> "$d/accuracy.err"
  cls=$(sed -n 's/.*"criterion":"gross".*"class":"\([^"]*\)".*/\1/p' "$d/accuracy.json")
  dl=$(sed -n 's/.*"criterion":"gross".*"delta_pct":\([^,}]*\).*/\1/p' "$d/accuracy.json")
  stats=$(awk -F, 'NR > 1 {
      e = $6; a = e < 0 ? -e : e; n++; s += e; sa += a; v[n] = a
      if (a > wa) { wa = a; w = e; wv = $2 "-axle " $3 " m/s " $4 " kg" }
      k[$2]++; ka[$2] += a }
    END {
      if (n == 0) { print "mean=- mae=- worst=-"; exit }
      # p90 of |error| (nearest rank)
      for (i = 1; i <= n; i++) for (j = i + 1; j <= n; j++) if (v[j] < v[i]) { t = v[i]; v[i] = v[j]; v[j] = t }
      r = int(0.9 * n + 0.999999); if (r < 1) r = 1
      printf "mean=%+.2f mae=%.2f worst=%+.2f", s / n, sa / n, w
      for (c = 2; c <= 5; c++) if (c != 4) printf " mae%d=%s", c, k[c] ? sprintf("%.2f", ka[c] / k[c]) : "-"
      printf " p90abs=%.2f worst_vehicle=\"%s\"", v[r], wv }' "$d/errors.csv")
  echo "bridge=$1 layout=$2 sensors=$(echo "$3" | tr ' ' ',') weighed=$ok/$n $stats" \
       "cost323=${cls:--} delta=${dl:--}"
}

# run BRIDGE LAYOUT "POS ...": queue it (LAYOUTS), weigh it (JOBS at once)
queued=""
running=0
run() {
  case " ${LAYOUTS:-$2} " in *" $2 "*) ;; *) return ;; esac
  queued="$queued$1 $2 $3
"
  [ "${SUMMARY_ONLY:-0}" = 1 ] && return
  weigh "$1" "$2" "$3" &
  running=$((running + 1))
  if [ "$running" -ge "${JOBS:-1}" ]; then
    wait
    running=0
  fi
}

for b in "$@"; do
  case $b in
    single)
      run single mid "10" ;;
    two)
      run two mid1 "10"
      run two 0.4L1 "8"
      run two near-support "18"
      run two per-span "10 30"
      run two two-in-1 "7 13"
      run two three "5 10 30" ;;
    three)
      run three mid1 "7.5"
      run three mid2 "25"
      run three near-support "14"
      run three per-span "7.5 25 42.5"
      run three end-and-middle "6 25" ;;
    *) die "unknown bridge $b (single, two, three)" ;;
  esac
done
wait
printf '%s' "$queued" | while read -r b l p; do
  summary "$b" "$l" "$p" < /dev/null
done
