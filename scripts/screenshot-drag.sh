#!/usr/bin/env bash
# Takes docs/screenshot-drag.png: the viewer on the default scene in a virtual X server,
# a corner of the cloth dragged with the mouse (xdotool), captured mid-drag (ImageMagick
# `import`). Usage: scripts/screenshot-drag.sh [OUT.png]   (needs a built `weft`: cargo build)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-test-deps.sh imagemagick
out=${1:-docs/screenshot-drag.png}
weft=${WEFT:-${CARGO_TARGET_DIR:-target}/debug/weft}
display=:$((200 + RANDOM % 200))
Xvfb "$display" -screen 0 1280x800x24 -nolisten tcp -noreset >/dev/null 2>&1 &
xvfb=$!
trap 'kill $xvfb 2>/dev/null || true' EXIT
sleep 1
export DISPLAY=$display WGPU_BACKEND=${WGPU_BACKEND:-vulkan}
"$weft" view --size 1280x800 --eye 1.0,1.7,2.7 --target 0.1,1.25,0 &
app=$!
for _ in $(seq 100); do xdotool search --name Weft >/dev/null 2>&1 && break; sleep 0.2; done
sleep 4
win=$(xdotool search --name Weft | head -1)
xdotool windowfocus --sync "$win"
# The middle of the cloth's lower edge (in the camera above, 1280x800), pulled down, left
# and toward the viewer.
xdotool mousemove --sync 615 470
sleep 0.5
xdotool mousedown 1
for i in $(seq 10); do xdotool mousemove $((615 - 16 * i)) $((470 + 13 * i)); sleep 0.15; done
sleep 2.5
import -window root -crop 1280x800+0+0 "$out"
xdotool mouseup 1
sleep 0.5
xdotool key q
wait $app
echo "wrote $out ($(stat -c %s "$out") bytes)"
