#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The store owns every SQL statement (store/store.h): no C file outside
# store/ includes sqlite3.h, product code or test. Tests that need raw SQL
# for their fixtures use store/store_testing.h (library amfi_store_testing).
# Usage: store_owns_sqlite.sh SOURCE_DIR
top=${1:?usage: store_owns_sqlite.sh SOURCE_DIR}
cd "$top" || exit 1
found=$(git ls-files '*.c' '*.h' 2>/dev/null | grep -v '^store/' |
        xargs -r grep -l '#[[:space:]]*include[[:space:]]*<sqlite3\.h>' 2>/dev/null)
[ -n "$(git ls-files '*.c' 2>/dev/null | head -1)" ] ||
    found=$(find . -path ./store -prune -o -path './build*' -prune -o \( -name '*.c' -o -name '*.h' \) -print |
            xargs -r grep -l '#[[:space:]]*include[[:space:]]*<sqlite3\.h>')
if [ -n "$found" ]; then
    echo "FAIL: sqlite3.h outside store/ (the store owns every statement; tests: store/store_testing.h):"
    echo "$found"
    exit 1
fi
echo "ok: sqlite3.h only in store/"
