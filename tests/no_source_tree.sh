#!/bin/sh
# no_source_tree.sh: no program knows the source tree it was built from. Its
# --help (which lists where it looks for data files) and its read-only data
# must not name SRC_DIR; every program answers --version with "NAME VERSION".
# (Debug information may name the sources: that is for debuggers, not for
# finding files.) Run with AMFI_DATA_DIR unset.
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
  readelf -p .rodata "$prog" 2>/dev/null | grep -qF "$src" && fail "$name: .rodata names $src"
  v=$("$prog" --version) || fail "$name --version exited $?"
  printf '%s\n' "$v" | grep -Eq "^$name [0-9]+\.[0-9]+\.[0-9]+" || fail "$name --version: '$v'"
  echo "ok   $name: $v"
done
echo "no_source_tree: ok"
