#!/usr/bin/env bash
# Installs what illum's tests need on Debian or Ubuntu, from one list each, so that the README's
# set-up line and CI cannot drift apart (tests/render_cli/docs.rs checks that the README's line is
# BASE_PACKAGES):
#
#     scripts/setup.sh              the default test run: lavapipe and a virtual display
#     scripts/setup.sh --browser    also the web viewer's browser test (chromium, node, the wasm
#                                   target, wasm-bindgen at Cargo.lock's version, playwright-core)
#     scripts/setup.sh --slurm      also the farm tests (slurm-wlm, munge, GNU parallel)
#
# As root or with sudo. `.ci/run` runs it with both options.
set -euo pipefail
cd "$(dirname "$0")/.."

# lavapipe (Mesa's software Vulkan driver) and the Vulkan loader: the GPU tests run on the CPU.
# xvfb and xauth: a virtual display for the viewer's windowed smoke test; libxcursor1, libxi6
# and libxkbcommon-x11-0: the X11 libraries winit loads at run time (on a clean Debian 12 the
# window failed without them: "Failed to load one of xlib's shared libraries").
# g++: nv-flip (the FLIP image metric) builds NVIDIA's C++ reference code; rustup's toolchain
# brings no C++ compiler, and a clean Debian 12 with Rust has none.
BASE_PACKAGES="mesa-vulkan-drivers libvulkan1 xvfb xauth libxcursor1 libxi6 libxkbcommon-x11-0 g++"
BROWSER_PACKAGES="chromium"
SLURM_PACKAGES="slurm-wlm munge parallel"

browser=false
slurm=false
for arg in "$@"; do
    case "$arg" in
        --browser) browser=true ;;
        --slurm) slurm=true ;;
        --print-base) echo "$BASE_PACKAGES"; exit 0 ;;
        *) echo "scripts/setup.sh: unknown option $arg (allowed: --browser, --slurm)" >&2; exit 2 ;;
    esac
done

export DEBIAN_FRONTEND=noninteractive
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

packages="$BASE_PACKAGES"
if $browser; then
    packages="$packages $BROWSER_PACKAGES"
    # Node and npm only when missing: a machine with another Node (nodesource's bundles npm,
    # which conflicts with Debian's npm package) keeps its own.
    command -v node > /dev/null || packages="$packages nodejs"
    command -v npm > /dev/null || packages="$packages npm"
fi
if $slurm; then
    packages="$packages $SLURM_PACKAGES"
fi
$SUDO apt-get update
# As the README's line does, recommended packages included; the lists are words, unquoted.
$SUDO apt-get install -y $packages

if $browser; then
    # The web viewer's build: the wasm target and wasm-bindgen at exactly Cargo.lock's version
    # (crates/illum-viewer/tests/web/main.rs fails under CI when any of this is missing).
    rustup target add wasm32-unknown-unknown
    wasm_bindgen_version=$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/"/, "", $3); print $3 }' Cargo.lock)
    if [ "$(wasm-bindgen --version 2> /dev/null | awk '{ print $2 }')" != "$wasm_bindgen_version" ]; then
        # Its own target folder, removed after: it shares nothing with the workspace's build.
        # Not --locked: its lock file names crates the registry may not have.
        wasm_bindgen_build="$(mktemp -d)"
        CARGO_TARGET_DIR="$wasm_bindgen_build" cargo install wasm-bindgen-cli --version "$wasm_bindgen_version"
        rm -rf "$wasm_bindgen_build"
    fi
    # Playwright's driver for the system chromium (no browser download), as package-lock.json
    # pins it.
    npm ci --prefix web/tests --no-audit --no-fund
fi
