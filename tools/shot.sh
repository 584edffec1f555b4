#!/usr/bin/env bash
# A viewer screenshot of a recording, headless, as ../shared/tools/shot.sh takes it, except that
# the X screen is wider than the window: Xvfb keeps its pointer at the screen's centre, which
# then falls right of the (top-left) window, so no hover tooltip lands on a view (docs/all.png).
# usage: tools/shot.sh FILE.rrd OUT.png [WxH]   (needs xvfb-run, mesa-vulkan-drivers, rerun 0.36.3)
set -u
size=${3:-1600x1000}
viewer=${RERUN:-$(command -v rerun)}
w=${size%x*}; h=${size#*x}
timeout 120 xvfb-run -a -s "-screen 0 $((4 * w + 200))x$((2 * h))x24" "$viewer" "$1" \
  --screenshot-to "$2" --window-size "$size" >"$2.log" 2>&1
if [ -s "$2" ]; then rm -f "$2.log"; echo "$2"; else echo "no screenshot; log: $2.log" >&2; exit 1; fi
