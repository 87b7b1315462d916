#!/usr/bin/env python3
"""illum's path tracer side by side with Mitsuba 3 on the same Cornell box.

Builds the box of scenes/cornell.toml in Mitsuba 3 (boxes as `cube` shapes, Lambertian
`diffuse` in `twosided`, the light a one-sided `rectangle` emitter, a triangle mesh as an `obj`
shape with Mitsuba's own loader and BVH (Embree in `llvm_ad_rgb`), `path` integrator with
max_depth = bounces + 2 and rr_depth = max_depth, box pixel filter, float32 `hdrfilm`), renders
it with Mitsuba's `llvm_ad_rgb` variant and with illum's `render` example at the same size, spp
and bounces, and prints for each: the wall time of the whole process (start to written EXR),
the throughput, the relMSE against a converged reference and the efficiency
1 / (relMSE x time). Optional: not part of `cargo test`.

    python3 -m venv venv && venv/bin/pip install mitsuba==3.9.1 numpy
    sudo apt-get install libllvm19        # Dr.Jit's LLVM backend; the preinstalled LLVM 15 aborts
    cargo build --release --example render
    venv/bin/python bench/vs_mitsuba.py [--size 256] [--spp 1024] [--bounces 2]
        [--samplers independent,multijitter,orthogonal,ldsampler] [--reference-spp 32768]
        [--reference-renderer mitsuba|illum] [--illum independent,low-discrepancy,adaptive,no-replicates]
        [--scene scenes/cornell.toml]

(`scripts/readme-figures.sh --mitsuba-venv` makes that venv itself, in out/mitsuba-venv, and
runs this script at bounces 2 and 8.) Where libLLVM-19 is installed, the script points Dr.Jit
at it (DRJIT_LIBLLVM_PATH) unless that is already set.

illum renders with independent numbers, the low-discrepancy sequence, that sequence with
adaptive sampling (`--adaptive`, the same mean spp), and that sequence without replicates
(`--replicates off`: one randomisation, no error estimate, as Mitsuba's samplers give none).

Run it on an idle machine: a parallel build doubles every time. The reference is rendered by
Mitsuba (`--reference-renderer mitsuba`, the default: its multijitter sampler at --reference-spp,
in passes of --spp samples with seeds 1, 2, ... averaged), so that a difference between the two
renderers' models of the box counts against illum as much as against Mitsuba; `illum` makes it
with illum's low-discrepancy sequence, seed 1, instead. It is cached in out/vs-mitsuba/; its own
relMSE adds about spp / reference-spp of a row's to every figure.
"""

import argparse
import math
import os
import subprocess
import sys
import time
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "out", "vs-mitsuba")
RENDER = os.path.join(ROOT, "target", "release", "examples", "render")
# Debian's libllvm19: Dr.Jit's LLVM backend aborts on the LLVM 15 that Mesa brings.
LIBLLVM19 = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
if os.path.exists(LIBLLVM19):
    os.environ.setdefault("DRJIT_LIBLLVM_PATH", LIBLLVM19)


def load_exr(path):
    """Linear RGB float image of an EXR, as a numpy array (height, width, 3)."""
    import mitsuba as mi
    import numpy as np

    bitmap = mi.Bitmap(path)
    image = np.array(bitmap, dtype=np.float64)
    return image[:, :, :3]


def rel_mse(image, reference):
    """Mean over pixels and channels of (image - reference)^2 / (reference^2 + 1e-2)."""
    import numpy as np

    return float(np.mean((image - reference) ** 2 / (reference**2 + 1e-2)))


