#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install what is missing, build with AddressSanitizer + UndefinedBehaviorSanitizer
# and warnings as errors, and run the whole test suite under ctest; then a
# ThreadSanitizer tree of only what the daemon's thread test needs (amfid,
# sim_publisher) and that test there (tests/daemon/daemon_reload.sh). The main
# suite's summary line is printed last; the exit status is non-zero when
# either run failed.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
mkdir -p "$top/build"
bash "$top/scripts/build.sh" "$top/build/asan" -DAMFI_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
cmake -S "$top" -B "$top/build/tsan" -DAMFI_WERROR=ON -DAMFI_TSAN=ON \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo > "$top/build/tsan.configure.log" 2>&1 ||
  { cat "$top/build/tsan.configure.log" >&2; exit 1; }
cmake --build "$top/build/tsan" --target amfid sim_publisher -j"$(nproc)"
tsan=0
(cd "$top/build/tsan" && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -R '^daemon_reload$') ||
  tsan=$?
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1
cd "$top/build/asan"
main=0
ctest --output-on-failure -j2 || main=$?
[ "$tsan" -eq 0 ] || echo "scripts/test.sh: the ThreadSanitizer test failed (above)" >&2
[ "$main" -eq 0 ] && [ "$tsan" -eq 0 ]
