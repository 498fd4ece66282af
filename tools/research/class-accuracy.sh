#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# class-accuracy.sh: COST 323 accuracy per vehicle class from the
# simulation's truth (docs/results/class-accuracy.md).
#   1. the first PER_CLASS records of every class of a class-format
#      population (the EU mix, sim_publisher/data/population-eu.csv), in
#      file order: a sample with every class represented (a plain draw of
#      the mix has 4-6 % R4 and A33);
#   2. sim_publisher --out: each vehicle alone on the bridge (CONFIG's
#      bridge, class A road, no noise unless SIM_ARGS);
#   3. amfi-solve --config CONFIG on every vehicle with the detector's speed
#      and every axle spacing (SOLVE_ARGS, e.g. --estimate-speed): its axle
#      loads, class and axle groups;
#   4. per class (the population's) and for all vehicles, amfi-accuracy
#      (CONDITION, ENVIRONMENT) on the criteria against the static loads
#      (REFERENCE):
#        gross       the gross weight;
#        group       a group of two or more axles (amfi-solve's groups), its
#                    load against the sum of its axles' static loads;
#        single      an axle outside any group;
#        group_axle  an axle inside a group (reported by amfi-solve, flagged
#                    not separable: never part of the single criterion).
# Prints the table (also OUT/table.txt), one row per class and criterion:
#   class n criterion mean_pct std_pct pi_pct pi0_pct cost323_class
# with the whole sample as class "all"; then a line of the vehicles whose
# class amfi-solve decided otherwise, and of those amfi-solve refused.
# OUT keeps vehicles.csv (one row per vehicle: the groups as axles per
# group, 1-1-3; the true and weighed axle loads as lists separated by ';'),
# weights-CLASS.csv (the amfi-accuracy inputs), accuracy-CLASS.json (its
# output) and pairs.txt: per class, the neighbouring groups of a vehicle (a
# single axle a group of one), the correlation of their errors (kg) and the
# RMS relative error of the front one, the back one and their sum.
#
# usage: class-accuracy.sh BIN_DIR OUT_DIR [PER_CLASS (30)] [POPULATION.csv]
# environment: CONFIG (site file, config/paper-20m.yaml),
#              SIM_ARGS (extra sim_publisher options; the paper's Table 5:
#                "--noise 0.03 --speed-error 0,0.03"),
#              SOLVE_ARGS (extra amfi-solve options, e.g. --estimate-speed),
#              SENSORS (positions in m, e.g. "5 10 15": CONFIG's sensors
#                replaced by these, ids 0, 1, ..., in OUT/site.yaml, which
#                both sim_publisher and amfi-solve then use),
#              SEED (sim_publisher's seed, 1),
#              CONDITION (RR2), ENVIRONMENT (I): amfi-accuracy's,
#              REFERENCE: static (the static loads, the default) or span (each
#                axle's mean contact force while on the span, AMFI_GRAVITY
#                9.81: what the bridge felt; static minus span is the
#                vehicle's dynamics, span minus measured the inverse problem's),
#              SOLVED (an earlier OUT_DIR: its sample, passages and amfi-solve
#                results judged again, e.g. with another REFERENCE; steps
#                1-3 skipped, PER_CLASS and POPULATION unused)
set -u
[ $# -ge 2 ] || { echo "usage: class-accuracy.sh BIN_DIR OUT_DIR [PER_CLASS] [POPULATION.csv]" >&2; exit 2; }
bin=$1 out=$2 per=${3:-30}
here=$(cd "$(dirname "$0")" && pwd)
pop=${4:-$here/../../sim_publisher/data/population-eu.csv}
cfg=${CONFIG:-$here/../../config/paper-20m.yaml}
sim=$bin/sim_publisher/sim_publisher
solve=$bin/tools/ops/amfi-solve
acc=$bin/tools/ops/amfi-accuracy
die() { echo "class-accuracy: $*" >&2; exit 1; }
ref=${REFERENCE:-static}
case $ref in static|span) ;; *) die "REFERENCE: '$ref' is not static or span";; esac
case $per in ''|*[!0-9]*) die "PER_CLASS: '$per' is not a whole number";; esac
[ "$per" -ge 1 ] || die "PER_CLASS: must be at least 1"
[ -r "$pop" ] || die "$pop: cannot read the population"
[ -r "$cfg" ] || die "$cfg: cannot read the site file"

