#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfid_cli.sh: amfid's command line (getopt_long): --help and --version
# exit 0 on stdout; long and short options, "--opt=value" and "--opt value",
# "--" ending the options; every bad command line exits 2 with one line on
# stderr naming the option by its long name, and nothing on stdout.
# Usage: amfid_cli.sh AMFID CONFIG
set -u
amfid=$1 config=$2
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

echo "amfid_cli.sh: $failures failed"
[ "$failures" -eq 0 ]
