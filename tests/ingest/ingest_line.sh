#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-ingest's line protocol (docs/ingest.md): accelerometer (A) and
# vehicle (V) lines over TCP on 127.0.0.1 inside the test's own network
# namespace (common/bus_prologue.sh), then the same lines over a serial
# line (a pseudo-terminal, raw 8N1 at 115200 baud set with termios). Good
# lines are published (to an LCM log, verified: signed, the samples the
# lines carried, a gap a gap, overlapping samples dropped); every bad line
# is named by peer:line number and field, counted, and nothing stops.
# Usage: ingest_line.sh AMFI_INGEST INGEST_TOOL
set -u
. "$(dirname "$0")/../common/bus_prologue.sh"
ingest=$1 tool=$2
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -40 "$f"; done; exit 1; }
T0=1767225600000000
cat > "$dir/site.yaml" <<YAML
sensors:
  - {id: 3, at_m: 5}
ingest:
  max_jump_s: 10
  line:
    listen: 127.0.0.1:7671
    source: loop-1
YAML
# sample k of sensor 3 as the verifier computes it (ingest_tool.c): m/s²
samples() { # FIRST COUNT
  awk -v k0="$1" -v n="$2" 'BEGIN { pi = atan2(0, -1)
    for (k = k0; k < k0 + n; k++) printf " %.3f", sprintf("%.0f", 1000 * sin(2 * pi * k / 50 + 3)) / 1000 }'
}
{
  echo "# a detector and an accelerometer on one connection"
  echo "V $((T0 + 1000000)) 20.5 1 3 3.2 1.3 id=42"
  echo "V $((T0 + 2000000)) abc 1 2 3.0"
  echo "A 3 $T0 1000$(samples 0 100)"
  echo "A 4 $T0 1000 0.1"
  echo "A 3 $((T0 + 100000)) 1000$(samples 100 100)"
  echo "A 3 $((T0 + 300000)) 1000$(samples 300 50)"
  echo "A 3 $((T0 + 320000)) 1000$(samples 320 50)"
  echo "V $((T0 + 3000000)) 20 1 2"
  echo "X 1 2 3"
  echo "A 3 $((T0 + 400000)) 500 1 2"
  printf 'V %s 20 1 2 3.0 ref=20000\r\n' $((T0 + 4000000))
  echo "A 3 $((T0 + 400000)) 1000 nan"
  echo "A 3 $((T0 + 400000)) 1000 0.5 2000"
  awk 'BEGIN { printf "A 3 1767225600400000 1000"; for (i = 0; i < 14000; i++) printf " 0.001"; print "" }'
  echo "V $((T0 - 100000000)) 20 1 2 3.0"
  echo "V $((T0 + 5000000)) 20 1 2 130.5"
  printf 'V %s 20 2 2 3.5' $((T0 + 6000000))  # the last line, no newline
} > "$dir/lines.txt"

check() { # LOG LABEL PEER-PATTERN
  log=$1 what=$2 peer=$3
  "$tool" verify "$dir/$what.lcmlog" "$bus_key" $T0 > "$dir/$what.got" ||
    fail "$what: verify: $(grep BAD "$dir/$what.got" | head -3)"
  grep -q "^sensor 3 intervals 0-199,300-369$" "$dir/$what.got" ||
    fail "$what: sensor 3: $(grep intervals "$dir/$what.got")"
  [ "$(grep -c '^V ' "$dir/$what.got")" -eq 4 ] || fail "$what: expected 4 vehicles"
  grep -q "^V $((T0 + 1000000)) 42 1 20.5 3 3.2 1.3 loop-1 0$" "$dir/$what.got" ||
    fail "$what: the first vehicle's fields"
  grep -q "^V $((T0 + 4000000)) $((T0 + 4000000)) 1 20 2 3 loop-1 20000$" "$dir/$what.got" ||
    fail "$what: the vehicle with a reference (CRLF line)"
  grep -q "^V $((T0 + 6000000)) $((T0 + 6000000)) 2 20 2 3.5 loop-1 0$" "$dir/$what.got" ||
    fail "$what: the last line without a newline"
  for want in \
    "$peer:line 3: speed_mps: not a number in (0, 100\], got 'abc'" \
    "$peer:line 5: sensor-id: not a sensor of sensors:, got '4'" \
    "$peer:line 7: sensor 3: gap of 0.100000 s (100 samples)" \
    "$peer:line 8: sensor 3: overlap: 30 of 50 samples" \
    "$peer:line 9: spacing_m\[1\]: missing" \
    "$peer:line 10: type: neither A nor V, got 'X'" \
    "$peer:line 11: sample rate: 500 Hz differs from sensors\[0\].rate_hz (1000 Hz)" \
    "$peer:line 13: v1: not a finite number, got 'nan'" \
    "$peer:line 14: samples: sample 2 is 2000 m/s²" \
    "$peer:line 15: line: longer than 65536 bytes" \
    "$peer:line 16: utime_us: the detector's time went back by 104.000 s" \
    "$peer:line 17: spacing_m\[1\]: not a number in (0, 100\] m, got '130.5'" \
    "bad line 9, .*gap 1 (100 samples missing), overlap 1 (30 samples dropped), time jump 0, time back 1"; do
    grep -q "$want" "$dir/$log" || fail "$what: no '$want'"
  done
}

# 1. TCP
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/tcp.lcmlog?mode=w" 2> "$dir/tcp.log" &
ipid=$!; pids="$pids $ipid"
i=0; until grep -q "running" "$dir/tcp.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "amfi-ingest did not start"; sleep 0.1; done
grep -q "line protocol on tcp 127.0.0.1:7671" "$dir/tcp.log" || fail "not listening"
"$tool" send 127.0.0.1 7671 "$dir/lines.txt" || fail "send"
i=0; until grep -q "disconnected after 18 lines" "$dir/tcp.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "the peer's lines were not all read"; sleep 0.1; done
kill -TERM $ipid; wait $ipid || fail "SIGTERM: exit status $?"
check tcp.log tcp "127.0.0.1:[0-9]*"

# 2. A serial line: a pseudo-terminal, 115200 baud
"$tool" pty "$dir/lines.txt" "$dir/pty.name" "$dir/go" "$dir/done" &
tpid=$!; pids="$pids $tpid"
i=0; until [ -s "$dir/pty.name" ]; do
  i=$((i + 1)); [ $i -lt 100 ] || fail "no pseudo-terminal"; sleep 0.1; done
tty=$(cat "$dir/pty.name")
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/serial.lcmlog?mode=w" --listen none \
  --serial "$tty" --baud 115200 2> "$dir/serial.log" &
ipid=$!; pids="$pids $ipid"
i=0; until grep -q "running" "$dir/serial.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "amfi-ingest did not start on $tty"; sleep 0.1; done
touch "$dir/go"
# every line read (the summary on SIGUSR1), then the far end closes
i=0; until kill -USR1 $ipid && sleep 0.2 && grep -q "amfi-ingest: 0 records, 16 lines" "$dir/serial.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "the serial lines were not all read"; done
touch "$dir/done"
wait $tpid
i=0; while kill -0 $ipid 2>/dev/null; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "amfi-ingest did not end with its serial line"; sleep 0.1; done
wait $ipid || fail "serial: exit status $?"
check serial.log serial "$tty"
echo "ok"