rm -rf "$out" && mkdir -p "$out" || die "cannot create $out"
if [ -n "${SENSORS:-}" ]; then
  # CONFIG without its sensors block (the top-level key and its indented or
  # comment lines), then the sensors at SENSORS; the site file's own checks
  # judge the positions
  for x in $SENSORS; do
    case $x in ''|*[!0-9.]*|*.*.*|.*) die "SENSORS: '$x' is not a position in m";; esac
  done
  { awk '/^sensors:/ { skip = 1; next } skip && /^([ \t]|#|$)/ { next } { skip = 0; print }' "$cfg"
    echo "sensors:"
    i=0; for x in $SENSORS; do echo "  - {id: $i, at_m: $x, weight: 1}"; i=$((i + 1)); done
  } > "$out/site.yaml" || die "cannot write $out/site.yaml"
  cfg=$out/site.yaml
fi
if [ -n "${SOLVED:-}" ]; then
  # an earlier run's sample, passages and weights, judged again (REFERENCE)
  for f in sample.csv sim/meta.csv solve.txt; do
    [ -r "$SOLVED/$f" ] || die "SOLVED: $SOLVED/$f: cannot read"
  done
  mkdir -p "$out/sim" && cp "$SOLVED/sample.csv" "$SOLVED/solve.txt" "$out/" &&
    cp "$SOLVED/sim/meta.csv" "$out/sim/" || die "cannot copy $SOLVED"
else
  # 1. the sample: the header, then the first PER_CLASS records of each class
  awk -F, -v per="$per" -v p="$pop" '
    NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i
              if (!("class" in c)) { print p ": no class column (a class-format population is needed)" > "/dev/stderr"; exit 1 }
              print; next }
    ++k[$c["class"]] <= per { print }' "$pop" > "$out/sample.csv" || die "the sample"
  nveh=$(($(wc -l < "$out/sample.csv") - 1))
  [ "$nveh" -ge 1 ] || die "$pop: no vehicles"

  # 2. the passages
  # shellcheck disable=SC2086
  "$sim" --config "$cfg" --population "$out/sample.csv" --out "$out/sim" --vehicles "$nveh" \
    --seed "${SEED:-1}" ${SIM_ARGS:-} 2>"$out/sim.err" || die "sim_publisher --out: $(cat "$out/sim.err")"

  # 3. every vehicle weighed: NAME<TAB>amfi-solve's JSON line (or "refused")
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    { s = $c["axle_spacings_m"]; gsub(";", ",", s)
      print $c["name"], $c["speed_mps"], $c["entry_time_s"], s }' "$out/sim/meta.csv" > "$out/passages.txt" ||
    die "meta.csv"
  : > "$out/solve.txt"
  while read -r name speed entry sp; do
    # shellcheck disable=SC2086
    if r=$("$solve" --config "$cfg" --accel "$out/sim/$name.csv" --speed "$speed" \
             --axle-spacing "$sp" --entry-time "$entry" ${SOLVE_ARGS:-} 2>>"$out/solve.err"); then
      printf '%s\t%s\n' "$name" "$r"
    else
      rc=$?
      [ $rc -eq 1 ] || die "amfi-solve $name exited $rc: $(tail -1 "$out/solve.err")"
      printf '%s\trefused\n' "$name"
    fi
  done < "$out/passages.txt" >> "$out/solve.txt"
fi

