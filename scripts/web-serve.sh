#!/usr/bin/env bash
# Serves the page scripts/web-build.sh built (web/dist/) on http://localhost:${PORT:-8080}/.
set -euo pipefail
cd "$(dirname "$0")/../web/dist"
port="${PORT:-8080}"
echo "the trainer: http://localhost:$port/ (?scenario=STEM picks a shipped scenario)"
exec python3 -m http.server "$port" --bind 127.0.0.1
