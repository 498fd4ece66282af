#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Install what is missing, build with AddressSanitizer + UndefinedBehaviorSanitizer
# and warnings as errors, and run the whole test suite under ctest; beside it,
# in the background, a ThreadSanitizer tree of only what the daemon's thread
# test needs (amfid, sim_publisher) and that test there
# (tests/daemon/daemon_reload.sh). ctest runs three tests at a time on two
# cores: the live-bus tests stream at a fixed speed-up and leave the CPU
# idle part of the time (measured: 908 s at -j2, 793 s at -j3, every test
# passed), and the ThreadSanitizer job fills some of the rest. The main
# suite's summary line is printed last; the exit status is non-zero when
# either run failed.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
bash "$top/scripts/install-deps.sh"
mkdir -p "$top/build"
bash "$top/scripts/build.sh" "$top/build/asan" -DAMFI_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo
tsan_job() {
  cmake -S "$top" -B "$top/build/tsan" -DAMFI_WERROR=ON -DAMFI_TSAN=ON \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo > "$top/build/tsan.configure.log" 2>&1 ||
    { cat "$top/build/tsan.configure.log"; return 1; }
  cmake --build "$top/build/tsan" --target amfid sim_publisher -j1 &&
    (cd "$top/build/tsan" && TSAN_OPTIONS=halt_on_error=1 ctest --output-on-failure -R '^daemon_reload$')
}
tsan_job > "$top/build/tsan.log" 2>&1 &
tsan_pid=$!
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0 UBSAN_OPTIONS=print_stacktrace=1
main=0
(cd "$top/build/asan" && ctest --output-on-failure -j3) | tee "$top/build/asan-ctest.log" || main=$?
tsan=0
wait "$tsan_pid" || tsan=$?
if [ "$tsan" -eq 0 ]; then
  echo "scripts/test.sh: the ThreadSanitizer test passed ($(grep -c 'Passed' "$top/build/tsan.log") of 1; build/tsan.log)"
else
  cat "$top/build/tsan.log" >&2
  echo "scripts/test.sh: the ThreadSanitizer tree or test failed (above, build/tsan.log)" >&2
fi
# the main suite's summary, last
grep -E '^[0-9]+% tests passed|^Total Test time' "$top/build/asan-ctest.log" || true
[ "$main" -eq 0 ] && [ "$tsan" -eq 0 ]
