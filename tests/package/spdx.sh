#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Every source, build and script file carries the project's licence
# identifier (GPL-3.0-or-later; LICENSE) in its first lines.
# Usage: spdx.sh SOURCE_DIR
set -u
src=$1
cd "$src" || exit 1
missing=$(find . -path ./build -prune -o -path ./.git -prune -o -path ./fuzz/corpus -prune -o \
  -type f \( -name '*.c' -o -name '*.h' -o -name '*.sh' -o -name 'CMakeLists.txt' -o \
  -name '*.cmake' -o -name '*.lcm' -o -name '*.scd' -o -name '*.yaml' -o -name '*.service.in' \) \
  -print | while read -r f; do head -3 "$f" | grep -q 'SPDX-License-Identifier: GPL-3.0-or-later' || echo "$f"; done)
[ -z "$missing" ] || { echo "no SPDX line in:"; echo "$missing"; exit 1; }
n=$(find . -path ./build -prune -o -path ./.git -prune -o -type f \( -name '*.c' -o -name '*.h' \) -print | wc -l)
echo "spdx: every source file carries GPL-3.0-or-later ($n C files among them)"
