#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Build the amfi .deb: a release tree configured for /usr (so the compiled-in
# paths, the systemd unit and the package's files agree), then cpack -G DEB.
# Usage: scripts/package.sh [BUILD_DIR]   (default build/deb); prints the .deb's path.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$top/build/deb}
mkdir -p "$(dirname "$dir")"
bash "$top/scripts/build.sh" "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_INSTALL_PREFIX=/usr >/dev/null
(cd "$dir" && cpack -G DEB >cpack.log 2>&1) || { cat "$dir/cpack.log" >&2; exit 1; }
ls "$dir"/amfi_*.deb
