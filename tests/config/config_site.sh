#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# config_site.sh: the short site file (config/site.yaml) checks like the
# untouched example it is (config_example.sh: ok, the three example
# warnings, --strict refuses it, configured it checks clean), and it holds
# only site facts: every key it writes is one a site owner must state (site,
# bridge, sensors, detector, the bus and the store); the tuning stays with
# the loader's defaults (test_config_site holds those equal to amfid.yaml).
#   config_site.sh AMFID SITE.yaml CONFIG_EXAMPLE.sh
set -u
amfid=$1 site=$2 example=$3
fail() { echo "FAIL: $*"; exit 1; }

# the key paths the file writes (comments and list items' keys aside)
keys=$(awk '
  /^[ ]*#/ || /^[ ]*-/ || !/^[ ]*[A-Za-z_0-9]+:/ { next }
  { match($0, /^ */); lvl = RLENGTH / 2; k = $0; sub(/^ */, "", k); sub(/:.*/, "", k)
    path[lvl] = k; p = path[0]; for (i = 1; i <= lvl; i++) p = p "." path[i]; print p }' "$site")
[ -n "$keys" ] || fail "no keys read from $site"
bad=""
for k in $keys; do
  case $k in
    site|site.id|site.name|site.latitude|site.longitude|site.bridge_type) ;;
    bridge|bridge.name|bridge.span_m|bridge.elements|bridge.E_pa|bridge.A_m2|bridge.I_m4) ;;
    bridge.density_kgm3|bridge.damping|bridge.damping.ratio|bridge.damping.modes) ;;
    bridge.supports|bridge.segments|sensors) ;;
    detector|detector.clock_offset_s|detector.speed_scale) ;;
    daemon|daemon.lcm_url|daemon.bus|daemon.bus.auth|daemon.bus.key_file|daemon.store|daemon.store.path) ;;
    *) bad="$bad $k" ;;
  esac
done
[ -z "$bad" ] || fail "$site holds keys that are not site facts (leave them to the defaults):$bad"
for k in site.id bridge.span_m bridge.supports sensors detector.clock_offset_s daemon.lcm_url daemon.store.path; do
  echo "$keys" | grep -qx "$k" || fail "$site does not state $k"
done
sh "$example" "$amfid" "$site" || fail "config_example.sh on $site"

echo "$site: $(echo "$keys" | wc -l) keys, all site facts: ok"
