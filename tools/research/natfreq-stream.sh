#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# natfreq-stream.sh: the natural frequency per passage on a simulated
# stream through the whole chain (sim_publisher -> LCM -> amfid -> store),
# for docs/results/natural-frequency.md. Runs in a private network
# namespace (unshare --net, loopback multicast only; root or a user
# namespace). Prints one summary block; keeps the store and the logs in OUT.
#
#   tools/research/natfreq-stream.sh BUILD OUT VEHICLES [sim_publisher flags...]
#
# BUILD: a built tree; OUT: a directory for the store, logs and f1.csv.
# Environment: BASELINE_N (amfid's daemon.natural_frequency.baseline_n,
# default 200), STEP (the vehicle index --damage-step-at was given, for the
# detection figures; default none), DAMAGE (the --damage given, for the
# model's frequency after STEP; default 0), SPEEDUP (default 20), MIN_R2
# and MAX_SE (daemon.natural_frequency.min_r2 and max_se_frac; default
# 0.8 and 0.01).
# The figures:
#   raw       f1 against the simulated bridge's first frequency at the deck
#             temperature of the last reading before the passage,
#             5.7338 Hz · sqrt(E(T)/E(10 °C) · (1 − d)) (docs/simulator.md;
#             without --environment site: T = 10 °C), mean and SD of the
#             relative error, per damage state;
#   comp      the compensated f1 relative to the baseline's mean, per state;
#   delay     with STEP: a one-sided CUSUM on z = ln(f_comp / f_ref) / sd
#             (sd of the compensated baseline), tuned for a 2.5 % stiffness
#             loss (k = ln(1/sqrt(0.975)) / (2 sd)), threshold h = 8: the
#             passages after STEP until it crosses, and its false crossings
#             before STEP.
set -u
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo &&
    AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
build=$(cd "$1" && pwd) out=$2 n=$3
shift 3
top=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
# the run's bus key (docs/messages.md): sim_publisher signs, amfid requires it
mkdir -p "$out/cred" && rm -f "$out/cred/amfi-bus-key" &&
  "$build/daemon/amfid" --make-bus-key "$out/cred/amfi-bus-key" > /dev/null || exit 1
export CREDENTIALS_DIRECTORY="$out/cred"
export AMFI_DATA_DIR="$top/config:$top/sim_publisher/data"
sed -e "s|^    baseline_n: 200 .*|    baseline_n: ${BASELINE_N:-200}|" \
    -e "s|^    min_r2: [0-9.]* .*|    min_r2: ${MIN_R2:-0.8}|" \
    -e "s|^    max_se_frac: [0-9.]* .*|    max_se_frac: ${MAX_SE:-0.01}|" "$top/config/amfid.yaml" \
  > "$out/amfid.yaml"
rm -f "$out"/a.db*
: > "$out/amfid.log"
"$build/daemon/amfid" --config "$out/amfid.yaml" --db "$out/a.db" 2> "$out/amfid.log" &
apid=$!
i=0; until grep -q "running" "$out/amfid.log"; do
  i=$((i + 1)); [ $i -lt 400 ] || { echo "amfid did not start" >&2; kill $apid; exit 1; }
  sleep 0.05; done
start=$(date +%s)
"$build/sim_publisher/sim_publisher" --allow-production-bus --vehicles "$n" --speedup "${SPEEDUP:-20}" "$@" \
  2> "$out/sim.log" || echo "sim_publisher exited $?" >&2
sleep 2
kill -TERM $apid; wait $apid
echo "wall time $(( $(date +%s) - start )) s"
grep "natural frequency" "$out/amfid.log" | sed 's/^<[0-9]>amfid: //'
sqlite3 -separator ' ' "$out/a.db" "
  SELECT p.vehicle_id, p.utime, p.status, coalesce(p.f1_hz, 'nan'), coalesce(p.f1_comp_hz, 'nan'),
         coalesce(p.f1_zeta, 'nan'),
         coalesce((SELECT e.deck_c FROM environment AS e WHERE e.utime <= p.utime
                   ORDER BY e.utime DESC LIMIT 1), 10)
  FROM passages AS p ORDER BY p.utime" > "$out/f1.csv"
awk -v step="${STEP:-none}" -v dmg="${DAMAGE:-0}" '
  function mod(t) { if (t >= 0) return 1 - 0.0025 * (t - 10); if (t < -10) t = -10; return 1.025 * (1 - 0.02 * t) }
  { k = NR - 1; st = (step != "none" && k >= step) ? 1 : 0
    if ($4 == "nan") { miss[st]++; next }
    d = st ? dmg : (step == "none" ? dmg : 0)
    e = $4 / (5.7338 * sqrt(mod($7) * (1 - d))) - 1
    n[st]++; s1[st] += e; s2[st] += e * e; tmin = (tmin == "" || $7 < tmin) ? $7 : tmin; tmax = ($7 > tmax) ? $7 : tmax
    r1[st] += $4; r2[st] += $4 * $4
    if ($5 != "nan") { c[st]++; cv[st, c[st]] = $5; ck[st, c[st]] = k } }
  END {
    printf "deck temperature %.1f .. %.1f C\n", tmin, tmax
    for (s = 0; s <= (step == "none" ? 0 : 1); s++) {
      if (!n[s]) continue
      m = s1[s] / n[s]; sd = sqrt(s2[s] / n[s] - m * m)
      rm = r1[s] / n[s]; rsd = sqrt(r2[s] / n[s] - rm * rm)
      printf "%s: %d passages with f1, %d without; f1 against the model: mean %+.3f %%, SD %.3f %%; raw f1 %.4f Hz, SD %.2f %%\n",
        s ? "after the step" : (step == "none" ? "all" : "before the step"), n[s], miss[s], 100 * m, 100 * sd, rm, 100 * rsd / rm
    }
    # the compensated baseline: the first compensated values before the step
    if (!c[0]) { print "no compensated f1"; exit }
    for (i = 1; i <= c[0]; i++) { z = log(cv[0, i]); a1 += z; a2 += z * z }
    ref = a1 / c[0]; csd = sqrt(a2 / c[0] - ref * ref)
    printf "compensated before the step: %d passages, mean %.4f Hz, SD %.3f %%\n", c[0], exp(ref), 100 * csd
    if (c[1]) { for (i = 1; i <= c[1]; i++) { z = log(cv[1, i]); b1 += z; b2 += z * z }
      bm = b1 / c[1]; printf "compensated after the step: %d passages, mean %.4f Hz (%+.2f %%), SD %.3f %%\n", c[1], exp(bm), 100 * (exp(bm - ref) - 1), 100 * sqrt(b2 / c[1] - bm * bm) }
    if (step == "none" || !c[1]) exit
    kref = log(1 / sqrt(0.975)) / (2 * csd); S = 0; fa = 0
    for (i = 1; i <= c[0]; i++) { S = S - log(cv[0, i] / exp(ref)) / csd - kref; if (S < 0) S = 0; if (S >= 8) { fa++; S = 0 } }
    S = 0
    for (i = 1; i <= c[1]; i++) { S = S - log(cv[1, i] / exp(ref)) / csd - kref; if (S < 0) S = 0
      if (S >= 8) { printf "CUSUM (k %.2f, h 8): crossed at the %d-th compensated passage after the step (vehicle %d); %d false crossings in %d passages before it\n", kref, i, ck[1, i], fa, c[0]; exit } }
    printf "CUSUM: no crossing in %d passages after the step; %d false crossings before it\n", c[1], fa
  }' "$out/f1.csv"
