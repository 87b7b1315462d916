#!/usr/bin/env bash
# Regenerates every picture the README shows and re-measures every number it quotes, from the
# code as it is now. One command:
#
#     scripts/readme-figures.sh
#
# Pictures are written over docs/images/; the numbers are printed, each under the README line it
# backs, for the README to be updated by hand where they moved. Timings are only meaningful on an
# idle machine (a parallel build doubles them). Needs the Vulkan driver, and xvfb-run for the
# viewer's screenshots (sudo apt-get install mesa-vulkan-drivers xvfb xauth). About 5 minutes
# after the release build on this project's 2-core machine.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --examples -p illum
cargo build --release -p illum-viewer
bin=target/release/examples
out=out/readme-figures
mkdir -p "$out" docs/images
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

echo "== Pictures"
"$bin/render" scenes/cornell.toml --spp 2048 -o docs/images/cornell.png
"$bin/raster_figures" --out docs/images
"$bin/render" scenes/whitted.toml --renderer whitted --width 640 --height 360 -o docs/images/whitted-raytraced.png
"$bin/render" scenes/whitted.toml --renderer pathtrace --width 640 --height 360 --spp 1024 --encoding linear \
    -o docs/images/whitted-pathtraced.png
cp docs/images/whitted-pathtraced.png docs/images/whitted-caustic.png
"$bin/render" scenes/whitted.toml --renderer pathtrace --width 640 --height 360 --spp 1024 --encoding linear \
    --caustics off -o docs/images/whitted-no-caustic.png
# docs/caustics.md: the caustic measured (scripts/caustic-measure.py reads these).
for caustics in on off; do
    "$bin/render" scenes/whitted.toml --renderer pathtrace --width 320 --height 180 --spp 1024 \
        --encoding linear --exposure -1 --caustics $caustics -o out/m-$caustics.png
    "$bin/render" scenes/whitted.toml --renderer pathtrace --width 320 --height 180 --spp 64 --seed 7 \
        --encoding linear --exposure -1 --caustics $caustics -o out/m-${caustics}64.png
done
python3 scripts/caustic-measure.py
"$bin/figures" --out "$out/figures"
cp "$out/figures/contact-sheet.png" docs/images/figures.png
if command -v xvfb-run > /dev/null; then
    xvfb-run -a -s "-screen 0 1280x800x24" target/release/illum-viewer scenes/cornell.toml \
        --screenshot docs/images/viewer-pathtrace.png --frames 60
    xvfb-run -a -s "-screen 0 1280x800x24" target/release/illum-viewer scenes/whitted.toml \
        --screenshot docs/images/viewer-raster.png --frames 60
else
    echo "xvfb-run is missing: the viewer screenshots were not redone (sudo apt-get install xvfb xauth)"
fi

echo
echo "== The ladder (docs/ladder-whitted.md, docs/ladder-cornell.md, the README's ladder table)"
"$bin/ladder" --out "$out/ladder"
cp "$out/ladder/ladder.md" docs/ladder-whitted.md
cp "$out/ladder/error-vs-time.png" docs/images/ladder-error-vs-time.png
cp "$out/ladder/flip-vs-time.png" docs/images/ladder-flip-vs-time.png
cp "$out/ladder/contact-sheet.png" docs/images/ladder-contact-sheet.png
"$bin/ladder" scenes/cornell.toml --width 128 --height 128 --truth-spp 8192 --spp-list 1,16,256 \
    --bounce-list 0,1,2,4,8 --bounce-spp 512 --out "$out/ladder-cornell"
cp "$out/ladder-cornell/ladder.md" docs/ladder-cornell.md
cp "$out/ladder-cornell/contact-sheet.png" docs/images/ladder-cornell-contact-sheet.png

echo
echo "== 'reaches 1% estimated relative error at about N spp' (512 x 512, the default scene)"
"$bin/render" --target-error 0.01 -o "$out/cornell-1pct.exr"
echo
echo "== 'With no stop-rule flag ... (on this project's 2-core machine: N spp, X% error, in T s)'"
"$bin/render" -o "$out/cornell-default.exr"
echo
echo "== 'A relMSE of 10^-2 (10% RMS error) takes about N spp'"
"$bin/render" --target-error 0.1 -o "$out/cornell-10pct.exr"
echo
echo "== 'The pipeline generated for each scene is about N times faster than the generic one'"
"$bin/bench" --quick
echo
echo "== 'Rasterizer, enhanced look: 1280 x 720 with every effect on, median frame about N ms' (camera moving; scene changing)"
"$bin/raster_bench" --look enhanced
