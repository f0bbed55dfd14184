#!/usr/bin/env bash
# Serves web/dist (built by `bash web/build.sh`) on http://127.0.0.1:8080
# (PORT changes it). Python's server gives .wasm its application/wasm type,
# which the browser's streaming compile needs.
set -euo pipefail
cd "$(dirname "$0")/dist" 2> /dev/null || {
    echo "web/serve.sh: no web/dist: build the page first with bash web/build.sh" >&2
    exit 1
}
port=${PORT:-8080}
echo "marbre: open http://127.0.0.1:$port/ in a browser with WebGPU (Ctrl-C stops)"
exec python3 -m http.server "$port" --bind 127.0.0.1
