#!/usr/bin/env python3
"""Writes the generated blocks of the README and the docs from what scripts/readme-figures.sh measured.

    readme-block.py ladder-summary LADDER.csv   README and docs/theory-whitted.md: selected rows of the ladder;
                                                docs/performance.md: the caustic estimators' efficiency
    readme-block.py headline DIR                README: the headline figures, from the outputs in DIR
    readme-block.py perf-tables DIR             docs/performance*.md: the bench tables, from DIR

A block sits between `<!-- NAME: ... -->` and `<!-- /NAME -->` in its page; everything between
the markers is replaced. Each block names the date and the CPU it was measured on, and leads
with ratios measured side by side (absolute figures hold only for the host named).
"""

import csv
import datetime
import os
import re
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
README = os.path.join(ROOT, "README.md")


def measured_on(paths):
    """The day (UTC) the outputs at `paths` were written, or the first and last day: a block
    regenerated from older outputs keeps their date. Today when none exists."""
    days = sorted({datetime.datetime.fromtimestamp(os.path.getmtime(p), datetime.timezone.utc).date()
                   for p in paths if os.path.exists(p)})
    if not days:
        return datetime.date.today().isoformat()
    return days[0].isoformat() if len(days) == 1 else f"{days[0].isoformat()} to {days[-1].isoformat()}"


def host(paths=()):
    """'2026-12-03, Intel(R) Xeon(R) Processor, 2 CPUs': when (see measured_on) and where."""
    cpu = "unknown CPU"
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout.splitlines():
            if line.startswith("Model name:"):
                cpu = line.split(":", 1)[1].strip()
                break
    except (OSError, subprocess.CalledProcessError):
        pass
    return f"{measured_on(paths)}, {cpu}, {os.cpu_count()} CPUs"


def replace_block(name, text, page=README):
    readme = open(page, encoding="utf-8").read()
    pattern = re.compile(rf"(<!-- {re.escape(name)}:[^>]*-->\n).*?(<!-- /{re.escape(name)} -->)", re.S)
    if not pattern.search(readme):
        sys.exit(f"{os.path.relpath(page, ROOT)} has no <!-- {name}: ... --> block")
    readme = pattern.sub(lambda m: m.group(1) + text.rstrip("\n") + "\n" + m.group(2), readme)
    tmp = page + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(readme)
    os.replace(tmp, page)


# The ladder's rows the README shows, and the regions beside the whole image.
LADDER_ROWS = [
    ("raster", "figure look"),
    ("raster", "enhanced look"),
    ("whitted", "depth 1, 2x2 rays per pixel"),
    ("whitted", "depth 8, 2x2 rays per pixel"),
    ("pathtrace", "1 spp, bounces 8"),
    ("pathtrace", "64 spp, bounces 8"),
    ("pathtrace", "1 spp, bounces 8, caustic estimator"),
    ("pathtrace", "64 spp, bounces 8, caustic estimator"),
    ("pathtrace", "1024 spp, bounces 8, caustic estimator"),
    ("pathtrace", "64 spp, bounces 8, manifold NEE"),
    ("pathtrace + à-trous", "16 spp, bounces 8, caustic estimator, à-trous"),
]
LADDER_REGIONS = [
    ("floor, lit", "lit floor"),
    ("floor in the glass sphere's shadow", "glass's shadow"),
    ("glass sphere", "glass"),
    ("metal sphere", "metal"),
]


def ladder_summary(path):
    rows = {}
    for r in csv.DictReader(open(path, encoding="utf-8")):
        rows.setdefault((r["renderer"], r["settings"]), {})[r["region"]] = r
    out = [
        "| renderer | settings | wall ms | relMSE | FLIP | "
        + " | ".join(f"luminance / truth: {short}" for _, short in LADDER_REGIONS)
        + " |",
        "|---" * (5 + len(LADDER_REGIONS)) + "|",
    ]
    for key in LADDER_ROWS:
        regions = rows.get(key)
        if regions is None:
            continue
        whole = regions["all"]
        cells = [key[0], key[1], f"{float(whole['wall_ms']):.1f}", f"{float(whole['rel_mse']):.2e}",
                 f"{float(whole['flip']):.3f}"]
        cells += [f"{float(regions[name]['luminance_ratio']):.2f}" if name in regions else "n/a"
                  for name, _ in LADDER_REGIONS]
        out.append("| " + " | ".join(cells) + " |")
    # The truth's settings, from the ladder's own page beside the CSV.
    truth = re.search(r"Truth: (path traced, .*?its own estimated relMSE [0-9.e+-]+)\.",
                      read(os.path.dirname(path), "ladder.md"))
    truth = f" Truth: {truth.group(1)}." if truth else ""
    out.append("")
    out.append(f"*Measured {host([path])} (lavapipe unless a GPU is present).{truth} wall ms: the median time per frame; "
               "for the rasterizer a whole frame with its shadow and cube maps made again, for the path tracer "
               "the time to render that many spp from nothing.*")
    # The README and the Whitted scene's theory page show the same rows.
    for page in (README, os.path.join(ROOT, "docs", "theory-whitted.md")):
        replace_block("ladder-summary", "\n".join(out), page)
    caustic_efficiency(rows, truth, path)