def mitsuba_scene(scene_path, size, spp, bounces, sampler):
    """The scene file's Cornell box as a Mitsuba 3 scene dictionary."""
    import mitsuba as mi

    T = mi.ScalarTransform4f
    with open(scene_path, "rb") as f:
        scene = tomllib.load(f)
    cam = scene["camera"]
    materials = {}
    for name, m in scene["materials"].items():
        if "albedo" in m:
            materials[name] = {
                "type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": m["albedo"]}},
            }
        elif "emission" in m:
            materials[name] = None
        else:
            sys.exit(f"{scene_path}: materials.{name}: only albedo and emission are translated")
    out = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": bounces + 2, "rr_depth": bounces + 2},
        "sensor": {
            "type": "perspective",
            "fov": cam["vfov"],
            "fov_axis": "y",
            "to_world": T().look_at(origin=cam["eye"], target=cam["target"], up=cam["up"]),
            "sampler": {"type": sampler, "sample_count": spp},
            "film": {
                "type": "hdrfilm",
                "width": size,
                "height": size,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
                "component_format": "float32",
            },
        },
    }
    for i, obj in enumerate(scene["objects"]):
        material = obj["material"]
        if "box" in obj:
            b = obj["box"]
            if "center" in b:
                lo = [c - h for c, h in zip(b["center"], b["half_extent"])]
                hi = [c + h for c, h in zip(b["center"], b["half_extent"])]
            else:
                lo, hi = b["min"], b["max"]
            centre = [(l + h) / 2 for l, h in zip(lo, hi)]
            half = [(h - l) / 2 for l, h in zip(lo, hi)]
            pivot = b.get("pivot", [0.0, 0.0, 0.0])
            move = b.get("translate", [0.0, 0.0, 0.0])
            # world = R_y (local - pivot) + pivot + translate; local = centre + half * cube.
            to_world = (
                T()
                .translate([p + t for p, t in zip(pivot, move)])
                .rotate([0, 1, 0], b.get("rotate_y", 0.0))
                .translate([-p for p in pivot])
                .translate(centre)
                .scale(half)
            )
            out[f"object{i}"] = {"type": "cube", "to_world": to_world, "bsdf": materials[material]}
        elif "quad" in obj:
            q = obj["quad"]
            u, v, corner = q["edge_u"], q["edge_v"], q["corner"]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            length = math.sqrt(sum(c * c for c in n))
            n = [c / length for c in n]
            centre = [c + (a + b) / 2 for c, a, b in zip(corner, u, v)]
            emission = scene["materials"][material].get("emission")
            if emission is not None:
                # The light lies in the ceiling's plane, where illum lets the light win the tie;
                # Mitsuba's shadow rays would find the ceiling. Moving it 0.01 units (2e-5 of the
                # room) off along its normal gives the same scene within far less than the noise.
                centre = [c + 0.01 * k for c, k in zip(centre, n)]
            # Mitsuba's rectangle is [-1, 1]^2 in z = 0 facing +z: columns u/2, v/2, n, centre.
            matrix = [
                [u[0] / 2, v[0] / 2, n[0], centre[0]],
                [u[1] / 2, v[1] / 2, n[1], centre[1]],
                [u[2] / 2, v[2] / 2, n[2], centre[2]],
                [0, 0, 0, 1],
            ]
            shape = {"type": "rectangle", "to_world": T(matrix)}
            if emission is not None:
                shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": emission}}
                shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}
            else:
                shape["bsdf"] = materials[material]
            out[f"object{i}"] = shape
        elif "mesh" in obj:
            out[f"object{i}"] = mitsuba_mesh(scene_path, obj["mesh"], materials[material])
        else:
            sys.exit(f"{scene_path}: objects[{i}]: only boxes, quads and meshes are translated")
    return out


def mitsuba_mesh(scene_path, mesh, bsdf):
    """A `mesh` object as Mitsuba's `obj` shape: world = translate + scale R_z R_y R_x local, and
    flat shading where illum shades flat (`flat = true`, or a file without vertex normals)."""
    import mitsuba as mi

    T = mi.ScalarTransform4f
    path = os.path.join(os.path.dirname(os.path.abspath(scene_path)), mesh["file"])
    if not path.endswith(".obj"):
        sys.exit(f"{scene_path}: mesh file {mesh['file']}: only OBJ files are translated")
    flat = mesh.get("flat", False)
    if not flat:
        with open(path) as f:
            flat = not any(line.startswith("vn ") for line in f)
    rx, ry, rz = mesh.get("rotate", [0.0, 0.0, 0.0])
    to_world = (
        T()
        .translate(mesh.get("translate", [0.0, 0.0, 0.0]))
        .rotate([0, 0, 1], rz)
        .rotate([0, 1, 0], ry)
        .rotate([1, 0, 0], rx)
        .scale(mesh.get("scale", 1.0))
    )
    return {"type": "obj", "filename": path, "face_normals": flat, "to_world": to_world, "bsdf": bsdf}


