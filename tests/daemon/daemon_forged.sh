#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Forged traffic from the LAN (docs/messages.md, "Signed messages"): amfid
# with the shipped configuration (config/amfid.yaml; only the key file and
# the store path added) and sim_publisher's real, signed vehicles in one
# private network namespace, the "site"; an attacker without the key in
# another, the "LAN", joined to it by a veth pair (10.231.0.1/30 the site,
# .2 the attacker; multicast routed over the veth on both sides, as on a
# real site whose bus follows its LAN interface). A sniffer records the bus
# (lcm-logger: what the attacker would capture on the LAN); once it holds
# two vehicles the attacker sends, as unicast datagrams to 10.231.0.1:7667
# and as multicast to LCM's group: a forged vehicle for each captured one
# unsigned (ids 991000+), the same signed with a wrong key as the real
# producer (ids 992000+), and every captured accel and vehicle message again
# (replays of valid signatures). Nothing leaves the two namespaces.
# Asserted: no forged row is stored; every real vehicle has one row, ok; no
# truth row (production: the truth channel is not subscribed); the refusals
# counted by reason equal what was sent (unsigned, bad_mac, replay).
# Then, with NFT_EXAMPLE (contrib/amfi-bus.nft) and nft installed, the
# example is loaded in the site's namespace (the sensors: this host's own
# address on the site's interface) and the attacker sends its unsigned
# vehicles again: the filter's drop counter must count every one, and amfid
# none (its refusal counts stay those of the first attack).
# An amfid without --make-bus-key (before the authenticated bus) runs the
# same attack unsigned, to show what it stores.
# Usage: daemon_forged.sh AMFID SIM_PUBLISHER LCM_FORGE CONFIG [NFT_EXAMPLE]
set -u
. "$(dirname "$0")/../common/proc.sh"
if [ "${AMFI_IN_NETNS:-}" != 1 ]; then
  exec unshare --net sh -c 'ip link set lo up && AMFI_IN_NETNS=1 exec sh "$0" "$@"' "$0" "$@"
fi
amfid=$1 sim=$2 forge=$3 config=$4 nftfile=${5:-}
N=8
dir=$(mktemp -d)
pids=""
cleanup() { for p in $pids; do kill -9 "$p" 2>/dev/null; done; rm -rf "$dir"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -15 "$f"; done; exit 1; }

# --- the attacker's namespace, joined by a veth pair ----------------------
unshare --net sleep 100000 &
attacker=$!; pids="$pids $attacker"
i=0; until [ "$(readlink /proc/$attacker/ns/net 2>/dev/null)" != "$(readlink /proc/$$/ns/net)" ] &&
           [ -n "$(readlink /proc/$attacker/ns/net 2>/dev/null)" ]; do
  i=$((i + 1)); [ $i -lt 100 ] || fail "no attacker namespace"; sleep 0.05; done
att() { nsenter --net=/proc/$attacker/ns/net "$@"; }
ip link add amfi-site type veth peer name amfi-lan || fail "ip link add veth"
ip link set amfi-lan netns "$attacker" || fail "veth into the attacker's namespace"
ip addr add 10.231.0.1/30 dev amfi-site && ip link set amfi-site up &&
  ip route add 224.0.0.0/4 dev amfi-site || fail "the site's end of the veth"
att ip link set lo up && att ip addr add 10.231.0.2/30 dev amfi-lan &&
  att ip link set amfi-lan up && att ip route add 224.0.0.0/4 dev amfi-lan ||
  fail "the attacker's end of the veth"
att ip route get 10.231.0.1 | grep -q "dev amfi-lan" || fail "no route from the attacker to the site"

# --- the site: amfid with the shipped configuration, the key, a store ------
auth=0
if "$amfid" --help 2>&1 | grep -q -- --make-bus-key; then
  auth=1
  "$amfid" --make-bus-key "$dir/bus.key" > /dev/null || fail "amfid --make-bus-key"
  [ "$(stat -c %a "$dir/bus.key")" = 600 ] || fail "the new key is not mode 600"
fi
sed -e "s|^    # key_file: .*|    key_file: $dir/bus.key|" \
    -e "s|^    path: amfi.db .*|    path: $dir/forged.db|" "$config" > "$dir/amfid.yaml"
grep -q "path: $dir/forged.db" "$dir/amfid.yaml" || fail "the store path did not apply"
[ $auth = 0 ] || grep -q "^    key_file: $dir/bus.key$" "$dir/amfid.yaml" ||
  fail "the key file did not apply"
diff "$config" "$dir/amfid.yaml" | grep '^>' | sed 's/^/  config: /'
"$amfid" --config "$dir/amfid.yaml" 2> "$dir/amfid.log" &
apid=$!; pids="$pids $apid"
wait_for running "$dir/amfid.log" $apid 60 || fail "amfid did not start"
lcm-logger "$dir/capture.lcmlog" > "$dir/logger.log" 2>&1 &
lpid=$!; pids="$pids $lpid"
sleep 0.5
simkey=""; [ $auth = 0 ] || simkey="--bus-key $dir/bus.key"
"$sim" --dt 2.5e-4 --allow-production-bus --vehicles $N --headway 3 --speedup 3 --seed 21 $simkey 2> "$dir/sim.log" &
spid=$!; pids="$pids $spid"

