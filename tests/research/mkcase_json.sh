#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# mkcase_json.sh: amfi-mkcase prints its truth as JSON a parser accepts
# whatever the output file is called (quotes, backslashes, control
# characters); the file name comes back unchanged.
# Usage: mkcase_json.sh AMFI_MKCASE JSON_CHECK
set -u
mkcase=$1 check=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
tab=$(printf '\t')
for name in 'a"b.csv' 'back\slash.csv' "tab${tab}name.csv" 'plain.csv.gz'; do
  out="$dir/$name"
  "$mkcase" --out "$out" --speed 25 --scan-rate 500 > "$dir/json" 2> "$dir/err" ||
    fail "$name: exit $?: $(cat "$dir/err")"
  "$check" "file=$out" < "$dir/json" || fail "$name: not valid JSON: $(cat "$dir/json")"
  [ -s "$out" ] || fail "$name: no CSV written"
  echo "ok   $name: $(cat "$dir/json")"
done
echo "mkcase_json: ok"
