#!/usr/bin/env bash
# Regenerates every picture the README shows and re-measures every number it quotes, from the
# code as it is now, and writes the numbers into the generated blocks of the README (`headline`,
# `ladder-summary`) and of docs/performance*.md (`bench-quick`, `viewer-bench`,
# `viewer-bench-whitted`, `caustic-parts`, `caustic-efficiency`, `glint-bench`, `raster-bench`,
# `largest-mesh`, `mitsuba-meshes`, with Mitsuba 3 `mitsuba-b2` and `mitsuba-b8`, and with
# --against `against-build`),
# each with the date and the CPU:
#
#     scripts/readme-figures.sh              pictures, the ladder, then the headline figures
#     scripts/readme-figures.sh --headline   only the headline figures
#     ... --mitsuba-venv                     (with either) first makes out/mitsuba-venv, a venv with
#                                            Mitsuba 3 from pip, installs Debian's libllvm19 for its
#                                            LLVM backend where missing, and compares with Mitsuba
#                                            at bounces 2 and 8 (bench/vs_mitsuba.py)
#     ... --against=REV                      (with either) builds commit REV's render in a worktree
#                                            (out/against-REV) and compares the efficiency of this
#                                            build's caustic estimators with it on the Whitted scene
#                                            against the ladder's truth (bench --against)
#
# Timings are only meaningful on an idle machine (a parallel build doubles them), and absolute
# ones only on the host named; the headline leads with ratios measured side by side. Needs the
# Vulkan driver, and xvfb-run for the viewer (scripts/setup.sh installs both).
set -euo pipefail
cd "$(dirname "$0")/.."

headline_only=false
mitsuba_venv=false
against=""
for arg in "$@"; do
    case "$arg" in
        --headline) headline_only=true ;;
        --mitsuba-venv) mitsuba_venv=true ;;
        --against=?*) against="${arg#--against=}" ;;
        *) echo "unknown option $arg (allowed: --headline, --mitsuba-venv, --against=REV)" >&2; exit 2 ;;
    esac
done
if [ -n "$against" ] && ! git rev-parse --verify --quiet "$against^{commit}" > /dev/null; then
    echo "--against=$against: not a commit of this repository" >&2
    exit 2
fi

# The Python that imports Mitsuba 3: the venv's when asked for, else the system's.
python=python3
if $mitsuba_venv; then
    venv=out/mitsuba-venv
    if [ ! -x "$venv/bin/python" ]; then
        python3 -m venv "$venv"
        "$venv/bin/pip" install --quiet mitsuba==3.9.1 numpy
    fi
    # Dr.Jit's LLVM backend aborts on the LLVM 15 that Mesa brings; bench/vs_mitsuba.py uses 19.
    if ! dpkg -s libllvm19 > /dev/null 2>&1; then
        if [ "$(id -u)" = 0 ]; then
            apt-get install -y libllvm19 || { apt-get update && apt-get install -y libllvm19; }
        else
            sudo apt-get install -y libllvm19
        fi
    fi
    python="$venv/bin/python"
fi

cargo build --release --workspace --examples --bins
bin=target/release/examples
out=out/readme-figures
mkdir -p "$out" docs/images
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-$(mktemp -d)}"

if ! $headline_only; then
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
echo "== The ladder (docs/ladder-whitted.md, docs/ladder-cornell.md, docs/ladder-tessellation.md, the README's ladder table)"
"$bin/ladder" --out "$out/ladder"
cp "$out/ladder/ladder.md" docs/ladder-whitted.md
cp "$out/ladder/error-vs-time.png" docs/images/ladder-error-vs-time.png
cp "$out/ladder/flip-vs-time.png" docs/images/ladder-flip-vs-time.png
cp "$out/ladder/contact-sheet.png" docs/images/ladder-contact-sheet.png
"$bin/ladder" scenes/cornell.toml --width 128 --height 128 --truth-spp 8192 --spp-list 1,16,256 \
    --bounce-list 0,1,2,4,8 --bounce-spp 512 --out "$out/ladder-cornell"
