#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi_top.sh: amfi-top on a private bus (tests/common/bus_prologue.sh):
# sim_publisher feeds amfid, amfi-top --count N prints every passage amfid
# stores (id, lane, class, speed, GVW, status equal to the store's rows),
# amfid's status and the counts by status; --once prints the view at
# amfid's next status; with another key nothing is shown (every message
# refused) and --once times out, exit 1; on a terminal (script(1)) the
# screen is redrawn with ANSI escapes; bad options exit 2.
# A hostile producer (top_inject): an alert with terminal escapes is shown
# with them replaced; unsigned, wrongly signed and lying passages are
# counted as refused and never shown; a good passage whose loads were refused
# shows the reason (its escape replaced), and the end counts it.
#   amfi_top.sh AMFI_TOP AMFID SIM_PUBLISHER CONFIG TOP_INJECT
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
top=$1 amfid=$2 sim=$3 config=$4 inject=$5
fail() { echo "FAIL: $*"; [ -f "$dir/top.out" ] && tail -20 "$dir/top.out"; exit 1; }
N=6
sed -e "s/^  id: local .*/  id: top-1/" -e "s/^  status_period_s: 1 /  status_period_s: 0.2 /" \
    "$config" > "$dir/a.yaml"
grep -q '^  status_period_s: 0.2 ' "$dir/a.yaml" || fail "the test's status period did not apply"
amfid_start "$amfid" "$dir/a.yaml"

"$top" --config "$dir/a.yaml" --count $N --timeout 240 > "$dir/top.out" 2> "$dir/top.err" &
tpid=$!; pids="$pids $tpid"
wait_for "^# amfi-top on udpm://" "$dir/top.out" $tpid 60 || fail "amfi-top did not start: $(cat "$dir/top.err")"
grep -q "signatures verified" "$dir/top.out" || fail "amfi-top does not verify: $(head -1 "$dir/top.out")"
"$sim" --allow-production-bus --vehicles $N --headway 3 --speedup 20 --seed 3 --dt 2.5e-4 \
  2> "$dir/sim.log" || fail "sim_publisher: $(tail -2 "$dir/sim.log")"
wait $tpid || fail "amfi-top --count $N: exit $?: $(cat "$dir/top.err")"
cat "$dir/top.out"
[ "$(grep -c '^passage ' "$dir/top.out")" = $N ] || fail "not $N passage lines"
grep -q "^status  amfid top-1: running at " "$dir/top.out" || fail "no status line"
# each line as the store holds the passage: id, lane, class, speed, GVW, status
sqlite3 -separator ' ' "$dir/s.db" "SELECT id, lane, CASE WHEN class IS NULL OR class = '' THEN '-' ELSE class END,
    CASE WHEN speed_mps > 0 THEN printf('%.1f', speed_mps * 3.6) ELSE '-' END,
    CASE WHEN gvw_kg IS NULL THEN '-' ELSE printf('%.2f', gvw_kg / 1000) END, status
    FROM passages ORDER BY id LIMIT $N" > "$dir/store.txt"
# the columns: passage TIME ID LANE CLASS SPEED km/h GVW t STATUS (GVW "-": no " t")
awk '$1 == "passage" { i = 6; speed = $i; if ($i != "-") i++; i++; gvw = $i; if ($i != "-") i++; i++
       print $3, $4, $5, speed, gvw, $i }' "$dir/top.out" > "$dir/top.txt"
cmp -s "$dir/store.txt" "$dir/top.txt" ||
    fail "amfi-top's passages differ from the store's: $(diff "$dir/store.txt" "$dir/top.txt" | head -6)"
ok=$(sqlite3 "$dir/s.db" "SELECT count(*) FROM passages WHERE status = 'ok' AND id <= $N")
grep -q "^passages $N: ok $ok" "$dir/top.out" || fail "the counts: $(tail -1 "$dir/top.out"), store ok $ok"