# The caustic's estimators side by side at one spp: the efficiency the ladder measured.
EFFICIENCY_ROWS = [
    ("without the caustic's estimators", "64 spp, bounces 8"),
    ("light tracer and photon gather", "64 spp, bounces 8, caustic estimator"),
    ("manifold NEE", "64 spp, bounces 8, manifold NEE"),
    ("manifold NEE, low-discrepancy (one randomisation)",
     "64 spp, bounces 8, manifold NEE, low-discrepancy (one randomisation)"),
]


def caustic_efficiency(rows, truth, path):
    """docs/performance.md: efficiency 1 / (relMSE x seconds) of the path tracer at 64 spp with each
    of the caustic's estimators, against the ladder's truth (made with the light tracer)."""
    found = [(name, rows[("pathtrace", settings)]["all"]) for name, settings in EFFICIENCY_ROWS
             if ("pathtrace", settings) in rows]
    if len(found) < len(EFFICIENCY_ROWS):
        return
    base = float(dict(found)["light tracer and photon gather"]["efficiency"])
    out = ["| caustic | wall ms | relMSE | efficiency, 1 / (relMSE x s) | against the light tracer |",
           "|---|---|---|---|---|"]
    for name, whole in found:
        e = float(whole["efficiency"])
        out.append(f"| {name} | {float(whole['wall_ms']):.0f} | {float(whole['rel_mse']):.3e} | {e:.0f} | "
                   f"{e / base:.2f}x |")
    out.append("")
    out.append(f"*Measured {host([path])} by the ladder (`cargo run --release --example ladder`, Whitted scene, "
               f"320 x 180, bounces 8, the median of 3 renders of 64 spp from nothing).{truth} Without the "
               "caustic's estimators the image is biased (the glass's shadow at half its light): its "
               "efficiency is not comparable.*")
    out.append("")
    out.append("*The last row renders as `render --caustic-method manifold --sequence low-discrepancy "
               "--replicates off`: it has no error estimate.*")
    replace_block("caustic-efficiency", "\n".join(out), os.path.join(ROOT, "docs", "performance.md"))


def read(directory, name):
    path = os.path.join(directory, name)
    return open(path, encoding="utf-8").read() if os.path.exists(path) else ""


def number_after(text, pattern):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else None


# The outputs the headline reads (each line from one or two of them).
HEADLINE_SOURCES = ["bench-quick.txt", "bench-viewer.txt", "bench-viewer-whitted.txt", "bench-parts.txt",
                    "against.txt", "vs-mitsuba.txt", "vs-mitsuba-b8.txt", "render-default.txt",
                    "render-1pct.txt", "raster-bench.txt"]


