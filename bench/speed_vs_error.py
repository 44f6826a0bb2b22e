#!/usr/bin/env python3
"""bench/speed_vs_error.py [SCENE.json ...] [options]: speed against error of every narval method (the
path tracer and every real-time option, each swept one parameter at a time) against a path-traced
reference: results.json and results.csv in --out, each scene's summary and the frame-budget picks
printed. Details: bench/README.md. Not a test."""
import csv
import functools
import json
import math
import os
import shlex
import shutil
import sys
import time
from pathlib import Path

import scene_env as b

DEFAULT_SCENES = ["scenes/cloud.json", "scenes/smoke.json", "scenes/disney_cloud.json",
                  "scenes/disney_cloud_front.json"]
REFERENCE_SEED, TEST_SEED = 1, 2
# The cache's methods as measured before its view layout became the default: named, not resolved.
CACHE = {"multipleScattering": "cache", "octaves": 1, "msCache.layout": "grid", "msCache.direct": False}
VIEW = dict(CACHE, **{"msCache.layout": "view", "msCache.filter": 0})
METHODS = {  # algorithm, fixed settings, base parameters that differ from what narval resolves
    "pathtrace": ("pathtrace", {}, {}),
    "raymarch-none": ("raymarch", {"multipleScattering": "none", "octaves": 1}, {}),
    "raymarch-octaves": ("raymarch", {"multipleScattering": "octaves"}, {"octaves": 4}),
    "raymarch-cache": ("raymarch", CACHE, {"steps": 60, "msCache.paths": 256}),
    "raymarch-cache-camera": ("raymarch", dict(CACHE, **{"msCache.closure": "camera"}), {"msCache.paths": 256}),
    "raymarch-cache-view": ("raymarch", dict(VIEW, areaLightPhase="exact"),
                            {"shadowWeighting": "phase", "msCache.tile": 4, "msCache.paths": 256}),
    "raymarch-cache-direct": ("raymarch", dict(VIEW, **{"msCache.direct": True}),
                              {"msCache.tile": 2, "msCache.paths": 256}),
    "raymarch-cache-filtered": ("raymarch", dict(VIEW, **{"msCache.direct": True, "msCache.tile": 1}),
                                {"msCache.paths": 160, "msCache.filter": 1, "msCache.filterTwicing": False}),
    "lobe-eq7": ("lobe", {"variant": "eq7"}, {}),
    "lobe-corrected": ("lobe", {"variant": "corrected"}, {}),
}
FULL_SWEEPS = {
    "pathtrace": {"spp": [1, 4, 16, 64, 256], "bounces": [1, 2, 4, 8]},
    "raymarch-none": {"steps": [15, 30, 60, 120], "shadowSteps": [5, 10, 20]},
    "raymarch-octaves": {"octaves": [2, 4, 8], "steps": [30, 60, 120]},
    "raymarch-cache": {"msCache.resolution": [8, 16, 32], "msCache.paths": [64, 256, 1024], "steps": [30, 60, 120],
                       "shadowAreaSamples": [1, 4], "areaLightSamples": [1, 2],
                       "areaLightPhase": ["points", "exact"]},
    "raymarch-cache-camera": {"msCache.resolution": [16, 32], "msCache.paths": [256, 1024],
                              "areaLightPhase": ["points", "exact"]},
    "raymarch-cache-view": {"msCache.tile": [2, 4, 8], "msCache.slices": [4, 8, 16],
                            "msCache.paths": [64, 256, 1024], "shadowWeighting": ["area", "phase"]},
    "raymarch-cache-direct": {"msCache.tile": [2, 4], "msCache.slices": [4, 8], "msCache.paths": [128, 256, 512]},
    "raymarch-cache-filtered": {"msCache.paths": [40, 160], "msCache.filter": [1, 1.5, 2],
                                "msCache.filterTwicing": [False, True]},
    "lobe-eq7": {"lobePoints": [10, 30, 60], "depthFactor": [5, 20, 100], "shadowSteps": [25, 50, 100]},
    "lobe-corrected": {"lobePoints": [10, 30, 60], "lobeRadius": [0.3, 1, 3, 10], "viewSteps": [8, 16, 32],
                       "areaLightPhase": ["points", "exact"]},
}