# --once: the view at amfid's next status message
"$top" --config "$dir/a.yaml" --once --timeout 60 > "$dir/once.out" 2> "$dir/once.err" || fail "--once: exit $?: $(cat "$dir/once.err")"
grep -q "^amfid top-1: running at .*stored $N " "$dir/once.out" || fail "--once: $(cat "$dir/once.out")"
grep -q "^time (UTC) " "$dir/once.out" || fail "--once: no passage table"
# another key: every message refused, nothing shown
(umask 077 && head -c 32 /dev/urandom > "$dir/other.key")
"$top" --config "$dir/a.yaml" --bus-key "$dir/other.key" --once --timeout 3 > "$dir/wrong.out" 2> "$dir/wrong.err"
rc=$?
[ $rc = 1 ] && grep -q "no status message from amfid" "$dir/wrong.err" || fail "another key: exit $rc: $(cat "$dir/wrong.err")"
# a terminal: the screen redrawn with ANSI escapes, no plain lines
timeout -s INT 3 script -qfec "$top --config $dir/a.yaml --interval 0.3" /dev/null > "$dir/tty.out" 2>&1
[ "$(grep -c "$(printf '\033\\[H\033\\[2J')" "$dir/tty.out")" -ge 2 ] || fail "no redrawn screen on a terminal: $(head -c 300 "$dir/tty.out" | od -c | head)"
grep -q "amfid top-1: running" "$dir/tty.out" || fail "the terminal view lacks amfid's status"
grep -q "^passage " "$dir/tty.out" && fail "plain lines on a terminal"
# a hostile producer: escapes replaced, bad passages refused and counted
"$top" --config "$dir/a.yaml" --plain > "$dir/hostile.out" 2> "$dir/hostile.err" &
hpid=$!; pids="$pids $hpid"
wait_for "^# amfi-top on udpm://" "$dir/hostile.out" $hpid 60 || fail "amfi-top --plain did not start"
"$inject" > "$dir/inject.log" 2>&1 || fail "top_inject: $(cat "$dir/inject.log")"
wait_for "^alert " "$dir/hostile.out" $hpid 30 || fail "the injected alert was not shown: $(cat "$dir/hostile.out")"
wait_for "^passage " "$dir/hostile.out" $hpid 30 || fail "the injected passage was not shown: $(cat "$dir/hostile.out")"
sleep 1
kill -INT $hpid; wait $hpid || fail "amfi-top --plain on SIGINT: exit $?"
cat "$dir/hostile.out"
grep -q "$(printf '\033')" "$dir/hostile.out" && fail "an escape from the bus reached the terminal"
grep -q "$(printf '\a')" "$dir/hostile.out" && fail "a bell from the bus reached the terminal"
grep -q "^alert   2026-01-01T00:00:00Z RAISED  warning std_?]0;owned? evil?\[2J??more$" "$dir/hostile.out" ||
    fail "the alert not shown with its control characters replaced"
[ "$(grep -c "^passage " "$dir/hostile.out")" = 1 ] || fail "not only the good passage shown"
grep -q "^passage .*  901    1  R2 .*ok; loads refused: group 2: 276000 kg, over ten times any legal load?\[2J$" \
  "$dir/hostile.out" || fail "the loads' refusal not shown (or not made safe)"
grep -q "^passages 1: ok 1; loads refused 1$" "$dir/hostile.out" || fail "the loads refused not counted"
grep -q "^refused here: 3 (unsigned 1, bad_mac 1, malformed 1); last: AMFI_PASSAGE: passage_t.status" "$dir/hostile.out" ||
    fail "the refusals not counted: $(tail -2 "$dir/hostile.out")"

# bad command lines
"$top" --rows 0 > /dev/null 2> "$dir/bad.err"; [ $? = 2 ] || fail "--rows 0 accepted"
"$top" --once --count 3 > /dev/null 2> "$dir/bad.err"; [ $? = 2 ] || fail "--once --count accepted"
"$top" --config "$dir/none.yaml" --once > /dev/null 2> "$dir/bad.err"; [ $? = 2 ] || fail "a missing --config accepted"
amfid_stop
echo "amfi-top: ok"