def headline(directory):
    sources = [os.path.join(directory, n) for n in HEADLINE_SOURCES]
    lines = [f"Measured {host(sources)}:", ""]
    # Throughput of the pipeline generated per scene against the generic one (bench --quick).
    bench = read(directory, "bench-quick.txt")
    rates = {}
    for row in bench.splitlines():
        cells = [c.strip() for c in row.strip().strip("|").split("|")]
        if len(cells) >= 6 and cells[0] == "256x256":
            try:
                rates[(int(cells[2]), cells[3])] = float(cells[5])
            except ValueError:
                pass
    for bounces in (2, 8):
        s, g = rates.get((bounces, "Specialised")), rates.get((bounces, "Generic"))
        if s and g:
            lines.append(f"- **Path tracer, pipeline generated per scene against the generic one** (`bench --quick`, "
                         f"Cornell box 256 x 256, bounces {bounces}): **{s / g:.1f}x** the throughput "
                         f"({s:.1f} against {g:.1f} Msamples/s on this host).")
    # The low-discrepancy sequence's time per sample against independent numbers (bench --quick).
    sequence = number_after(bench, r"low-discrepancy / independent samples/s \(wall\), \d+ pairs: median ([0-9.]+)")
    if sequence:
        lines.append(f"- **Low-discrepancy sequence against independent numbers** (`bench --quick`, Cornell box "
                     f"256 x 256, 256 spp, bounces 2, runs alternated): **{1 / sequence:.2f}x** the time per sample, "
                     "its error estimate from 4 replicates included.")
    single = number_after(bench, r"low-discrepancy \(one randomisation\) / independent samples/s \(wall\), \d+ pairs: "
                                 r"median ([0-9.]+)")
    if single:
        lines.append(f"- **The same sequence without replicates** (`--replicates off`, same runs): **{1 / single:.2f}x** "
                     "the time per sample, with no error estimate.")
    # The viewer against render (bench --viewer), on the Cornell box and on the Whitted scene.
    for name, scene in (("bench-viewer.txt", ""), ("bench-viewer-whitted.txt", ", the Whitted scene")):
        viewer = read(directory, name)
        ratio = number_after(viewer, r"viewer / render, median of \d+ runs: ([0-9.]+)")
        fps = [float(c.split("|")[4]) for c in viewer.splitlines() if re.match(r"\| \d+ \|", c)]
        if ratio is not None:
            lines.append(f"- **Viewer, path tracer with the view still{scene}** (`bench --viewer`, 960 x 600 window "
                         f"under Xvfb): **{ratio:.2f}x** `render`'s throughput at the same resolution, measured side "
                         f"by side, while the window repaints at {statistics.median(fps):.1f} fps.")
    # The Whitted scene's caustic: its estimators' cost per spp (bench --parts) and, where
    # measured (--against), their efficiency against an older build's light tracer.
    parts = read(directory, "bench-parts.txt")
    cost = {}
    for size in ("320 x 180", "1280 x 720"):
        section = parts.split(size, 1)[1] if size in parts else ""
        for label, key in (("whole render, caustics on", "light"), ("whole render, caustic method manifold", "manifold")):
            value = number_after(section, rf"\| {label} \| wall \| [0-9.]+ \| ([0-9.]+) \|")
            if value is not None:
                cost[(size, key)] = value
    if len(cost) == 4:
        lines.append(f"- **Whitted scene, the caustic solved** (manifold next-event estimation, `bench --parts`): "
                     f"**{cost[('320 x 180', 'manifold')]:.1f}x** the camera paths' cost per spp at 320 x 180 and "
                     f"**{cost[('1280 x 720', 'manifold')]:.1f}x** at 1280 x 720, against "
                     f"{cost[('320 x 180', 'light')]:.1f}x and {cost[('1280 x 720', 'light')]:.1f}x with the light "
                     "tracer and its photon gather.")
    against = read(directory, "against.txt")
    commit = re.search(r"commit ([0-9a-f]+)", against)
    one = number_after(against, r"one randomisation: no error estimate\) \| [^|]+ \| [^|]+ \| [^|]+ \| ([0-9.]+)x")
    independent = number_after(against, r"this build, manifold NEE \| [^|]+ \| [^|]+ \| [^|]+ \| ([0-9.]+)x")
    if commit and one is not None and independent is not None:
        lines.append(f"- **Whitted scene, efficiency against the light tracer of commit {commit.group(1)}** "
                     "(`bench --against`, 320 x 180, 64 spp, 1 / (relMSE x time), side by side): "
                     f"**{one:.2f}x** with the solve and one randomisation of the low-discrepancy sequence (no "
                     f"error estimate), {independent:.2f}x with the solve and independent numbers.")
    # Mitsuba 3 (bench/vs_mitsuba.py), when installed.
    mitsuba = read(directory, "vs-mitsuba.txt")
    # bench/vs_mitsuba.py names illum's first row: "throughput illum (independent) / Mitsuba ...".
    thr = number_after(mitsuba, r"throughput illum(?: \([a-z -]+\))? / Mitsuba \(fastest sampler\): ([0-9.]+)x")
    eff = number_after(mitsuba, r"efficiency illum / Mitsuba \(best of each\): ([0-9.]+)x")
    mitsuba8 = read(directory, "vs-mitsuba-b8.txt")
    eff8 = number_after(mitsuba8, r"efficiency illum / Mitsuba \(best of each\): ([0-9.]+)x")
    kept = r"efficiency illum with its error estimate / Mitsuba \(best of each\): ([0-9.]+)x"
    kept2, kept8 = number_after(mitsuba, kept), number_after(mitsuba8, kept)
    if thr is not None and eff is not None:
        at8 = f"; at bounces 8, **{eff8:.2f}x** its efficiency" if eff8 is not None else ""
        best_row = re.search(r"efficiency illum / Mitsuba \(best of each\): [0-9.]+x \((.+)\)", mitsuba)
        best = f": {best_row.group(1)}" if best_row else ""
        with_estimate = ""
        if kept2 is not None and kept8 is not None:
            with_estimate = (f" Keeping illum's error estimate (the low-discrepancy sequence's 4 replicates): "
                             f"{kept2:.2f}x at bounces 2, {kept8:.2f}x at 8.")
        lines.append(f"- **Against Mitsuba 3** (`bench/vs_mitsuba.py`, the same Cornell box, 256 x 256, 1024 spp, "
                     f"bounces 2, whole processes, against a reference Mitsuba rendered): **{thr:.2f}x** its "
                     f"throughput and **{eff:.2f}x** its efficiency (1 / (relMSE x time), best of each{best}){at8}."
                     f"{with_estimate}")
    else:
        lines.append("- Against Mitsuba 3: not re-measured in this run (Mitsuba 3 not installed; "
                     "`bench/vs_mitsuba.py` says how); docs/performance.md has the last measured ratios.")
    # The default render and the 1% target (render).
    for name, label in (("render-default.txt", "`render` with no stop rule (Cornell box, 512 x 512)"),
                        ("render-1pct.txt", "`render --target-error 0.01` (Cornell box, 512 x 512)")):
        text = read(directory, name)
        spp = number_after(text, r"512x512, (\d+) spp")
        seconds = number_after(text, r", ([0-9.]+) s, ")
        error = number_after(text, r"estimated relative error ([0-9.]+)%")
        if spp is not None and seconds is not None and error is not None:
            lines.append(f"- {label}: {spp:.0f} spp, estimated relative error {error:.2f}%, "
                         f"{seconds:.1f} s on this host.")
    # The rasterizer (raster_bench).
    raster = read(directory, "raster-bench.txt")
    moving = number_after(raster, r"camera moving, scene unchanged .*?median frame ([0-9.]+) ms")
    changing = number_after(raster, r"scene changing every frame .*?median frame ([0-9.]+) ms")
    reduced = number_after(raster, r"cube maps at 1/4 side while it changes .*?median frame ([0-9.]+) ms")
    reduced_error = number_after(raster, r"against full size, the frame after a moved sphere: mean ([0-9.]+) levels")
    if moving is not None and changing is not None:
        line = (f"- **Rasterizer**, enhanced look, 1280 x 720, every effect on (`raster_bench`): median frame "
                f"{moving:.1f} ms ({1000 / moving:.0f} fps) with the camera moving, {changing:.1f} ms "
                f"({1000 / changing:.0f} fps) with the scene changing every frame")
        if reduced is not None and reduced_error is not None:
            line += (f", {reduced:.1f} ms ({1000 / reduced:.0f} fps) with its cube maps at a quarter side while it "
                     f"changes (what the viewer does; the moving frames differ from exact ones by "
                     f"{reduced_error:.2f} 8-bit levels on average)")
        lines.append(line + ", on this host.")
    replace_block("headline", "\n".join(lines))


