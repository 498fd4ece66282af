#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# daemon_calls.sh: amfid's files must not call each other in a circle.
#
# Reads the static library of the whole daemon but main() (amfid_lib) with
# nm: a member that leaves a symbol undefined which another member defines
# calls that member (a module's descriptor in amfid.c's table counts as a
# call; the context's function pointers, by design, do not). Prints the graph
# (file -> files it calls), fails when tsort finds a cycle, and fails when
# the graph differs from the one documented in daemon/ctx.h (so the
# documentation cannot drift from the code).
#
# usage: daemon_calls.sh PATH/TO/libamfid_lib.a PATH/TO/ctx.h
set -u

lib=${1:?usage: daemon_calls.sh LIBAMFID_LIB_A CTX_H}
doc=${2:?usage: daemon_calls.sh LIBAMFID_LIB_A CTX_H}
NM=${NM:-nm}
[ -r "$lib" ] || { echo "daemon_calls.sh: $lib: cannot read" >&2; exit 1; }
[ -r "$doc" ] || { echo "daemon_calls.sh: $doc: cannot read" >&2; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/daemon_calls.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

# "member symbol D|U" for every global symbol; member "solver.c.o" -> "solver.c"
"$NM" -A "$lib" >"$tmp/nm" 2>"$tmp/nm.err" ||
    { echo "daemon_calls.sh: $NM $lib failed:" >&2; cat "$tmp/nm.err" >&2; exit 1; }
awk '{
    n = split($1, part, ":"); member = part[n - 1]; sub(/\.o$/, "", member)
    if (NF == 3 && $2 == "U") print member, $3, "U"
    else if (NF == 3 && $2 ~ /^[A-TV-Z]$/) print member, $3, "D"
}' "$tmp/nm" >"$tmp/syms"
[ -s "$tmp/syms" ] || { echo "daemon_calls.sh: no symbols in $lib" >&2; exit 1; }

# edges "caller callee" between distinct members (two passes: definitions first)
awk 'NR == FNR { if ($3 == "D") def[$2] = $1; next }
     $3 == "U" && ($2 in def) && def[$2] != $1 { print $1, def[$2] }' \
    "$tmp/syms" "$tmp/syms" | sort -u >"$tmp/edges"

# the graph, one line per calling file
awk '{ out[$1] = out[$1] " " $2 } END { for (f in out) print f " ->" out[f] }' "$tmp/edges" |
    sort >"$tmp/graph"
echo "amfid call graph (from $lib):"
sed 's/^/  /' "$tmp/graph"

status=0
if ! tsort "$tmp/edges" >/dev/null 2>"$tmp/tsort.err"; then
    echo "FAIL: amfid's files call each other in a circle:" >&2
    cat "$tmp/tsort.err" >&2
    status=1
fi

# the documented graph: lines " *   file.c -> a.c b.c" in ctx.h
sed -n 's/^ \*   \([a-z_0-9]*\.c\) ->\(.*\)$/\1 ->\2/p' "$doc" |
    awk '{ line = $1 " ->"; for (i = 3; i <= NF; i++) w[i] = $i
           n = NF; for (i = 3; i <= n; i++) for (j = i + 1; j <= n; j++)
               if (w[j] < w[i]) { t = w[i]; w[i] = w[j]; w[j] = t }
           for (i = 3; i <= n; i++) line = line " " w[i]; print line }' |
    sort >"$tmp/documented"
if ! cmp -s "$tmp/graph" "$tmp/documented"; then
    echo "FAIL: the call graph documented in $doc differs from the library (- documented, + actual):" >&2
    diff "$tmp/documented" "$tmp/graph" | sed -n 's/^</  -/p; s/^>/  +/p' >&2
    status=1
fi
[ "$status" -eq 0 ] && echo "ok: no cycle, and the documented graph matches"
exit "$status"
