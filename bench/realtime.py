#!/usr/bin/env python3
"""bench/realtime.py frames|tuning|methods|motion [options]: the real-time kernels. frames: with and without
their light-transmittance cache (frame time, cache build, error against exact marching and a path-traced
reference); tuning: how the cache's and kernels' automatic settings were chosen; methods: each method at
each scene's pick, as the README's picture shows them; motion: the pick's cache baked at the scene's pose,
then orbited, K frames within a budget with it (reprojected) and without. Details: bench/README.md."""
import json
import math
import shlex
import sys
from pathlib import Path

import scene_env as b

SCENES = "scenes/listing_4_1.json scenes/disney_cloud.json scenes/cloud.json scenes/smoke.json"
DEFAULTS = {"frames": dict(resolutions="320x240 1280x720", frames=7, ref_spp=256, ref_resolutions="320x240",
                           scenes=SCENES, out="build/realtime_frames"),
            "tuning": dict(resolutions="320x240", frames=5, scenes=SCENES),
            "methods": dict(resolutions="320x240", frames=3, ref_spp=2048, out="build/realtime_methods",
                            picture="docs/images/realtime_methods.png",
                            scenes="scenes/cloud.json scenes/smoke.json scenes/disney_cloud.json "
                                   "scenes/disney_cloud_front.json"),
            "motion": dict(resolutions="160x120", frames=2, ref_spp=4096, out="build/realtime_motion",
                           scenes="scenes/cloud.json")}
p = b.parser(__doc__)
p.add_argument("experiment", choices=DEFAULTS)
p.add_argument("--frames", type=int, help="frames per render, the first not timed")
p.add_argument("--resolutions")
p.add_argument("--scenes")
p.add_argument("--ref-spp", type=int, help="frames, methods: the references' samples per pixel")
p.add_argument("--ref-resolutions", help="frames: the resolutions with a reference")
p.add_argument("--refs", help="methods: the references' folder (default OUT/references)")
p.add_argument("--out", help="frames, methods: where images and references stay")
p.add_argument("--picture", help="methods: the PNG it draws (default docs/images/realtime_methods.png)")
b.options(p, orbits="5 30 90", counts="1 20 100", target_ms=50.0)  # motion: bench/README.md
experiment = p.parse_known_args()[0].experiment
p.set_defaults(**DEFAULTS[experiment])
if experiment == "methods":  # before any work: it may run this script again under /usr/bin/python3
    b.need_pillow("realtime.py")
a = b.parse(p)
if a.frames < 2:
    p.error("--frames wants an integer >= 2 (the first frame is not timed)")
out = Path(a.out) if a.out else a.work
COMMAND = shlex.join(["bench/realtime.py"] + sys.argv[1:])
out.mkdir(parents=True, exist_ok=True)


def render(scene, algorithm, resolution, name, *sets):
    """Renders into OUT/NAME.exr; its stats. What frames and tuning measure: the lobe as Eq. 7 and the ray
    marcher as the dissertation's single-scattering march (b.MARCH)."""
    sets = ({"lobe": 'renderer.lobe.variant="eq7"', "raymarch": b.MARCH}[algorithm],) + sets
    return b.render(a, scene, "--algorithm", algorithm, "--resolution", resolution, "--frames", a.frames,
                    sets=sets, out=out / (name + ".exr"))


def delta(reference, test):
    """(mean ΔE76, JND%) of OUT/TEST.exr against REFERENCE (a name in OUT, or a path)."""
    c = b.compare(a, out / (reference + ".exr") if isinstance(reference, str) else reference,
                  out / (test + ".exr"), *b.LINEAR)
    return c["mean_dE76"], c["jnd76_pct"]


def frames_row(scene, name, resolution, ref, algorithm):
    stem = "%s-%s-%s" % (name, resolution, algorithm)
    print("  %s %s %s" % (name, resolution, algorithm), file=sys.stderr)
    off = render(scene, algorithm, resolution, stem + "-cacheoff", "renderer.lightCache.resolution=0")
    on = render(scene, algorithm, resolution, stem + "-cacheon")
    de_off, jnd_off = delta(stem + "-cacheoff", stem + "-cacheon")
    de_ref, jnd_ref = delta(ref, stem + "-cacheon") if ref else (None, None)
    return {"scene": name, "resolution": resolution, "algorithm": algorithm, "device": on["device"],
            "off_ms": off["ms_per_frame"]["median"], "on_ms": on["ms_per_frame"]["median"],
            "cache_ms": on.get("light_cache_ms", 0.0), "cells": on.get("light_cache_cells", [0, 0, 0]),
            "builds": on.get("light_cache_builds", 0), "off_cache_builds": off.get("light_cache_builds", 0),
            "de_off": de_off, "jnd_off": jnd_off, "de_ref": de_ref, "jnd_ref": jnd_ref}


