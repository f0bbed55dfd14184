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
target=${CARGO_TARGET_DIR:-target}
wasm=$target/wasm32-unknown-unknown/web/marbre_web.wasm

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

# The `web` profile (Cargo.toml) optimises for size.
cargo build --profile web --locked --target wasm32-unknown-unknown -p marbre-web
rm -rf "$dist"
mkdir -p "$dist"
if command -v wasm-opt > /dev/null; then
    # Shrunk before wasm-bindgen adds its table of JavaScript objects:
    # Debian's binaryen (108) writes a module with two tables back with
    # the table export pointing at the wrong one (the page then fails in
    # WebAssembly.Table.set). The features are those rustc's wasm32 target
    # uses, which binaryen 108 does not assume.
    mkdir -p "$target/web-opt"
    wasm-opt -Oz --enable-bulk-memory --enable-mutable-globals --enable-sign-ext \
        --enable-nontrapping-float-to-int --enable-reference-types --enable-multivalue \
        "$wasm" -o "$target/web-opt/marbre_web.wasm"
    wasm=$target/web-opt/marbre_web.wasm
else
    echo "web/build.sh: wasm-opt (Debian's binaryen) is not installed: the wasm is left unshrunk" >&2
fi
wasm-bindgen --target web --no-typescript --out-dir "$dist" "$wasm"
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
