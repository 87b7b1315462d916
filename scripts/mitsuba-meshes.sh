#!/usr/bin/env bash
# illum's path tracer against Mitsuba 3 on triangle meshes (docs/performance-geometry.md, "Meshes"):
#
#     scripts/mitsuba-meshes.sh PYTHON OUT_DIR
#
# PYTHON imports Mitsuba 3 (scripts/readme-figures.sh --mitsuba-venv makes one). First the
# image check on scenes/cornell-mesh.toml (1280 triangles): illum at 1024 spp against a
# 4096-spp Mitsuba reference, 256 x 256, bounces 2. Then the Cornell box with an icosphere of
# 20 480, 327 680 and 1 310 720 triangles (scripts/icosphere.py --subdivision 5, 7, 8, written
# into OUT_DIR/meshes), each at 64 spp against a 1024-spp Mitsuba reference: whole-process time,
# throughput and efficiency, side by side (bench/vs_mitsuba.py prints each table).
set -euo pipefail
cd "$(dirname "$0")/.."
python="$1"
out="$2"
mkdir -p "$out/meshes"

# The tables only (not the reference renders' progress); the machine's load beside them, since
# a second job on the 2 cores slows both renderers' whole processes unevenly.
tables() { grep -v '^rendering the reference'; }
echo "Load average at the start: $(cut -d' ' -f1-3 /proc/loadavg)."
echo
echo "### The image: scenes/cornell-mesh.toml (1280 triangles)"
"$python" bench/vs_mitsuba.py --scene scenes/cornell-mesh.toml --size 256 --spp 1024 --bounces 2 \
    --reference-spp 4096 --samplers independent --illum independent | tables
for k in 5 7 8; do
    python3 scripts/icosphere.py --subdivision "$k" --out "$out/meshes"
    echo
    echo "### $((20 * 4 ** k)) triangles (icosphere subdivision $k)"
    "$python" bench/vs_mitsuba.py --scene "$out/meshes/cornell-mesh-$k.toml" --size 256 --spp 64 --bounces 2 \
        --reference-spp 1024 --samplers independent,multijitter --illum independent,low-discrepancy | tables
done
