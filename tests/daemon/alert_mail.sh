#!/bin/sh
# SPDX-License-Identifier: GPL-3.0-or-later
# The example alerts.command contrib/amfi-alert-mail (issue 11), run as amfid
# runs it (no shell in between, the alert in AMFI_* variables), under the
# system's /bin/sh:
#  1. With a sendmail on PATH (a recording stand-in): one mail to root with
#     -oi, its To/Subject/body carrying the site, kind, level, raised or
#     cleared, time, ids and message; RCPT changes the recipient; exit 0.
#  2. A sendmail that fails (exit 75): the script fails too, so amfid logs
#     and counts the notice as failed.
#  3. No sendmail at all: the alert on stderr, nothing on stdout, exit 0.
# Usage: alert_mail.sh SCRIPT
set -u
script=$1
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
. "$(dirname "$0")/../common/bus_key.sh" # the test's site bus key, CREDENTIALS_DIRECTORY
fail() { echo "FAIL: $*"; for f in "$dir"/out "$dir"/err "$dir"/args "$dir"/mail; do
  [ -f "$f" ] && { echo "--- $f"; cat "$f"; }; done; exit 1; }
[ -x "$script" ] || fail "$script is not executable"
sh -n "$script" || fail "$script: syntax"
mkdir "$dir/bin" "$dir/empty"
cat > "$dir/bin/sendmail" <<EOS
#!/bin/sh
printf '%s\n' "\$@" > "$dir/args"
cat > "$dir/mail"
exit \${FAKE_SENDMAIL_RC:-0}
EOS
chmod +x "$dir/bin/sendmail"
msg='STD ratio 1.31 over 1.25 (p 0.0004) "quoted" $HOME `x`'
notice() { # RAISED PATH [VAR=value...]: the script with amfid's variables
  raised=$1 p=$2; shift 2
  env -i PATH="$p" AMFI_ALERT_ID=42 AMFI_ALERT_KIND=std_increase AMFI_ALERT_LEVEL=warning \
    AMFI_ALERT_RAISED="$raised" AMFI_ALERT_MESSAGE="$msg" AMFI_ALERT_UTIME=1764367200000000 \
    AMFI_ALERT_TIME=2025-11-28T22:00:00Z AMFI_ALERT_INDICATOR_ID=7 AMFI_SITE_ID=a1-bridge \
    AMFI_SITE_NAME='A1 over the river' AMFI_DB=/var/lib/amfid/amfi.db "$@" \
    "$script" > "$dir/out" 2> "$dir/err"
}
has() { grep -qxF -- "$2" "$dir/$1" || fail "$1 lacks the line: $2"; }

# 1. raised, then cleared to another recipient
notice 1 "$dir/bin:/usr/bin:/bin" || fail "exit $? with a working sendmail"
[ "$(cat "$dir/args")" = "$(printf '%s\n' -oi -- root)" ] || fail "sendmail arguments"
has mail "To: root"
has mail "Subject: [amfi a1-bridge] warning std_increase raised"
has mail "Site:      A1 over the river (a1-bridge)"
has mail "Alert:     std_increase (warning), raised"
has mail "Data time: 2025-11-28T22:00:00Z (utime 1764367200000000)"
has mail "Alert id:  42, indicator id 7"
has mail "Store:     /var/lib/amfid/amfi.db"
has mail "$msg"
[ ! -s "$dir/out" ] || fail "output on stdout"
rm -f "$dir/args" "$dir/mail"
notice 0 "$dir/bin:/usr/bin:/bin" RCPT=ops@example.org || fail "exit $? on a clear"
[ "$(cat "$dir/args")" = "$(printf '%s\n' -oi -- ops@example.org)" ] || fail "RCPT arguments"
has mail "To: ops@example.org"
has mail "Subject: [amfi a1-bridge] warning std_increase cleared"
echo "alert_mail: a raise and a clear mailed through sendmail, every field in the mail"

# 2. sendmail fails
notice 1 "$dir/bin:/usr/bin:/bin" FAKE_SENDMAIL_RC=75 && fail "exit 0 although sendmail failed"
echo "alert_mail: a failing sendmail fails the notice"

# 3. no sendmail (the script also looks at /usr/sbin/sendmail)
if [ -e /usr/sbin/sendmail ]; then
  echo "alert_mail: /usr/sbin/sendmail exists here; the no-sendmail case not run"
  exit 0
fi
rm -f "$dir/args" "$dir/mail"
notice 1 "$dir/empty" || fail "exit $? without sendmail"
[ ! -e "$dir/mail" ] || fail "mail sent without sendmail"
[ ! -s "$dir/out" ] || fail "output on stdout"
grep -qF "no sendmail" "$dir/err" && grep -qF "[amfi a1-bridge] warning std_increase raised" "$dir/err" &&
  grep -qF "$msg" "$dir/err" || fail "stderr without the alert"
echo "alert_mail: without sendmail the alert goes to stderr, exit 0"
