#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# fuzz_corpus: the committed seed corpora (fuzz/corpus/) are what
# fuzz/make_corpus.sh writes from today's sources (docs/fuzzing.md): a
# changed .lcm type or config/*.yaml must refresh them.
#   fuzz_corpus.sh BUILD SRC
# The corpora are written again into BUILD/fuzz-corpus-now/, then:
#   - the same files;
#   - config/, accel_csv/, traffic/ (text copied or printed from the sources
#     with integers) and msg_*/ (lcm-gen encodings of fixed bit patterns:
#     no arithmetic) byte for byte;
#   - intake/ (sim_publisher's traffic: simulator output, whose last bits
#     differ between CPUs and BLAS kernels) decoded record by record with
#     today's types (tests/intake_seed_dump: a stale fingerprint or a cut
#     record fails), the committed and the new one with the same records,
#     channels, times, ids and counts, and values within 1e-6 relative or
#     1e-6 absolute (m/s², kg, m/s: far below the simulated noise).
set -u
build=$1 src=$2
committed=$src/fuzz/corpus
now=$build/fuzz-corpus-now
dump=$build/tests/intake_seed_dump
refresh="refresh: sh fuzz/make_corpus.sh $build"
fail() { echo "FAIL: fuzz/corpus is stale: $*; $refresh"; exit 1; }
rm -rf "$now" && mkdir -p "$now" || exit 1
sh "$src/fuzz/make_corpus.sh" "$build" "$now" >/dev/null || { echo "FAIL: make_corpus.sh"; exit 1; }
(cd "$committed" && find . -type f | LC_ALL=C sort) >"$now.list-committed"
(cd "$now" && find . -type f | LC_ALL=C sort) >"$now.list-now"
cmp -s "$now.list-committed" "$now.list-now" ||
  fail "other files: $(diff "$now.list-committed" "$now.list-now" | grep '^[<>]' | head -5 | tr '\n' ' ')"
n_bytes=0 n_num=0
while read -r f; do
  case $f in
    ./intake/*)
      "$dump" "$committed/$f" >"$now.a" || fail "$f does not decode"
      "$dump" "$now/$f" >"$now.b" || { echo "FAIL: make_corpus.sh wrote $f that does not decode"; exit 1; }
      sh "$src/tests/common/num_cmp.sh" -r 1e-6 -a 1e-6 "$now.a" "$now.b" >"$now.why" ||
        fail "$f: $(cat "$now.why")"
      n_num=$((n_num + 1)) ;;
    *)
      cmp -s "$committed/$f" "$now/$f" || fail "$f differs"
      n_bytes=$((n_bytes + 1)) ;;
  esac
done <"$now.list-now"
rm -f "$now.a" "$now.b" "$now.why" "$now.list-committed" "$now.list-now"
[ "$n_num" -ge 1 ] || { echo "FAIL: no intake seed compared"; exit 1; }
echo "fuzz_corpus: ok ($n_bytes files byte for byte, $n_num intake seeds decoded and compared numerically)"
