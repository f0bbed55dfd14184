#!/usr/bin/env bash
# Builds marbre's web page into web/dist (issue 34): the viewer compiled to
# wasm32 (`web/src/lib.rs` → `marbre::app::web`), bound to JavaScript by
# wasm-bindgen, shrunk by binaryen's wasm-opt where it is installed, with
# the page, the shipped presets, env maps, meshes and images beside it and
# `assets.json` listing them (the page fetches them before it starts).
#
# Needs: rustup's wasm32-unknown-unknown target, and wasm-bindgen-cli at
# the lockfile's wasm-bindgen version (README, "The viewer in a browser").
# Serve the result with `bash web/serve.sh`.
set -euo pipefail
cd "$(dirname "$0")/.."
dist=web/dist
wasm=target/wasm32-unknown-unknown/web/marbre_web.wasm

bindgen_version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/"/, "", $3); print $3 }' Cargo.lock)
if ! command -v wasm-bindgen > /dev/null; then
    echo "web/build.sh: wasm-bindgen is not installed: cargo install wasm-bindgen-cli --version $bindgen_version" >&2
    exit 1
fi
if [ "$(wasm-bindgen --version | awk '{print $2}')" != "$bindgen_version" ]; then
    echo "web/build.sh: wasm-bindgen $(wasm-bindgen --version | awk '{print $2}') is installed, the lockfile needs $bindgen_version:" \
        "cargo install wasm-bindgen-cli --version $bindgen_version" >&2
    exit 1
fi

# The `web` profile (Cargo.toml) optimises for size. Without reference
# types: wasm-bindgen then keeps JavaScript objects in a table of its own,
# which Debian's binaryen (108) optimises correctly; with them, its
# wasm-opt broke the page (a table of functions typed as one of objects).
CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="-Ctarget-feature=-reference-types" \
    cargo build --profile web --locked --target wasm32-unknown-unknown -p marbre-web
rm -rf "$dist"
mkdir -p "$dist"
wasm-bindgen --target web --no-typescript --out-dir "$dist" "$wasm"
if command -v wasm-opt > /dev/null; then
    # The features rustc's wasm32 target enables by default; binaryen's
    # own defaults are older.
    wasm-opt -Oz --enable-bulk-memory --enable-mutable-globals --enable-sign-ext \
        --enable-nontrapping-float-to-int --enable-multivalue \
        "$dist/marbre_web_bg.wasm" -o "$dist/marbre_web_bg.wasm"
else
    echo "web/build.sh: wasm-opt (Debian's binaryen) is not installed: the wasm is left unshrunk" >&2
fi
cp web/index.html "$dist/"
# The shipped files, with their paths as the presets name them.
find presets envmaps -type f ! -name README.md | sort > "$dist/.assets"
while read -r file; do
    mkdir -p "$dist/$(dirname "$file")"
    cp "$file" "$dist/$file"
done < "$dist/.assets"
python3 -c 'import json, sys; print(json.dumps([l.strip() for l in open(sys.argv[1]) if l.strip()]))' \
    "$dist/.assets" > "$dist/assets.json"
rm "$dist/.assets"
echo "web/build.sh: $dist ready ($(du -h "$dist/marbre_web_bg.wasm" | cut -f1) of wasm, $(du -sh "$dist" | cut -f1) in all)"
