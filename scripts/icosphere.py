#!/usr/bin/env python3
"""Writes the icosphere meshes and the Cornell box with a mesh in it (docs/scenes.md, "Meshes").

    scripts/icosphere.py            # writes scenes/models/icosphere-{0..4}.obj, scenes/cornell-mesh.toml,
                                    # scenes/cornell-sphere.toml
    scripts/icosphere.py --subdivision 7 --out out/meshes
                                    # writes out/meshes/icosphere-7.obj and cornell-mesh-7.toml:
                                    # the same box with that subdivision's icosphere (benchmarks)

An icosphere of subdivision k is the regular icosahedron (12 vertices, 20 faces) with every
triangle split into four at its edges' midpoints k times, each new vertex pushed out onto the
unit sphere: 20 * 4^k triangles, 10 * 4^k + 2 vertices. Every face is wound counter-clockwise
seen from outside (its front normal points out), as a closed glass mesh needs. No normals are
written: a renderer shades each triangle flat, which is what the tessellation costs in accuracy.
Vertices are written with 9 significant digits, enough to read back the same f32.

cornell-mesh.toml is scenes/cornell.toml, read from the repository unchanged, with one object
added: the icosphere of subdivision 3 (1280 triangles), radius 80, resting on the short block
(its top face is at y = 165; the block's footprint centre is (157.95, 168.95), docs/scenes.md).
cornell-sphere.toml is the same box with an analytic sphere of the same centre and radius in
the icosphere's place: the scene the ladder's tessellation rows start from (examples/ladder,
--tessellate), whose icospheres have their vertices on this sphere.
With --subdivision k the box holds the icosphere of subdivision k instead (k = 5, 6, 7, 8 give
20 480, 81 920, 327 680 and 1 310 720 triangles), written with its OBJ into --out, never into
scenes/: a million triangles take 80 MB of text.
"""

import argparse
import math
import pathlib

ROOT = pathlib.Path(__file__).resolve().parent.parent
SUBDIVISIONS = range(5)
CORNELL_SUBDIVISION = 3


def icosahedron():
    t = (1.0 + math.sqrt(5.0)) / 2.0
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
                (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
                (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
             (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
             (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
             (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    return [unit(v) for v in vertices], faces


def unit(v):
    n = math.sqrt(sum(c * c for c in v))
    return tuple(c / n for c in v)


def subdivide(vertices, faces):
    midpoint = {}

    def middle(a, b):
        key = (min(a, b), max(a, b))
        if key not in midpoint:
            vertices.append(unit(tuple((vertices[a][i] + vertices[b][i]) / 2.0 for i in range(3))))
            midpoint[key] = len(vertices) - 1
        return midpoint[key]

    out = []
    for a, b, c in faces:
        ab, bc, ca = middle(a, b), middle(b, c), middle(c, a)
        out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
    return vertices, out


def outward(vertices, faces):
    """Every face's normal (b - a) x (c - a) points away from the centre."""
    for a, b, c in faces:
        pa, pb, pc = vertices[a], vertices[b], vertices[c]
        e1 = [pb[i] - pa[i] for i in range(3)]
        e2 = [pc[i] - pa[i] for i in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        if sum(n[i] * (pa[i] + pb[i] + pc[i]) for i in range(3)) <= 0.0:
            return False
    return True


def obj_text(k, vertices, faces):
    lines = [f"# icosphere, subdivision {k}: {len(faces)} triangles on the unit sphere, written by scripts/icosphere.py"]
    lines += [f"v {x:.9g} {y:.9g} {z:.9g}" for x, y, z in vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in faces]
    return "\n".join(lines) + "\n"


def icosphere(k):
    """The icosphere of subdivision k, checked: counts and outward winding."""
    vertices, faces = icosahedron()
    for _ in range(k):
        vertices, faces = subdivide(vertices, faces)
    assert outward(vertices, faces), f"subdivision {k} has a face wound inward"
    assert len(faces) == 20 * 4 ** k and len(vertices) == 10 * 4 ** k + 2
    return vertices, faces


# Where the ball rests: centred over the short block's footprint, on its top face (y = 165).
BALL_CENTRE = "[157.95, 245.0, 168.95]"
BALL_RADIUS = "80.0"


def cornell_renamed(name, what):
    """scenes/cornell.toml, renamed, under a header saying it was written here with `what` added."""
    cornell = (ROOT / "scenes" / "cornell.toml").read_text()
    header = (f"# Written by scripts/icosphere.py: scenes/cornell.toml with {what} resting on the\n"
              "# short block (docs/scenes.md, \"Meshes\"). Edit the script, not this file.\n\n")
    return header + cornell.replace('name = "cornell"', f'name = "{name}"', 1)


def cornell_with(k, mesh_file, name):
    """scenes/cornell.toml, renamed, with the icosphere of subdivision k (radius 80) on the short block."""
    ball = (f"\n# The icosphere of subdivision {k} ({20 * 4 ** k} flat triangles), radius 80, on the short block's top (y = 165).\n"
            "[[objects]]\n"
            "name = \"icosphere\"\n"
            "material = \"white\"\n"
            f"mesh = {{ file = \"{mesh_file}\", translate = {BALL_CENTRE}, scale = {BALL_RADIUS} }}\n")
    return cornell_renamed(name, "an icosphere mesh") + ball


def cornell_with_sphere():
    """scenes/cornell.toml, renamed, with an analytic sphere where cornell_with puts the icosphere."""
    ball = ("\n# An analytic sphere of radius 80 on the short block's top (y = 165), where cornell-mesh.toml\n"
            "# has its icosphere: the ladder's tessellation rows put icospheres in its place.\n"
            "[[objects]]\n"
            "name = \"sphere\"\n"
            "material = \"white\"\n"
            f"sphere = {{ center = {BALL_CENTRE}, radius = {BALL_RADIUS} }}\n")
    return cornell_renamed("cornell-sphere", "an analytic sphere") + ball


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--subdivision", type=int, help="write only this subdivision's box, into --out")
    parser.add_argument("--out", type=pathlib.Path, help="the directory for --subdivision's files")
    args = parser.parse_args()
    if args.subdivision is not None:
        if args.out is None or not 0 <= args.subdivision <= 9:
            parser.error("--subdivision takes 0 to 9 and needs --out")
        k = args.subdivision
        args.out.mkdir(parents=True, exist_ok=True)
        vertices, faces = icosphere(k)
        (args.out / f"icosphere-{k}.obj").write_text(obj_text(k, vertices, faces))
        (args.out / f"cornell-mesh-{k}.toml").write_text(cornell_with(k, f"icosphere-{k}.obj", f"cornell-mesh-{k}"))
        return
    models = ROOT / "scenes" / "models"
    models.mkdir(parents=True, exist_ok=True)
    for k in SUBDIVISIONS:
        vertices, faces = icosphere(k)
        (models / f"icosphere-{k}.obj").write_text(obj_text(k, vertices, faces))
    scene = cornell_with(CORNELL_SUBDIVISION, f"models/icosphere-{CORNELL_SUBDIVISION}.obj", "cornell-mesh")
    (ROOT / "scenes" / "cornell-mesh.toml").write_text(scene)
    (ROOT / "scenes" / "cornell-sphere.toml").write_text(cornell_with_sphere())


if __name__ == "__main__":
    main()
