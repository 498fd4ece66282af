#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# amfi_spy: tools/ops/amfi-spy (lcm-spy with amfi_types.jar) starts headless under
# Xvfb, finds the eight amfi types and decodes every AMFI_* channel that
# lcm_selftest publishes on LCM's default UDP multicast URL.
#
# Everything runs inside a private network namespace (unshare --net) whose
# only interface is lo, with 224.0.0.0/4 routed to lo: the multicast can reach
# nothing outside it, and the test refuses to publish if it sees any other
# interface or a default route. Needs root (or CAP_SYS_ADMIN); where
# unshare --net is refused, or Xvfb/xwd/ip are missing, it exits 77 (skipped).
#
# What lcm-spy itself prints is only "Found N LCM types"; the rest is read
# from inside the running lcm-spy by a small Java agent (written and compiled
# below, loaded through JAVA_TOOL_OPTIONS): the type database lcm-spy built
# from the classpath, its channel table as displayed (channel, type, message
# count, undecodable count) and the last message it decoded on each channel,
# field by field, which must equal `lcm_selftest --expect` bit for bit.
# A screenshot of the screen is left in WORKDIR/spy.xwd (view: xwud -in FILE).
#
# Usage: test_spy.sh AMFI_SPY LCM_SELFTEST JAVAC JAR WORKDIR
set -u
N=30          # rounds published (10 Hz: 3 s)

