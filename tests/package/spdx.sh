#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# Every source, build and script file carries the project's licence
# identifier (GPL-3.0-or-later; LICENSE) in its first lines.
# Usage: spdx.sh SOURCE_DIR
set -u
src=$1
cd "$src" || exit 1
# one awk over every file (a head and a grep per file cost 8 s of CPU, half
# of it in fork and exec); an empty file has no line, so find names it
missing=$(find . -path ./build -prune -o -path ./.git -prune -o -path ./fuzz/corpus -prune -o \
  -type f \( -name '*.c' -o -name '*.h' -o -name '*.sh' -o -name 'CMakeLists.txt' -o \
  -name '*.cmake' -o -name '*.lcm' -o -name '*.scd' -o -name '*.yaml' -o -name '*.service.in' \) \
  \( -empty -print -o ! -empty -exec awk '
    FNR == 1 { if (NR > 1 && !ok) print prev; ok = 0; prev = FILENAME }
    FNR <= 3 && index($0, "SPDX-License-Identifier: GPL-3.0-or-later") { ok = 1 }
    END { if (NR > 0 && !ok) print prev }' {} + \))
[ -z "$missing" ] || { echo "no SPDX line in:"; echo "$missing"; exit 1; }
n=$(find . -path ./build -prune -o -path ./.git -prune -o -type f \( -name '*.c' -o -name '*.h' \) -print | wc -l)
echo "spdx: every source file carries GPL-3.0-or-later ($n C files among them)"