def perf_tables(directory):
    """The bench outputs as they were printed, each with the host it was measured on."""
    def measured(name):
        return f"*Measured {host([os.path.join(directory, name)])}, by `scripts/readme-figures.sh`.*"

    docs = os.path.join(ROOT, "docs")
    blocks = [
        ("bench-quick.txt", "bench-quick", "performance.md", False),
        ("bench-viewer.txt", "viewer-bench", "performance.md", False),
        ("bench-viewer-whitted.txt", "viewer-bench-whitted", "performance.md", False),
        ("bench-parts.txt", "caustic-parts", "performance-caustics.md", False),
        ("against.txt", "against-build", "performance.md", False),
        ("bench-glint.txt", "glint-bench", "performance-caustics.md", False),
        ("raster-bench.txt", "raster-bench", "performance-raster.md", True),
        ("vs-mitsuba-meshes.txt", "mitsuba-meshes", "performance-geometry.md", False),
        ("bench-largest-mesh.txt", "largest-mesh", "performance-geometry.md", True),
        ("bench-first-image.txt", "first-image", "performance-geometry.md", False),
    ]
    # bench/vs_mitsuba.py's tables, from the first table's heading line on (before it: Mitsuba's
    # own log lines); a run without Mitsuba has none and leaves the last measured blocks.
    for name, block in [("vs-mitsuba.txt", "mitsuba-b2"), ("vs-mitsuba-b8.txt", "mitsuba-b8")]:
        text = read(directory, name)
        table = re.search(r"^\d+ x \d+, \d+ spp, bounces .*", text, re.M | re.S)
        if table:
            heading, rest = table.group(0).strip().split("\n", 1)
            text = f"{heading}\n\n{rest}\n\n{measured(name)}"
            replace_block(block, text, os.path.join(docs, "performance.md"))
    for name, block, page, preformatted in blocks:
        text = read(directory, name).strip()
        if text:
            text = f"```text\n{text}\n```" if preformatted else text
            replace_block(block, f"{text}\n\n{measured(name)}", os.path.join(docs, page))


if __name__ == "__main__":
    commands = {"ladder-summary": ladder_summary, "headline": headline, "perf-tables": perf_tables}
    if len(sys.argv) != 3 or sys.argv[1] not in commands:
        sys.exit(__doc__)
    commands[sys.argv[1]](sys.argv[2])
