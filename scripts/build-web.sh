#!/usr/bin/env bash
# Builds the web viewer into web/dist/ (index.html, illum_viewer.js, illum_viewer_bg.wasm), and
# records in web/dist/inputs.sha256 the fingerprint of what it was built from.
# With --if-stale, builds only when web/dist's fingerprint differs from the sources' (the browser
# test, crates/illum-viewer/tests/web/main.rs, calls it so; .ci/run builds the page beside the
# tests, and the test waits for that build).
# With --serve, then serves it on http://127.0.0.1:8000/ (PORT=... to change).
#
# Needs: rustup target add wasm32-unknown-unknown
#        cargo install wasm-bindgen-cli --version <the wasm-bindgen version in Cargo.lock>
set -euo pipefail
cd "$(dirname "$0")/.."

target_dir="${CARGO_TARGET_DIR:-$PWD/target}"
dist="web/dist"

# wasm-bindgen-cli must be exactly the wasm-bindgen crate's version.
wanted=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/"/, "", $3); print $3 }' Cargo.lock)
if ! command -v wasm-bindgen >/dev/null; then
    echo "error: wasm-bindgen is not installed; install it with: cargo install wasm-bindgen-cli --version $wanted" >&2
    exit 1
fi
have=$(wasm-bindgen --version | awk '{ print $2 }')
if [ "$have" != "$wanted" ]; then
    echo "error: wasm-bindgen $have is installed but Cargo.lock has wasm-bindgen $wanted; install the same: cargo install wasm-bindgen-cli --version $wanted" >&2
    exit 1
fi
if command -v rustup >/dev/null && ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    echo "error: the wasm32-unknown-unknown target is missing; add it with: rustup target add wasm32-unknown-unknown" >&2
    exit 1
fi

# Everything the page is built from: the toolchain and wasm-bindgen, the flags, the manifests and
# lock file, every crate's sources and shaders (their tests and benches aside), the built-in
# scenes, the page and this script. One sha256 over the files' own sha256 lines.
fingerprint() {
    {
        rustc --version
        wasm-bindgen --version
        echo "RUSTFLAGS=${RUSTFLAGS:-}"
        find Cargo.toml Cargo.lock rust-toolchain.toml web/index.html scripts/build-web.sh scenes crates \
            -type f -not -path 'crates/*/tests/*' -not -path 'crates/*/benches/*' -print0 |
            sort -z | xargs -0 sha256sum
    } | sha256sum | cut -d' ' -f1
}

mode="${1:-}"
# One build at a time: a second caller (the browser test while .ci/run builds the page beside
# the tests) waits here, then finds the page up to date.
mkdir -p web
exec 9>web/.build-lock
flock 9
inputs=$(fingerprint)
if [ "$mode" = "--if-stale" ] && [ "$(cat "$dist/inputs.sha256" 2>/dev/null)" = "$inputs" ]; then
    echo "$dist is up to date (built from the same inputs, $inputs)"
    exit 0
fi

cargo build --release --target wasm32-unknown-unknown -p illum-viewer --bin illum-viewer
rm -rf "$dist"
mkdir -p "$dist"
wasm-bindgen --target web --no-typescript --out-name illum_viewer --out-dir "$dist" \
    "$target_dir/wasm32-unknown-unknown/release/illum-viewer.wasm"
cp web/index.html "$dist/"
# Last, so that a build cut short leaves no fingerprint and is built again.
echo "$inputs" >"$dist/inputs.sha256"
echo "built $dist: $(du -sh "$dist" | cut -f1)"

if [ "$mode" = "--serve" ]; then
    exec 9>&-
    port="${PORT:-8000}"
    echo "serving on http://127.0.0.1:$port/ (Ctrl-C stops)"
    exec python3 -m http.server "$port" --bind 127.0.0.1 --directory "$dist"
fi