# 4. criteria per class: vehicles.csv and weights-CLASS.csv
awk -v out="$out" -v ref="$ref" '
  FNR == 1 { f++ }
  # the sample: class of record k (vehicle v0000k)
  f == 1 { if (FNR == 1) { split($0, h, ","); for (i in h) hc[h[i]] = i; next }
           split($0, a, ","); cls[sprintf("v%05d", FNR - 1)] = a[hc["class"]]; next }
  # meta.csv: the true static loads
  f == 2 { if (FNR == 1) { n = split($0, h, ","); for (i = 1; i <= n; i++) mc[h[i]] = i; next }
           split($0, a, ","); nm = a[mc["name"]]
           if (ref == "span") {  # the mean contact force on the span, in kg
             k = split(a[mc["mean_forces_N"]], fz, ";"); tk[nm] = ""; tg[nm] = 0
             for (i = 1; i <= k; i++) { tk[nm] = tk[nm] (i > 1 ? ";" : "") sprintf("%.6f", fz[i] / 9.81); tg[nm] += fz[i] / 9.81 }
           } else { tk[nm] = a[mc["axle_kgs"]]; tg[nm] = a[mc["gvw_kg"]] }
           next }
  # solve.txt
  { split($0, a, "\t"); name = a[1]; j = a[2]; c = cls[name]
    if (j == "refused") { refused = refused " " name "(" c ")"; nref++; next }
    na = split(tk[name], t, ";")
    match(j, /"axle_kg":\[[^]]*\]/); s = substr(j, RSTART + 11, RLENGTH - 12)
    if (split(s, m, ",") != na) { print "class-accuracy: " name ": " na " true axles, amfi-solve gave " s > "/dev/stderr"; exit 1 }
    match(j, /"gvw_kg":[-0-9.e+]*/); gvw = substr(j, RSTART + 9, RLENGTH - 9)
    sc = "null"; if (match(j, /"class":"[^"]*"/)) sc = substr(j, RSTART + 9, RLENGTH - 10)
    if (sc != c) { other = other " " name "(" c "->" sc ")"; nother++ }
    # the groups: every "axles":[...] of the JSON line, in order
    rest = j; ng = 0; gs = ""
    while (match(rest, /"axles":\[[0-9,]*\]/)) {
      g = substr(rest, RSTART + 9, RLENGTH - 10); rest = substr(rest, RSTART + RLENGTH)
      ng++; nk = split(g, ax, ","); gs = gs (ng > 1 ? "-" : "") nk
      mm = 0; rr = 0
      for (i = 1; i <= nk; i++) { mm += m[ax[i] + 1]; rr += t[ax[i] + 1] }
      if (nk == 1) row(c, "single", mm, rr)
      else {
        row(c, "group", mm, rr)
        for (i = 1; i <= nk; i++) row(c, "group_axle", m[ax[i] + 1], t[ax[i] + 1])
      }
    }
    if (ng == 0) { print "class-accuracy: " name ": no groups in amfi-solve'"'"'s line" > "/dev/stderr"; exit 1 }
    row(c, "gross", gvw, tg[name])
    ls = s; gsub(",", ";", ls)
    printf "%s,%s,%s,%s,%.6f,%.3f,%s,%s\n", name, c, sc, gs, tg[name], gvw, tk[name], ls >> (out "/vehicles.csv")
    seen[c] = 1 }
  function row(c, k, mm, rr) {
    line = sprintf("%s,%.6f,%.6f", k, mm, rr)
    if (!hd[c]++) print "criterion,measured_kg,reference_kg" > (out "/weights-" c ".csv")
    if (!hd["all"]++) print "criterion,measured_kg,reference_kg" > (out "/weights-all.csv")
    print line >> (out "/weights-" c ".csv"); print line >> (out "/weights-all.csv") }
  BEGIN { print "name,class,class_solved,groups,gvw_true_kg,gvw_kg,axle_true_kg,axle_kg" > (out "/vehicles.csv") }
  END { for (c in seen) cl = cl " " c
        printf "%d %s|%s|%d %s\n", nother, other, refused, nref, cl > (out "/summary.txt") }
' "$out/sample.csv" "$out/sim/meta.csv" "$out/solve.txt" || die "the criteria"

# 5. amfi-accuracy per class (the classes in the sample's order), then all
classes=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "class") k = i; next }
                   !s[$k]++ { print $k }' "$out/sample.csv")
{
  printf '%-6s %5s  %-10s %8s %7s %7s %7s  %s\n' class n criterion mean_pct std_pct pi_pct pi0_pct cost323
  for c in $classes all; do
    w=$out/weights-$c.csv
    [ -f "$w" ] || continue
    "$acc" --input "$w" --condition "${CONDITION:-RR2}" --environment "${ENVIRONMENT:-I}" \
      > "$out/accuracy-$c.json" 2>>"$out/accuracy.err"
    rc=$?
    # exit 1 with its lines: a criterion without a class (too few values);
    # without its overall line: the input was refused
    [ $rc -le 1 ] && grep -q '"criterion":"overall"' "$out/accuracy-$c.json" ||
      die "amfi-accuracy on $w exited $rc: $(tail -1 "$out/accuracy.err")"
    for k in gross group single group_axle; do
      l=$(grep "\"criterion\":\"$k\"" "$out/accuracy-$c.json") || continue
      printf '%s\n' "$l" | awk -v c="$c" -v k="$k" '
        function num(key, fmt) { if (match($0, "\"" key "\":[-0-9.e+]+")) return sprintf(fmt, substr($0, RSTART + length(key) + 3, RLENGTH - length(key) - 3)); return "-" }
        { cl = "-"
          if (match($0, /"class":"[^"]*"/)) cl = substr($0, RSTART + 9, RLENGTH - 10)
          else if (match($0, /"reason":"[^"]*"/)) { r = substr($0, RSTART + 10, RLENGTH - 11); sub(/ \(.*/, "", r); cl = "none: " r }
          printf "%-6s %5s  %-10s %8s %7s %7s %7s  %s\n", c, num("n", "%d"), k, num("mean_pct", "%+.2f"), num("std_pct", "%.2f"), num("pi_pct", "%.1f"), num("pi0_pct", "%.1f"), cl }'
    done
  done
  awk -F'|' '{ split($1, o, " "); printf "classed otherwise by amfi-solve: %d%s\n", o[1], substr($1, length(o[1]) + 1)
               split($3, r, " "); printf "refused by amfi-solve: %d %s\n", r[1], $2 }' "$out/summary.txt"
} | tee "$out/table.txt"

# 6. why a group or a single axle is harder than the gross weight: the errors
# (kg) of neighbouring groups of a vehicle (a single axle a group of one),
# their correlation and the RMS relative errors of each and of their sum
awk -F, 'NR > 1 { c = $2; ng = split($4, g, "-"); split($7, t, ";"); split($8, m, ";"); a = 1
    for (i = 1; i <= ng; i++) { T[i] = M[i] = 0
      for (k = 0; k < g[i]; k++) { T[i] += t[a]; M[i] += m[a]; a++ } }
    for (i = 1; i < ng; i++) {
      e1 = M[i] - T[i]; e2 = M[i + 1] - T[i + 1]; n[c]++
      s1[c] += e1; s2[c] += e2; q1[c] += e1 * e1; q2[c] += e2 * e2; x[c] += e1 * e2
      P1[c] += (100 * e1 / T[i]) ^ 2; P2[c] += (100 * e2 / T[i + 1]) ^ 2
      PS[c] += (100 * (e1 + e2) / (T[i] + T[i + 1])) ^ 2 } }
  END { printf "%-6s %5s %7s %9s %9s %9s\n", "class", "pairs", "corr", "rms_1_pct", "rms_2_pct", "rms_sum_pct"
    for (c in n) { N = n[c]; v1 = q1[c] / N - (s1[c] / N) ^ 2; v2 = q2[c] / N - (s2[c] / N) ^ 2
      cv = x[c] / N - s1[c] / N * s2[c] / N
      printf "%-6s %5d %7.2f %9.2f %9.2f %9.2f\n", c, N, (v1 > 0 && v2 > 0 ? cv / sqrt(v1 * v2) : 0),
             sqrt(P1[c] / N), sqrt(P2[c] / N), sqrt(PS[c] / N) } }' "$out/vehicles.csv" > "$out/pairs.txt" ||
  die "pairs.txt"