def parse_args(argv):
    p = b.parser(__doc__)
    p.add_argument("scenes", nargs="*", metavar="SCENE.json")
    p.add_argument("--resolution", help="WIDTHxHEIGHT (default 320x240; --quick 48x24)")
    p.add_argument("--reference-spp", type=int, help="reference samples per pixel (default 2048; --quick 64)")
    p.add_argument("--base-spp", type=int, help="pathtrace spp while bounces vary (default 16; --quick 4)")
    p.add_argument("--frames", type=int, default=3, help="frames per real-time render; median taken")
    p.add_argument("--jnd-threshold", type=float, default=5.0, help="JND76%% bound of the summary and picks")
    p.add_argument("--methods", default=",".join(METHODS), metavar="M1,M2", help="of %s" % ", ".join(METHODS))
    p.add_argument("--budgets-ms", default="16,100", metavar="B1,B2", help="frame budgets of the picks")
    p.add_argument("--out", default=str(b.REPO / "build" / "speed_vs_error"))
    p.add_argument("--quick", action="store_true", help="tiny configuration for smoke testing")
    p.add_argument("--references-only", action="store_true", help="render (or find) the references and stop")
    a = b.parse(p, argv)
    a.command_line = shlex.join(["bench/speed_vs_error.py"] + list(argv))
    a.resolution = a.resolution or ("48x24" if a.quick else "320x240")
    a.reference_spp = a.reference_spp or (64 if a.quick else 2048)
    a.base_spp = a.base_spp or (4 if a.quick else 16)
    a.scenes = a.scenes or DEFAULT_SCENES
    names = a.methods.split(",")
    if set(names) - set(METHODS):
        p.error("--methods: unknown %s (known: %s)" % (", ".join(set(names) - set(METHODS)), ", ".join(METHODS)))
    a.methods = [m for m in METHODS if m in names]
    a.budgets_ms = sorted({float(v) for v in a.budgets_ms.split(",")})
    a.sweeps = {m: dict(FULL_SWEEPS[m]) for m in a.methods}
    if a.quick:  # a smoke test: the first two values of each method's first two sweeps
        a.sweeps = {m: {k: v[:2] for k, v in list(sweeps.items())[:2]} for m, sweeps in a.sweeps.items()}
    return a


def text(value):
    """A parameter value as names and tables show it."""
    return str(value) if isinstance(value, (int, str)) else "%g" % value


def load_scene(path, a):
    """{path, name, skip (why it cannot be rendered, else None), bounces (narval's resolved value)}."""
    scene = {"path": str(Path(path).resolve()), "name": Path(path).stem, "skip": None}
    if b.missing_volumes(path):
        scene["skip"] = "%s absent (NARVAL_DATA_DIR names the data's folder)" % ", ".join(b.missing_volumes(path))
    else:
        scene["bounces"] = b.resolved_scene(a.narval, scene["path"])["renderer"]["bounces"]
    return scene


def method_sets(method):
    """A method's fixed settings as --set PATH=VALUE strings; values JSON-encoded (strings quoted)."""
    algorithm, settings, _ = METHODS[method]
    return ["renderer.%s.%s=%s" % (algorithm, k, json.dumps(v)) for k, v in settings.items()]


def base_parameters(a, scene, method):
    """The values a method's parameters keep while another one varies: pathtrace at --base-spp and the
    scene's bounces; a real-time method's named base, else the value narval resolves for the scene
    with the method's settings applied (the scene's, else the loader's default)."""
    algorithm, _, named = METHODS[method]
    if algorithm == "pathtrace":
        return {"spp": a.base_spp, "bounces": scene["bounces"]}
    resolved = b.resolved_scene(a.narval, scene["path"], ["renderer.algorithm=" + json.dumps(algorithm)]
                                + method_sets(method))["renderer"][algorithm]
    return {parameter: named.get(parameter, functools.reduce(dict.get, parameter.split("."), resolved))
            for parameter in a.sweeps[method]}


