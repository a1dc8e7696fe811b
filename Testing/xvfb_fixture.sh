#!/bin/sh
# One Xvfb server for all the tests that render (pvbatch aborts without a
# display). Starting an xvfb-run per test races on display numbers and on
# servers still shutting down; one shared server does not.
#
#   xvfb_fixture.sh start STATE    start Xvfb on a free display, write "N PID" to STATE
#   xvfb_fixture.sh stop STATE     stop it
#   xvfb_fixture.sh run STATE CMD...   run CMD with DISPLAY=:N
set -eu
action=$1
state=$2
shift 2
case "$action" in
  start)
    n=170
    while [ $n -lt 260 ]; do
      if [ ! -e /tmp/.X$n-lock ] && [ ! -e /tmp/.X11-unix/X$n ]; then
        Xvfb :$n -screen 0 1280x1024x24 -nolisten tcp >/dev/null 2>&1 &
        pid=$!
        i=0
        while [ $i -lt 100 ]; do
          if [ -e /tmp/.X11-unix/X$n ]; then
            echo "$n $pid" > "$state"
            echo "Xvfb running on :$n (pid $pid)"
            exit 0
          fi
          kill -0 $pid 2>/dev/null || break
          sleep 0.1
          i=$((i + 1))
        done
        kill $pid 2>/dev/null || true
      fi
      n=$((n + 1))
    done
    echo "could not start Xvfb on any display from :170 to :259" >&2
    exit 1
    ;;
  stop)
    if [ -f "$state" ]; then
      read -r n pid < "$state"
      kill "$pid" 2>/dev/null || true
      rm -f "$state"
    fi
    ;;
  run)
    read -r n pid < "$state"
    DISPLAY=:$n
    export DISPLAY
    exec "$@"
    ;;
  *)
    echo "usage: $0 start|stop|run STATE [CMD...]" >&2
    exit 2
    ;;
esac
