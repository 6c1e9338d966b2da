#!/usr/bin/env bash
# Installs the system packages the trainer needs on Debian/Ubuntu: the X11 and Vulkan runtime
# libraries its window loads, Mesa's Vulkan drivers (software rendering where there is no GPU
# driver), Xvfb, the virtual X server the window tests draw into, and the PostgreSQL server
# the shared-history tests start clusters of their own with. Building needs nothing beyond the
# Rust toolchain and a C compiler.
#   scripts/setup-debian.sh --web   also what the browser test needs: Chromium, and Node.js
#                                   where the machine has none
set -euo pipefail
packages=(
  pkg-config
  libx11-6 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0
  libvulkan1 mesa-vulkan-drivers
  xvfb
  postgresql
)
case "${1:-}" in
  "") ;;
  --web)
    packages+=(chromium)
    command -v node >/dev/null && command -v npm >/dev/null || packages+=(nodejs npm)
    ;;
  *) echo "setup: unknown option \`$1\` (the one option is --web)" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "setup: installing ${missing[*]}"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
