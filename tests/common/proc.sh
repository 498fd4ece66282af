# SPDX-License-Identifier: GPL-3.0-or-later
# proc.sh: starting and stopping the programs of a bus test, in one place.
# Sourced by tests/common/bus_prologue.sh (and so by every bus test) and by
# the tests that run amfid without it. Functions return non-zero with a
# line on stderr; the caller decides (`|| fail "..."`).
#
# wait_for PATTERN FILE [PID [SECONDS]]: until FILE holds a line matching the
# grep pattern; 1 when PID (if given) has exited first or SECONDS (default
# 60: a start under ASan on a loaded machine) have passed.
wait_for() {
  _wf_n=$(( ${4:-60} * 10 )); _wf_i=0
  until grep -q -- "$1" "$2" 2>/dev/null; do
    if [ -n "${3:-}" ] && ! kill -0 "$3" 2>/dev/null; then
      grep -q -- "$1" "$2" 2>/dev/null && return 0
      echo "wait_for: process $3 exited before '$1' in $2" >&2; return 1
    fi
    _wf_i=$((_wf_i + 1))
    [ $_wf_i -lt $_wf_n ] || { echo "wait_for: no '$1' in $2 after ${4:-60} s" >&2; return 1; }
    sleep 0.1
  done
}
# wait_caught PID SIGNUM [SECONDS]: until PID has a handler for signal
# SIGNUM (/proc/PID/status SigCgt), so that a signal sent next is caught and
# not the default action (SIGUSR1's kills a program still starting under
# ASan); 1 when PID has exited or SECONDS (default 60) have passed.
wait_caught() {
  _wc_bit=$(( 1 << ($2 - 1) )); _wc_n=$(( ${3:-60} * 10 )); _wc_i=0
  while :; do
    _wc_m=$(sed -n 's/^SigCgt:[[:space:]]*//p' "/proc/$1/status" 2>/dev/null) ||
      { echo "wait_caught: process $1 is gone" >&2; return 1; }
    [ -n "$_wc_m" ] || { echo "wait_caught: process $1 is gone" >&2; return 1; }
    [ $(( 0x$_wc_m & _wc_bit )) -ne 0 ] && return 0
    _wc_i=$((_wc_i + 1))
    [ $_wc_i -lt $_wc_n ] || { echo "wait_caught: $1 has no handler for signal $2 after ${3:-60} s" >&2; return 1; }
    sleep 0.1
  done
}
# stop_pid PID [SECONDS]: SIGTERM, wait until it is gone (default 300 s: a
# drain under ASan takes minutes) and return its exit status (1 on timeout,
# after SIGKILL).
stop_pid() {
  kill -TERM "$1" 2>/dev/null
  _sp_n=$(( ${2:-300} * 10 )); _sp_i=0
  while kill -0 "$1" 2>/dev/null; do
    _sp_i=$((_sp_i + 1))
    if [ $_sp_i -ge $_sp_n ]; then
      echo "stop_pid: $1 did not stop within ${2:-300} s of SIGTERM" >&2
      kill -9 "$1" 2>/dev/null; wait "$1" 2>/dev/null; return 1
    fi
    sleep 0.1
  done
  wait "$1"
}
