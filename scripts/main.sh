#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The main job: install what is missing, build, then on a private bus (a
# network namespace of its own: nothing leaves this machine) amfid listens
# while sim_publisher streams 500 vehicles of the European heavy traffic by
# class (sim_publisher/data/population-eu.csv: two-axle rigid trucks to
# six-axle articulated ones), one every 2 s of data at 25 times real time,
# the bridge losing 20 % of its stiffness from vehicle 251 on (half way).
# Ends with what amfid stored: passages, indicator trend, alerts, and the
# plots of them (PNG files next to the database, named at the end).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
mkdir -p "$top/build"
bash "$top/scripts/build.sh" "$top/build/release" -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
bin="$top/build/release"
out="$top/build/demo"
rm -rf "$out"
mkdir -p "$out"
config="$top/config/demo.yaml"
# the demo site's bus key (docs/messages.md): amfid refuses unsigned messages
"$bin/daemon/amfid" --make-bus-key "$out/bus.key" >/dev/null
# the shipped population (and configurations) for a build that is not installed
export AMFI_DATA_DIR="$top/config:$top/sim_publisher/data"
# the heavy traffic by class (docs/simulator.md, "Vehicle classes")
population="$top/sim_publisher/data/population-eu.csv"
echo "== amfid and sim_publisher on a private bus: 500 trucks of the EU mix, 20 % damage from vehicle 251 (half way)"
echo "   (a minute or more: about 55 s of CPU; logs in $out)"
OPENBLAS_NUM_THREADS=1 unshare --net bash -c '
  set -eu
  ip link set lo up
  ip route add 224.0.0.0/4 dev lo
  "$1/daemon/amfid" --config "$2" --db "$3/demo.db" --bus-key "$3/bus.key" 2> "$3/amfid.log" &
  pid=$!
  for i in $(seq 100); do grep -q running "$3/amfid.log" && break; sleep 0.1; done
  "$1/sim_publisher/sim_publisher" --allow-production-bus --config "$2" --bus-key "$3/bus.key" \
    --population "$4" --vehicles 500 --headway 2 --speedup 25 \
    --damage 0.2 --damage-step-at 250 --seed 1 2> "$3/sim_publisher.log"
  sleep 1
  kill -TERM "$pid"
  wait "$pid"
' demo "$bin" "$config" "$out" "$population"
grep -E "ALERT|alert cleared|baseline" "$out/amfid.log" | sed 's/^<[0-9]>//' || true
echo
"$bin/tools/ops/amfi-report" --db "$out/demo.db" --summary --trend --alerts --errors
echo
echo "== plots of the stored results (amfi-report --plot), next to the database"
"$bin/tools/ops/amfi-report" --db "$out/demo.db" --plot "$out/plots" --config "$config"
