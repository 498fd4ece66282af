#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# report_calls.sh: amfi-report's files must not call each other in a circle,
# and its helpers (report_plot.c, report_cols.c, report_util.c) call no
# other report file.
#
# Reads the objects of the amfi-report target with nm: an object that leaves
# a symbol undefined which another object defines calls that object. Prints
# the graph (file -> files it calls), fails when tsort finds a cycle, when a
# helper calls a report file, and when the graph differs from the one
# documented in tools/ops/report.h (so the documentation cannot drift).
#
# usage: report_calls.sh 'OBJ1;OBJ2;...' PATH/TO/report.h
set -u

objs=${1:?usage: report_calls.sh OBJECTS REPORT_H}
doc=${2:?usage: report_calls.sh OBJECTS REPORT_H}
NM=${NM:-nm}
leaves="report_plot.c report_cols.c report_util.c"
[ -r "$doc" ] || { echo "report_calls.sh: $doc: cannot read" >&2; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/report_calls.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

# "object symbol D|U" for every global symbol; "report_plot.c.o" -> "report_plot.c"
: > "$tmp/syms"
n=0
old_ifs=$IFS
IFS=';'
for o in $objs; do
    IFS=$old_ifs
    [ -r "$o" ] || { echo "report_calls.sh: $o: cannot read" >&2; exit 1; }
    name=$(basename "$o" .o)
    "$NM" "$o" > "$tmp/nm" 2> "$tmp/nm.err" ||
        { echo "report_calls.sh: $NM $o failed:" >&2; cat "$tmp/nm.err" >&2; exit 1; }
    awk -v m="$name" '
        NF == 2 && $1 == "U" { print m, $2, "U" }
        NF == 3 && $2 ~ /^[A-TV-Z]$/ { print m, $3, "D" }' "$tmp/nm" >> "$tmp/syms"
    n=$((n + 1))
done
IFS=$old_ifs
[ "$n" -ge 2 ] || { echo "report_calls.sh: fewer than two objects in '$objs'" >&2; exit 1; }

# edges "caller callee" between distinct objects (two passes: definitions first)
awk 'NR == FNR { if ($3 == "D") def[$2] = $1; next }
     $3 == "U" && ($2 in def) && def[$2] != $1 { print $1, def[$2] }' \
    "$tmp/syms" "$tmp/syms" | sort -u > "$tmp/edges"

# the graph, one line per calling file, callees sorted
awk '{ out[$1] = out[$1] " " $2 } END { for (f in out) print f " ->" out[f] }' "$tmp/edges" |
    sort > "$tmp/graph"
echo "amfi-report call graph ($n objects):"
sed 's/^/  /' "$tmp/graph"

status=0
if ! tsort "$tmp/edges" > /dev/null 2> "$tmp/tsort.err"; then
    echo "FAIL: amfi-report's files call each other in a circle:" >&2
    cat "$tmp/tsort.err" >&2
    status=1
fi
for leaf in $leaves; do
    if grep -q "^$leaf " "$tmp/edges"; then
        echo "FAIL: $leaf must call no other report file, but calls:" \
            $(awk -v l="$leaf" '$1 == l { print $2 }' "$tmp/edges") >&2
        status=1
    fi
done

# the documented graph: lines " *   file.c -> a.c b.c" in report.h (a file
# may have several lines)
sed -n 's/^ \*   \([a-z_0-9-]*\.c\) ->\(.*\)$/\1\2/p' "$doc" |
    awk '{ for (i = 2; i <= NF; i++) print $1, $i }' | sort -u |
    awk '{ out[$1] = out[$1] " " $2 } END { for (f in out) print f " ->" out[f] }' |
    sort > "$tmp/documented"
if ! cmp -s "$tmp/graph" "$tmp/documented"; then
    echo "FAIL: the call graph documented in $doc differs from the objects (- documented, + actual):" >&2
    diff "$tmp/documented" "$tmp/graph" | sed -n 's/^</  -/p; s/^>/  +/p' >&2
    status=1
fi
[ "$status" -eq 0 ] && echo "ok: no circle, the helpers call no report file, the documented graph matches"
exit "$status"