def frames():
    rows = []
    for scene in a.scenes.split():
        name, missing = b.scene_name(scene), b.missing_volumes(scene)
        if missing:
            rows.append({"scene": name, "skip": "skipped: %s absent" % ", ".join(missing)})
            continue
        for resolution in a.resolutions.split():
            ref = None
            if resolution in a.ref_resolutions.split():
                ref = out / ("ref-%s-%s-%dspp.exr" % (name, resolution, a.ref_spp))
                print("  %s %s reference: %d spp (reused when it is there)" % (name, resolution, a.ref_spp),
                      file=sys.stderr)
                b.reference(a, scene, ref, a.ref_spp, "--resolution", resolution)
            rows += [frames_row(scene, name, resolution, ref, alg) for alg in ("raymarch", "lobe")]
    (out / "rows.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    done = [r for r in rows if "skip" not in r]
    print("device: %s\ncommand: %s\n" % (done[0]["device"] if done else "(nothing rendered)", COMMAND))
    b.header("scene", "resolution", "kernel", "ms cache off", "ms cache on", "cache build ms", "cache cells",
             "builds", "ΔE76 on vs off", "JND% on vs off", "ΔE76 on vs ref", "JND% on vs ref")
    ms = lambda v: "%.2f" % v if v < 10 else "%.1f" % v  # noqa: E731
    for r in rows:
        if "skip" in r:
            b.row(r["scene"], r["skip"], *[""] * 10)
            continue
        cells = "x".join(str(c) for c in r["cells"]) if any(r["cells"]) else "off"
        ref = ["—", "—"] if r["de_ref"] is None else ["%.2f" % r["de_ref"], "%.1f%%" % r["jnd_ref"]]
        b.row(r["scene"], r["resolution"], r["algorithm"], ms(r["off_ms"]), ms(r["on_ms"]), ms(r["cache_ms"]),
              cells, r["builds"], "%.2f" % r["de_off"], "%.1f%%" % r["jnd_off"], *ref)
    print("\nms: median kernel ms per frame of the %d frame(s) after the first; references %d spp in %s; —: no "
          "reference at that resolution." % (a.frames - 1, a.ref_spp, out))
    if any(r["off_cache_builds"] for r in done):
        print("WARNING: a cache-off render reports cache builds (light_cache_builds > 0).")


def tuning_row(scene, resolution, algorithm, label, name, sets, reference=None, build=""):
    """One row: NAME rendered with the --set values, against REFERENCE (itself: 0). label may name the
    light cache's cells, {cells}; build: the column's text, or True for the cache's build ms."""
    s = render(scene, algorithm, resolution, name, *sets)
    error = [f % v for f, v in zip(("%.3f", "%.2f%%"), delta(reference, name))] if reference else ["0", "0%"]
    cells = max(s["light_cache_cells"])
    build = "%.1f" % s["light_cache_ms"] if build is True else build
    b.row(algorithm, label.format(cells=cells), "%.1f" % s["ms_per_frame"]["median"], build, *error)


def tuning():
    print("device: %s\ncommand: %s" % (b.run_narval(a.narval, ["devices"]).splitlines()[1], COMMAND))
    term = lambda eps: ["renderer.%s.minTransmittance=%s" % (k, eps) for k in ("raymarch", "lobe")]  # noqa: E731
    for scene in a.scenes.split():
        name, missing = b.scene_name(scene), b.missing_volumes(scene)
        if missing:
            print("\n## %s: skipped, %s absent" % (name, ",".join(missing)))
            continue
        for res in a.resolutions.split():
            print("\n## %s (%s)\n" % (name, res))
            b.header("kernel", "setting", "ms/frame", "cache build ms", "mean ΔE76", "JND%")
            for alg in ("raymarch", "lobe"):
                tuning_row(scene, res, alg, "cache off (exact)", "exact", ["renderer.lightCache.resolution=0"],
                           build="—")
                for n in (16, 32, 64, 96, 128):
                    tuning_row(scene, res, alg, "cache %d" % n, str(n), ["renderer.lightCache.resolution=%d" % n],
                               "exact", build=True)
                for eps in ("0", "1e-4", "1e-3"):
                    tuning_row(scene, res, alg, "cache {cells}, minTransmittance " + eps, "term" + eps, term(eps),
                               None if eps == "0" else "term0")
            tuning_row(scene, res, "lobe", "viewSteps 100", "view100", ["renderer.lobe.viewSteps=100"])
            for steps in (8, 16, 24, 32, 48):
                tuning_row(scene, res, "lobe", "viewSteps %d" % steps, "view%d" % steps,
                           ["renderer.lobe.viewSteps=%d" % steps], "view100")


def view_cache(tile, paths, sigma, **more):
    """The view cache with the direct light and the filter (`more`: other msCache keys a pick names)."""
    cache = dict(dict(layout="view", direct=True, tile=tile, paths=paths, filter=sigma, filterTwicing=False), **more)
    return ["--algorithm", "raymarch", "--set", 'renderer.raymarch.multipleScattering="cache"',
            "--set", "renderer.raymarch.steps=30"] + [
        x for k, v in cache.items() for x in ("--set", "renderer.raymarch.msCache.%s=%s" % (k, json.dumps(v)))]


# The cache's pick per scene (a build under 60 s on 2 CPU cores; bench/RESULTS.md).
CACHE_PICKS = {"cloud": view_cache(1, 100, 1.5), "smoke": view_cache(1, 100, 1.5),
               "disney_cloud": view_cache(1, 136, 1.5, filterTwicing=True), "disney_cloud_front": view_cache(2, 480, 2)}
METHODS = [("raymarch, single scattering", ["--algorithm", "raymarch", "--set", b.MARCH]),
           ("raymarch + multiple-scattering cache", None),
           ("lobe, Eq. 7", ["--algorithm", "lobe", "--set", 'renderer.lobe.variant="eq7"']),
           ("lobe, corrected", ["--algorithm", "lobe", "--set", 'renderer.lobe.variant="corrected"'])]


def methods():
    refs, resolution = Path(a.refs or out / "references"), a.resolutions.split()[0]
    refs.mkdir(parents=True, exist_ok=True)
    b.header("scene", "method", "ms/frame", "cache build s", "mean ΔE76", "JND76%", "FLIP")
    tiles = []
    for scene in a.scenes.split():
        name = b.scene_name(scene)
        ref = refs / (name + ".exr")  # used as it is, whatever its samples
        if not ref.is_file():
            print("rendering the reference %s at %d spp" % (ref, a.ref_spp), file=sys.stderr)
            b.render(a, scene, "--resolution", resolution, "--spp", a.ref_spp, "--seed", 1, out=ref)
        tiles.append([(ref.with_suffix(".png"), name)])
        for index, (method, options) in enumerate(METHODS):
            exr = out / ("%s_%d.exr" % (name, index))
            s = b.render(a, scene, "--resolution", resolution, "--frames", a.frames, "--seed", 1,
                         *(options or CACHE_PICKS[name]), out=exr)
            c, ms, flip = b.compare(a, ref, exr), s["ms_per_frame"]["median"], b.flip([(ref, exr)])[0]
            build = s["ms_cache_ms"] / 1e3 if s.get("ms_cache_builds", 0) > 0 else None
            b.row(name, method, "%.1f" % ms, "" if build is None else "%.1f" % build, "%.2f" % c["mean_dE76"],
                  "%.1f" % c["jnd76_pct"], "%.4f" % flip)
            tiles[-1].append((exr.with_suffix(".png"), "%.0f ms%s, dE %.2f, JND %.1f%%" % (
                ms, "" if build is None else " + %.0f s build" % build, c["mean_dE76"], c["jnd76_pct"])))
    b.montage(tiles, a.picture, ["path tracer (reference)"] + [m for m, _ in METHODS])


def motion():
    refs, res = Path(a.refs or out / "references"), a.resolutions.split()[0]
    refs.mkdir(parents=True, exist_ok=True)
    b.header("scene", "orbit °", "frames", "wall s", "JND76% reprojected", "JND76% without", "JND76% built there",
             "JND76% reprojected vs built there")
    jnd = lambda ref, test: "%.2f" % b.compare(a, ref, test)["jnd76_pct"]  # noqa: E731
    for scene in a.scenes.split():
        name, cam = b.scene_name(scene), b.resolved_scene(a.narval, scene)["camera"]
        pick, baked = CACHE_PICKS[name] + ["--resolution", res, "--seed", 1], out / (name + ".mscache")
        b.render(a, scene, *pick, "--ms-cache-out", baked)
        for degrees in map(float, a.orbits.split()):
            t, (px, py, pz), (lx, _, lz) = math.radians(degrees), cam["position"], cam["lookAt"]
            x, z = (lx + (px - lx) * math.cos(t) + (pz - lz) * math.sin(t),
                    lz - (px - lx) * math.sin(t) + (pz - lz) * math.cos(t))
            pose, stem = ["--set", "camera.position=[%r,%r,%r]" % (x, py, z)], str(out / ("%s_%g" % (name, degrees)))
            ref, there = refs / ("%s_%s_%g.exr" % (name, res, degrees)), Path(stem + ".built.exr")
            b.reference(a, scene, ref, a.ref_spp, "--resolution", res, "--seed", 7, *pose)
            b.render(a, scene, *pick, *pose, out=there)
            for count in map(int, a.counts.split()):
                runs = [(Path("%s.%d%s.exr" % (stem, count, "reused" if more else "")), more)
                        for more in (["--ms-cache-in", baked], [])]
                s = [b.render(a, scene, *pick, *pose, "--frames", count, "--target-ms", a.target_ms, *more, out=exr)
                     for exr, more in runs][0]
                b.row(name, "%g" % degrees, count, "%.2f" % s["seconds"], jnd(ref, runs[0][0]), jnd(ref, runs[1][0]),
                      jnd(ref, there), jnd(there, runs[0][0]))


b.main({"frames": frames, "tuning": tuning, "methods": methods, "motion": motion}[a.experiment])
