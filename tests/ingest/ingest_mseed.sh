#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi-ingest on MiniSEED written by libmseed (tests/ingest/ingest_tool.c
# gen): Steim-1, Steim-2, int16, int32, float32 and float64 records of three
# channels in five files given out of order; a 0.25 s gap; a record repeated
# and one overlapping by 30 samples; a record with corrupted Steim data, one
# with a destroyed header, one at another rate than the sensor's, one whose
# header claims 60000 samples; a channel not configured; a channel with a
# latency. The messages go to an LCM log (LCM's file:// provider: no network
# at all) and are verified sample by sample: signed, every value the
# generator's, every sample once, a gap a gap (no sample invented), the
# refused records' samples missing and each named by file:record. Then the
# same files as a stream (stdin, a FIFO, a growing file), the
# configuration's refusals by file:line, hostile input (mutated files, random
# bytes and lines), and a start without a key refused.
# Usage: ingest_mseed.sh AMFI_INGEST INGEST_TOOL
set -u
ingest=$1 tool=$2
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh"
. "$(dirname "$0")/../common/proc.sh"
fail() { echo "FAIL: $*"; for f in "$dir"/*.log; do echo "--- $f"; tail -30 "$f"; done; exit 1; }
T0=1767225600000000

cat > "$dir/site.yaml" <<YAML
sensors:
  - {id: 3, at_m: 5}
  - {id: 5, at_m: 10}
  - {id: 7, at_m: 15}
ingest:
  block: 100
  max_jump_s: 10
  channels:
    - {seed: XX.BRG.00.HNZ, sensor: 3, gain: 0.001}
    - {seed: XX.BRG.00.HNN, sensor: 5, gain: 0.001}
    - {seed: XX.BRG.00.HNE, sensor: 7, gain: 0.001, offset_s: 0.5}
YAML
"$ingest" --config "$dir/site.yaml" --check-config > "$dir/check.txt" || fail "check-config"
grep -q "XX.BRG.00.HNE -> sensor 7 (1000 Hz), gain 0.001 m/s² per count, offset 0.5 s" \
  "$dir/check.txt" || fail "check-config does not show the mapping: $(cat "$dir/check.txt")"

"$tool" gen "$dir" || fail "the generator"
# files out of order: merged by data time
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/out.lcmlog?mode=w" \
  "$dir/b.mseed" "$dir/c2.mseed" "$dir/a2.mseed" "$dir/c1.mseed" "$dir/a1.mseed" \
  2> "$dir/ingest.log" || fail "amfi-ingest exit status $?"
"$tool" verify "$dir/out.lcmlog" "$bus_key" $T0 7=500000 > "$dir/got.log" ||
  fail "verify: $(grep BAD "$dir/got.log" | head -5)"
for s in 3 5 7; do
  want=$(grep "^sensor $s intervals" "$dir/expect.txt")
  got=$(grep "^sensor $s intervals" "$dir/got.log")
  echo "want: $want"
  echo "got:  $got"
  [ "$want" = "$got" ] || fail "sensor $s: the samples published differ from the records kept"
done
grep -q "a2.mseed:record 3: data: " "$dir/ingest.log" ||
  fail "the corrupted Steim-2 record is not named"
grep -q "b.mseed:record 10: header: not a MiniSEED data record header: 512 bytes skipped" \
  "$dir/ingest.log" || fail "the record with a destroyed header is not named"
grep -q "a2.mseed:record 2 (XX.BRG.00.HN1): channel XX.BRG.00.HN1 is not in ingest.channels" \
  "$dir/ingest.log" || fail "the unmapped channel is not named"
grep -q "a2.mseed:record 1 (XX.BRG.00.HNZ): sensor 3: gap of 0.250000 s (250 samples)" \
  "$dir/ingest.log" || fail "the gap is not reported"
rep=$(awk '/^records/ {print $10}' "$dir/expect.txt")
grep -q "b.mseed:record 8 (XX.BRG.00.HNN): sensor 5: overlap: $rep of $rep samples" \
  "$dir/ingest.log" || fail "the repeated record is not reported as an overlap"
bn=$(( $(wc -c < "$dir/b.mseed") / 512 ))
grep -q "b.mseed:record $bn (XX.BRG.00.HNN): sensor 5: overlap: 30 of 130 samples" "$dir/ingest.log" ||
  fail "the partial overlap is not reported"
nrec=$(awk '/^records/ {print $2}' "$dir/expect.txt")
grep -q "amfi-ingest: $nrec records, 0 lines; published .* signed" "$dir/ingest.log" ||
  fail "summary: expected $nrec records"
c2n=$(( $(wc -c < "$dir/c2.mseed") / 512 ))
grep -q "c2.mseed:record $c2n (XX.BRG.00.HNE): sample rate: 500 Hz differs from sensors\[2\].rate_hz (1000 Hz) of sensor 7: refused" \
  "$dir/ingest.log" || fail "the record at another rate is not named"
grep -q "bad record 3, bad line 0, unmapped channel 1, gap 3 .*, overlap 2 ($((rep + 30)) samples dropped), time jump 0, time back 0, wall clock 0, publish failed 0" \
  "$dir/ingest.log" || fail "summary counts: $(tail -1 "$dir/ingest.log")"

# The same channel as a stream on stdin, record by record: the same samples.
cat "$dir/a1.mseed" "$dir/a2.mseed" | "$ingest" --config "$dir/site.yaml" \
  --lcm-url "file://$dir/stdin.lcmlog?mode=w" --mseed-stream - --listen none \
  2> "$dir/stream.log" || fail "stream from stdin: exit status $?"
"$tool" verify "$dir/stdin.lcmlog" "$bus_key" $T0 > "$dir/got2.log" || fail "verify (stdin)"
[ "$(grep "^sensor 3 intervals" "$dir/got2.log")" = "$(grep "^sensor 3 intervals" "$dir/expect.txt")" ] ||
  fail "stdin: sensor 3 differs"
grep -q "stdin: end of the stream" "$dir/stream.log" || fail "stdin: no end of the stream"
# the data are from 2026-01-01, the service checks them against the wall clock
grep -q "wall clock [1-9]" "$dir/stream.log" || fail "a stream far from the wall clock not counted"
# A FIFO written in pieces by two writers one after the other (a logger that
# restarts): the service holds it open, one stream; SIGTERM ends it.
mkfifo "$dir/fifo"
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/fifo.lcmlog?mode=w" \
  --mseed-stream "$dir/fifo" --listen none 2> "$dir/fifo.log" &
ipid=$!
sleep 0.3  # the service waits for a writer without ending
kill -0 $ipid || fail "the service ended before the FIFO had a writer"
{ head -c 700 "$dir/c1.mseed"; sleep 0.3; tail -c +701 "$dir/c1.mseed"; } > "$dir/fifo"
cat "$dir/c2.mseed" > "$dir/fifo"
nf=$(( ($(wc -c < "$dir/c1.mseed") + $(wc -c < "$dir/c2.mseed")) / 512 ))
wait_caught $ipid 10 || fail "FIFO: no SIGUSR1 handler"  # SIGUSR1: 10 on Linux
i=0; until kill -USR1 $ipid && sleep 0.2 && grep -q "amfi-ingest: $nf records" "$dir/fifo.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "the FIFO was not read to its end"; done
kill -TERM $ipid; wait $ipid || fail "stream from a FIFO: exit status $?"
"$tool" verify "$dir/fifo.lcmlog" "$bus_key" $T0 7=500000 > "$dir/got3.log" || fail "verify (FIFO)"
grep -q "^sensor 7 intervals 0-3999$" "$dir/got3.log" || fail "FIFO: sensor 7 incomplete"

# A growing file, followed as the logger writes it; SIGTERM ends the service.
: > "$dir/grow.mseed"
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/grow.lcmlog?mode=w" \
  --mseed-stream "$dir/grow.mseed" --listen none 2> "$dir/grow.log" &
ipid=$!
cat "$dir/c1.mseed" >> "$dir/grow.mseed"; sleep 0.5; cat "$dir/c2.mseed" >> "$dir/grow.mseed"
wait_caught $ipid 10 || fail "growing file: no SIGUSR1 handler"
i=0; until kill -USR1 $ipid && sleep 0.2 && grep -q "amfi-ingest: $(( $(wc -c < "$dir/grow.mseed") / 512 )) records" "$dir/grow.log"; do
  i=$((i + 1)); [ $i -lt 300 ] || fail "the growing file was not read to its end"; done
kill -TERM $ipid; wait $ipid || fail "SIGTERM: exit status $?"
"$tool" verify "$dir/grow.lcmlog" "$bus_key" $T0 7=500000 > "$dir/got4.log" || fail "verify (growing)"
grep -q "^sensor 7 intervals 0-3999$" "$dir/got4.log" || fail "growing file: sensor 7 incomplete"

# The configuration's refusals name the file and line.
check_bad() { # LINE-EXPECTED MESSAGE-PATTERN; the YAML in $dir/bad.yaml
  "$ingest" --config "$dir/bad.yaml" --check-config > /dev/null 2> "$dir/bad.log" &&
    fail "accepted: $(cat "$dir/bad.yaml")"
  grep -q "bad.yaml:$1: $2" "$dir/bad.log" || fail "expected 'bad.yaml:$1: $2', got: $(cat "$dir/bad.log")"
}
printf 'sensors:\n  - {id: 3, at_m: 5}\ningest:\n  channels:\n    - {seed: XX.BRG.00.HNZ, sensor: 4, gain: 1}\n' > "$dir/bad.yaml"
check_bad 5 "ingest.channels\[0\].sensor: sensor 4 is not in sensors:"
printf 'sensors:\n  - {id: 3, at_m: 5}\ningest:\n  channels:\n    - {seed: XX.BRG.HNZ, sensor: 3, gain: 1}\n' > "$dir/bad.yaml"
check_bad 5 "ingest.channels\[0\].seed: must be NET.STA.LOC.CHA"
printf 'sensors:\n  - {id: 3, at_m: 5}\ningest:\n  channels:\n    - {seed: XX.BRG.00.HNZ, sensor: 3}\n' > "$dir/bad.yaml"
check_bad 5 "ingest.channels\[0\].gain: missing (required)"
printf 'sensors:\n  - {id: 3, at_m: 5}\n  - {id: 4, at_m: 6}\ningest:\n  channels:\n    - {seed: XX.BRG.00.HNZ, sensor: 3, gain: 1}\n    - {seed: XX.BRG.00.HNZ, sensor: 4, gain: 1}\n' > "$dir/bad.yaml"
check_bad 7 "ingest.channels\[1\].seed: duplicate channel XX.BRG.00.HNZ (also ingest.channels\[0\])"
printf 'sensors:\n  - {id: 3, at_m: 5}\ningest:\n  channels:\n    - {seed: XX.BRG.00.HNZ, sensor: 3, gain: 1}\n    - {seed: XX.BRG.00.HNN, sensor: 3, gain: 1}\n' > "$dir/bad.yaml"
check_bad 6 "ingest.channels\[1\].sensor: sensor 3 is fed by ingest.channels\[0\] already"
printf 'ingest:\n  line:\n    listen: localhost:80\n' > "$dir/bad.yaml"
check_bad 3 "ingest.line.listen: must be IPV4-ADDRESS:PORT"
printf 'ingest:\n  line:\n    baud: 9601\n' > "$dir/bad.yaml"
check_bad 3 "ingest.line.baud:"
printf 'ingest:\n  block: 161\n' > "$dir/bad.yaml"
check_bad 2 "ingest.block:"
printf 'ingest:\n  producer: "a b"\n' > "$dir/bad.yaml"
check_bad 2 "ingest.producer: must be"
printf 'ingest:\n  max_jump_s: 0\n' > "$dir/bad.yaml"
check_bad 2 "ingest.max_jump_s:"

# A header that claims more samples than its record holds: refused by name
# (libmseed's int and float decoders are not bounded by the record: read
# past it, they crashed amfi-ingest now and then).
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/h.lcmlog?mode=w" "$dir/huge.mseed" \
  2> "$dir/huge.log" || fail "huge.mseed: exit status $?"
grep -q "huge.mseed:record 1: data: 60000 samples cannot fit in the record's [0-9]* data bytes" \
  "$dir/huge.log" || fail "the record claiming 60000 samples is not refused by name"

# Hostile input: the files with bytes changed (24 variants), random bytes,
# random lines: every one read to its end, counted, nothing crashes (the
# ASan tree runs this too).
cat "$dir/a1.mseed" "$dir/a2.mseed" "$dir/b.mseed" "$dir/c1.mseed" "$dir/c2.mseed" > "$dir/all.mseed"
s=0; while [ $s -lt 24 ]; do
  "$tool" mutate "$dir/all.mseed" "$dir/m.mseed" $s || fail "mutate"
  "$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/m.lcmlog?mode=w" "$dir/m.mseed" \
    2> "$dir/hostile.log" || fail "mutated file $s: exit status $?"
  grep -q "^amfi-ingest: bad record [0-9]*, " "$dir/hostile.log" || fail "mutated file $s: no summary"
  s=$((s + 1))
done
head -c 100000 /dev/urandom > "$dir/random.bin"
awk 'BEGIN { srand(7); split("A V 3 5 7 1767225600000000 -1 1000 nan inf 1e400 0.1 id= ref=5000 12 13 0 99999999999999999999 x -0 1e-320", t, " ")
  for (i = 0; i < 2000; i++) { n = int(rand() * 30); l = ""; for (j = 0; j < n; j++) l = l " " t[1 + int(rand() * 21)]; print l } }' > "$dir/random.txt"
"$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/r.lcmlog?mode=w" "$dir/random.bin" \
  --lines "$dir/random.txt" --lines "$dir/random.bin" 2> "$dir/hostile.log" || fail "random input: exit status $?"
grep -q "^amfi-ingest: bad record [1-9][0-9]*, bad line [1-9][0-9]*, " "$dir/hostile.log" ||
  fail "random input: not counted as bad"

# Without a key it does not publish (unless told --unsigned).
env -u CREDENTIALS_DIRECTORY "$ingest" --config "$dir/site.yaml" --lcm-url "file://$dir/x.lcmlog?mode=w" \
  "$dir/a1.mseed" 2> "$dir/nokey.log" && fail "published without a key"
grep -q "no bus key" "$dir/nokey.log" || fail "no message about the missing key"
echo "ok"