def reference(a, scene, folder):
    """folder/reference.exr (+ snapshot.exr of its first quarter), kept in the cache between runs; sets
    scene["display"] from what `narval compare` applies to it. Its description, with the JND% its own
    noise alone reads (what a noise-free image would read against it)."""
    bounces, base = scene["bounces"], os.environ.get("NARVAL_CACHE_DIR")  # "off": in the scene's fresh folder
    cache = folder if base == "off" else Path(base or Path.home() / ".cache" / "narval") / "speed_vs_error"
    stem = "%s_%s_%dspp_%db" % (scene["name"], a.resolution, a.reference_spp, bounces)
    exr, snapshot = cache / (stem + ".exr"), cache / (stem + "_snapshot.exr")
    cache.mkdir(parents=True, exist_ok=True)
    print("  reference: pathtrace %d spp, %d bounces, %s (%s)" % (a.reference_spp, bounces, a.resolution, exr),
          flush=True)
    stats = b.reference(a, scene["path"], exr, a.reference_spp, "--bounces", bounces, "--resolution", a.resolution,
                        "--seed", REFERENCE_SEED, snapshot=snapshot)
    own = b.compare(a, exr, exr, "--reference-snapshot", snapshot)
    scene["display"] = {"exposure": own["exposure"], "tonemap": own["tonemap"]}
    noise = own["reference_noise"]
    print("  reference noise alone: JND %.2f%% (from its first %d samples)" % (noise["jnd76_pct"],
                                                                             noise["snapshot_spp"]), flush=True)
    return {"exr": str(exr), "spp": a.reference_spp, "bounces": bounces, "seed": REFERENCE_SEED,
            "device": stats["device"], "noise": noise}


def row_of(scene, method, parameter, value, parameters, base, seconds, build, comparison):
    algorithm, settings, _ = METHODS[method]
    row = {"scene": scene["name"], "method": method, "algorithm": algorithm, "parameter": parameter,
           "value": value, "seconds": seconds, "build_seconds": build,
           "configuration": method + "_" + "_".join(k + text(v) for k, v in sorted(parameters.items())),
           "settings": settings, "parameters": parameters, "is_base": parameters == base}
    row.update({k: comparison[k] for k in ("mean_dE76", "jnd76_pct", "mean_dE2000", "jnd2000_pct", "p95_dE76", "flip")})
    build_text = "  build %6.2f s" % build if build is not None else ""
    print("  %-23s %-22s %-5s %10s%s  mean ΔE76 %6.2f  JND76 %6.2f%%  FLIP %.4f" % (
        method, parameter, text(value), time_text(row), build_text, row["mean_dE76"], row["jnd76_pct"], row["flip"]),
        flush=True)
    return row


def pathtrace_rows(a, scene, ref, folder, base):
    """The path tracer's sweeps by `narval sweep --reference`: spp at the base bounces, bounces at --base-spp."""
    rows = []
    for parameter, values in a.sweeps["pathtrace"].items():
        fixed = "bounces" if parameter == "spp" else "spp"
        out = folder / ("pathtrace_" + parameter)
        b.run_narval(a.narval, ["sweep", scene["path"], "-o", out, "--" + parameter, ",".join(map(str, values)),
                                "--" + fixed, base[fixed], "--reference", ref["exr"], "--resolution", a.resolution,
                                "--seed", TEST_SEED] + (["--device", a.device] if a.device else []))
        measured = {r["value"]: r for r in json.loads((out / "sweep.json").read_text())["rows"]}
        flips = b.flip([(ref["exr"], out / (("spp_%05d" if parameter == "spp" else "bounces_%04d") % v + ".exr"))
                        for v in values])  # the sweep's file names (host/analysis/sweep.cpp, sweepFileName)
        for value, f in zip(values, flips):
            r = dict(measured[value], flip=f)
            rows.append(row_of(scene, "pathtrace", parameter, value, dict(base, **{parameter: value}), base,
                               r["seconds"], None, r))
    return rows


