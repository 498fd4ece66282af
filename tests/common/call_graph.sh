#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# call_graph.sh: a component's files must not call each other in a circle,
# and the graph documented in its header must be the built one (so the
# documentation cannot drift). Used by libamfi_calls, daemon_calls and
# report_calls.
#
# Reads the built code with nm: a member (of a static library) or an object
# that leaves a symbol undefined which another defines calls it. Prints the
# graph (file -> files it calls); fails when tsort finds a cycle, when a
# LEAF calls another file of the component, and when the graph differs from
# the lines " *   file.c -> a.c b.c" of DOC (a file may have several lines).
#
# usage: call_graph.sh NAME DOC 'LEAF ...' 'FILE;FILE;...'
#   NAME: the component in messages; LEAVES: files that must call no other
#   ("" none); FILES: static libraries and/or objects, ';'-separated (as
#   CMake's $<TARGET_OBJECTS:...> gives them).
set -u

name=${1:?usage: call_graph.sh NAME DOC LEAVES FILES}
doc=${2:?usage: call_graph.sh NAME DOC LEAVES FILES}
leaves=${3?usage: call_graph.sh NAME DOC LEAVES FILES}
files=${4:?usage: call_graph.sh NAME DOC LEAVES FILES}
NM=${NM:-nm}
[ -r "$doc" ] || { echo "call_graph.sh: $doc: cannot read" >&2; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/call_graph.XXXXXX") || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM

# "member symbol D|U" for every global symbol; "lib.a:solver.c.o:" and
# "dir/report_plot.c.o:" -> "solver.c", "report_plot.c"
: > "$tmp/syms"
old_ifs=$IFS
IFS=';'
for f in $files; do
    IFS=$old_ifs
    [ -r "$f" ] || { echo "call_graph.sh: $f: cannot read" >&2; exit 1; }
    "$NM" -A "$f" > "$tmp/nm" 2> "$tmp/nm.err" ||
        { echo "call_graph.sh: $NM $f failed:" >&2; cat "$tmp/nm.err" >&2; exit 1; }
    awk '{
        n = split($1, part, ":"); member = part[n - 1]
        sub(/.*\//, "", member); sub(/\.o$/, "", member)
        if (NF == 3 && $2 == "U") print member, $3, "U"
        else if (NF == 3 && $2 ~ /^[A-TV-Z]$/) print member, $3, "D"
    }' "$tmp/nm" >> "$tmp/syms"
done
IFS=$old_ifs
[ "$(cut -d' ' -f1 "$tmp/syms" | sort -u | wc -l)" -ge 2 ] ||
    { echo "call_graph.sh: fewer than two files with symbols in '$files'" >&2; exit 1; }

# edges "caller callee" between distinct files (two passes: definitions first)
awk 'NR == FNR { if ($3 == "D") def[$2] = $1; next }
     $3 == "U" && ($2 in def) && def[$2] != $1 { print $1, def[$2] }' \
    "$tmp/syms" "$tmp/syms" | sort -u > "$tmp/edges"

# the graph, one line per calling file, callees sorted
group() { awk '{ out[$1] = out[$1] " " $2 } END { for (f in out) print f " ->" out[f] }' | sort; }
group < "$tmp/edges" > "$tmp/graph"
echo "$name call graph:"
sed 's/^/  /' "$tmp/graph"

status=0
if ! tsort "$tmp/edges" > /dev/null 2> "$tmp/tsort.err"; then
    echo "FAIL: $name's files call each other in a circle:" >&2
    cat "$tmp/tsort.err" >&2
    status=1
fi
for leaf in $leaves; do
    if grep -q "^$leaf " "$tmp/edges"; then
        echo "FAIL: $leaf must call no other $name file, but calls:" \
            $(awk -v l="$leaf" '$1 == l { print $2 }' "$tmp/edges") >&2
        status=1
    fi
done

sed -n 's/^ \*   \([a-z_0-9-]*\.c\) ->\(.*\)$/\1\2/p' "$doc" |
    awk '{ for (i = 2; i <= NF; i++) print $1, $i }' | sort -u | group > "$tmp/documented"
if ! cmp -s "$tmp/graph" "$tmp/documented"; then
    echo "FAIL: the call graph documented in $doc differs from the built one (- documented, + actual):" >&2
    diff "$tmp/documented" "$tmp/graph" | sed -n 's/^</  -/p; s/^>/  +/p' >&2
    status=1
fi
[ "$status" -eq 0 ] && echo "ok: no circle${leaves:+, the leaves ($leaves) call no other file}, the documented graph matches"
exit "$status"
