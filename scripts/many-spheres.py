#!/usr/bin/env python3
"""Writes the Whitted scene with N small spheres (or quads, or boxes) added on its floor: a scene
with many specular objects, for measuring what each renderer's cost does as objects are added
(docs/performance-caustics.md, "Many specular objects"; docs/performance-geometry.md, "Many spheres").

    scripts/many-spheres.py 200 > out/spheres-200.toml
    scripts/many-spheres.py 50 -o out/spheres-50.toml
    scripts/many-spheres.py 200 --shape quad -o out/quads-200.toml

With `--shape quad` each sphere's place holds a square of its diameter standing on its lower edge,
tilted back by 30 degrees and turned about +Y; with `--shape box` a cube of its diameter resting
on the floor, turned about +Y.

The spheres cycle through glass, mirror and a diffuse white, in that order, on a jittered grid
over the lit part of the floor (x in [-10, 6], z in [-7, 7]) that keeps clear of the scene's two
spheres. Their radii and places come from a fixed seed, so a count always gives the same file.
The rest of the scene is scenes/whitted.toml unchanged, read from the repository: its camera,
sky, sun, materials and settings.
"""

import argparse
import math
import os
import pathlib
import random
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
BASE = ROOT / "scenes" / "whitted.toml"
# The scene's own spheres (centre x, z, radius), kept clear of.
KEEP_CLEAR = [(4.2, -4.2, 1.0), (2.0, -2.5, 1.0)]
MATERIALS = ["glass", "metal", "white"]
X_RANGE = (-10.0, 6.0)
Z_RANGE = (-7.0, 7.0)
MAX_COUNT = 2000


def spheres(count, seed=1):
    """Up to `count` non-overlapping spheres resting on the floor (y = radius)."""
    rng = random.Random(seed)
    # A grid with at least `count` cells over the area, each sphere jittered inside its cell.
    width = X_RANGE[1] - X_RANGE[0]
    depth = Z_RANGE[1] - Z_RANGE[0]
    # Spare cells (a tenth, and at least 8) for those that meet the scene's own spheres.
    cells_wanted = count + max(8, count // 10)
    columns = max(1, math.ceil(math.sqrt(cells_wanted * width / depth)))
    rows = max(1, math.ceil(cells_wanted / columns))
    cell = min(width / columns, depth / rows)
    placed = []
    cells = [(i, j) for j in range(rows) for i in range(columns)]
    rng.shuffle(cells)
    for i, j in cells:
        if len(placed) == count:
            break
        radius = cell * rng.uniform(0.2, 0.4)
        x = X_RANGE[0] + (i + 0.5) * width / columns + rng.uniform(-1, 1) * (cell / 2 - radius)
        z = Z_RANGE[0] + (j + 0.5) * depth / rows + rng.uniform(-1, 1) * (cell / 2 - radius)
        if any(math.hypot(x - cx, z - cz) < r + radius + 0.05 for cx, cz, r in KEEP_CLEAR):
            continue
        placed.append((x, radius, z))
    return placed


def vec(v):
    return "[" + ", ".join(f"{c:.4f}" for c in v) + "]"


def shape_line(shape, x, radius, z, turn):
    """The TOML of one small object in the place of the sphere (x, radius, z)."""
    if shape == "sphere":
        return f"sphere = {{ center = {vec((x, radius, z))}, radius = {radius:.4f} }}"
    side = 2.0 * radius
    if shape == "box":
        return (f"box = {{ min = {vec((-radius, 0.0, -radius))}, max = {vec((radius, side, radius))}, "
                f"rotate_y = {math.degrees(turn):.2f}, translate = {vec((x, 0.0, z))} }}")
    # A square on its lower edge (along the turned x axis), its other edge tilted back 30 degrees.
    c, s = math.cos(turn), math.sin(turn)
    edge_u = (side * c, 0.0, -side * s)
    tilt = math.radians(30.0)
    back = (side * math.sin(tilt) * s, side * math.cos(tilt), side * math.sin(tilt) * c)
    corner = (x - edge_u[0] / 2, 0.001, z - edge_u[2] / 2)
    return f"quad = {{ corner = {vec(corner)}, edge_u = {vec(edge_u)}, edge_v = {vec(back)} }}"


def scene(count, shape="sphere"):
    base = BASE.read_text()
    # The base scene's name and materials, plus the diffuse white the objects use.
    base = base.replace('name = "whitted"', f'name = "whitted-{count}-{shape}s"', 1)
    out = [base.rstrip("\n"), "", "# Added by scripts/many-spheres.py.", "[materials.white]",
           "albedo = [0.8, 0.8, 0.8]", ""]
    placed = spheres(count)
    turns = random.Random(2)
    for k, (x, radius, z) in enumerate(placed):
        material = MATERIALS[k % len(MATERIALS)]
        out += [
            "[[objects]]",
            f'name = "small {shape} {k}"',
            f'material = "{material}"',
            shape_line(shape, x, radius, z, turns.uniform(0.0, math.pi)),
            "",
        ]
    return "\n".join(out), len(placed)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("count", type=int, help=f"spheres to add, 1 to {MAX_COUNT}")
    parser.add_argument("--shape", choices=["sphere", "quad", "box"], default="sphere",
                        help="the shape added (default sphere)")
    parser.add_argument("-o", "--output", help="file to write (atomically); standard output if absent")
    args = parser.parse_args()
    if not 1 <= args.count <= MAX_COUNT:
        parser.error(f"count {args.count}: must be 1 to {MAX_COUNT}")
    text, placed = scene(args.count, args.shape)
    if placed < args.count:
        print(f"many-spheres.py: placed {placed} of {args.count} {args.shape}s (the rest met the scene's own)",
              file=sys.stderr)
    if args.output is None:
        sys.stdout.write(text)
        return
    target = pathlib.Path(args.output)
    target.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile("w", dir=target.parent, delete=False, suffix=".tmp") as f:
        f.write(text)
    os.replace(f.name, target)


if __name__ == "__main__":
    main()
