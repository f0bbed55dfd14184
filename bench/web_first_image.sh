#!/usr/bin/env bash
# The web page's start (issue 34's target: under 5 s from navigation to
# the first image, in headless Chromium on SwiftShader): builds the page,
# then opens it RUNS times (default 5), each in a new browser session, and
# prints each time and the median (web/tests/page.rs, bench_first_image).
#
#   bash bench/web_first_image.sh [RUNS]
#
# Needs what web/test.sh needs (README, "The viewer in a browser").
set -euo pipefail
cd "$(dirname "$0")/.."
bash web/build.sh
MARBRE_WEB_RUNS=${1:-5} MARBRE_REQUIRE_WEB=1 \
    cargo test --locked --release -p marbre-web --test page bench_first_image -- --ignored --nocapture
