#!/usr/bin/env bash
# Installs the system packages Weft's tests need, skipping those already installed:
# a virtual X server and a mouse driver for the viewer's end-to-end test (xvfb, xdotool),
# software Vulkan and OpenGL/EGL (Mesa lavapipe and llvmpipe) for wgpu, and the X11 client
# libraries winit loads at run time. Debian/Ubuntu (apt-get); as root, or through sudo.
# Extra packages may be named on the command line (e.g. imagemagick for screenshots).
set -euo pipefail

packages=(
  xvfb xdotool
  mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri
  libx11-6 libx11-xcb1 libxcursor1 libxi6 libxrandr2 libxkbcommon0 libxkbcommon-x11-0
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-test-deps: missing packages (${missing[*]}) and no apt-get: install them by hand" >&2
  exit 1
fi
if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1 && sudo -n true 2>/dev/null; then
  as_root=(sudo -n)
else
  echo "install-test-deps: need root (or password-less sudo) to install: ${missing[*]}" >&2
  exit 1
fi
echo "install-test-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
