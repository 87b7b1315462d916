#!/usr/bin/env python3
"""Measures the Whitted scene's caustic from path-traced PNGs (docs/caustics.md).

Inputs (linear PNGs at --exposure -1, so 8-bit value v is radiance 2 v / 255; 320 x 180):
  out/m-on.png, out/m-off.png      1024 spp with the caustic's light tracer on / off
  out/m-on64.png, out/m-off64.png  64 spp, another seed
made by scripts/readme-figures.sh. Regions are found by tracing each pixel's centre ray in the
scene's own geometry (scenes/whitted.toml): the floor in the glass ball's hard shadow, and the
lit floor within 3 units of that shadow. Only the red channel is used: every tile's red albedo
is 0.8, so it does not depend on the checkerboard. Needs Pillow.
"""

import math
import sys

from PIL import Image

W, H = 320, 180
EYE = (7.5, 2.3, -4.2)
FORWARD, RIGHT, UP = (-1.0, 0.0, 0.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)
TAN, ASPECT = math.tan(math.radians(30.0)), W / H
GLASS, METAL = ((4.2, 2.6, -4.2), 1.0), ((2.0, 1.9, -2.5), 1.0)
L = tuple(c / math.sqrt(10 * 10 + 13 * 13 + 2 * 2) for c in (10.0, 13.0, -2.0))


def add(a, b, s=1.0):
    return tuple(x + s * y for x, y in zip(a, b))


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def hits(o, d, sphere):
    """Nearest t > 0 at which the ray (o, d unit) meets the sphere, or None."""
    c, r = sphere
    m = add(o, c, -1.0)
    b = dot(m, d)
    disc = b * b - (dot(m, m) - r * r)
    if disc < 0.0:
        return None
    for t in (-b - math.sqrt(disc), -b + math.sqrt(disc)):
        if t > 1e-9:
            return t
    return None


def region(x, y):
    """'shadow', 'lit', or None for a pixel's centre ray."""
    sx = (2.0 * (x + 0.5) / W - 1.0) * ASPECT * TAN
    sy = (1.0 - 2.0 * (y + 0.5) / H) * TAN
    d = add(add(FORWARD, RIGHT, sx), UP, sy)
    n = math.sqrt(dot(d, d))
    d = tuple(c / n for c in d)
    if d[1] >= 0.0 or hits(EYE, d, GLASS) is not None or hits(EYE, d, METAL) is not None:
        return None
    p = add(EYE, d, -EYE[1] / d[1])
    if not (-23.0 <= p[0] <= 7.0 and -7.5 <= p[2] <= 7.5):
        return None
    in_glass = hits(p, L, GLASS) is not None
    in_metal = hits(p, L, METAL) is not None
    if in_glass and not in_metal:
        return "shadow"
    centre = (2.2, 0.0, -3.8)  # the glass shadow's centre
    if not in_glass and not in_metal and math.dist(p, centre) < 3.0:
        return "lit"
    return None


def red(path):
    image = Image.open(path).convert("RGB")
    assert image.size == (W, H), f"{path}: {image.size}"
    return [[2.0 * image.getpixel((x, y))[0] / 255.0 for x in range(W)] for y in range(H)]


def main():
    on, off = red("out/m-on.png"), red("out/m-off.png")
    on64, off64 = red("out/m-on64.png"), red("out/m-off64.png")
    pixels = {"shadow": [], "lit": []}
    for y in range(H):
        for x in range(W):
            r = region(x, y)
            if r:
                pixels[r].append((x, y))
    mean = lambda img, k: sum(img[y][x] for x, y in pixels[k]) / len(pixels[k])
    lit = mean(on, "lit")
    print(f"pixels: shadow {len(pixels['shadow'])}, lit floor nearby {len(pixels['lit'])}")
    print(f"lit floor (red): {lit:.4f}")
    for name, img in (("on", on), ("off", off)):
        s = mean(img, "shadow")
        print(f"glass shadow, caustic {name}: {s:.4f} = {s / lit:.3f} x the lit floor")
    # The brightest 3 x 3 block inside the shadow, caustic on.
    best = 0.0
    shadow = set(pixels["shadow"])
    for x, y in pixels["shadow"]:
        block = [(x + i, y + j) for i in (-1, 0, 1) for j in (-1, 0, 1)]
        if all(p in shadow for p in block):
            best = max(best, sum(on[b][a] for a, b in block) / 9.0)
    print(f"brightest 3x3 block in the shadow: {best:.4f} = {best / lit:.3f} x the lit floor")
    print(f"the caustic's share of the shadow's light: {1 - mean(off, 'shadow') / mean(on, 'shadow'):.3f}")
    # relMSE of the 64-spp render against the 1024-spp one, per region (red channel; the
    # reference's own noise, 1/16 of the 64-spp render's, is taken out), and the spp that
    # would bring it to 1e-4 (1% RMS relative error) at the 1/N rate.
    for name, ref, img in (("on", on, on64), ("off", off, off64)):
        for k in ("shadow", "lit"):
            e = sum((img[y][x] - ref[y][x]) ** 2 / (ref[y][x] ** 2 + 1e-2) for x, y in pixels[k]) / len(pixels[k])
            e *= 16.0 / 17.0
            print(f"caustic {name}, {k}: relMSE at 64 spp {e:.3e}; 1% needs about {64 * e / 1e-4:.0f} spp")


if __name__ == "__main__":
    sys.exit(main())
