#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Build the amfi .deb: a release tree configured for /usr (so the compiled-in
# paths, the systemd unit and the package's files agree) with the
# distribution's build flags (dpkg-buildflags), then cpack -G DEB.
# Usage: scripts/package.sh [BUILD_DIR]   (default build/deb); prints the .deb's path.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
dir=${1:-$top/build/deb}
mkdir -p "$(dirname "$dir")"
# The distribution's build flags, as a Debian package build gets them
# (dpkg-buildflags, with every hardening feature unless the caller chose
# DEB_BUILD_MAINT_OPTIONS); the tree adds the same hardening on its own
# (cmake/amfi_hardening.cmake), so a flag dpkg leaves out is still there.
command -v dpkg-buildflags >/dev/null ||
  { echo "scripts/package.sh: dpkg-buildflags not found: apt-get install dpkg-dev (or run scripts/install-deps.sh)" >&2; exit 1; }
export DEB_BUILD_MAINT_OPTIONS=${DEB_BUILD_MAINT_OPTIONS:-hardening=+all}
flags() { (cd "$top" && dpkg-buildflags --get "$1"); }
cflags="$(flags CPPFLAGS) $(flags CFLAGS)"
ldflags=$(flags LDFLAGS)
bash "$top/scripts/build.sh" "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_INSTALL_PREFIX=/usr -DAMFI_TESTS=OFF \
  "-DCMAKE_C_FLAGS=$cflags" "-DCMAKE_EXE_LINKER_FLAGS=$ldflags" "-DCMAKE_SHARED_LINKER_FLAGS=$ldflags" \
  "-DCMAKE_MODULE_LINKER_FLAGS=$ldflags" >/dev/null
(cd "$dir" && cpack -G DEB >cpack.log 2>&1) || { cat "$dir/cpack.log" >&2; exit 1; }
ls "$dir"/amfi_*.deb
