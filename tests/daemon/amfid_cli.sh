#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid_cli.sh: amfid's command line (getopt_long): --help and --version
# exit 0 on stdout; long and short options, "--opt=value" and "--opt value",
# "--" ending the options; every bad command line exits 2 with one line on
# stderr naming the option by its long name, and nothing on stdout; every
# configuration key --help names is a key of the loader's table.
# Usage: amfid_cli.sh AMFID CONFIG TEST_CONFIG_MAN
set -u
. "$(dirname "$0")/../common/proc.sh"
amfid=$1 config=$2 keys=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
problem() { echo "FAIL $name: $*"; failures=$((failures + 1)); }

# ok NAME PATTERN ARGS...: exit 0, stdout matches PATTERN, stderr empty
ok() {
    name=$1 pattern=$2
    shift 2
    "$amfid" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    [ $rc -eq 0 ] || problem "status $rc: $(head -c 300 "$tmp/err")"
    grep -Eq -- "$pattern" "$tmp/out" || problem "stdout lacks /$pattern/: $(head -c 300 "$tmp/out")"
    [ -s "$tmp/err" ] && problem "stderr: $(head -c 300 "$tmp/err")"
}
# bad NAME PATTERN ARGS...: exit 2, one stderr line matching PATTERN, no stdout
bad() {
    name=$1 pattern=$2
    shift 2
    "$amfid" "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    [ $rc -eq 2 ] || problem "status $rc, expected 2"
    [ "$(wc -l < "$tmp/err")" -eq 1 ] || problem "stderr: $(cat "$tmp/err")"
    grep -Eq -- "$pattern" "$tmp/err" || problem "stderr '$(cat "$tmp/err")' does not match /$pattern/"
    [ -s "$tmp/out" ] && problem "stdout: $(head -c 300 "$tmp/out")"
}

ok help '^usage: amfid ' --help
ok help-short '--check-config' -h
ok version '^amfid [0-9]+\.[0-9]+' --version
# the keys --help names (daemon.store.path, daemon.lcm_url, ...) exist
name=help-keys
"$keys" --print > "$tmp/keys" || problem "test_config_man --print"
"$amfid" --help > "$tmp/help"
named=$(grep -Eo '(site|bridge|sensors|solver|daemon|simulation|alerts|metrics|report|detector|ingest|classes)\.[a-z_.]*[a-z_]' "$tmp/help" | grep -v '\.md$' | sort -u)
[ -n "$named" ] || problem "--help names no configuration key"
for k in $named; do
    grep -q "^\*$k\* (" "$tmp/keys" || problem "--help names $k, not a configuration key"
done
ok version-short '^amfid [0-9]+\.[0-9]+' -V
ok check-long ': ok \(site local, bridge' --config "$config" --check-config
ok check-equals ': ok \(site local, bridge' --config="$config" --check-config
ok check-short ': ok \(site local, bridge' -c "$config" -C
ok check-joined ': ok \(site local, bridge' -c"$config" -C
ok db-override 'store /tmp/x\.db\)' -C -c "$config" --db=/tmp/x.db
ok db-short 'store /tmp/y\.db\)' -C -c "$config" -d /tmp/y.db -u file:///dev/null
ok dashdash ': ok' -c "$config" -C --

bad unknown '^amfid: --bogus: unknown option' --bogus
bad unknown-short '^amfid: -x: unknown option' -x
bad missing '^amfid: --config: needs a value' --config
bad missing-short '^amfid: --config: needs a value' -c
bad empty '^amfid: --db: empty value' -C --db=
bad stray '^amfid: extra: unexpected argument' -c "$config" -C extra
bad after-dashdash '^amfid: --help: unexpected argument' -c "$config" -C -- --help
bad no-flag-value '^amfid: --check-config: unknown option' --check-config=1
bad no-config '' --config "$tmp/none.yaml" --check-config

