#!/usr/bin/env bash
# The browser test: builds the page (scripts/web-build.sh), serves it on a free local port,
# and runs tests/web/browser.mjs in headless Chromium (/usr/bin/chromium, or $CHROMIUM), which
# scores shipped scenarios' scripted runs in the page, drawn by each renderer built
# (WEB_RENDERERS, both by default). The canvases land in web/dist/shot-<renderer>.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/web-build.sh
(cd web && npm ci --no-audit --no-fund --loglevel=error)
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
python3 scripts/web_serve.py "$port" web/dist >/dev/null 2>&1 &
server=$!
trap 'kill $server' EXIT
for _ in $(seq 50); do
  python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/')" 2>/dev/null && break
  sleep 0.1
done
node tests/web/browser.mjs "http://127.0.0.1:$port/" web/dist "${WEB_RENDERERS:-webgl2 webgpu}"