def realtime_rows(a, scene, ref, folder, method, base):
    """A real-time method's sweeps, one render per distinct configuration, after a tiny warm-up (PoCL
    compiles again at a kernel's first launch; the cache's build kernel too, on a 1-cell cache)."""
    algorithm, settings, _ = METHODS[method]
    warm = ["renderer.raymarch.msCache.resolution=1", "renderer.raymarch.msCache.paths=1"]
    b.render(a, scene["path"], "--algorithm", algorithm, "--resolution", "16x8", "--frames", 1,
             sets=method_sets(method) + (warm if settings.get("multipleScattering") == "cache" else []))
    rows, measured = [], {}
    for parameter, values in a.sweeps[method].items():
        for value in values:
            parameters = dict(base, **{parameter: value})
            key = json.dumps(parameters, sort_keys=True)
            if key not in measured:
                out = folder / ("%s_%d.exr" % (method, len(measured)))
                sets = method_sets(method) + ["renderer.%s.%s=%s" % (algorithm, k, json.dumps(v))
                                              for k, v in sorted(parameters.items())]
                s = b.render(a, scene["path"], "--algorithm", algorithm, "--resolution", a.resolution,
                             "--seed", TEST_SEED, "--frames", a.frames, out=out, sets=sets)
                build = s.get("ms_cache_ms", 0.0) / 1e3 if settings.get("multipleScattering") == "cache" else None
                comparison = dict(b.compare(a, ref["exr"], out), flip=b.flip([(ref["exr"], out)])[0])
                measured[key] = (b.seconds(s), build, comparison)
            rows.append(row_of(scene, method, parameter, value, parameters, base, *measured[key]))
    return rows


def time_text(row):
    """'1.234 s' per image for pathtrace, '12.34 ms' per frame for the real-time methods."""
    return "%.4g s" % row["seconds"] if row["algorithm"] == "pathtrace" else "%.2f ms" % (row["seconds"] * 1e3)


def label(row):
    return "%s %s" % (row["method"], ", ".join("%s %s" % (k, text(v)) for k, v in row["parameters"].items()))


def distinct(rows):
    """One row per distinct configuration (the base appears once per parameter swept)."""
    first = {}
    for r in rows:
        first.setdefault(r["configuration"], r)
    return list(first.values())


def summarise(rows, threshold):
    """Lines: per method the fastest configuration under the JND bound and the most accurate one; the
    Pareto front of time against JND76%."""
    points = distinct(rows)
    described = lambda p: "%s in %s (JND %.2f%%, mean ΔE76 %.2f)" % (  # noqa: E731
        label(p), time_text(p), p["jnd76_pct"], p["mean_dE76"])
    lines = []
    for method in METHODS:
        mine = [p for p in points if p["method"] == method]
        if mine:
            within = [p for p in mine if p["jnd76_pct"] <= threshold]
            fast = min(within, key=lambda p: (p["seconds"], p["jnd76_pct"]), default=None)
            fastest = ("fastest under JND %g%%: %s" % (threshold, described(fast)) if fast
                       else "none under JND %g%%" % threshold)
            lines.append("%s: %s; lowest JND: %s" % (method, fastest, described(min(
                mine, key=lambda p: (p["jnd76_pct"], p["seconds"])))))
    front, best = [], math.inf
    for p in sorted(points, key=lambda p: (p["seconds"], p["jnd76_pct"])):
        if p["jnd76_pct"] < best:
            front.append(p)
            best = p["jnd76_pct"]
    lines.append("Pareto front (time, JND76%%): %s" % "; ".join("%s %s (%s, %.2f%%)" % (
        p["method"], "base" if p["is_base"] else "%s=%s" % (p["parameter"], text(p["value"])), time_text(p),
        p["jnd76_pct"]) for p in front))
    return lines


def budget_picks(rows, budgets_ms, threshold):
    """Per frame budget, the real-time configuration with the lowest JND76% within it (ties: lower mean
    ΔE76, then faster); the cache's build is a one-off cost outside the frame time."""
    realtime = [r for r in distinct(rows) if r["algorithm"] != "pathtrace"]
    picks = []
    for budget in budgets_ms:
        within = [r for r in realtime if r["seconds"] * 1e3 <= budget]
        if not within:
            fastest = min(realtime, key=lambda r: r["seconds"]) if realtime else None
            picks.append({"budget_ms": budget, "method": None, "reason": "none within %g ms (fastest: %s)" % (
                budget, "%s, %.2f ms" % (label(fastest), fastest["seconds"] * 1e3) if fastest else "none run")})
            continue
        r = min(within, key=lambda r: (r["jnd76_pct"], r["mean_dE76"], r["seconds"]))
        picks.append({"budget_ms": budget, "method": r["method"], "label": label(r), "config": r["configuration"],
                      "ms_per_frame": r["seconds"] * 1e3, "build_seconds": r["build_seconds"],
                      "mean_dE76": r["mean_dE76"], "jnd76_pct": r["jnd76_pct"],
                      "meets_jnd_threshold": r["jnd76_pct"] <= threshold})
    return picks


