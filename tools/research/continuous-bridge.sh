# SPDX-License-Identifier: GPL-3.0-or-later
# continuous-bridge.sh: sourced by continuous-sensors.sh and
# natfreq-continuous.sh, the bridges they share.
#
#   continuous_bridge_yaml BRIDGE ID "SENSOR_X ..."
#       prints the site file's site:, bridge: and sensors: sections for
#       BRIDGE (single: 20 m; two: 20 + 20 m; three: 15 + 20 + 15 m; the
#       paper's section, one element a metre, 3 % damping) with site id ID
#       and a sensor at each position (m); returns 1 for an unknown bridge
#   continuous_traffic SRC OUT.csv
#       the 2-, 3- and 5-axle vehicles of SRC's population-eu.csv, in order

continuous_bridge_yaml() {
  case $1 in
    single) span=20 sup='    - {at_m: 0, type: pinned}
    - {at_m: 20, type: roller}' ;;
    two) span=40 sup='    - {at_m: 0, type: pinned}
    - {at_m: 20, type: roller}
    - {at_m: 40, type: roller}' ;;
    three) span=50 sup='    - {at_m: 0, type: pinned}
    - {at_m: 15, type: roller}
    - {at_m: 35, type: roller}
    - {at_m: 50, type: roller}' ;;
    *) return 1 ;;
  esac
  echo "site:"
  echo "  id: $2"
  echo "bridge:"
  echo "  name: $1"
  echo "  span_m: $span"
  echo "  elements: $span"
  echo "  E_pa: 3.5e10"
  echo "  A_m2: 2.046"
  echo "  I_m4: 0.2991"
  echo "  density_kgm3: 2400"
  echo "  damping:"
  echo "    ratio: 0.03"
  echo "    modes: [1, 2]"
  echo "  supports:"
  echo "$sup"
  echo "sensors:"
  i=0
  for x in $3; do
    echo "  - {id: $i, at_m: $x, weight: 1}"
    i=$((i + 1))
  done
}

continuous_traffic() {
  awk -F, 'NR == 1 || $6 == 2 || $6 == 3 || $6 == 5' "$1/sim_publisher/data/population-eu.csv" > "$2"
}
