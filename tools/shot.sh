#!/usr/bin/env bash
# A viewer screenshot of a recording, headless, as a user first sees it on opening the file.
# usage: tools/shot.sh FILE.rrd OUT.png [WxH]   (needs xvfb-run, mesa-vulkan-drivers, rerun 0.36.3;
#        python3 with Pillow to bring the picture to WxH pixels)
# - The viewer starts from a fresh state folder of its own: it otherwise reads and writes
#   ~/.local/share/rerun (the window, a zoom factor, blueprints a user changed per application
#   id), shared by every viewer run on the machine. A state left there by earlier runs opened
#   this viewer with a "Wgpu validation error 6: Surface::configure ... Requested was (20000,
#   20000)" toast over the top right view (reproduced by copying that app.ron into a fresh
#   folder; gone without it): the tool, not the recording.
# - `--port auto`: a viewer already listening on Rerun's port 9876 (another screenshot, a live
#   test) would otherwise be sent the file, and this one would draw nothing of it.
# - The X screen is wider than the window: Xvfb keeps its pointer at the screen's centre, which
#   then falls right of the (top-left) window, so no hover tooltip lands on a view.
# - The viewer's screenshot mode draws at twice the window's size; the picture is scaled back to
#   WxH, the size the layout is made for.
set -u
size=${3:-1600x1000}
viewer=${RERUN:-$(command -v rerun)}
w=${size%x*}; h=${size#*x}
state=$(mktemp -d) || exit 1
trap 'rm -rf "$state"' EXIT
XDG_DATA_HOME=$state/data XDG_CONFIG_HOME=$state/config XDG_CACHE_HOME=$state/cache \
  timeout 120 xvfb-run -a -s "-screen 0 $((4 * w + 200))x$((2 * h))x24" "$viewer" "$1" \
  --port auto --screenshot-to "$2" --window-size "$size" >"$2.log" 2>&1
# The viewer panics on quitting after the screenshot ("Failed to take store hub"), exit 102:
# the picture is written by then, so only the picture decides.
if [ ! -s "$2" ]; then echo "no screenshot; log: $2.log" >&2; exit 1; fi
python3 -c 'import sys; from PIL import Image; i = Image.open(sys.argv[1]); size = (int(sys.argv[2]), int(sys.argv[3]))
if i.size != size: i.resize(size, Image.LANCZOS).save(sys.argv[1], optimize=True)' "$2" "$w" "$h" || exit 1
rm -f "$2.log"; echo "$2"
