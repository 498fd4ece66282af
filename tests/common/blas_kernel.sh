#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Run a numerical test under one OpenBLAS kernel (ctest's *_haswell and
# *_skylakex entries): floating point differs between kernels (summation
# order, FMA), and the solver must not depend on which one a CPU gets.
#   blas_kernel.sh KERNEL BLAS_CORE -- COMMAND [ARG...]
# KERNEL: Haswell or SkylakeX (OPENBLAS_CORETYPE), or native: the kernel
# OpenBLAS picks for this CPU, skipped when that is one of the two (their
# entries cover it) or when both of them run on this CPU (the two forced
# kernels are the suite's check; the rest of the suite runs on the
# machine's own kernel, and the native entry would add a third copy of the
# longest numerical tests to the suite's time). Exit 77 (ctest SKIP_RETURN_CODE) when this CPU lacks
# the kernel's instructions (/proc/cpuinfo: Haswell needs avx2 and fma,
# SkylakeX avx512f; run anyway it would die of an illegal instruction) or
# OpenBLAS does not honour OPENBLAS_CORETYPE (not built for several
# kernels); otherwise COMMAND's own status, with one BLAS thread.
set -u
kernel=$1 core=$2
shift 2
[ "${1-}" = "--" ] && shift
[ $# -ge 1 ] || { echo "usage: blas_kernel.sh KERNEL BLAS_CORE -- COMMAND [ARG...]" >&2; exit 2; }
export OPENBLAS_NUM_THREADS=1
has_flags() {
  for f in "$@"; do
    grep -q "^flags.*[[:space:]]$f\([[:space:]]\|\$\)" /proc/cpuinfo 2>/dev/null || return 1
  done
}
case $kernel in
  Haswell) need="avx2 fma" ;;
  SkylakeX) need="avx512f" ;;
  native) need="" ;;
  *) echo "blas_kernel.sh: unknown kernel '$kernel' (Haswell, SkylakeX, native)" >&2; exit 2 ;;
esac
if [ "$kernel" = native ]; then
  if has_flags avx2 fma avx512f; then
    echo "SKIP: the _haswell and _skylakex entries both run on this CPU"; exit 77
  fi
  unset OPENBLAS_CORETYPE
  got=$("$core") || { echo "blas_kernel.sh: $core failed" >&2; exit 1; }
  case $got in
    Haswell|SkylakeX) echo "SKIP: this CPU's kernel is $got, run by the _$(echo "$got" | tr A-Z a-z) entry"; exit 77 ;;
  esac
  echo "blas_kernel.sh: OpenBLAS kernel $got (native)"
else
  # shellcheck disable=SC2086
  has_flags $need || { echo "SKIP: this CPU lacks $need for OpenBLAS's $kernel kernel"; exit 77; }
  export OPENBLAS_CORETYPE=$kernel
  got=$("$core") || { echo "blas_kernel.sh: $core failed" >&2; exit 1; }
  [ "$got" = "$kernel" ] || { echo "SKIP: OpenBLAS gives kernel '$got' for OPENBLAS_CORETYPE=$kernel (not built for several)"; exit 77; }
  echo "blas_kernel.sh: OpenBLAS kernel $got"
fi
exec "$@"
