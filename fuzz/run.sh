#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# run.sh: the fuzz targets in the test suite (tests/CMakeLists.txt) and by hand
# (docs/fuzzing.md).
#   sh fuzz/run.sh build SRC DIR
#       configure DIR with clang and -DAMFI_FUZZ=ON (warnings as errors) and
#       build the fuzz targets (fuzz_all); incremental when DIR exists
#   sh fuzz/run.sh run DIR NAME SECONDS [SEED]
#       run DIR/fuzz/fuzz_NAME for SECONDS from the committed seed corpus
#       fuzz/corpus/NAME/ (read only: new inputs go to DIR/fuzz-out/NAME/),
#       seed SEED (default 1); a crash, leak, sanitizer report or timeout (25 s
#       for one input) fails, leaving the input in DIR/fuzz-artifacts/
set -eu
top=$(cd "$(dirname "$0")/.." && pwd)
case "${1:-}" in
build)
  src=${2:?usage: run.sh build SRC DIR}
  dir=${3:?usage: run.sh build SRC DIR}
  if ! command -v clang >/dev/null 2>&1; then
    echo "run.sh: clang not found (scripts/install-deps.sh installs clang and libclang-rt-14-dev)" >&2
    exit 1
  fi
  mkdir -p "$dir"
  cmake -S "$src" -B "$dir" -DCMAKE_C_COMPILER=clang -DAMFI_FUZZ=ON -DAMFI_WERROR=ON \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo >"$dir/configure.log" 2>&1 ||
    { cat "$dir/configure.log" >&2; exit 1; }
  cmake --build "$dir" --target fuzz_all -j2
  ;;
run)
  dir=${2:?usage: run.sh run DIR NAME SECONDS [SEED]}
  name=${3:?usage: run.sh run DIR NAME SECONDS [SEED]}
  secs=${4:?usage: run.sh run DIR NAME SECONDS [SEED]}
  seed=${5:-1}
  corpus=$top/fuzz/corpus/$name
  [ -d "$corpus" ] || { echo "run.sh: no seed corpus $corpus" >&2; exit 1; }
  out=$dir/fuzz-out/$name
  mkdir -p "$out" "$dir/fuzz-artifacts"
  exec "$dir/fuzz/fuzz_$name" -seed="$seed" -max_total_time="$secs" -timeout=25 \
    -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$dir/fuzz-artifacts/$name-" "$out" "$corpus"
  ;;
*)
  echo "usage: run.sh build SRC DIR | run DIR NAME SECONDS [SEED]" >&2
  exit 2
  ;;
esac
