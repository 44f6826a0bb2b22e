#!/usr/bin/env python3
"""bench/realtime_picture.py: the README's picture of the real-time methods (run it through
bench/realtime_picture.sh, which installs python3-pil).

One row per shipped scene (the default cloud, the smoke, the Disney cloud lit from behind and from
the front), one column per method at 320x240: the path-traced reference, the ray marcher with
single scattering, the ray marcher with the multiple-scattering cache at this scene's pick
(bench/RESULTS.md: the view cache with the direct light and the filter over its nodes), the Lobe
Estimator as Eq. 7 and corrected. Under each image: ms per frame (median of --frames by profiling
events; the cache's build in seconds apart), mean ΔE76 and JND% against the reference
(`narval compare`).

References: --refs DIR holds NAME.exr and NAME.png (as `narval render` writes them) for NAME in
cloud, smoke, disney_cloud, disney_cloud_front; a missing one is rendered there at
--reference-spp (default 2048; a render already there with fewer samples is continued with
--resume). The README's picture used 32768 spp (the default cloud) and 131072 spp (the Disney
scenes, rendered on an H200 by bench/device/ms_cache_gpu.sh); at 2048 spp the references' own
noise shows in the JND of the better methods (bench/RESULTS.md, "the references' own noise").

Usage: bench/realtime_picture.sh [--refs DIR] [--reference-spp N] [--frames K] [--out PNG]
                                 [--work DIR] [--narval PATH]
Exit 2 with one line on bad usage; 1 when a narval command fails (its stderr is printed).
"""
import argparse
import json
import os
import sys
from pathlib import Path

from scene_env import NarvalError, run_json, run_narval

REPO = Path(__file__).resolve().parent.parent
RESOLUTION = "320x240"
SCENES = [("cloud", "scenes/cloud.json"), ("smoke", "scenes/smoke.json"),
          ("disney_cloud", "scenes/disney_cloud.json"), ("disney_cloud_front", "scenes/disney_cloud_front.json")]


def view_cache(tile, paths, sigma, tolerance, **more):
    """The view cache with the direct light and the filter; `more`: other renderer.raymarch.msCache
    keys (guide, filterTwicing, allocation), set only where a pick names them (README,
    bench/RESULTS.md). The rest is the scene's as narval resolves it."""
    cache = dict(layout="view", direct=True, tile=tile, paths=paths, filter=sigma, filterTolerance=tolerance, **more)
    return ["--algorithm", "raymarch", "--set", 'renderer.raymarch.multipleScattering="cache"',
            "--set", "renderer.raymarch.steps=30"] + [
        a for k, v in cache.items() for a in ("--set", "renderer.raymarch.msCache.%s=%s" % (k, json.dumps(v)))]


# The cache's pick per scene (a build under 60 s on 2 CPU cores; bench/RESULTS.md).
CACHE_PICKS = {"cloud": view_cache(1, 100, 1.5, 2), "smoke": view_cache(1, 100, 1.5, 2),
               "disney_cloud": view_cache(1, 136, 1.5, 2, filterTwicing=True, allocation="perceptual"),
               "disney_cloud_front": view_cache(2, 480, 2, 0.5, guide=0.15)}
METHODS = [
    ("raymarch, single scattering", lambda scene: ["--algorithm", "raymarch", "--set",
                                                   'renderer.raymarch.multipleScattering="none"']),
    ("raymarch + multiple-scattering cache", lambda scene: CACHE_PICKS[scene]),
    ("lobe, Eq. 7", lambda scene: ["--algorithm", "lobe", "--set", 'renderer.lobe.variant="eq7"']),
    ("lobe, corrected", lambda scene: ["--algorithm", "lobe", "--set", 'renderer.lobe.variant="corrected"']),
]


def usage_error(message):
    print("realtime_picture: " + message, file=sys.stderr)
    sys.exit(2)


def exr_int_attribute(path, name):
    """The int attribute `name` of an OpenEXR file's header (None when absent): the header is the magic
    number and version (8 bytes), then attributes as name\\0 type\\0 size (int32 LE) value, ended by an
    empty name (OpenEXR's file layout)."""
    import struct
    with open(path, "rb") as f:
        data = f.read(1 << 16)  # narval's headers are a few kilobytes
    if data[:4] != b"\x76\x2f\x31\x01":
        raise NarvalError("%s is not an OpenEXR file" % path)
    at = 8
    while at < len(data) and data[at] != 0:
        end = data.index(b"\0", at)
        key = data[at:end].decode("latin-1")
        type_end = data.index(b"\0", end + 1)
        kind = data[end + 1:type_end].decode("latin-1")
        (size,) = struct.unpack_from("<i", data, type_end + 1)
        value_at = type_end + 5
        if key == name and kind == "int" and size == 4:
            return struct.unpack_from("<i", data, value_at)[0]
        at = value_at + size
    return None


