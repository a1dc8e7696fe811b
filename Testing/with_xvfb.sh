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
# ran). That one failure, and only that, is retried once on a new server.
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
    Xvfb :$n -screen 0 1280x1024x24 -nolisten tcp 2>"$dir/xvfb.log" &
    xpid=$!
    i=0
    while [ $i -lt 200 ] && kill -0 "$xpid" 2>/dev/null; do
      if [ -S /tmp/.X11-unix/X$n ]; then
        sleep 0.1
        if kill -0 "$xpid" 2>/dev/null; then
          DISPLAY=:$n
          export DISPLAY
          return 0
        fi
      fi
      sleep 0.05
      i=$((i + 1))
    done
    stop_x
  done
  echo "with_xvfb.sh: no Xvfb could be started:" >&2
  cat "$dir/xvfb.log" >&2
  exit 1
}

for attempt in 1 2; do
  start_x
  "$@" >"$dir/out" 2>&1
  rc=$?
  cat "$dir/out"
  stop_x
  if [ $rc -eq 0 ] || [ $attempt -eq 2 ] || ! grep -q "bad X server connection" "$dir/out"; then
    exit $rc
  fi
  echo "with_xvfb.sh: the X connection failed before the test ran; retrying once" >&2
done
