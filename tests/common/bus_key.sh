# SPDX-License-Identifier: GPL-3.0-or-later
# bus_key.sh: sourced by the tests that run amfid, sim_publisher or the
# lcm_* test programs (after $dir exists; tests/common/bus_prologue.sh does it for
# the bus tests). Makes the test's site bus key $dir/cred/amfi-bus-key (32
# random bytes, mode 0600) and exports CREDENTIALS_DIRECTORY=$dir/cred, the
# systemd credential every amfi program looks up when neither --bus-key nor
# daemon.bus.key_file names a key (docs/messages.md): amfid with the shipped
# daemon.bus.auth: required accepts what sim_publisher and the test programs
# sign with it. $bus_key is its path.
mkdir -p "$dir/cred"
bus_key="$dir/cred/amfi-bus-key"
(umask 077 && head -c 32 /dev/urandom > "$bus_key") || { echo "FAIL: cannot make $bus_key"; exit 1; }
chmod 600 "$bus_key"
CREDENTIALS_DIRECTORY="$dir/cred"
export CREDENTIALS_DIRECTORY
