#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Compare two text outputs that hold floating-point numbers, numerically:
# the same lines and tokens (split at blanks, commas, '|', ';', '=', ':',
# brackets), words and integers exactly, other numbers within
# |a - b| <= ABS + REL * max(|a|, |b|) (nan equals nan, inf equals inf of
# its sign). Floating point differs in its last bits between CPUs, BLAS
# kernels and compilers, so no test compares such output byte for byte.
#   num_cmp.sh [-r REL] [-a ABS] A B
# REL default 1e-9, ABS default 1e-12. Exit 0 alike, 1 (naming the first
# difference: file, line, token) when not, 2 on usage.
set -u
rel=1e-9 abs=1e-12
while [ $# -gt 2 ]; do
  case $1 in
    -r) rel=$2; shift 2 ;;
    -a) abs=$2; shift 2 ;;
    *) break ;;
  esac
done
[ $# -eq 2 ] || { echo "usage: num_cmp.sh [-r REL] [-a ABS] A B" >&2; exit 2; }
[ -r "$1" ] && [ -r "$2" ] || { echo "num_cmp.sh: cannot read $1 or $2" >&2; exit 2; }
exec awk -v rel="$rel" -v abs="$abs" -v fa="$1" -v fb="$2" '
function isint(t) { return t ~ /^[-+]?[0-9]+$/ }
function isnum(t) { return t ~ /^[-+]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][-+]?[0-9]+)?$/ }
function special(t) { t = tolower(t); sub(/^\+/, "", t); return t ~ /^-?(nan|inf|infinity)$/ }
function norm(t) { t = tolower(t); sub(/^\+/, "", t); sub(/infinity/, "inf", t); sub(/^-nan/, "nan", t); return t }
function fabs(x) { return x < 0 ? -x : x }
function differ(where, a, b) {
  printf "num_cmp: %s and %s differ at %s: \"%s\" vs \"%s\"\n", fa, fb, where, a, b
  bad = 1; exit 1
}
BEGIN {
  sep = "[][ \t,|;=:()]+"
  for (ln = 1; ; ln++) {
    ra = (getline la < fa); rb = (getline lb < fb)
    if (ra < 0 || rb < 0) { print "num_cmp: read error"; bad = 2; exit 2 }
    if (ra == 0 && rb == 0) break
    if (ra == 0 || rb == 0) differ("line " ln " (one file ends)", ra ? la : "EOF", rb ? lb : "EOF")
    na = split(la, ta, sep); nb = split(lb, tb, sep)
    if (na != nb) differ("line " ln " (" na " vs " nb " tokens)", la, lb)
    for (i = 1; i <= na; i++) {
      a = ta[i]; b = tb[i]
      if (a == b) continue
      where = "line " ln " token " i
      if (special(a) || special(b)) {
        if (!(special(a) && special(b) && norm(a) == norm(b))) differ(where, a, b)
        continue
      }
      if (!isnum(a) || !isnum(b) || (isint(a) && isint(b))) differ(where, a, b)
      x = a + 0; y = b + 0
      m = fabs(x) > fabs(y) ? fabs(x) : fabs(y)
      if (fabs(x - y) > abs + rel * m) differ(where, a, b)
    }
  }
  exit 0
}
END { exit bad }'
