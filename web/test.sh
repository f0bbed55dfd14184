#!/usr/bin/env bash
# The web page's tests (issue 34), in a real browser: Debian's Chromium
# and chromedriver, WebGPU on SwiftShader (the flags are web/webdriver.json's).
#   1. builds the page (web/build.sh);
#   2. traces a shipped preset natively (lavapipe), both kernels, as the
#      browser test's reference (web/tests/browser_parity.rs);
#   3. traces it inside headless Chromium with wasm-bindgen's test runner
#      and compares;
#   4. drives the built page end to end (web/tests/page.rs): load, a
#      slider edit, a shared link reopened.
# Every missing piece fails here (MARBRE_REQUIRE_WEB=1): .ci/run decides
# beforehand whether the web can be tested at all.
set -euo pipefail
cd "$(dirname "$0")/.."
export MARBRE_REQUIRE_WEB=1
# The browser test builds in the native step's images: without an adapter
# that step must fail, not skip and leave an older run's images in place.
export MARBRE_REQUIRE_GPU=1
target=${CARGO_TARGET_DIR:-target}
rm -f "$target"/wasm32-unknown-unknown/tmp/web-parity-*.f32
for tool in chromium chromedriver wasm-bindgen-test-runner; do
    command -v "$tool" > /dev/null || { echo "web/test.sh: $tool is not installed (README, \"The viewer in a browser\")" >&2; exit 1; }
done
bash web/build.sh
cargo test --locked -p marbre-web --test browser_parity
# The runner reads web/webdriver.json from the package's folder, where
# cargo runs it.
CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner \
    CHROMEDRIVER=$(command -v chromedriver) WASM_BINDGEN_TEST_TIMEOUT=300 \
    cargo test --locked -p marbre-web --target wasm32-unknown-unknown --test browser_parity
cargo test --locked -p marbre-web --test page -- --nocapture
