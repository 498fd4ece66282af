#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Configure and build one tree. Usage: scripts/build.sh DIR [extra cmake args]
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:?usage: build.sh DIR [cmake args]}
shift
mkdir -p "$dir"
cmake -S "$top" -B "$dir" -DAMFI_WERROR=ON "$@" >"$dir.configure.log" 2>&1 ||
  { cat "$dir.configure.log" >&2; exit 1; }
cmake --build "$dir" -j"$(nproc)"