# The bus key (docs/messages.md): --make-bus-key makes a 0600 key and never
# overwrites one; amfid refuses to start with a key group or others can read,
# with a key of the wrong size, or with daemon.bus.auth required and no key
# at all; every refusal names the file (or says where amfid looked).
unset CREDENTIALS_DIRECTORY
ok make-bus-key "new bus key $tmp/k1" --make-bus-key "$tmp/k1"
name=make-bus-key-mode
[ "$(stat -c '%a %s' "$tmp/k1")" = "600 32" ] || problem "the key is $(stat -c '%a %s bytes' "$tmp/k1")"
name=make-bus-key-again
cp "$tmp/k1" "$tmp/k1.copy"
"$amfid" --make-bus-key "$tmp/k1" > "$tmp/out" 2> "$tmp/err" && problem "an existing key overwritten"
grep -q "$tmp/k1: cannot create: File exists (an existing key is never overwritten)" "$tmp/err" ||
    problem "stderr: $(cat "$tmp/err")"
cmp -s "$tmp/k1" "$tmp/k1.copy" || problem "the existing key changed"
# start-up refusals: exit 2 before the bus is read (a store in $tmp, the in-memory bus)
refused() {
    name=$1 pattern=$2
    shift 2
    "$amfid" -c "$config" -d "$tmp/s.db" -u memq:// "$@" > "$tmp/out" 2> "$tmp/err"
    rc=$?
    [ $rc -eq 2 ] || problem "status $rc, expected 2: $(tail -3 "$tmp/err")"
    grep -Eq -- "$pattern" "$tmp/err" || problem "stderr '$(cat "$tmp/err")' does not match /$pattern/"
    grep -q "running" "$tmp/err" && problem "amfid ran"
}
cp "$tmp/k1" "$tmp/k644" && chmod 644 "$tmp/k644"
refused key-mode-644 "bus key $tmp/k644: mode 0644 lets group or others read it; refused" \
    --bus-key "$tmp/k644"
(umask 077 && head -c 31 /dev/urandom > "$tmp/k31")
refused key-size "bus key $tmp/k31: 31 bytes: neither 32 raw bytes nor 64 hex digits" \
    --bus-key "$tmp/k31"
refused key-missing "bus key $tmp/none: cannot open" --bus-key "$tmp/none"
refused no-key "daemon.bus.auth is required but there is no bus key"
mkdir -p "$tmp/cred" && cp "$tmp/k644" "$tmp/cred/amfi-bus-key"
CREDENTIALS_DIRECTORY=$tmp/cred refused credential-mode \
    "bus key $tmp/cred/amfi-bus-key: mode 0644 .*\(from the credential\)"
# a hex key is accepted (and the run then reads the in-memory bus until SIGTERM)
name=hex-key
od -An -tx1 -v "$tmp/k1" | tr -d ' \n' > "$tmp/khex" && echo >> "$tmp/khex" && chmod 600 "$tmp/khex"
# the file is emptied here, not by the background job's redirection, which may
# run after the first grep below and let it see the previous run's "running"
: > "$tmp/err"
"$amfid" -c "$config" -d "$tmp/h.db" -u memq:// --bus-key "$tmp/khex" 2> "$tmp/err" &
hpid=$!
wait_for running "$tmp/err" $hpid 60 || true
grep -q "bus authentication required, key $tmp/khex (from the option)" "$tmp/err" ||
    problem "hex key not taken: $(head -5 "$tmp/err")"
kill -TERM $hpid 2>/dev/null; wait $hpid || problem "amfid with a hex key exited $?"

# daemon.bus.auth: off (a lab bus) starts without a key, with a warning
name=auth-off
sed "s/^    auth: required .*/    auth: off/" "$config" > "$tmp/off.yaml"
grep -q "^    auth: off$" "$tmp/off.yaml" || problem "the test's daemon.bus.auth did not apply"
: > "$tmp/err"
"$amfid" -c "$tmp/off.yaml" -d "$tmp/o.db" -u memq:// 2> "$tmp/err" &
opid=$!
wait_for running "$tmp/err" $opid 60 || true
grep -q "daemon.bus.auth is off: every message on the bus is accepted unchecked" "$tmp/err" ||
    problem "no warning: $(head -5 "$tmp/err")"
kill -TERM $opid 2>/dev/null; wait $opid || problem "amfid with auth off exited $?"

echo "amfid_cli.sh: $failures failed"
[ "$failures" -eq 0 ]
