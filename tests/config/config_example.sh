#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# config_example.sh: amfid --check-config on the untouched shipped example
# (config/amfid.yaml: site.id local, the paper's 20 m bridge, no site.name)
# says ok but prints a WARNING line for each, at FILE:LINE of the key, and
# exits 2 with --strict; a configured site (its own id, name and bridge)
# has no warning, also with --strict; --strict without --check-config is a
# bad command line.
#   config_example.sh AMFID CONFIG
set -u
amfid=$1 config=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$amfid" --check-config --config "$config" > "$tmp/out" 2> "$tmp/err" || fail "exit $? on the example: $(cat "$tmp/err")"
cat "$tmp/out"
[ -s "$tmp/err" ] && fail "stderr: $(cat "$tmp/err")"
l_id=$(grep -n '^  id: local' "$config" | cut -d: -f1)
grep -qx "amfid: $config:$l_id: site.id: WARNING: 'local' is the shipped example's site id: .*" "$tmp/out" ||
  fail "no warning for site.id at line $l_id"
grep -q "^amfid: $config:[0-9]*: bridge: WARNING: the bridge is the paper's 20 m example" "$tmp/out" ||
  fail "no warning for the paper's bridge"
grep -q "^amfid: $config:[0-9]*: site.name: WARNING: not given" "$tmp/out" || fail "no warning for site.name"
grep -q ": ok (site local, .* with 3 warning(s)$" "$tmp/out" || fail "the verdict does not count 3 warnings"
"$amfid" --check-config --strict --config "$config" > "$tmp/out" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "--strict on the example: exit $rc, not 2"
grep -q "refused (--strict)" "$tmp/out" || fail "--strict: $(cat "$tmp/out")"

# only the bridge's name changed: the model is still the paper's
sed -e 's/^  id: local .*/  id: a1-km12/' -e 's/^  # name: .*/  name: "Sava bridge, km 12"/' \
    -e 's/^  name: paper-20m .*/  name: sava-km12/' "$config" > "$tmp/half.yaml"
"$amfid" --check-config --config "$tmp/half.yaml" > "$tmp/out" 2>&1 || fail "half: exit $?"
[ "$(grep -c WARNING "$tmp/out")" -eq 1 ] || fail "half configured: $(cat "$tmp/out")"
grep -q "half.yaml:[0-9]*: bridge: WARNING: the bridge is the paper's" "$tmp/out" || fail "half: $(cat "$tmp/out")"

# a configured site: its own id, name and bridge
sed -e 's/^  span_m: 20 .*/  span_m: 24/' -e 's/^    - {at_m: 20, type: roller}.*/    - {at_m: 24, type: roller}/' \
    -e 's/^  - {id: 0, at_m: 10, weight: 1}/  - {id: 0, at_m: 12, weight: 1}/' "$tmp/half.yaml" > "$tmp/site.yaml"
grep -q '^  span_m: 24' "$tmp/site.yaml" || fail "the test's span did not apply"
"$amfid" --check-config --strict --config "$tmp/site.yaml" > "$tmp/out" 2>&1 || fail "configured, --strict: exit $?: $(cat "$tmp/out")"
grep -q WARNING "$tmp/out" && fail "configured site warned: $(cat "$tmp/out")"
grep -q ": ok (site a1-km12, bridge sava-km12," "$tmp/out" || fail "configured: $(cat "$tmp/out")"

"$amfid" --strict --config "$config" > "$tmp/out" 2> "$tmp/err"
rc=$?
[ $rc -eq 2 ] && grep -q -- "--strict: only with --check-config" "$tmp/err" || fail "--strict alone: exit $rc: $(cat "$tmp/err")"
echo "amfid --check-config on the shipped example: ok"
