#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# model-fit-trial.sh: amfid's model fit on one simulated site
# (docs/results/model-fit.md): sim_publisher writes a stream (LCM log, no
# bus) of VEHICLES on the as-built bridge CASE.yaml ("none": the design
# itself), amfid weighs it with the design CONFIG (uncommissioned) from the
# log, and the store is read back. Prints one line of key=value pairs:
#   passages, fitted (with a fit_ratio), ratio_med / ratio_p05 / ratio_p95
#   (the fit ratios), gvw_bias_pct (mean inferred / true GVW − 1 over ok
#   passages), raised_at (the ok passages up to and including the one whose
#   storage raised model_mismatch; "none"), natfreq_at (the same for natfreq).
# usage: model-fit-trial.sh BUILD CONFIG CASE.yaml|none OUT VEHICLES [sim_publisher args ...]
set -u
bin=$1 cfg=$2 case=$3 out=$4 nveh=$5
shift 5
die() { echo "model-fit-trial: $*" >&2; exit 1; }
rm -rf "$out" && mkdir -p "$out" || die "cannot create $out"
"$bin/daemon/amfid" --make-bus-key "$out/bus.key" > /dev/null 2>&1 || die "amfid --make-bus-key"
ab=""
[ "$case" = none ] || ab="--as-built $case"
# shellcheck disable=SC2086
"$bin/sim_publisher/sim_publisher" --config "$cfg" $ab --vehicles "$nveh" --speedup max \
  --bus-key "$out/bus.key" \
  --lcm-url none --log "$out/s.lcmlog" "$@" > "$out/sim.log" 2>&1 || die "sim_publisher: $(tail -2 "$out/sim.log")"
"$bin/daemon/amfid" --config "$cfg" --db "$out/a.db" --bus-key "$out/bus.key" \
  --lcm-url "file://$out/s.lcmlog?speed=0" > "$out/amfid.log" 2>&1 || die "amfid: $(tail -2 "$out/amfid.log")"
q() { sqlite3 "$out/a.db" "$1"; }
n=$(q "SELECT count(*) FROM passages")
fitted=$(q "SELECT count(*) FROM passages WHERE fit_ratio IS NOT NULL")
pct() { # the P-th percentile of fit_ratio (nearest rank)
  q "SELECT fit_ratio FROM passages WHERE fit_ratio IS NOT NULL ORDER BY fit_ratio
     LIMIT 1 OFFSET (SELECT max(0, CAST(round($1 * count(*)) AS INTEGER) - 1)
                     FROM passages WHERE fit_ratio IS NOT NULL)"
}
bias=$(q "SELECT printf('%+.2f', 100 * (avg(p.gvw_kg / t.gvw_kg) - 1)) FROM passages p
          JOIN truth t USING (vehicle_id) WHERE p.status = 'ok'")
at() { # ok passages up to the first raise of kind $1
  r=$(q "SELECT count(*) FROM passages WHERE status = 'ok' AND utime <=
         (SELECT min(utime) FROM alerts WHERE kind = '$1' AND raised = 1)
         AND EXISTS (SELECT 1 FROM alerts WHERE kind = '$1' AND raised = 1)")
  [ "$r" -gt 0 ] 2>/dev/null && echo "$r" || echo none
}
echo "passages=$n fitted=$fitted ratio_med=$(pct 0.5) ratio_p05=$(pct 0.05)" \
     "ratio_p95=$(pct 0.95) gvw_bias_pct=$bias raised_at=$(at model_mismatch)" \
     "natfreq_at=$(at natfreq) alerts=$(q "SELECT group_concat(kind || ':' || raised, ',') FROM alerts")"