if [ "${1:-}" != --inside ]; then
  [ $# -eq 5 ] || { echo "usage: test_spy.sh AMFI_SPY LCM_SELFTEST JAVAC JAR WORKDIR" >&2; exit 2; }
  spy=$1 selftest=$2 javac=$3 jar=$4 work=$5
  for tool in unshare ip Xvfb xwd timeout; do
    command -v "$tool" >/dev/null 2>&1 ||
      { echo "SKIP: $tool not found (Debian: util-linux, iproute2, xvfb, x11-apps)"; exit 77; }
  done
  if ! unshare --net true 2>/dev/null; then
    echo "SKIP: unshare --net is not permitted here (needs root or CAP_SYS_ADMIN);"
    echo "      the test never sends multicast outside a private network namespace"
    exit 77
  fi
  rm -rf "$work" && mkdir -p "$work/probe/src" || exit 1

  # The probe: a Java agent in lcm-spy's JVM. Reads lcm-spy's state by
  # reflection (lcm 1.3.1 names: Spy.handlers.classes, Spy.channelList,
  # ChannelData.last), writes probe.ready once the window is up and probe.txt
  # when dump.request appears.
  cat > "$work/probe/src/AmfiSpyProbe.java" <<'EOF'
import java.awt.Component;
import java.awt.Container;
import java.awt.Frame;
import java.io.File;
import java.io.FileWriter;
import java.io.PrintWriter;
import java.io.StringWriter;
import java.lang.reflect.Field;
import java.lang.reflect.Modifier;
import java.util.ArrayList;
import java.util.List;
import java.util.Map;
import javax.swing.JTable;
import javax.swing.SwingUtilities;
import javax.swing.table.TableModel;

public class AmfiSpyProbe {
    public static void premain(String dir) {
        Thread t = new Thread(() -> run(dir), "amfi-spy-probe");
        t.setDaemon(true);
        t.start();
    }

    static void run(String dir) {
        File request = new File(dir, "dump.request");
        try {
            JTable table = null;
            long end = System.currentTimeMillis() + 150000;
            while (System.currentTimeMillis() < end) {
                if (table == null && (table = findTable()) != null)
                    write(new File(dir, "probe.ready"), "ready\n");
                if (table != null && request.exists()) {
                    write(new File(dir, "probe.txt"), dump(table));
                    return;
                }
                Thread.sleep(200);
            }
            write(new File(dir, "probe.txt"), "SPY-ERROR\tno lcm-spy channel table (or no dump request) in 150 s\n");
        } catch (Throwable e) {
            StringWriter s = new StringWriter();
            e.printStackTrace(new PrintWriter(s));
            try {
                write(new File(dir, "probe.txt"), "SPY-ERROR\t" + s.toString().replace('\n', ' ') + "\n");
            } catch (Exception ignored) {
            }
        }
    }

    static JTable findTable() {
        for (Frame f : Frame.getFrames()) {
            JTable t = find(f);
            if (t != null)
                return t;
        }
        return null;
    }

    static JTable find(Component c) {
        if (c instanceof JTable)
            return (JTable) c;
        if (c instanceof Container)
            for (Component k : ((Container) c).getComponents()) {
                JTable t = find(k);
                if (t != null)
                    return t;
            }
        return null;
    }

    static Object get(Object o, String name) throws Exception {
        for (Class<?> c = o.getClass(); c != null; c = c.getSuperclass()) {
            try {
                Field f = c.getDeclaredField(name);
                f.setAccessible(true);
                return f.get(o);
            } catch (NoSuchFieldException e) {
                // try the superclass
            }
        }
        throw new NoSuchFieldException(o.getClass().getName() + "." + name);
    }

    static String value(Object v) {
        if (v instanceof Double)
            return String.format("0x%016x", Double.doubleToRawLongBits((Double) v));
        if (v instanceof double[]) {
            StringBuilder b = new StringBuilder("[");
            double[] a = (double[]) v;
            for (int i = 0; i < a.length; i++)
                b.append(i > 0 ? "," : "").append(String.format("0x%016x", Double.doubleToRawLongBits(a[i])));
            return b.append("]").toString();
        }
        if (v != null && v.getClass().isArray()) { // short[], byte[], int[], long[]: decimal
            StringBuilder b = new StringBuilder("[");
            for (int i = 0; i < java.lang.reflect.Array.getLength(v); i++)
                b.append(i > 0 ? "," : "").append(String.valueOf(java.lang.reflect.Array.get(v, i)));
            return b.append("]").toString();
        }
        return String.valueOf(v);
    }

    static String dump(JTable table) throws Exception {
        StringBuilder out = new StringBuilder();
        // What lcm-spy found on the classpath.
        Object sorter = table.getModel();
        TableModel model = (TableModel) sorter.getClass().getMethod("getTableModel").invoke(sorter);
        Object spy = get(model, "this$0");
        Map<?, ?> classes = (Map<?, ?>) get(get(spy, "handlers"), "classes");
        for (Map.Entry<?, ?> e : classes.entrySet())
            out.append(String.format("SPY-TYPE\t%s\t%016x\n", ((Class<?>) e.getValue()).getName(), (Long) e.getKey()));
        // The channel table as displayed.
        List<String> rows = new ArrayList<>();
        SwingUtilities.invokeAndWait(() -> {
            int cols = table.getColumnCount();
            int channel = -1, type = -1, count = -1, bad = -1;
            for (int c = 0; c < cols; c++) {
                String n = table.getColumnName(c);
                if (n.equals("Channel")) channel = c;
                if (n.equals("Type")) type = c;
                if (n.equals("Num Msgs")) count = c;
                if (n.equals("Undecodable")) bad = c;
            }
            for (int r = 0; r < table.getRowCount(); r++)
                rows.add(String.format("SPY-ROW\t%s\t%s\t%s\t%s\n",
                    channel < 0 ? "?" : String.valueOf(table.getValueAt(r, channel)).trim(),
                    type < 0 ? "?" : String.valueOf(table.getValueAt(r, type)).trim(),
                    count < 0 ? "?" : String.valueOf(table.getValueAt(r, count)).trim(),
                    bad < 0 ? "?" : String.valueOf(table.getValueAt(r, bad)).trim()));
        });
        for (String r : rows)
            out.append(r);
        // The last message lcm-spy decoded on each channel.
        List<?> channels = (List<?>) get(spy, "channelList");
        synchronized (channels) {
            for (Object cd : channels) {
                Object last = cd.getClass().getField("last").get(cd);
                String name = (String) cd.getClass().getField("name").get(cd);
                if (last == null) {
                    out.append("SPY-DECODED\t" + name + "\t(nothing decoded)\t\n");
                    continue;
                }
                StringBuilder f = new StringBuilder();
                for (Field field : last.getClass().getFields()) {
                    if (Modifier.isStatic(field.getModifiers()))
                        continue;
                    f.append(f.length() > 0 ? ";" : "").append(field.getName()).append('=').append(value(field.get(last)));
                }
                out.append("SPY-DECODED\t" + name + "\t" + last.getClass().getName() + "\t" + f + "\n");
            }
        }
        out.append("SPY-END\n");
        return out.toString();
    }

    static void write(File f, String s) throws Exception {
        File tmp = new File(f.getPath() + ".tmp");
        try (FileWriter w = new FileWriter(tmp)) {
            w.write(s);
        }
        if (!tmp.renameTo(f))
            throw new Exception("cannot rename " + tmp);
    }
}
EOF
  printf 'Premain-Class: AmfiSpyProbe\n' > "$work/probe/manifest.txt"
  if ! { mkdir -p "$work/probe/classes" &&
         timeout 60 "$javac" -nowarn -d "$work/probe/classes" "$work/probe/src/AmfiSpyProbe.java" &&
         timeout 30 "$jar" cfm "$work/probe/probe.jar" "$work/probe/manifest.txt" -C "$work/probe/classes" .; }; then
    echo "FAIL: cannot build the probe agent"
    exit 1
  fi

  # The rest runs in the namespace; timeout bounds it as a whole.
  exec timeout -k 5 150 unshare --net sh "$0" --inside "$spy" "$selftest" "$work"
fi

# ---- inside the private network namespace ----
shift
spy=$1 selftest=$2 work=$3
fail() { echo "FAIL: $*"; failed=1; }
failed=0
xpid='' spid=''
cleanup() {
  [ -n "$spid" ] && kill "$spid" 2>/dev/null
  [ -n "$xpid" ] && kill "$xpid" 2>/dev/null
  wait 2>/dev/null
}
trap cleanup EXIT
trap 'exit 1' INT TERM

if ! { ip link set lo up && ip route add 224.0.0.0/4 dev lo; }; then
  echo "FAIL: cannot set up lo and the multicast route in the namespace"
  exit 1
fi
# Refuse to send anything unless lo is the only way out.
others=$(ip -o link show | awk -F': ' '$2 != "lo" { print $2 }')
[ -z "$others" ] || { echo "FAIL: interfaces other than lo in the namespace ($others); not publishing"; exit 1; }
[ -z "$(ip route show default)" ] || { echo "FAIL: a default route in the namespace; not publishing"; exit 1; }

# Xvfb on the first free display; it writes the number when it is ready.
timeout -k 5 120 Xvfb -displayfd 3 -nolisten tcp -screen 0 1280x800x24 \
  3>"$work/display" >"$work/xvfb.log" 2>&1 &
xpid=$!
i=0
while [ ! -s "$work/display" ] && [ $i -lt 100 ]; do sleep 0.1; i=$((i + 1)); done
[ -s "$work/display" ] || { echo "FAIL: Xvfb did not start:"; cat "$work/xvfb.log"; exit 1; }
display=:$(cat "$work/display")

# amfi-spy on the default URL, the probe agent in its JVM.
unset LCM_DEFAULT_URL CLASSPATH AMFI_SPY_JAVA_OPTS
DISPLAY=$display JAVA_TOOL_OPTIONS="-javaagent:$work/probe/probe.jar=$work" \
  timeout -k 5 110 "$spy" >"$work/spy.log" 2>&1 &
spid=$!
# Ready: the window is up (probe.ready) and lcm-spy has subscribed (it
# prints "Found N plugins" after subscribeAll).
ready() { [ -e "$work/probe.ready" ] && grep -q '^Found [0-9]* plugins' "$work/spy.log"; }
i=0
while ! ready && [ $i -lt 600 ] && kill -0 "$spid" 2>/dev/null; do
  sleep 0.1; i=$((i + 1))
done
ready || { echo "FAIL: amfi-spy did not start in 60 s:"; cat "$work/spy.log"; exit 1; }

timeout -k 5 30 "$selftest" "" "$N" || fail "lcm_selftest publish exited $?"
sleep 1
touch "$work/dump.request"
i=0
while [ ! -e "$work/probe.txt" ] && [ $i -lt 200 ]; do sleep 0.1; i=$((i + 1)); done
timeout 10 xwd -root -silent -display "$display" -out "$work/spy.xwd" || echo "note: no screenshot (xwd exited $?)"
cleanup
spid='' xpid=''

echo "== lcm-spy said:"
sed 's/^/   /' "$work/spy.log"
[ -e "$work/probe.txt" ] || { echo "FAIL: the probe wrote nothing"; exit 1; }
echo "== read from lcm-spy:"
cut -c1-160 "$work/probe.txt" | sed 's/^/   /'
grep '^SPY-ERROR' "$work/probe.txt" && fail "the probe could not read lcm-spy"

# 1. The classpath scan: eight types, by name.
grep -qx 'Found 8 LCM types' "$work/spy.log" || fail "lcm-spy did not report 'Found 8 LCM types'"
grep -E 'Spy.messageReceived ex|Bad LCM Type|Class changed|Exception|Error:' "$work/spy.log" &&
  fail "lcm-spy reported errors"
"$selftest" --expect $((N - 1)) >"$work/expected.txt" || fail "lcm_selftest --expect"
while IFS="$(printf '\t')" read -r channel type fields; do
  grep -q "^SPY-TYPE	$type	" "$work/probe.txt" || fail "lcm-spy did not find $type"
  # 2. The channel table: the right type (shown without its package), every
  #    message, none undecodable.
  row=$(grep "^SPY-ROW	$channel	" "$work/probe.txt")
  [ -n "$row" ] || { fail "$channel not in lcm-spy's channel table"; continue; }
  echo "$row" | awk -F'\t' -v t="${type#amfi.}" -v n="$N" -v c="$channel" '
    $3 != t { print "FAIL: " c " shown as type \"" $3 "\", not " t; bad = 1 }
    $4 != n { print "FAIL: " c ": " $4 " messages, published " n; bad = 1 }
    $5 != 0 { print "FAIL: " c ": " $5 " undecodable"; bad = 1 }
    END { exit bad }' || failed=1
  # 3. The last message lcm-spy decoded equals what was sent, every field.
  got=$(grep "^SPY-DECODED	$channel	" "$work/probe.txt" | cut -f3-)
  [ "$(printf '%s' "$got" | cut -f1)" = "$type" ] || { fail "$channel decoded as '$(printf '%s' "$got" | cut -f1)'"; continue; }
  printf '%s\n' "$fields" | tr ';' '\n' | sort >"$work/want.$channel"
  printf '%s\n' "$got" | cut -f2 | tr ';' '\n' | sort >"$work/got.$channel"
  diff "$work/want.$channel" "$work/got.$channel" >"$work/diff.$channel" ||
    { fail "$channel: decoded fields differ from lcm_selftest's (< sent, > lcm-spy):"; cat "$work/diff.$channel"; }
done <"$work/expected.txt"
[ "$(wc -l <"$work/expected.txt")" -eq 8 ] || fail "expected 8 channels from lcm_selftest --expect"

[ $failed -eq 0 ] || exit 1
echo "amfi_spy: lcm-spy found the 8 amfi types and decoded all 8 AMFI_* channels ($N messages each) field for field"