def run_mitsuba(args, sampler, path):
    """Renders with Mitsuba in a child process and returns its whole wall time."""
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, __file__, "--mitsuba-child", sampler, path, "--size", str(args.size),
         "--spp", str(args.spp), "--bounces", str(args.bounces), "--scene", args.scene],
        check=True,
    )
    return time.perf_counter() - started


def mitsuba_child(args):
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    sampler, path = args.mitsuba_child
    scene = mi.load_dict(mitsuba_scene(args.scene, args.size, args.spp, args.bounces, sampler))
    image = mi.render(scene, spp=args.spp)
    mi.util.write_bitmap(path, image)


def mitsuba_reference_child(args):
    """The reference: Mitsuba's multijitter sampler, --reference-spp in passes of --spp samples
    (one wavefront of every sample at once would not fit in memory), seeds 1, 2, ... so that no
    pass repeats a measured row's samples (seed 0), averaged in float64."""
    import mitsuba as mi
    import numpy as np

    mi.set_variant("llvm_ad_rgb")
    path = args.mitsuba_reference
    passes = max(1, args.reference_spp // args.spp)
    scene = mi.load_dict(mitsuba_scene(args.scene, args.size, args.spp, args.bounces, "multijitter"))
    total = None
    for k in range(passes):
        image = np.array(mi.render(scene, spp=args.spp, seed=1 + k), dtype=np.float64)
        total = image if total is None else total + image
    mi.util.write_bitmap(path, mi.Bitmap((total / passes).astype(np.float32)))


def reference_image(args, tag):
    """The converged image every row is compared with, rendered once and cached."""
    spp = args.reference_spp
    if args.reference_renderer == "mitsuba":
        path = os.path.join(OUT, f"reference-mitsuba-multijitter-{tag}-{spp}spp.exr")
        if not os.path.exists(path):
            print(f"rendering the reference ({spp} spp, Mitsuba multijitter, seeds from 1) ...", flush=True)
            subprocess.run(
                [sys.executable, __file__, "--mitsuba-reference", path, "--size", str(args.size), "--spp",
                 str(args.spp), "--reference-spp", str(spp), "--bounces", str(args.bounces), "--scene", args.scene],
                check=True,
            )
    else:
        # Another seed than the measured rows (seed 0): the reference's samples must not include
        # theirs, or the low-discrepancy row would be compared partly with itself.
        path = os.path.join(OUT, f"reference-{tag}-{spp}spp-seed1.exr")
        if not os.path.exists(path):
            print(f"rendering the reference ({spp} spp, illum, low-discrepancy, seed 1) ...", flush=True)
            run_illum(args, path, spp, "low-discrepancy", seed=1)
    return load_exr(path)


def run_illum(args, path, spp, sequence, seed=0, extra=()):
    started = time.perf_counter()
    subprocess.run(
        [RENDER, args.scene, "--width", str(args.size), "--height", str(args.size), "--spp", str(spp),
         "--bounces", str(args.bounces), "--sequence", sequence, "--seed", str(seed), "-o", path, *extra],
        check=True, stdout=subprocess.DEVNULL,
    )
    return time.perf_counter() - started


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default=os.path.join(ROOT, "scenes", "cornell.toml"))
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--spp", type=int, default=1024)
    parser.add_argument("--bounces", type=int, default=2)
    parser.add_argument("--samplers", default="independent,multijitter,orthogonal,ldsampler")
    parser.add_argument("--illum", default="independent,low-discrepancy,adaptive,no-replicates",
                        help="illum's rows: independent, low-discrepancy, adaptive, no-replicates (the first is "
                             "timed for throughput)")
    parser.add_argument("--reference-spp", type=int, default=32768)
    parser.add_argument("--reference-renderer", choices=["mitsuba", "illum"], default="mitsuba")
    parser.add_argument("--mitsuba-child", nargs=2, help=argparse.SUPPRESS)
    parser.add_argument("--mitsuba-reference", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.mitsuba_child:
        return mitsuba_child(args)
    if args.mitsuba_reference:
        return mitsuba_reference_child(args)
    if not os.path.exists(RENDER):
        sys.exit(f"{RENDER} is missing: cargo build --release --example render")
    os.makedirs(OUT, exist_ok=True)

    tag = f"{os.path.basename(args.scene)}-{args.size}-b{args.bounces}"
    reference = reference_image(args, tag)

    rows = []
    # Adaptive sampling (render --adaptive): the same mean spp, spread over the image by a pilot.
    # Without replicates (render --replicates off): one randomisation of the sequence, no error
    # estimate, as Mitsuba's samplers have none.
    variants = {"independent": ("independent", (), "independent"),
                "low-discrepancy": ("low-discrepancy", (), "low-discrepancy"),
                "adaptive": ("low-discrepancy", ("--adaptive",), "low-discrepancy, adaptive"),
                "no-replicates": ("low-discrepancy", ("--replicates", "off"), "low-discrepancy, no replicates")}
    for name in args.illum.split(","):
        if name not in variants:
            sys.exit(f"--illum {args.illum}: {name!r} is not one of {', '.join(variants)}")
    for sequence, extra, label in (variants[name] for name in args.illum.split(",")):
        path = os.path.join(OUT, f"illum-{label.replace(', ', '-')}-{tag}.exr")
        seconds = run_illum(args, path, args.spp, sequence, extra=extra)
        image = load_exr(path)
        rows.append((f"illum ({label})", seconds, rel_mse(image, reference), image.mean() / reference.mean()))
    for sampler in args.samplers.split(","):
        path = os.path.join(OUT, f"mitsuba-{sampler}-{tag}.exr")
        seconds = run_mitsuba(args, sampler, path)
        image = load_exr(path)
        rows.append((f"Mitsuba llvm_ad_rgb ({sampler})", seconds, rel_mse(image, reference), image.mean() / reference.mean()))

    samples = args.size * args.size * args.spp
    print(f"\n{args.size} x {args.size}, {args.spp} spp, bounces {args.bounces}, whole process each; "
          f"reference: {args.reference_renderer}, {args.reference_spp} spp")
    # The mean ratio shows both renderers compute the same image (1 within the noise).
    print("| renderer | wall s | Msamples/s | relMSE | efficiency 1/(relMSE x s) | mean / reference mean |")
    print("|---|---|---|---|---|---|")
    for name, seconds, error, ratio in rows:
        print(f"| {name} | {seconds:.2f} | {samples / seconds / 1e6:.2f} | {error:.3e} | {1 / (error * seconds):.0f} | {ratio:.4f} |")
    best_mitsuba_time = min(s for n, s, _, _ in rows if n.startswith("Mitsuba"))
    best_mitsuba_eff = max(1 / (e * s) for n, s, e, _ in rows if n.startswith("Mitsuba"))
    illum_time = rows[0][1]
    illum_eff = max(1 / (e * s) for n, s, e, _ in rows if n.startswith("illum"))
    best_illum = max((r for r in rows if r[0].startswith("illum")), key=lambda r: 1 / (r[1] * r[2]))[0]
    # The rows that keep an error estimate (all but one randomisation without replicates).
    estimated = [1 / (e * s) for n, s, e, _ in rows if n.startswith("illum") and "no replicates" not in n]
    print(f"\nthroughput {rows[0][0]} / Mitsuba (fastest sampler): {best_mitsuba_time / illum_time:.2f}x")
    print(f"efficiency illum / Mitsuba (best of each): {illum_eff / best_mitsuba_eff:.2f}x ({best_illum})")
    if estimated:
        print(f"efficiency illum with its error estimate / Mitsuba (best of each): "
              f"{max(estimated) / best_mitsuba_eff:.2f}x")


if __name__ == "__main__":
    main()
