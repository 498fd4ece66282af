#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# man_pages.sh: a program's man page (scdoc source) lists every long option
# its --help prints, and renders with scdoc and man -l without a warning.
# Usage: man_pages.sh PROGRAM PAGE.scd
set -u
prog=$1 page=$2
fail() { echo "FAIL: $*"; exit 1; }
for tool in scdoc man; do
  command -v $tool > /dev/null || { echo "man_pages: no $tool (scripts/install-deps.sh)"; exit 77; }
done
help=$("$prog" --help) || fail "$prog --help exited $?"
opts=$(printf '%s\n' "$help" | grep -oE -- '--[a-z0-9][a-z0-9-]*' | sort -u)
[ -n "$opts" ] || fail "$prog --help lists no long option"
n=0
for o in $opts; do
  grep -qF -- "*$o*" "$page" || fail "$page does not document $o (printed by $prog --help)"
  n=$((n + 1))
done
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
scdoc < "$page" > "$dir/page" 2> "$dir/scdoc.err" || fail "scdoc: $(cat "$dir/scdoc.err")"
MANWIDTH=80 man --warnings -l -P cat - < "$dir/page" > "$dir/out" 2> "$dir/man.err" ||
  fail "man -l exited $?: $(cat "$dir/man.err")"
[ ! -s "$dir/man.err" ] || fail "man -l warned: $(cat "$dir/man.err")"
name=$(basename "$page" .scd)
grep -q "^NAME" "$dir/out" || fail "rendered page has no NAME section"
echo "man_pages: $name documents all $n long options of $prog --help and renders"
