#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# help_keys.sh: every configuration key a program's --help names is a key
# of the loader's table (test_config_man --print, the keys of
# amfid.yaml(5)); "SECTION.*" must be a section with keys. amfid --help once
# named daemon.db_path, a key that does not exist (daemon.store.path).
#   help_keys.sh TEST_CONFIG_MAN PROGRAM...
set -u
keys=$1; shift
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$keys" --print > "$tmp/keys" || { echo "FAIL: test_config_man --print"; exit 1; }
failures=0
for p in "$@"; do
    "$p" --help > "$tmp/help" 2>&1 || { echo "FAIL: $p --help exited $?"; failures=$((failures + 1)); continue; }
    named=$(grep -Eo '\b(site|bridge|sensors|solver|daemon|simulation|alerts|metrics|report|detector|ingest|classes)\.[a-z_.]*[a-z_*]' "$tmp/help" |
            grep -Ev '\.(md|dat|yaml|c|h)$' | sort -u)
    for k in $named; do
        case $k in
        *.\*) grep -q "^\*${k%.\*}\." "$tmp/keys" || { echo "FAIL: $(basename "$p") --help names $k, not a section"; failures=$((failures + 1)); } ;;
        *) grep -q "^\*$k\* (" "$tmp/keys" || { echo "FAIL: $(basename "$p") --help names $k, not a configuration key"; failures=$((failures + 1)); } ;;
        esac
    done
    echo "$(basename "$p"): $(echo $named | wc -w) key(s) named: $(echo $named)"
done
[ $failures = 0 ] || exit 1
echo "help_keys: ok"
