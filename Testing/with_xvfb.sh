#!/bin/sh
# Runs a command with its own Xvfb (pvbatch aborts without a display).
#
#   with_xvfb.sh CMD [ARGS...]
#
# Each test gets its own server on a random display number from 200 to 999
# (xvfb-run -a, and Xvfb -displayfd, start every server at :0 and race for
# it when tests start together); a number in use makes Xvfb exit at once and
# another is tried.
#
# Under load, pvbatch now and then fails to open a connection to a server that
# has just started ("bad X server connection", then SIGABRT, before any check
# ran). That one failure, and only that, is retried on a new server (twice).
set -u
dir=$(mktemp -d)
xpid=
stop_x() {
  if [ -n "$xpid" ]; then
    kill "$xpid" 2>/dev/null
    wait "$xpid" 2>/dev/null
  fi
  xpid=
}
trap 'stop_x; rm -rf "$dir"' EXIT

start_x() {
  tries=0
  while [ $tries -lt 20 ]; do
    tries=$((tries + 1))
    n=$(( $(od -An -N2 -tu2 /dev/urandom) % 800 + 200 ))
    [ -e /tmp/.X$n-lock ] && continue
    # An Xvfb that inherits SIGUSR1 as ignored sends it to its parent once it
    # accepts connections (X's own readiness signal, which xvfb-run uses too):
    # a socket file alone can appear before the server answers.
    ready=0
    trap 'ready=1' USR1
    (trap '' USR1; exec Xvfb :$n -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>"$dir/xvfb.log") &
    xpid=$!
    i=0
    while [ $ready -eq 0 ] && [ $i -lt 400 ] && kill -0 "$xpid" 2>/dev/null; do
      sleep 0.05
      i=$((i + 1))
    done
    # The server signals again at every reset (each time its last client
    # leaves): keep catching it, or the default action would end this script.
    trap : USR1
    if [ $ready -eq 1 ] && kill -0 "$xpid" 2>/dev/null; then
      DISPLAY=:$n
      export DISPLAY
      return 0
    fi
    stop_x
  done
  echo "with_xvfb.sh: no Xvfb could be started:" >&2
  cat "$dir/xvfb.log" >&2
  exit 1
}

for attempt in 1 2 3; do
  start_x
  "$@" >"$dir/out" 2>&1
  rc=$?
  cat "$dir/out"
  stop_x
  if [ $rc -eq 0 ] || [ $attempt -eq 3 ] || ! grep -q "bad X server connection" "$dir/out"; then
    exit $rc
  fi
  echo "with_xvfb.sh: the X connection failed before the test ran; retrying on a new server" >&2
done