# --- the attack, once the sniffer holds two vehicles ------------------------
i=0; while :; do
  cp "$dir/capture.lcmlog" "$dir/snap.lcmlog" 2>/dev/null &&
    [ "$("$forge" count - "$dir/snap.lcmlog")" -ge 2 ] && break
  i=$((i + 1)); [ $i -lt 600 ] || fail "the sniffer captured no two vehicles"; sleep 0.1
done
# the sniffer stops: with two sockets on port 7667 (SO_REUSEADDR) the kernel
# hands a unicast datagram to one of them only, and it must be amfid's
kill $lpid; wait $lpid 2>/dev/null
for addr in 10.231.0.1 239.255.76.67; do
  for m in unsigned wrongkey replay; do
    att "$forge" $m $addr "$dir/snap.lcmlog" > "$dir/sent.$m.$addr" || fail "lcm_forge $m $addr"
  done
done
sent() { cat "$dir"/sent.$1.* | awk '{s += $2} END {print s + 0}'; }
echo "attack from 10.231.0.2: $(sent unsigned) unsigned forged vehicles, $(sent wrongkey) signed" \
  "with a wrong key, $(sent replay) replayed messages (unicast to 10.231.0.1:7667 and multicast)"
# the nftables example in front of amfid: the sensor network is this host's
# own address on amfi-site (where its looped-back multicast comes in), the
# attacker's 10.231.0.2 is outside it
filtered=none
if [ -n "$nftfile" ] && command -v nft > /dev/null 2>&1; then
  sed -e 's|^define SENSOR_IF = .*|define SENSOR_IF = "amfi-site"|' \
      -e 's|^define SENSOR_NET = .*|define SENSOR_NET = 10.231.0.1/32|' "$nftfile" > "$dir/bus.nft"
  grep -q '^define SENSOR_NET = 10.231.0.1/32$' "$dir/bus.nft" || fail "the test's nft defines did not apply"
  nft -f "$dir/bus.nft" || fail "nft -f $nftfile"
  for addr in 10.231.0.1 239.255.76.67; do
    att "$forge" unsigned $addr "$dir/snap.lcmlog" > "$dir/nft.$addr" || fail "lcm_forge behind nft"
  done
  filtered=$(cat "$dir"/nft.* | awk '{s += $2} END {print s + 0}')
  dropped=$(nft list chain inet amfi_bus input | sed -n 's/.*counter packets \([0-9]*\) bytes .* drop.*/\1/p')
  echo "behind contrib/amfi-bus.nft: $filtered more forged datagrams sent, ${dropped:-no} dropped by the filter"
  [ "${dropped:-0}" -eq "$filtered" ] || fail "the nftables example dropped ${dropped:-no} of $filtered"
fi
wait $spid || fail "sim_publisher"
kill -TERM $apid
i=0; while kill -0 $apid 2>/dev/null; do
  i=$((i + 1)); [ $i -lt 3000 ] || fail "amfid did not stop"; sleep 0.1; done
wait $apid || fail "amfid exit status $?"

# --- what was stored, what was refused --------------------------------------
q() { sqlite3 "$dir/forged.db" "$1"; }
forged=$(q "SELECT count(*) FROM passages WHERE vehicle_id >= 991000")
rows=$(q "SELECT count(*) FROM passages WHERE vehicle_id BETWEEN 1 AND $N")
ok=$(q "SELECT count(*) FROM passages WHERE vehicle_id BETWEEN 1 AND $N AND status = 'ok'")
truth=$(q "SELECT count(*) FROM truth")
refused() { sed -n "s/.*refused since start: .* $1: \([0-9]*\)$/\1/p" "$dir/amfid.log" |
            awk '{s += $1} END {print s + 0}'; }
echo "stored: $forged forged rows, $rows rows of the $N real vehicles ($ok ok), $truth truth rows"
echo "refused: unsigned $(refused unsigned), bad_mac $(refused bad_mac), replay $(refused replay)," \
  "skew $(refused skew)"
sed -n 's/.*refused since start: /  /p' "$dir/amfid.log"
[ "$forged" -eq 0 ] || { q "SELECT vehicle_id, status, substr(reason, 1, 60) FROM passages
                              WHERE vehicle_id >= 991000 LIMIT 5" | sed 's/^/  forged row: /'
                         fail "$forged forged rows stored"; }
[ "$rows" -eq $N ] && [ "$ok" -eq $N ] || fail "real vehicles: $rows rows, $ok ok of $N"
[ "$truth" -eq 0 ] || fail "$truth truth rows stored by a production configuration"
[ "$(sent unsigned)" -gt 0 ] && [ "$(sent wrongkey)" -gt 0 ] && [ "$(sent replay)" -gt 0 ] ||
  fail "nothing sent"
[ "$(refused unsigned)" -eq "$(sent unsigned)" ] || fail "unsigned: sent $(sent unsigned), refused $(refused unsigned)"
[ "$(refused bad_mac)" -eq "$(sent wrongkey)" ] || fail "wrong key: sent $(sent wrongkey), refused $(refused bad_mac)"
[ "$(refused replay)" -eq "$(sent replay)" ] || fail "replays: sent $(sent replay), refused $(refused replay)"
grep -q "stopped: .* $(( $(sent unsigned) + $(sent wrongkey) + $(sent replay) )) refused by the bus authentication" \
  "$dir/amfid.log" || fail "the stop line does not count the refusals"
echo "forged traffic: nothing forged stored, $N of $N real vehicles ok, every forgery refused and counted"
