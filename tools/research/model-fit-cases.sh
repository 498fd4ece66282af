#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# model-fit-cases.sh: model-fit-trial.sh on every as-built case of
# tools/research/as-built (docs/results/model-fit.md), one after the other.
# usage: model-fit-cases.sh BUILD CONFIG OUT VEHICLES [sim_publisher args ...]
set -u
bin=$1 cfg=$2 out=$3 nveh=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
for c in "$here"/as-built/*.yaml; do
  name=$(basename "$c" .yaml)
  echo "$name $("$here/model-fit-trial.sh" "$bin" "$cfg" "$c" "$out/$name" "$nveh" "$@")"
done