cp "$out/ladder-cornell/ladder.md" docs/ladder-cornell.md
cp "$out/ladder-cornell/contact-sheet.png" docs/images/ladder-cornell-contact-sheet.png
# docs/ladder-tessellation.md: the box's sphere against icospheres in its place (the truth at the
# rows' own bounces, so that a row's error is its noise and its geometry's).
"$bin/ladder" scenes/cornell-sphere.toml --width 256 --height 256 --truth-spp 8192 --truth-bounces 2 \
    --spp-list 16 --depths 1 --bounce-spp 0 --denoise-spp-list --tessellate 1,2,3,4 --tessellate-flat 1,3 \
    --tessellate-spp 256 --frames 3 --out "$out/ladder-tessellation"
sed 's|](tessellation-sheet.png)|](images/ladder-tessellation-sheet.png)|' "$out/ladder-tessellation/ladder.md" \
    > docs/ladder-tessellation.md
cp "$out/ladder-tessellation/tessellation-sheet.png" docs/images/ladder-tessellation-sheet.png
# docs/auto-check.md: render --renderer auto against the truth, predicted against measured.
"$bin/auto_check" --out "$out/auto-check"
cp "$out/auto-check/auto-check.md" docs/auto-check.md


# The README's ladder table: selected rows of ladder.csv.
python3 scripts/readme-block.py ladder-summary "$out/ladder/ladder.csv"
fi

echo
echo "== The headline figures (README, between the headline markers)"
"$bin/render" --target-error 0.01 -o "$out/cornell-1pct.exr" | tee "$out/render-1pct.txt"
"$bin/render" -o "$out/cornell-default.exr" | tee "$out/render-default.txt"
"$bin/bench" --quick --runs 3 | tee "$out/bench-quick.txt"
"$bin/bench" --viewer --runs 3 | tee "$out/bench-viewer.txt"
"$bin/bench" --viewer --runs 3 scenes/whitted.toml | tee "$out/bench-viewer-whitted.txt"
"$bin/raster_bench" --look enhanced | tee "$out/raster-bench.txt"
for n in 10 50 200; do python3 scripts/many-spheres.py $n -o "$out/spheres-$n.toml"; done
"$bin/bench" --runs 3 --parts scenes/whitted.toml | tee "$out/bench-parts.txt"
"$bin/bench" --runs 3 --glint scenes/whitted.toml "$out"/spheres-{10,50,200}.toml | tee "$out/bench-glint.txt"
# docs/performance-geometry.md, "Many spheres": the time to the first image, cold and warm.
"$bin/bench" --runs 3 --first-image scenes/whitted.toml "$out"/spheres-{50,200}.toml | tee "$out/bench-first-image.txt"
# docs/performance-geometry.md, "Meshes": the largest mesh the device holds.
"$bin/bench" --largest-mesh | tee "$out/bench-largest-mesh.txt"
if "$python" -c "import mitsuba" 2> /dev/null; then
    "$python" bench/vs_mitsuba.py --bounces 2 | tee "$out/vs-mitsuba.txt"
    "$python" bench/vs_mitsuba.py --bounces 8 | tee "$out/vs-mitsuba-b8.txt"
    scripts/mitsuba-meshes.sh "$python" "$out" | tee "$out/vs-mitsuba-meshes.txt"
else
    echo "Mitsuba 3 is not installed here: the comparison is not re-measured (see bench/vs_mitsuba.py)" \
        | tee "$out/vs-mitsuba.txt"
fi
if [ -n "$against" ]; then
    # The ladder's truth (light tracer, 16384 spp, bounces unbounded), made by the ladder above
    # or by an earlier run of this script.
    truth=$(ls "$out"/ladder/reference-whitted-*.exr 2> /dev/null | head -n 1)
    if [ -z "$truth" ]; then
        echo "--against: no ladder truth in $out/ladder (run this script once without --headline)" >&2
        exit 1
    fi
    tree="out/against-$against"
    [ -d "$tree" ] || git worktree add --detach "$tree" "$against"
    (cd "$tree" && CARGO_TARGET_DIR="$PWD/target" cargo build --release --example render)
    { echo "The other build: commit $(git rev-parse --short "$against")'s \`render\`."
      "$bin/bench" --runs 5 --against "$tree/target/release/examples/render" --truth "$truth" scenes/whitted.toml
    } | tee "$out/against.txt"
fi
python3 scripts/readme-block.py headline "$out"
python3 scripts/readme-block.py perf-tables "$out"