def reference(settings, name, scene):
    """REFS/NAME.exr and .png: rendered when missing, continued (--resume) to --reference-spp when the
    EXR holds fewer samples (its narval:spp), used as it is when it holds as many or more (a reference
    rendered longer elsewhere, on a GPU say)."""
    exr = settings.refs / (name + ".exr")
    png = exr.with_suffix(".png")
    have = exr_int_attribute(exr, "narval:spp") if exr.is_file() else 0
    if have is None:
        raise NarvalError("%s has no narval:spp attribute: not a narval path-traced render" % exr)
    if have >= settings.reference_spp:
        if not png.is_file():
            raise NarvalError("%s holds %d spp but %s is missing; render it again with `narval render %s -o %s "
                              "--resolution %s --spp %d --seed 1`" % (exr, have, png, scene, exr, RESOLUTION, have))
        return exr, png
    args = ["render", scene, "-o", exr, "--resolution", RESOLUTION, "--spp", settings.reference_spp, "--seed", 1]
    if have > 0:
        args.append("--resume")
    print("realtime_picture: rendering the reference %s from %d to %d spp" % (exr, have, settings.reference_spp),
          flush=True)
    run_narval(settings.narval, args, cwd=REPO)
    return exr, png


def measure(settings, name, scene, index, options, ref_exr):
    """Renders one tile; returns its PNG and its caption."""
    out = settings.work / ("%s_%d.exr" % (name, index))
    stats = out.with_suffix(".json")
    run_narval(settings.narval, ["render", scene, "-o", out, "--resolution", RESOLUTION, "--frames", settings.frames,
                                 "--seed", 1, "--stats-json", stats] + options, cwd=REPO)
    with open(stats) as f:
        s = json.load(f)
    c = run_json(settings.narval, ["compare", ref_exr, out, "--json"], cwd=REPO)
    caption = "%.0f ms" % s["ms_per_frame"]["median"]
    if s.get("ms_cache_builds", 0) > 0:
        caption += " + %.0f s build" % (s["ms_cache_ms"] / 1000.0)
    caption += ", dE %.2f, JND %.1f%%" % (c["mean_dE76"], c["jnd76_pct"])
    print("  %-20s %-38s %s" % (name, METHODS[index][0], caption), flush=True)
    return out.with_suffix(".png"), caption


def montage(rows, headers, out):
    """rows: [(scene name, [(png, caption)])]; a header line over the columns, a caption under each tile."""
    from PIL import Image, ImageDraw, ImageFont
    font = ImageFont.load_default()
    tiles = [[Image.open(png).convert("RGB") for png, _ in row] for _, row in rows]
    w, h = tiles[0][1].size  # a render's (the reference's PNG may come from elsewhere)
    for (_, row), images in zip(rows, tiles):
        for (png, _), image in zip(row, images):
            if image.size != (w, h):
                raise NarvalError("%s is %dx%d, not %dx%d like the renders" % (png, image.size[0], image.size[1], w, h))
    line = 16
    sheet = Image.new("RGB", (w * len(headers), line + len(rows) * (h + line)), "white")
    draw = ImageDraw.Draw(sheet)
    for j, header in enumerate(headers):
        draw.text((j * w + 4, 2), header, fill="black", font=font)
    for i, (name, row) in enumerate(rows):
        top = line + i * (h + line)
        for j, (tile, (_, caption)) in enumerate(zip(tiles[i], row)):
            sheet.paste(tile, (j * w, top))
            draw.text((j * w + 4, top + h + 2), name if j == 0 else caption, fill="black", font=font)
    sheet.save(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0], add_help=True)
    p.add_argument("--refs", type=Path, default=REPO / "build" / "realtime_picture" / "references")
    p.add_argument("--reference-spp", type=int, default=2048)
    p.add_argument("--frames", type=int, default=3)
    p.add_argument("--out", type=Path, default=REPO / "docs" / "images" / "realtime_methods.png")
    p.add_argument("--work", type=Path, default=REPO / "build" / "realtime_picture")
    p.add_argument("--narval", type=Path, default=REPO / "build" / "narval")
    settings = p.parse_args()
    if settings.reference_spp < 1:
        usage_error("--reference-spp wants a positive integer")
    if settings.frames < 1:
        usage_error("--frames wants a positive integer")
    if not os.access(settings.narval, os.X_OK):
        usage_error("no narval at %s (scripts/setup.sh builds it)" % settings.narval)
    try:
        import PIL  # noqa: F401  (bench/realtime_picture.sh installs python3-pil)
    except ImportError:
        usage_error("needs Pillow: run bench/realtime_picture.sh (it installs python3-pil)")
    settings.refs.mkdir(parents=True, exist_ok=True)
    settings.work.mkdir(parents=True, exist_ok=True)
    rows = []
    try:
        for name, scene in SCENES:
            ref_exr, ref_png = reference(settings, name, scene)
            row = [(ref_png, "")]
            for index, (_, options) in enumerate(METHODS):
                row.append(measure(settings, name, scene, index, options(name), ref_exr))
            rows.append((name, row))
    except NarvalError as e:
        print("realtime_picture: %s" % e, file=sys.stderr)
        return 1
    try:
        montage(rows, ["path tracer (reference)"] + [m[0] for m in METHODS], settings.out)
    except NarvalError as e:
        print("realtime_picture: %s" % e, file=sys.stderr)
        return 1
    print("realtime_picture: wrote %s" % settings.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