def print_picks(scenes, threshold):
    print("\nBudget picks (real-time methods; lowest JND76%% within the frame budget; build not in the frame "
          "time; meets: JND76%% ≤ %g%%):\n" % threshold)
    b.header("scene", "budget", "method and parameters", "ms/frame", "build s", "mean ΔE76", "JND76%", "meets")
    for scene in scenes:
        for pick in scene.get("budget_picks", [{"budget_ms": None, "method": None, "reason": scene["skipped"]}]):
            budget = "" if pick["budget_ms"] is None else "%g ms" % pick["budget_ms"]
            if pick["method"] is None:
                b.row(scene["name"], budget, pick["reason"], "", "", "", "", "")
                continue
            build = "" if pick["build_seconds"] is None else "%.2f" % pick["build_seconds"]
            meets = "yes" if pick["meets_jnd_threshold"] else "no"
            b.row(scene["name"], budget, pick["label"], "%.2f" % pick["ms_per_frame"], build,
                  "%.3f" % pick["mean_dE76"], "%.2f" % pick["jnd76_pct"], meets)


def run(a):
    started = time.monotonic()
    out = Path(a.out).resolve()
    version = b.run_narval(a.narval, ["--version"]).strip()
    print("%s; %s; reference %d spp; %s" % (version, a.resolution, a.reference_spp, "references only"
                                          if a.references_only else "methods " + ", ".join(a.methods)), flush=True)
    scenes, rows = [], []
    for path in a.scenes:
        scene = load_scene(path, a)
        entry = {"name": scene["name"], "path": scene["path"], "skipped": scene["skip"]}
        scenes.append(entry)
        print("[%s]%s" % (scene["name"], " skipped: " + scene["skip"] if scene["skip"] else ""), flush=True)
        if scene["skip"]:
            continue
        folder = out / scene["name"]
        shutil.rmtree(folder, ignore_errors=True)
        folder.mkdir(parents=True)
        ref = reference(a, scene, folder)
        if a.references_only:
            continue
        bases = {m: base_parameters(a, scene, m) for m in a.methods}
        mine = [r for m in a.methods for r in (pathtrace_rows(a, scene, ref, folder, bases[m]) if m == "pathtrace"
                                               else realtime_rows(a, scene, ref, folder, m, bases[m]))]
        entry.update(display=scene["display"], reference=ref, base_parameters=bases,
                     summary=summarise(mine, a.jnd_threshold),
                     budget_picks=budget_picks(mine, a.budgets_ms, a.jnd_threshold))
        rows += mine
        print("\n".join("  " + line for line in entry["summary"]), flush=True)
    if a.references_only or not rows:
        return 0 if a.references_only else "speed_vs_error.py: every scene was skipped; nothing to report"
    header = {"generated": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "command": a.command_line,
              "narval": version, "device": next(s["reference"]["device"] for s in scenes if "reference" in s),
              "resolution": a.resolution, "reference_spp": a.reference_spp, "base_spp": a.base_spp,
              "frames": a.frames, "jnd_threshold": a.jnd_threshold, "budgets_ms": a.budgets_ms, "sweeps": a.sweeps,
              "methods": {m: dict(zip(("algorithm", "settings", "base"), METHODS[m])) for m in a.methods},
              "wall_seconds": time.monotonic() - started}
    (out / "results.json").write_text(json.dumps({"run": header, "scenes": scenes, "results": rows}, indent=2))
    columns = ["scene", "method", "algorithm", "parameter", "value", "seconds", "build_seconds", "mean_dE76",
               "jnd76_pct", "mean_dE2000", "jnd2000_pct", "flip"]
    with open(out / "results.csv", "w", newline="") as f:
        csv.writer(f).writerows([columns] + [["" if r[c] is None else r[c] for c in columns] for r in rows])
    print("wrote %s/results.json and results.csv in %.0f s" % (out, header["wall_seconds"]), flush=True)
    print_picks(scenes, a.jnd_threshold)
    return 0


if __name__ == "__main__":
    args = parse_args(sys.argv[1:])
    b.main(lambda: run(args))
