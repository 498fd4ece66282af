#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# no_source_tree.sh: no program knows the source tree it was built from. Its
# --help (which lists where it looks for data files) and its read-only data
# must not name a path inside SRC_DIR other than a source file (.c, .h: the
# sanitizers keep source locations there, debuggers too; not for finding
# files); every program answers --version with "NAME VERSION". Run with
# AMFI_DATA_DIR unset.
# Usage: no_source_tree.sh SRC_DIR PROGRAM...
set -u
src=$1
shift
fail() { echo "FAIL: $*"; exit 1; }
unset AMFI_DATA_DIR
for prog in "$@"; do
  name=$(basename "$prog")
  help=$("$prog" --help) || fail "$name --help exited $?"
  case $help in *"$src"*) fail "$name --help names the source tree $src";; esac
  paths=$(readelf -p .rodata "$prog" 2>/dev/null | grep -oE "$src/[^ ]*" | grep -vE '\.[ch]$')
  [ -z "$paths" ] || fail "$name: .rodata names $(printf '%s' "$paths" | head -1)"
  v=$("$prog" --version) || fail "$name --version exited $?"
  printf '%s\n' "$v" | grep -Eq "^$name [0-9]+\.[0-9]+\.[0-9]+" || fail "$name --version: '$v'"
  echo "ok   $name: $v"
done
echo "no_source_tree: ok"
