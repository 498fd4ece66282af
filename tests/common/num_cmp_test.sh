#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# tests/common/num_cmp.sh itself: what it takes as equal and what it refuses (the
# tests that compare floating-point output through it rely on both).
set -u
here=$(cd "$(dirname "$0")" && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/num_cmp.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
bad=0
case_() { # WANT(0 same, 1 differ) A B [OPTIONS...]
    want=$1
    printf '%b' "$2" > "$tmp/a"
    printf '%b' "$3" > "$tmp/b"
    shift 3
    sh "$here/num_cmp.sh" "$@" "$tmp/a" "$tmp/b" > "$tmp/out" 2>&1
    got=$?
    if [ "$got" -ne "$want" ]; then
        echo "FAIL: '$(cat "$tmp/a")' vs '$(cat "$tmp/b")' $*: exit $got, expected $want ($(cat "$tmp/out"))"
        bad=1
    fi
}
case_ 0 'a,1.0000000001,3\nb 2 nan\n' 'a,1.0000000002,3\nb 2 NaN\n'
case_ 1 'a,1.0000000001\n' 'a,1.0000000002\n' -r 1e-12
case_ 1 'x,3\n' 'x,4\n'                      # integers exactly
case_ 1 'x,3\n' 'x,3.001\n' -r 1e-6   # a number beside an integer
case_ 1 'ok|1.5\n' 'error|1.5\n'             # words exactly
case_ 1 '1.5\n' '1.5\n2\n'                   # one file ends
case_ 1 '1.5,2.5\n' '1.5\n'                  # a token missing
case_ 1 'inf\n' '-inf\n'
case_ 0 '-Infinity\n' '-inf\n'
case_ 1 'nan\n' '1.0\n'
case_ 0 '-1.84 %\n' '-1.85 %\n' -r 0 -a 0.0101
case_ 1 '-1.84 %\n' '-1.86 %\n' -r 0 -a 0.0101
case_ 0 '[1e-3 2.5e+02]\n' '[0.001 250]\n'
case_ 2 '1\n' '1\n' -x 1                     # usage
[ "$bad" -eq 0 ] && echo "num_cmp: ok"
exit "$bad"
