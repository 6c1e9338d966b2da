#!/usr/bin/env bash
# Serves the page scripts/web-build.sh built (web/dist/) on http://localhost:${PORT:-8080}/.
set -euo pipefail
cd "$(dirname "$0")/.."
exec python3 scripts/web_serve.py "${PORT:-8080}" web/dist
