#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# sim_production_bus.sh: sim_publisher refuses to stream on amfid's bus
# (on a site box its simulated vehicles would be weighed and stored as real
# passages) unless --allow-production-bus is given: amfid's built-in
# default (LCM's default URL, also by $LCM_DEFAULT_URL or with other
# options), the daemon.lcm_url of the configuration it reads; a private bus,
# --out and --lcm-url none are not touched. Inside a private network
# namespace (tests/common/bus_prologue.sh): nothing leaves it.
#   sim_production_bus.sh SIM_PUBLISHER
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
sim=$1
fail() { echo "FAIL: $*"; exit 1; }
run() { "$sim" --vehicles 1 --headway 2 --speedup max --seed 3 "$@" > "$dir/out" 2> "$dir/err"; }
refused() { # WHAT, then the arguments
  what=$1; shift
  run "$@"; rc=$?
  [ $rc -eq 2 ] || fail "$what: exit $rc, not 2 (refused): $(tail -2 "$dir/err")"
  grep -q "refusing to publish on" "$dir/err" || fail "$what: no refusal: $(cat "$dir/err")"
  grep -q -- "--allow-production-bus" "$dir/err" || fail "$what: the message does not name the flag"
  grep -q "store them as real passages" "$dir/err" || fail "$what: the message does not say why"
}
allowed() { # WHAT, then the arguments
  what=$1; shift
  run "$@" || fail "$what: exit $?: $(tail -3 "$dir/err")"
}

refused "no URL (LCM's default)"
grep -q "amfid's default bus" "$dir/err" || fail "no URL: $(cat "$dir/err")"
refused "LCM's default with other options" --lcm-url 'udpm://239.255.76.67:7667?ttl=1'
refused "LCM's default without a port" --lcm-url 'udpm://239.255.76.67'
LCM_DEFAULT_URL='udpm://239.255.76.67:7667?ttl=0' refused '$LCM_DEFAULT_URL'
grep -q 'LCM_DEFAULT_URL' "$dir/err" || fail "\$LCM_DEFAULT_URL not named: $(cat "$dir/err")"
# the configuration's own daemon.lcm_url: the bus amfid reads with that file
sed -e 's|^  lcm_url: "" .*|  lcm_url: "udpm://239.255.76.99:7670?ttl=0"|' \
  "$(dirname "$0")/../../config/amfid.yaml" > "$dir/site.yaml"
grep -q '^  lcm_url: "udpm://239.255.76.99:7670' "$dir/site.yaml" || fail "the test's daemon.lcm_url did not apply"
refused "the configuration's daemon.lcm_url" --config "$dir/site.yaml" --lcm-url 'udpm://239.255.76.99:7670'
grep -q "$dir/site.yaml: daemon.lcm_url" "$dir/err" || fail "the file not named: $(cat "$dir/err")"

# the installed amfid.yaml's daemon.lcm_url (the path --help names), in a
# private mount namespace over a tmpfs: the real one is never touched
inst=$("$sim" --help | sed -n 's|^ *\(/[^ ]*/amfid/amfid\.yaml\)'"'"'s or the configuration'"'"'s$|\1|p')
[ -n "$inst" ] || fail "--help does not name the installed amfid.yaml"
etc=$(dirname "$(dirname "$inst")")
sed -e 's|^  lcm_url: "" .*|  lcm_url: "udpm://239.255.76.97:7671?ttl=0"|' \
  "$(dirname "$0")/../../config/amfid.yaml" > "$dir/installed.yaml"
cat > "$dir/inst.sh" <<EOS
mkdir -p "$etc" && mount -t tmpfs none "$etc" && mkdir "$etc/amfid" && cp "$dir/installed.yaml" "$inst" &&
  exec "$sim" --vehicles 1 --headway 2 --speedup max --seed 3 --lcm-url 'udpm://239.255.76.97:7671'
EOS
if unshare --mount true 2> /dev/null; then
    unshare --mount sh "$dir/inst.sh" > "$dir/out" 2> "$dir/err"
    rc=$?
    [ $rc = 2 ] && grep -q "the bus of the installed amfid ($inst: daemon.lcm_url)" "$dir/err" ||
        fail "the installed amfid.yaml's bus: exit $rc: $(cat "$dir/err")"
    [ -f "$inst" ] && grep -q '239.255.76.97:7671' "$inst" && fail "the test wrote the real $inst"
    echo "installed amfid.yaml: $(cat "$dir/err" | cut -c1-120)"
else
    echo "no mount namespace: the installed amfid.yaml's case skipped"
fi

# allowed: the flag, a private bus, no bus, files
allowed "--allow-production-bus" --allow-production-bus
grep -q "refusing" "$dir/err" && fail "--allow-production-bus still refused"
allowed "a private bus" --lcm-url 'udpm://239.255.76.68:7668?ttl=0'
allowed "a private bus beside the configuration's" --config "$dir/site.yaml" \
  --lcm-url 'udpm://239.255.76.68:7668?ttl=0'
allowed "--lcm-url none" --lcm-url none --log "$dir/x.lcmlog"
allowed "--out" --out "$dir/o"
# the help names the flag
"$sim" --help | grep -q -- "--allow-production-bus" || fail "--help does not name --allow-production-bus"
echo "sim_publisher production bus: ok"
