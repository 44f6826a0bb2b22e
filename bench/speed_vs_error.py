#!/usr/bin/env python3
"""Speed-versus-error report (issue 4, item 3): bench/speed_vs_error.py [SCENE.json ...] [options]

The path tracer and every real-time option of narval as *methods*: a method is an algorithm with
fixed scene settings (passed as `--set renderer.ALGORITHM.KEY=JSON`, strings JSON-quoted), named
base parameters and sweeps (METHODS, FULL_SWEEPS below; each sweep varies one parameter from the
base). pathtrace sweeps spp (bounces: the scene's) and bounces (spp: --base-spp); the ray marcher
runs with multiple scattering none, octaves, or its cache (the grid layout, the camera closure, the
view-space layout, with the lights' direct light, and filtered over its nodes); the lobe as Eq. 7
and corrected. A base parameter a method does not name is the scene's as narval resolves it
(`narval scene SCENE --set <the method's settings> --resolved`): the scene's value, else the
loader's default. A dotted parameter is a nested key: msCache.resolution is
renderer.raymarch.msCache.resolution.

For each scene (default scenes/cloud.json, scenes/smoke.json, scenes/disney_cloud.json (the Disney
cloud lit from behind, the dissertation's Listing 4.1) and scenes/disney_cloud_front.json (lit from
the front); a scene whose volume file is absent is skipped, saying why):
  1. a converged path-traced reference: `narval render SCENE --spp N --resolution R --seed 1`
     (N/4 samples first, kept as snapshot.exr, then continued by --resume: `compare
     --reference-snapshot` then estimates the JND% its own noise alone gives, reported with it),
     cached under a hash of the scene file, its volume files (path, size, mtime), resolution, spp,
     bounces, the narval version and the reference format, so reruns skip it (the path tracer's pixels
     are pinned by its bitwise golden tests; --refresh-reference renders again after changing it);
  2. every method across its sweeps (pathtrace with seed 2, not the reference's). Time: the stats'
     `seconds` per image for pathtrace; per frame for the others, the median of `--frames 3`
     (kernel time by profiling events); each method gets one tiny warm-up render first (PoCL
     compiles again at the first launch). Cache methods' rows also record `build_seconds`, the
     multiple-scattering cache's build (stats `ms_cache_ms`), which is not part of the frame time;
  3. `narval compare REFERENCE TEST --json` under the scene's display transform (the one both EXRs
     record: its exposure and tone mapping, as narval's PNG shows it) for mean ΔE76, JND76% (ΔE76 >
     2.3), mean ΔE2000 and JND2000%;
  4. budget picks: per frame budget (--budgets-ms, default 16 and 100 ms), the configuration of a
     real-time method (not pathtrace) with the lowest JND76% whose frame time is within the budget
     (ties: lower mean ΔE76), and whether its JND76% meets --jnd-threshold.
Writes into --out (default build/speed_vs_error, git-ignored): results.json (run header with device,
date, command line and sweeps; per scene its base parameters, summary and `budget_picks`; one row per
sweep entry), results.csv, per scene SCENE_time_vs_jnd.svg and SCENE_time_vs_de.svg (time on a log
axis, one marker shape and colour per method, the Pareto front over all methods as a step line, the
budgets as verticals), the renders and their PNGs under SCENE/, and report.md + report.html (run
header, methods table; per scene the summary, budget picks, plots, results with a build column and a
labelled thumbnail grid; a closing budget x scene table). The budget picks are printed at the end.

Options: --help. Reference cache: $NARVAL_CACHE_DIR/speed_vs_error, else ~/.cache/narval/speed_vs_error;
NARVAL_CACHE_DIR=off renders the reference every time. Python 3 standard library only.
Not a test: nothing is asserted. Exit codes: 0 done, 1 a narval command failed, 2 bad usage (one
line on stderr), 130 interrupted.
"""

import argparse
import csv
import hashlib
import html
import json
import math
import os
import re
import shlex
import shutil
import sys
import tempfile
import time
from pathlib import Path

from scene_env import NarvalError, run_json, run_narval, resolved_scene, value_at, volume_path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_SCENES = ["scenes/cloud.json", "scenes/smoke.json", "scenes/disney_cloud.json",
                  "scenes/disney_cloud_front.json"]
REFERENCE_SEED = 1
REFERENCE_FORMAT = 3  # raise when the path tracer's output changes on purpose: cached references go stale
TEST_SEED = 2
DEFAULT_BUDGETS_MS = [16, 100]

# A method is an algorithm with fixed scene settings (passed as --set renderer.ALGORITHM.KEY=JSON),
# named base parameters that override the scene's (only where the method's base differs from what
# narval resolves), and a style (marker shape and colour in plots and legends). Order: the order
# measured and reported.
METHODS = {
    "pathtrace": {"algorithm": "pathtrace", "settings": {}, "base": {}, "style": ("circle", "#1f77b4")},
    "raymarch-none": {"algorithm": "raymarch", "settings": {"multipleScattering": "none", "octaves": 1},
                      "base": {}, "style": ("square", "#d95f02")},
    "raymarch-octaves": {"algorithm": "raymarch", "settings": {"multipleScattering": "octaves"},
                         "base": {"octaves": 4}, "style": ("diamond", "#a6761d")},
    "raymarch-cache": {"algorithm": "raymarch", "settings": {"multipleScattering": "cache", "octaves": 1},
                       "base": {}, "style": ("triangle-down", "#e7298a")},
    "raymarch-cache-camera": {"algorithm": "raymarch",
                              "settings": {"multipleScattering": "cache", "octaves": 1, "msCache.closure": "camera"},
                              "base": {}, "style": ("square", "#66a61e")},
    "raymarch-cache-view": {"algorithm": "raymarch",
                            "settings": {"multipleScattering": "cache", "octaves": 1, "msCache.layout": "view",
                                         "areaLightPhase": "exact"},
                            "base": {"shadowWeighting": "phase"}, "style": ("diamond", "#e6ab02")},
    "raymarch-cache-direct": {"algorithm": "raymarch",
                              "settings": {"multipleScattering": "cache", "octaves": 1, "msCache.layout": "view",
                                           "msCache.direct": True},
                              "base": {"msCache.tile": 2}, "style": ("triangle-down", "#666666")},
    "raymarch-cache-filtered": {"algorithm": "raymarch",
                                "settings": {"multipleScattering": "cache", "octaves": 1, "msCache.layout": "view",
                                             "msCache.direct": True, "msCache.tile": 1},
                                "base": {"msCache.paths": 160, "msCache.filter": 1, "msCache.filterTolerance": 2},
                                "style": ("circle", "#e41a1c")},
    "lobe-eq7": {"algorithm": "lobe", "settings": {"variant": "eq7"}, "base": {}, "style": ("triangle", "#1b9e77")},
    "lobe-corrected": {"algorithm": "lobe", "settings": {"variant": "corrected"}, "base": {},
                       "style": ("cross", "#7570b3")},
}

# Quality parameters swept per method, one at a time from the base.
FULL_SWEEPS = {
    "pathtrace": {"spp": [1, 4, 16, 64, 256], "bounces": [1, 2, 4, 8]},
    "raymarch-none": {"steps": [15, 30, 60, 120], "shadowSteps": [5, 10, 20]},
    "raymarch-octaves": {"octaves": [2, 4, 8], "steps": [30, 60, 120]},
    "raymarch-cache": {"msCache.resolution": [8, 16, 32], "msCache.paths": [64, 256, 1024], "steps": [30, 60, 120],
                       "shadowAreaSamples": [1, 4], "areaLightSamples": [1, 2], "areaLightPhase": ["points", "exact"],
                       "msCache.closure": ["linear", "hg"]},
    "raymarch-cache-camera": {"msCache.resolution": [16, 32], "msCache.paths": [256, 1024],
                              "areaLightPhase": ["points", "exact"], "msCache.interpolation": ["geometric", "linear"]},
    "raymarch-cache-view": {"msCache.tile": [2, 4, 8], "msCache.slices": [4, 8, 16], "msCache.paths": [64, 256, 1024],
                            "shadowWeighting": ["area", "phase"]},
    "raymarch-cache-direct": {"msCache.tile": [2, 4], "msCache.slices": [4, 8], "msCache.paths": [128, 256, 512]},
    "raymarch-cache-filtered": {"msCache.paths": [40, 160], "msCache.filter": [1, 1.5, 2],
                                "msCache.filterTolerance": [0.5, 2, 8], "msCache.filterTwicing": [False, True],
                                "msCache.allocation": ["even", "perceptual"]},
    "lobe-eq7": {"lobePoints": [10, 30, 60], "depthFactor": [5, 20, 100], "shadowSteps": [25, 50, 100]},
    "lobe-corrected": {"lobePoints": [10, 30, 60], "lobeRadius": [0.3, 1, 3, 10], "viewSteps": [8, 16, 32],
                       "areaLightPhase": ["points", "exact"]},
}
QUICK_SWEEPS = {
    "pathtrace": {"spp": [1, 16], "bounces": [1, 4]},
    "raymarch-none": {"steps": [15, 60], "shadowSteps": [5, 20]},
    "raymarch-octaves": {"octaves": [2, 4], "steps": [30, 60]},
    "raymarch-cache": {"msCache.resolution": [8, 16], "msCache.paths": [64, 256], "steps": [30, 60]},
    "raymarch-cache-camera": {"msCache.resolution": [8, 16], "msCache.paths": [64, 256]},
    "raymarch-cache-view": {"msCache.tile": [4, 8], "msCache.paths": [16, 64]},
    "raymarch-cache-direct": {"msCache.tile": [4, 8], "msCache.paths": [16, 64]},
    "raymarch-cache-filtered": {"msCache.paths": [8, 32]},
    "lobe-eq7": {"lobePoints": [10, 30], "depthFactor": [5, 100], "shadowSteps": [25, 100]},
    "lobe-corrected": {"lobePoints": [10, 30], "lobeRadius": [0.3, 3], "viewSteps": [8, 16]},
}


# ---------------------------------------------------------------------------------------------
# Command line and settings
# ---------------------------------------------------------------------------------------------

def usage_error(message):
    """Bad usage: one line on stderr, exit 2."""
    print("speed_vs_error.py: %s" % message, file=sys.stderr)
    sys.exit(2)


def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="speed_vs_error.py",
        description="Speed versus error of every narval method (algorithm and settings) against a converged "
                    "path-traced reference; writes results, SVG plots, frame-budget picks and a Markdown/HTML "
                    "report.")
    p.add_argument("scenes", nargs="*", metavar="SCENE.json",
                   help="scenes (default: %s)" % " ".join(DEFAULT_SCENES))
    p.add_argument("--resolution", help="WIDTHxHEIGHT (default 320x240; --quick 48x24)")
    p.add_argument("--reference-spp", type=int, help="reference samples per pixel (default 2048; --quick 64)")
    p.add_argument("--reference-bounces", type=int, help="reference bounces (default: the scene's)")
    p.add_argument("--base-spp", type=int, help="pathtrace spp while bounces vary (default 16; --quick 4)")
    p.add_argument("--frames", type=int, default=3, help="frames per real-time render; median taken (default 3)")
    p.add_argument("--device", help="narval --device for every render")
    p.add_argument("--jnd-threshold", type=float, default=5.0,
                   help="JND76%% bound for the summary and the budget picks (default 5)")
    p.add_argument("--methods", metavar="M1,M2",
                   help="methods to run, of %s (default: all)" % ", ".join(METHODS))
    p.add_argument("--sweep", action="append", default=[], metavar="METHOD.PARAMETER=V1,V2",
                   help="replace one sweep, e.g. raymarch-cache.msCache.resolution=8,16 (repeatable)")
    p.add_argument("--budgets-ms", default=",".join(str(b) for b in DEFAULT_BUDGETS_MS), metavar="B1,B2",
                   help="frame budgets in ms for the budget picks (default %s)" % ",".join(
                       str(b) for b in DEFAULT_BUDGETS_MS))
    p.add_argument("--out", help="output folder (default build/speed_vs_error)")
    p.add_argument("--narval", default=str(REPO / "build" / "narval"), help="narval binary (default build/narval)")
    p.add_argument("--refresh-reference", action="store_true", help="render the references again, ignoring the cache")
    p.add_argument("--quick", action="store_true", help="tiny configuration for smoke testing")
    p.add_argument("--references-only", action="store_true",
                   help="render (or find cached) the references and stop: nothing else is timed")
    args = p.parse_args(argv)
    args.command_line = " ".join(["bench/speed_vs_error.py"] + [shlex.quote(a) for a in argv])

    if args.resolution is None:
        args.resolution = "48x24" if args.quick else "320x240"
    if not re.fullmatch(r"[1-9][0-9]*x[1-9][0-9]*", args.resolution):
        usage_error("--resolution wants WIDTHxHEIGHT, got '%s'" % args.resolution)
    if args.reference_spp is None:
        args.reference_spp = 64 if args.quick else 2048
    if args.base_spp is None:
        args.base_spp = 4 if args.quick else 16
    for name in ("reference_spp", "base_spp", "frames"):
        if getattr(args, name) < 1:
            usage_error("--%s wants a positive integer" % name.replace("_", "-"))
    if args.reference_bounces is not None and args.reference_bounces < 0:
        usage_error("--reference-bounces wants a non-negative integer")
    if args.out is None:
        args.out = str(REPO / "build" / "speed_vs_error")
    args.default_scenes = not args.scenes
    args.scenes = args.scenes or [str(REPO / s) for s in DEFAULT_SCENES]
    try:
        args.methods = parse_methods(args.methods)
        args.sweeps = build_sweeps(args.quick, args.methods, args.sweep)
        args.budgets_ms = parse_budgets(args.budgets_ms)
    except ValueError as e:
        usage_error(str(e))
    if not os.access(args.narval, os.X_OK):
        usage_error("narval binary %s not found: build it (cmake --build build --target narval)" % args.narval)
    return args


def parse_number(text):
    """'16' -> 16, '2.5' -> 2.5; ValueError otherwise."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError("not a finite number: %s" % text)
    return int(value) if value == int(value) and "." not in text and "e" not in text.lower() else value


def parse_methods(text):
    """'raymarch-cache,lobe-corrected' -> those names in METHODS order; None -> every method."""
    if text is None:
        return list(METHODS)
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        raise ValueError("--methods wants a comma-separated list of %s" % ", ".join(METHODS))
    for name in names:
        if name not in METHODS:
            raise ValueError("--methods: unknown method '%s' (known: %s)" % (name, ", ".join(METHODS)))
    return [m for m in METHODS if m in names]


def parse_budgets(text):
    """'16,100' -> [16, 100] (ms, positive, ascending)."""
    try:
        budgets = [parse_number(v) for v in text.split(",")]
    except ValueError:
        raise ValueError("--budgets-ms wants comma-separated numbers of milliseconds, got '%s'" % text)
    if not budgets or any(b <= 0 for b in budgets):
        raise ValueError("--budgets-ms wants positive numbers of milliseconds, got '%s'" % text)
    return sorted(set(budgets))


def build_sweeps(quick, methods, overrides):
    """{method: {parameter: [values]}} for the methods run, with the --sweep overrides applied."""
    table = QUICK_SWEEPS if quick else FULL_SWEEPS
    sweeps = {m: json.loads(json.dumps(table[m])) for m in methods}  # a deep copy
    for item in overrides:
        m = re.fullmatch(r"([A-Za-z0-9-]+)\.([A-Za-z0-9_.]+)=(.+)", item)
        if not m:
            raise ValueError("--sweep wants METHOD.PARAMETER=V1,V2,..., got '%s'" % item)
        method, parameter, values = m.groups()
        if method in METHODS and method not in sweeps:
            raise ValueError("--sweep %s: method %s is not among --methods (%s)" % (item, method, ", ".join(methods)))
        if method not in sweeps or parameter not in sweeps[method]:
            known = ", ".join("%s.%s" % (a, q) for a, s in sweeps.items() for q in s)
            raise ValueError("--sweep: unknown parameter %s.%s (known: %s)" % (method, parameter, known))
        try:
            sweeps[method][parameter] = [parse_number(v) for v in values.split(",")]
        except ValueError:
            raise ValueError("--sweep %s: expected comma-separated numbers" % item)
    return sweeps


def format_value(value):
    """A parameter value as names and tables show it: integers and names as they are, numbers %g."""
    return str(value) if isinstance(value, (int, str)) else "%g" % value


# ---------------------------------------------------------------------------------------------
# Scenes and narval
# ---------------------------------------------------------------------------------------------

def load_scene(path, settings):
    """What the report needs from a scene file (its bytes and volume files key the reference cache;
    its bounces are narval's resolved value), or a 'skip' reason when it cannot be rendered."""
    scene = {"path": str(Path(path).resolve()), "name": Path(path).stem, "skip": None, "volumes": []}
    with open(path, "rb") as f:
        scene["bytes"] = f.read()
    data = json.loads(scene["bytes"])
    for material in data.get("materials", []):
        if material.get("type") != "volume" or "path" not in material:
            continue
        try:
            volume = volume_path(scene["path"], material["path"])
        except ValueError as e:
            scene["skip"] = "volume path of material %s: %s" % (material.get("name"), e)
            continue
        if not volume.is_file():
            scene["skip"] = "volume file %s is absent (set NARVAL_DATA_DIR)" % volume
            continue
        stat = volume.stat()
        scene["volumes"].append({"path": str(volume), "size": stat.st_size, "mtime_ns": stat.st_mtime_ns})
    if not scene["skip"]:
        scene["bounces"] = resolved_scene(settings.narval, scene["path"])["renderer"]["bounces"]
    return scene


def narval_version(settings):
    """The version string. Not the binary's hash: every commit rebuilds it, and a converged reference
    costs tens of minutes on 2 cores; the path tracer's pixels are pinned by its golden tests."""
    return run_narval(settings.narval, ["--version"]).strip()


def device_options(settings):
    return ["--device", settings.device] if settings.device else []


def describe_device(settings, name):
    """The `narval devices --json` entry of the device called name (from a render's stats), else the
    one --device picks (index or name substring; the first without --device), as 'NAME (TYPE,
    PLATFORM DRIVER, N CUs, MEMORY)'. Falls back to name, else '?'."""
    try:
        devices = run_json(settings.narval, ["devices", "--json"])
    except NarvalError:
        return name or "?"
    wanted = (settings.device or "").lower()
    for d in devices:
        if (d["name"] == name if name else
                not wanted or wanted == str(d["index"]) or (not wanted.isdigit() and wanted in d["name"].lower())):
            return "%s (%s, %s %s, %d CUs, %.0f GiB)" % (d["name"], d["type"], d["platform"], d["driver_version"],
                                                         d["compute_units"], d["global_mem_bytes"] / 2 ** 30)
    return name or "?"


def method_sets(method):
    """A method's fixed settings as --set PATH=VALUE strings; values JSON-encoded (strings quoted)."""
    algorithm = METHODS[method]["algorithm"]
    return ["renderer.%s.%s=%s" % (algorithm, k, json.dumps(v)) for k, v in METHODS[method]["settings"].items()]


def method_settings_arguments(method):
    return [a for s in method_sets(method) for a in ("--set", s)]


def warm_up(settings, scene, method):
    """One tiny render per method, thrown away: PoCL compiles again at a kernel's first launch (the
    multiple-scattering cache's build kernel too, on a 1-cell cache of 1 path per node)."""
    algorithm = METHODS[method]["algorithm"]
    frames = ["--spp", 1] if algorithm == "pathtrace" else ["--frames", 1]
    arguments = ["--algorithm", algorithm, "--resolution", "16x8"] + frames + method_settings_arguments(method)
    if METHODS[method]["settings"].get("multipleScattering") == "cache":
        arguments += ["--set", "renderer.raymarch.msCache.resolution=1", "--set", "renderer.raymarch.msCache.paths=1"]
    with tempfile.TemporaryDirectory(prefix="speed_vs_error_") as scratch:
        run_narval(settings.narval, ["render", scene["path"], "-o", Path(scratch) / "warm_up.exr"] + arguments
                   + device_options(settings))


def compare(settings, reference_exr, test_exr, *options):
    """`narval compare REFERENCE TEST --json` under the display transform both EXRs record (the
    scene's, as its PNG shows it); an error when they record none in common."""
    result = run_json(settings.narval, ["compare", reference_exr, test_exr, "--json"] + list(options))
    if result["display_transform"] != "as both EXRs record it":
        raise NarvalError("compare %s %s: display transform %s, not the scene's (--refresh-reference renders the "
                          "reference again)" % (reference_exr, test_exr, result["display_transform"]))
    return result


# ---------------------------------------------------------------------------------------------
# Reference (cached)
# ---------------------------------------------------------------------------------------------

def cache_root():
    """$NARVAL_CACHE_DIR/speed_vs_error, else ~/.cache/narval/speed_vs_error; None for 'off'."""
    base = os.environ.get("NARVAL_CACHE_DIR")
    if base == "off":
        return None
    return Path(base or Path.home() / ".cache" / "narval") / "speed_vs_error"


def reference_key(scene, settings, bounces, version):
    """sha256 of everything the reference's pixels depend on."""
    description = {
        "scene_sha256": hashlib.sha256(scene["bytes"]).hexdigest(),
        "volumes": scene["volumes"],
        "resolution": settings.resolution,
        "spp": settings.reference_spp,
        "bounces": bounces,
        "seed": REFERENCE_SEED,
        "narval": version,
        "format": REFERENCE_FORMAT,
    }
    text = json.dumps(description, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest(), description


def render_reference(settings, scene, bounces, folder):
    """Renders the reference into folder/reference.exr (+ .png, stats.json), a quarter of its samples
    first, kept as folder/snapshot.exr, then the rest by --resume (the same pixels as one render:
    its samples are counter-based); returns its stats, seconds summed over both runs. The snapshot
    lets `compare --reference-snapshot` estimate the reference's own noise floor."""
    folder.mkdir(parents=True, exist_ok=True)
    common = ["render", scene["path"], "-o", folder / "reference.exr", "--algorithm", "pathtrace", "--bounces",
              bounces, "--resolution", settings.resolution, "--seed", REFERENCE_SEED,
              "--stats-json", folder / "stats.json"] + device_options(settings)
    snapshot_spp = max(1, settings.reference_spp // 4)
    run_narval(settings.narval, common + ["--spp", snapshot_spp])
    stats = json.loads((folder / "stats.json").read_text())
    if settings.reference_spp > snapshot_spp:
        seconds = stats["seconds"]
        shutil.copyfile(folder / "reference.exr", folder / "snapshot.exr")
        run_narval(settings.narval, common + ["--spp", settings.reference_spp, "--resume"])
        stats = json.loads((folder / "stats.json").read_text())
        stats["seconds"] += seconds
        (folder / "stats.json").write_text(json.dumps(stats))
    return stats


def ensure_reference(settings, scene, version, scene_out):
    """The reference for this scene in scene_out (reference.exr/.png), from the cache when possible;
    sets scene["display"] (exposure, tone mapping) from what `narval compare` applies to it."""
    bounces = settings.reference_bounces if settings.reference_bounces is not None else scene["bounces"]
    key, description = reference_key(scene, settings, bounces, version)
    root = cache_root()
    cached = root / key[:24] if root else scene_out / "reference_render"
    # key.json is written last: a folder without it holds an unfinished render.
    from_cache = bool(root and (cached / "key.json").is_file() and not settings.refresh_reference)
    if from_cache:
        print("  reference: cached (%s)" % cached, flush=True)
    else:
        print("  reference: pathtrace %d spp, %d bounces, %s ..." % (settings.reference_spp, bounces,
                                                                    settings.resolution), flush=True)
        shutil.rmtree(cached, ignore_errors=True)
        render_reference(settings, scene, bounces, cached)
        (cached / "key.json").write_text(json.dumps(description, indent=2, sort_keys=True))
    stats = json.loads((cached / "stats.json").read_text())
    for name in ("reference.exr", "reference.png", "snapshot.exr"):
        if (cached / name).is_file():
            shutil.copyfile(cached / name, scene_out / name)
    if not from_cache:
        print("  reference: %.1f s" % stats["seconds"], flush=True)
    # The reference against itself: the display transform compare applies, and with the snapshot
    # what the reference's own noise alone reads (the JND% and mean ΔE76 a noise-free image would have).
    exr, snapshot = scene_out / "reference.exr", scene_out / "snapshot.exr"
    own = compare(settings, exr, exr, *(["--reference-snapshot", snapshot] if snapshot.is_file() else []))
    scene["display"] = {"exposure": own["exposure"], "tonemap": own["tonemap"]}
    noise = own.get("reference_noise")
    if noise:
        print("  reference noise alone: JND %.2f%% (from its first %d samples)" % (noise["jnd76_pct"],
                                                                                 noise["snapshot_spp"]), flush=True)
    return {"exr": exr, "png": "reference.png", "spp": settings.reference_spp,
            "bounces": bounces, "seed": REFERENCE_SEED, "seconds": stats["seconds"], "device": stats["device"],
            "cached": from_cache, "key": key, "cache_folder": str(cached), "noise": noise}


# ---------------------------------------------------------------------------------------------
# Configurations
# ---------------------------------------------------------------------------------------------

def base_parameters(settings, scene, method):
    """The values a method's parameters keep while another one varies: pathtrace at --base-spp and
    the scene's bounces; a real-time method's named base (METHODS), else the value narval resolves
    for the scene with the method's settings applied (the scene's, else the loader's default)."""
    if METHODS[method]["algorithm"] == "pathtrace":
        return {"spp": settings.base_spp, "bounces": scene["bounces"]}
    algorithm = METHODS[method]["algorithm"]
    resolved = resolved_scene(settings.narval, scene["path"],
                              ["renderer.algorithm=%s" % json.dumps(algorithm)] + method_sets(method))
    base = {}
    for parameter in settings.sweeps[method]:
        try:
            base[parameter] = METHODS[method]["base"].get(parameter, value_at(resolved["renderer"][algorithm],
                                                                              parameter))
        except KeyError:
            raise NarvalError("narval scene --resolved has no renderer.%s.%s (method %s)" % (algorithm, parameter,
                                                                                            method))
    return base


def configuration_id(method, parameters):
    """File-name-safe identity of one effective parameter set, e.g. raymarch-none_shadowSteps10_steps60."""
    return method + "_" + "_".join("%s%s" % (k, format_value(v)) for k, v in sorted(parameters.items()))


def render_arguments(method, parameters):
    """narval render options that select the method and set the parameters."""
    algorithm = METHODS[method]["algorithm"]
    options = ["--algorithm", algorithm]
    if algorithm == "pathtrace":
        return options + ["--spp", parameters["spp"], "--bounces", parameters["bounces"]]
    options += method_settings_arguments(method)
    for name, value in sorted(parameters.items()):
        encoded = json.dumps(value) if isinstance(value, str) else format_value(value)
        options += ["--set", "renderer.%s.%s=%s" % (algorithm, name, encoded)]
    return options


def build_configurations(settings, bases):
    """One entry per (method, parameter, value); entries with equal parameters share one render."""
    configurations = []
    for method in settings.methods:
        base = bases[method]
        for parameter, values in settings.sweeps[method].items():
            for value in values:
                parameters = dict(base, **{parameter: value})
                configurations.append({
                    "method": method,
                    "algorithm": METHODS[method]["algorithm"],
                    "parameter": parameter,
                    "value": value,
                    "parameters": parameters,
                    "id": configuration_id(method, parameters),
                    "is_base": parameters == base,
                })
    return configurations


def render_configuration(settings, scene, configuration, renders):
    """Renders one configuration into renders/ID.exr (+ .png); returns (seconds, build seconds or None,
    stats): pathtrace's time per image, else the median kernel time of --frames frames; the build
    is the multiple-scattering cache's (cache methods only), which is not in the frame time."""
    method = configuration["method"]
    exr = renders / (configuration["id"] + ".exr")
    stats_path = renders / (configuration["id"] + ".json")
    arguments = ["render", scene["path"], "-o", exr, "--resolution", settings.resolution,
                 "--seed", TEST_SEED, "--stats-json", stats_path] + device_options(settings)
    arguments += render_arguments(method, configuration["parameters"])
    if configuration["algorithm"] != "pathtrace":
        arguments += ["--frames", settings.frames]
    run_narval(settings.narval, arguments)
    stats = json.loads(stats_path.read_text())
    if configuration["algorithm"] == "pathtrace":
        return stats["seconds"], None, stats
    build = None
    if METHODS[method]["settings"].get("multipleScattering") == "cache":
        build = stats.get("ms_cache_ms", 0.0) / 1000.0
    return stats["ms_per_frame"]["median"] / 1000.0, build, stats


def measure_scene(settings, scene, reference, scene_out, bases):
    """Renders and compares every configuration; returns (result rows, one per configuration entry;
    the device name the renders report)."""
    renders = scene_out / "renders"
    renders.mkdir(parents=True, exist_ok=True)
    measured = {}  # configuration id -> (seconds, build seconds, light cache seconds, comparison)
    rows = []
    warmed = set()
    device = None
    for configuration in build_configurations(settings, bases):
        method = configuration["method"]
        if method not in warmed:
            warm_up(settings, scene, method)
            warmed.add(method)
        if configuration["id"] not in measured:
            seconds, build, stats = render_configuration(settings, scene, configuration, renders)
            device = device or stats.get("device")
            light = stats.get("light_cache_ms") / 1000.0 if stats.get("light_cache_ms") is not None else None
            comparison = compare(settings, reference["exr"], renders / (configuration["id"] + ".exr"))
            measured[configuration["id"]] = (seconds, build, light, comparison)
            note = ""
        else:
            note = " (same render as above)"
        seconds, build, light, comparison = measured[configuration["id"]]
        row = {
            "scene": scene["name"],
            "method": method,
            "algorithm": configuration["algorithm"],
            "parameter": configuration["parameter"],
            "value": configuration["value"],
            "seconds": seconds,
            "build_seconds": build,
            "light_cache_seconds": light if configuration["algorithm"] != "pathtrace" else None,
            "mean_dE76": comparison["mean_dE76"],
            "jnd76_pct": comparison["jnd76_pct"],
            "mean_dE2000": comparison["mean_dE2000"],
            "jnd2000_pct": comparison["jnd2000_pct"],
            "p95_dE76": comparison["p95_dE76"],
            "configuration": configuration["id"],
            "settings": METHODS[method]["settings"],
            "parameters": configuration["parameters"],
            "is_base": configuration["is_base"],
            "image": "%s/renders/%s.png" % (scene["name"], configuration["id"]),
        }
        rows.append(row)
        print("  %-16s %-18s %-5s %10s%s  mean ΔE76 %6.2f  JND76 %6.2f%%%s" % (
            method, configuration["parameter"], format_value(configuration["value"]), time_text(row),
            "  build %6.2f s" % build if build is not None else "", row["mean_dE76"], row["jnd76_pct"], note),
            flush=True)
    return rows, device


# ---------------------------------------------------------------------------------------------
# Analysis
# ---------------------------------------------------------------------------------------------

def unique_configurations(rows):
    """One row per distinct render (the default configuration appears once per parameter swept)."""
    seen = {}
    for row in rows:
        seen.setdefault(row["configuration"], row)
    return list(seen.values())


def pareto_front(points, error_key):
    """Points not dominated in (time, error): sorted by time, each strictly better than all faster ones."""
    front = []
    best = math.inf
    for point in sorted(points, key=lambda p: (p["seconds"], p[error_key])):
        if point[error_key] < best:
            front.append(point)
            best = point[error_key]
    return front


def short_label(row):
    """'spp=16', or 'base' for the configuration every sweep of the method passes through."""
    if row["is_base"]:
        return "base"
    return "%s=%s" % (row["parameter"], format_value(row["value"]))


def parameters_text(parameters):
    """'steps 60, shadowSteps 10' (in the order given)."""
    return ", ".join("%s %s" % (k, format_value(v)) for k, v in parameters.items())


def full_label(row):
    """'raymarch-cache msCache.resolution 16, msCache.paths 256, steps 60' (sweep order)."""
    return "%s %s" % (row["method"], parameters_text(row["parameters"]))


def summarise(rows, threshold):
    """Lines of plain text: per method the fastest configuration under the JND bound and the most
    accurate one; the overall fastest under the bound; the Pareto front."""
    lines = []
    points = unique_configurations(rows)
    for method in METHODS:
        mine = [p for p in points if p["method"] == method]
        if not mine:
            continue
        within = [p for p in mine if p["jnd76_pct"] <= threshold]
        most_accurate = min(mine, key=lambda p: (p["jnd76_pct"], p["seconds"]))
        accurate_text = "%s in %s (JND %.2f%%, mean ΔE76 %.2f)" % (
            full_label(most_accurate), time_text(most_accurate), most_accurate["jnd76_pct"],
            most_accurate["mean_dE76"])
        if within:
            fastest = min(within, key=lambda p: (p["seconds"], p["jnd76_pct"]))
            lines.append("%s: fastest under JND %g%%: %s in %s (JND %.2f%%, mean ΔE76 %.2f); lowest JND: %s" % (
                method, threshold, full_label(fastest), time_text(fastest), fastest["jnd76_pct"],
                fastest["mean_dE76"], accurate_text))
        else:
            lines.append("%s: none under JND %g%%; lowest JND: %s" % (method, threshold, accurate_text))
    within = [p for p in points if p["jnd76_pct"] <= threshold]
    if within:
        best = min(within, key=lambda p: (p["seconds"], p["jnd76_pct"]))
        lines.append("Fastest of all under JND %g%%: %s, %s" % (threshold, full_label(best), time_text(best)))
    else:
        lines.append("No configuration of any method reaches JND %g%%." % threshold)
    front = pareto_front(points, "jnd76_pct")
    lines.append("Pareto front (time, JND76%%): %s" % "; ".join(
        "%s %s (%s, %.2f%%)" % (p["method"], short_label(p), time_text(p), p["jnd76_pct"]) for p in front))
    return lines


def budget_picks(rows, budgets_ms, threshold):
    """Per frame budget (ms), the real-time configuration (any method but pathtrace) with the lowest
    JND76% whose frame time is within it (ties: lower mean ΔE76, then faster); the cache build is a
    one-off cost outside the frame time and does not count. One dict per budget; method None and a
    reason where nothing fits."""
    realtime = [p for p in unique_configurations(rows) if p["algorithm"] != "pathtrace"]
    picks = []
    for budget in budgets_ms:
        within = [p for p in realtime if p["seconds"] * 1000.0 <= budget]
        pick = {"budget_ms": budget}
        if not within:
            if realtime:
                fastest = min(realtime, key=lambda p: p["seconds"])
                reason = "no real-time configuration runs within %g ms a frame (fastest: %s, %.2f ms)" % (
                    budget, full_label(fastest), fastest["seconds"] * 1000.0)
            else:
                reason = "no real-time method was run"
            pick.update(method=None, reason=reason)
            picks.append(pick)
            continue
        best = min(within, key=lambda p: (p["jnd76_pct"], p["mean_dE76"], p["seconds"]))
        pick.update(method=best["method"], algorithm=best["algorithm"], settings=best["settings"],
                    parameters=best["parameters"], configuration=best["configuration"], label=full_label(best),
                    ms_per_frame=best["seconds"] * 1000.0, build_seconds=best["build_seconds"],
                    mean_dE76=best["mean_dE76"], jnd76_pct=best["jnd76_pct"],
                    meets_jnd_threshold=best["jnd76_pct"] <= threshold, image=best["image"])
        picks.append(pick)
    return picks


def build_text(build_seconds, digits=2):
    """The build column: blank when the method has no cache to build."""
    return "" if build_seconds is None else "%.*f" % (digits, build_seconds)


def pick_cells(pick):
    """[method and parameters, ms/frame, build s, mean ΔE76, JND76%, meets] for one budget pick."""
    if pick["method"] is None:
        return [pick["reason"], "", "", "", "", ""]
    return [pick["label"], "%.2f" % pick["ms_per_frame"], build_text(pick["build_seconds"]),
            "%.3f" % pick["mean_dE76"], "%.2f" % pick["jnd76_pct"], "yes" if pick["meets_jnd_threshold"] else "no"]


def pick_summary(pick):
    """Short text for the cross-scene table."""
    if pick["method"] is None:
        return "none within budget"
    build = ", build %.2f s" % pick["build_seconds"] if pick["build_seconds"] is not None else ""
    return "%s (%.2f ms%s, JND %.2f%%, %s)" % (pick["label"], pick["ms_per_frame"], build, pick["jnd76_pct"],
                                             "meets" if pick["meets_jnd_threshold"] else "misses")


# ---------------------------------------------------------------------------------------------
# SVG plots
# ---------------------------------------------------------------------------------------------

def nice_step(raw):
    """The smallest 1, 2 or 5 x 10^k at or above raw."""
    if raw <= 0:
        return 1.0
    decade = 10 ** math.floor(math.log10(raw))
    for multiple in (1, 2, 5, 10):
        if multiple * decade >= raw * (1 - 1e-9):
            return multiple * decade
    return 10 * decade


def svg_polygon(colour, corners):
    """A filled marker polygon through the corners [(x, y)]."""
    return '<polygon points="%s" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
        " ".join("%.1f,%.1f" % c for c in corners), colour)


def svg_marker(shape, colour, x, y, size=5.5):
    """One marker: circle, square, diamond, triangle, triangle-down or cross (a plus sign)."""
    if shape == "circle":
        return '<circle cx="%.1f" cy="%.1f" r="%.1f" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
            x, y, size, colour)
    if shape == "square":
        return '<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
            x - size * 0.9, y - size * 0.9, size * 1.8, size * 1.8, colour)
    if shape == "diamond":
        r = size * 1.25
        return svg_polygon(colour, [(x, y - r), (x + r, y), (x, y + r), (x - r, y)])
    if shape == "triangle-down":
        return svg_polygon(colour, [(x, y + size * 1.15), (x - size * 1.05, y - size * 0.8),
                                    (x + size * 1.05, y - size * 0.8)])
    if shape == "cross":
        r, w = size * 1.15, size * 0.42
        return svg_polygon(colour, [(x - w, y - r), (x + w, y - r), (x + w, y - w), (x + r, y - w), (x + r, y + w),
                                    (x + w, y + w), (x + w, y + r), (x - w, y + r), (x - w, y + w), (x - r, y + w),
                                    (x - r, y - w), (x - w, y - w)])
    return svg_polygon(colour, [(x, y - size * 1.15), (x - size * 1.05, y + size * 0.8),
                                (x + size * 1.05, y + size * 0.8)])


def svg_scatter(title, points, error_key, error_label, threshold=None, budgets_ms=()):
    """Time (log x, decade ticks) against an error (linear y from 0); markers per method, the
    Pareto front (over all methods) as a step line, an optional dashed threshold, the frame budgets
    as dotted vertical lines (the axis reaches them). Returns the SVG text."""
    width, height = 760, 460
    left, right, top, bottom = 72, 190, 44, 56
    plot_w, plot_h = width - left - right, height - top - bottom
    times = [max(p["seconds"], 1e-6) for p in points] + [b / 1000.0 for b in budgets_ms]
    low = math.floor(math.log10(min(times)))
    high = math.ceil(math.log10(max(times)))
    if high == low:
        high = low + 1
    errors = [p[error_key] for p in points] + ([threshold] if threshold is not None else [])
    step = nice_step(max(errors) * 1.08 / 5)
    top_value = step * max(1, math.ceil(max(errors) * 1.08 / step))

    def x_of(seconds):
        return left + (math.log10(max(seconds, 1e-6)) - low) / (high - low) * plot_w

    def y_of(error):
        return top + plot_h - error / top_value * plot_h

    out = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" viewBox="0 0 %d %d" '
           'font-family="Helvetica, Arial, sans-serif" font-size="12">' % (width, height, width, height),
           '<rect width="100%" height="100%" fill="white"/>',
           '<text x="%d" y="24" font-size="15" font-weight="bold">%s</text>' % (left, html.escape(title))]
    # Grid and ticks: decades labelled, 2..9 light; y every step.
    for decade in range(low, high + 1):
        x = x_of(10.0 ** decade)
        out.append('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#bbb"/>' % (x, top, x, top + plot_h))
        out.append('<text x="%.1f" y="%d" text-anchor="middle">%s</text>' % (x, top + plot_h + 18, "%g" % 10.0 ** decade))
        if decade < high:
            for multiple in range(2, 10):
                xm = x_of(multiple * 10.0 ** decade)
                out.append('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#eee"/>' % (xm, top, xm, top + plot_h))
    tick = 0.0
    while tick <= top_value * (1 + 1e-9):
        y = y_of(tick)
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#e4e4e4"/>' % (left, y, left + plot_w, y))
        out.append('<text x="%d" y="%.1f" text-anchor="end">%g</text>' % (left - 6, y + 4, round(tick, 10)))
        tick += step
    out.append('<rect x="%d" y="%d" width="%d" height="%d" fill="none" stroke="#333"/>' % (left, top, plot_w, plot_h))
    out.append('<text x="%.1f" y="%d" text-anchor="middle">time (s, log scale): per frame, pathtrace per image'
               '</text>' % (left + plot_w / 2, height - 14))
    out.append('<text transform="translate(18 %.1f) rotate(-90)" text-anchor="middle">%s</text>' % (
        top + plot_h / 2, html.escape(error_label)))
    if threshold is not None:
        y = y_of(threshold)
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#c00" stroke-dasharray="6 4"/>' % (
            left, y, left + plot_w, y))
    for budget in budgets_ms:
        x = x_of(budget / 1000.0)
        out.append('<line x1="%.1f" y1="%d" x2="%.1f" y2="%d" stroke="#777" stroke-dasharray="2 3"/>' % (
            x, top, x, top + plot_h))
        out.append('<text x="%.1f" y="%d" font-size="10" fill="#555" text-anchor="middle">%g ms</text>' % (
            x, top - 4, budget))
    # Pareto front: the lowest error reachable within a time, a step function.
    front = pareto_front(points, error_key)
    path = "M %.1f %.1f" % (x_of(front[0]["seconds"]), y_of(front[0][error_key]))
    for point in front[1:]:
        path += " H %.1f V %.1f" % (x_of(point["seconds"]), y_of(point[error_key]))
    path += " H %d" % (left + plot_w)
    out.append('<path d="%s" fill="none" stroke="#444" stroke-width="1.6" stroke-dasharray="5 3"/>' % path)
    # Markers, with the full configuration as a tooltip; Pareto points labelled.
    for point in points:
        shape, colour = METHODS[point["method"]]["style"]
        x, y = x_of(point["seconds"]), y_of(point[error_key])
        tip = "%s: %.4f s, %s %.3f" % (full_label(point), point["seconds"], error_label, point[error_key])
        out.append('<g><title>%s</title>%s</g>' % (html.escape(tip), svg_marker(shape, colour, x, y)))
    # Labels alternate above and below the step line so that neighbours overlap less.
    for index, point in enumerate(front):
        x, y = x_of(point["seconds"]), y_of(point[error_key])
        dy = -8 if index % 2 == 0 else 16
        out.append('<text x="%.1f" y="%.1f" font-size="10" fill="%s">%s</text>' % (
            x + 6, y + dy, METHODS[point["method"]]["style"][1], html.escape(short_label(point))))
    # Legend.
    lx, ly = left + plot_w + 18, top + 10
    for method in METHODS:
        if not any(p["method"] == method for p in points):
            continue
        shape, colour = METHODS[method]["style"]
        out.append(svg_marker(shape, colour, lx + 6, ly))
        out.append('<text x="%d" y="%d">%s</text>' % (lx + 18, ly + 4, method))
        ly += 22
    out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="#444" stroke-width="1.6" stroke-dasharray="5 3"/>' % (
        lx, ly, lx + 12, ly))
    out.append('<text x="%d" y="%d">Pareto front</text>' % (lx + 18, ly + 4))
    ly += 22
    if threshold is not None:
        out.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="#c00" stroke-dasharray="6 4"/>' % (lx, ly, lx + 12, ly))
        out.append('<text x="%d" y="%d">JND %g%%</text>' % (lx + 18, ly + 4, threshold))
    out.append("</svg>")
    return "\n".join(out) + "\n"


def write_plots(out, scene_name, rows, settings, reference):
    """SCENE_time_vs_jnd.svg and SCENE_time_vs_de.svg; returns their file names."""
    points = unique_configurations(rows)
    subtitle = "%s (reference: pathtrace %d spp, %s)" % (scene_name, reference["spp"], settings.resolution)
    plots = {
        "jnd": svg_scatter(subtitle + ": time vs JND", points, "jnd76_pct",
                           "pixels over 1 JND (ΔE76 > 2.3), %", settings.jnd_threshold, settings.budgets_ms),
        "de": svg_scatter(subtitle + ": time vs mean ΔE", points, "mean_dE76", "mean ΔE76",
                          budgets_ms=settings.budgets_ms),
    }
    names = {}
    for kind, text in plots.items():
        names[kind] = "%s_time_vs_%s.svg" % (scene_name, kind)
        (out / names[kind]).write_text(text, encoding="utf-8")
    return names


# ---------------------------------------------------------------------------------------------
# Results files
# ---------------------------------------------------------------------------------------------

CSV_COLUMNS = ["scene", "method", "algorithm", "parameter", "value", "seconds", "build_seconds", "mean_dE76",
               "jnd76_pct", "mean_dE2000", "jnd2000_pct"]


def write_results(out, header, scenes, rows):
    """results.json (run header, scenes with their budget picks, rows) and results.csv (rows; an
    empty build_seconds for methods without a cache)."""
    with open(out / "results.json", "w") as f:
        json.dump({"run": header, "scenes": scenes, "results": rows}, f, indent=2)
        f.write("\n")
    with open(out / "results.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(CSV_COLUMNS)
        for row in rows:
            writer.writerow(["" if row[c] is None else row[c] for c in CSV_COLUMNS])


# ---------------------------------------------------------------------------------------------
# Reports
# ---------------------------------------------------------------------------------------------

def sweep_groups(rows):
    """[(method, parameter, [rows in sweep order])] in the order measured."""
    groups = []
    for row in rows:
        if not groups or groups[-1][0] != row["method"] or groups[-1][1] != row["parameter"]:
            groups.append((row["method"], row["parameter"], []))
        groups[-1][2].append(row)
    return groups


def time_text(row):
    """'1.234 s' per image for pathtrace, '12.34 ms' per frame for the real-time methods."""
    if row["algorithm"] == "pathtrace":
        return "%.4g s" % row["seconds"]
    return "%.2f ms" % (row["seconds"] * 1000.0)


def cell_caption(row):
    build = " · build %.2f s" % row["build_seconds"] if row["build_seconds"] is not None else ""
    return "%s%s · JND %.1f%% · ΔE %.2f" % (time_text(row), build, row["jnd76_pct"], row["mean_dE76"])


def value_text(row):
    """The swept value, marked '(base)' where the configuration is the method's base."""
    return format_value(row["value"]) + (" (base)" if row["is_base"] else "")


def settings_text(method):
    """'multipleScattering "cache", octaves 1' for a method's fixed settings; '-' for none."""
    fixed = METHODS[method]["settings"]
    return ", ".join("%s %s" % (k, json.dumps(v)) for k, v in fixed.items()) or "-"


def reference_sentence(scene, reference):
    how = "from the cache" if reference["cached"] else "rendered in %.1f s" % reference["seconds"]
    noise = reference.get("noise")
    floor = (" Its own noise alone reads JND %.2f%% (mean ΔE76 %.3f): what a noise-free image would read "
             "against it, estimated from its first %d samples (`compare --reference-snapshot`); a JND%% near "
             "this is at the reference's floor." % (noise["jnd76_pct"], noise["mean_dE76"], noise["snapshot_spp"])
             if noise else "")
    return ("Reference: pathtrace, %d spp, %d bounces, seed %d, on %s (%s). ΔE under the scene's display: "
            "tone mapping %s, exposure %g.%s" % (reference["spp"], reference["bounces"], reference["seed"],
                                                 reference["device"], how, scene["display"]["tonemap"],
                                                 scene["display"]["exposure"], floor))


def base_sentence(bases):
    """One line naming every method's base parameters in this scene."""
    return "Base parameters: " + "; ".join("%s %s" % (m, parameters_text(b)) for m, b in bases.items()) + "."


def run_sentence(header):
    """The report's first line: date, wall time, command line, narval, device, resolution, reference."""
    return ("Generated %s in %.0f s by `%s`: %s on %s; %s; reference pathtrace %d spp (each scene's bounces); "
            "%d frames per real-time render; JND threshold %g%%; frame budgets %s ms." % (
                header["generated"], header["wall_seconds"], header["command"], header["narval"], header["device"],
                header["resolution"], header["reference_spp"], header["frames"], header["jnd_threshold"],
                ", ".join("%g" % b for b in header["budgets_ms"])))


def method_lines(header):
    return [
        "A method is an algorithm with fixed settings (table below). Each is swept one quality parameter "
        "at a time from its base (named in the table, else the scene's value, else narval's default; "
        "pathtrace at %d spp while bounces vary) and compared with a converged path-traced reference by "
        "`narval compare` (CIELAB ΔE76, JND = ΔE76 > 2.3)." % header["base_spp"],
        "Time: `--stats-json` seconds per image for pathtrace (seed %d); for the real-time methods the "
        "median of `--frames %d` (kernel time by profiling events) per frame, after one warm-up render per "
        "method. The multiple-scattering cache's build (`ms_cache_ms`, column *build*) happens once "
        "before the first frame and is not in the frame time; the light cache's build is not either." % (
            TEST_SEED, header["frames"]),
        "Budget picks: per frame budget, the real-time configuration (not pathtrace) with the lowest "
        "JND76%% whose frame time fits the budget (ties: lower mean ΔE76); *meets* says whether its "
        "JND76%% is at most %g%%. Only configurations measured here are candidates." % header["jnd_threshold"],
        "Plots: one marker per distinct configuration and method (hover for its parameters); the dashed "
        "step line is the Pareto front over all methods (no other configuration is both faster and more "
        "accurate), labelled; dotted verticals mark the frame budgets.",
    ]


def methods_table_rows(header):
    """[method, algorithm, fixed settings, sweeps (with the named base)] per method run."""
    rows = []
    for method, sweeps in header["sweeps"].items():
        named = METHODS[method]["base"]
        sweep_text = "; ".join("%s %s%s" % (parameter, ", ".join(format_value(v) for v in values),
                                             " (base %s)" % format_value(named[parameter]) if parameter in named else "")
                               for parameter, values in sweeps.items())
        rows.append([method, METHODS[method]["algorithm"], settings_text(method), sweep_text])
    return rows


PICK_COLUMNS = ["budget", "method and parameters", "ms/frame", "build s", "mean ΔE76", "JND76%"]


def markdown_table(head, rows):
    """Lines of a Markdown table of text cells."""
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    return lines


def markdown_report(header, scene_reports):
    threshold = header["jnd_threshold"]
    lines = ["# narval: speed versus error", "", run_sentence(header), ""]
    lines += ["- " + line for line in method_lines(header)] + [""]
    lines += markdown_table(["method", "algorithm", "fixed settings", "sweeps"], methods_table_rows(header)) + [""]
    for report in scene_reports:
        scene = report["scene"]
        lines += ["## %s" % scene["name"], ""]
        if scene["skip"]:
            lines += ["Skipped: %s." % scene["skip"], ""]
            continue
        reference = report["reference"]
        lines += ["`%s`. %s" % (scene["path"], reference_sentence(scene, reference)), "",
                  base_sentence(report["bases"]), ""]
        lines += ["- " + line for line in report["summary"]] + [""]
        lines += ["### Budget picks", ""]
        lines += markdown_table(PICK_COLUMNS + ["meets (JND76%% ≤ %g%%)" % threshold],
                                [["%g ms" % pick["budget_ms"]] + pick_cells(pick)
                                 for pick in report["budget_picks"]]) + [""]
        lines += ["![time vs JND](%s)" % report["plots"]["jnd"], "", "![time vs mean ΔE](%s)" % report["plots"]["de"], ""]
        lines += ["### Results", ""]
        lines += markdown_table(
            ["method", "parameter", "value", "time", "build s", "mean ΔE76", "JND76%", "mean ΔE2000", "JND2000%"],
            [[row["method"], row["parameter"], value_text(row), time_text(row), build_text(row["build_seconds"]),
              "%.3f" % row["mean_dE76"], "%.2f" % row["jnd76_pct"], "%.3f" % row["mean_dE2000"],
              "%.2f" % row["jnd2000_pct"]] for row in report["rows"]])
        lines += ["", "### Thumbnails", "", "Reference: ![reference](%s/%s)" % (scene["name"], reference["png"]), ""]
        groups = sweep_groups(report["rows"])
        columns = max(len(g[2]) for g in groups)
        lines.append("| sweep |" + " |" * columns)
        lines.append("|---|" + "---|" * columns)
        for method, parameter, group in groups:
            cells = ["%s=%s<br>![](%s)<br>%s" % (parameter, format_value(r["value"]), r["image"], cell_caption(r))
                     for r in group]
            cells += [""] * (columns - len(cells))
            lines.append("| %s %s | %s |" % (method, parameter, " | ".join(cells)))
        lines.append("")
    lines += ["## Budget picks: budget × scene", "",
              "The real-time configuration with the lowest JND76%% within each frame budget (ms per frame, "
              "JND76%%, and whether it meets JND %g%%)." % threshold, ""]
    lines += markdown_table(["budget"] + [r["scene"]["name"] for r in scene_reports], cross_scene_rows(header, scene_reports))
    lines.append("")
    return "\n".join(lines)


def cross_scene_rows(header, scene_reports):
    """Rows of the budget × scene table: one per budget, one cell per scene."""
    rows = []
    for index, budget in enumerate(header["budgets_ms"]):
        cells = ["%g ms" % budget]
        for report in scene_reports:
            if report["scene"]["skip"]:
                cells.append("skipped")
            else:
                cells.append(pick_summary(report["budget_picks"][index]))
        rows.append(cells)
    return rows


HTML_STYLE = """
body { font-family: Helvetica, Arial, sans-serif; margin: 24px; color: #222; max-width: 1200px; }
table { border-collapse: collapse; margin: 8px 0 20px; }
td, th { border: 1px solid #ccc; padding: 4px 8px; font-size: 13px; vertical-align: top; }
th { background: #f3f3f3; }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
table.thumbs td { text-align: center; font-size: 11px; }
table.thumbs img { width: %dpx; image-rendering: pixelated; display: block; margin: 2px auto; }
.plots svg { margin: 6px 0; max-width: 100%%; height: auto; }
"""


def inline_svg(path):
    text = Path(path).read_text(encoding="utf-8")
    return text[text.index("<svg"):]


def html_table(head, rows, numeric_from=None):
    """A table of escaped text; cells from column numeric_from on are right-aligned numbers."""
    esc = html.escape
    parts = ["<table><tr>%s</tr>" % "".join("<th>%s</th>" % esc(h) for h in head)]
    for cells in rows:
        parts.append("<tr>%s</tr>" % "".join(
            '<td%s>%s</td>' % (' class="num"' if numeric_from is not None and i >= numeric_from else "", esc(c))
            for i, c in enumerate(cells)))
    parts.append("</table>")
    return "".join(parts)


def html_report(out, header, scene_reports, thumbnail_width):
    esc = html.escape
    threshold = header["jnd_threshold"]
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8"><title>narval: speed versus error</title>',
             "<style>%s</style></head><body>" % (HTML_STYLE % thumbnail_width),
             "<h1>narval: speed versus error</h1>",
             "<p>%s</p>" % esc(run_sentence(header)).replace("`", ""),
             "<ul>%s</ul>" % "".join("<li>%s</li>" % esc(line).replace("`", "").replace("*", "")
                                     for line in method_lines(header)),
             html_table(["method", "algorithm", "fixed settings", "sweeps"], methods_table_rows(header))]
    for report in scene_reports:
        scene = report["scene"]
        parts.append("<h2>%s</h2>" % esc(scene["name"]))
        if scene["skip"]:
            parts.append("<p>Skipped: %s.</p>" % esc(scene["skip"]))
            continue
        reference = report["reference"]
        parts.append("<p><code>%s</code>. %s</p>" % (esc(scene["path"]), esc(reference_sentence(scene, reference))))
        parts.append("<p>%s</p>" % esc(base_sentence(report["bases"])))
        parts.append("<ul>%s</ul>" % "".join("<li>%s</li>" % esc(line) for line in report["summary"]))
        parts.append("<h3>Budget picks</h3>")
        parts.append(html_table(PICK_COLUMNS + ["meets (JND76%% ≤ %g%%)" % threshold],
                                [["%g ms" % pick["budget_ms"]] + pick_cells(pick)
                                 for pick in report["budget_picks"]], numeric_from=2))
        parts.append('<div class="plots">%s%s</div>' % (inline_svg(out / report["plots"]["jnd"]),
                                                      inline_svg(out / report["plots"]["de"])))
        parts.append("<h3>Results</h3>")
        parts.append(html_table(
            ["method", "parameter", "value", "time", "build s", "mean ΔE76", "JND76%", "mean ΔE2000", "JND2000%"],
            [[row["method"], row["parameter"], value_text(row), time_text(row), build_text(row["build_seconds"]),
              "%.3f" % row["mean_dE76"], "%.2f" % row["jnd76_pct"], "%.3f" % row["mean_dE2000"],
              "%.2f" % row["jnd2000_pct"]] for row in report["rows"]], numeric_from=2))
        parts.append("<h3>Thumbnails</h3>")
        parts.append('<table class="thumbs"><tr><th>reference</th><td><img src="%s/%s" alt="reference">pathtrace %d spp</td></tr>' % (
            esc(scene["name"]), esc(reference["png"]), reference["spp"]))
        for method, parameter, group in sweep_groups(report["rows"]):
            cells = "".join('<td><img src="%s" alt="%s">%s=%s<br>%s</td>' % (
                esc(r["image"]), esc(full_label(r)), esc(parameter), format_value(r["value"]), esc(cell_caption(r)))
                for r in group)
            parts.append("<tr><th>%s<br>%s</th>%s</tr>" % (esc(method), esc(parameter), cells))
        parts.append("</table>")
    parts.append("<h2>Budget picks: budget × scene</h2>")
    parts.append("<p>The real-time configuration with the lowest JND76%% within each frame budget (ms per frame, "
                 "JND76%%, and whether it meets JND %g%%).</p>" % threshold)
    parts.append(html_table(["budget"] + [r["scene"]["name"] for r in scene_reports],
                            cross_scene_rows(header, scene_reports)))
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def print_budget_picks(header, scene_reports):
    """The budget picks of every scene as a plain-text table on stdout."""
    threshold = header["jnd_threshold"]
    head = ["scene"] + PICK_COLUMNS + ["meets (JND76%% ≤ %g%%)" % threshold]
    rows = []
    for report in scene_reports:
        if report["scene"]["skip"]:
            rows.append([report["scene"]["name"], "-", "skipped: %s" % report["scene"]["skip"]] + [""] * 5)
            continue
        for pick in report["budget_picks"]:
            rows.append([report["scene"]["name"], "%g ms" % pick["budget_ms"]] + pick_cells(pick))
    # A row without a pick (its reason in the third cell, the rest empty) does not widen that column.
    widths = [max(len(r[i]) for r in rows + [head] if i != 2 or any(r[3:])) for i in range(len(head))]
    print("Budget picks (real-time methods; lowest JND76% within the frame budget; build not in the frame time):")
    for cells in [head] + rows:
        print("  " + "  ".join(c.ljust(w) if i < 3 else c.rjust(w) for i, (c, w) in enumerate(zip(cells, widths))).rstrip())
    sys.stdout.flush()


# ---------------------------------------------------------------------------------------------
# Main
# ---------------------------------------------------------------------------------------------

def select_scenes(settings):
    """Loaded scenes; a default scene missing its file is skipped, a named one missing is an error."""
    scenes = []
    for path in settings.scenes:
        if not Path(path).is_file():
            if settings.default_scenes:
                scenes.append({"path": path, "name": Path(path).stem, "skip": "scene file %s is absent" % path})
                continue
            print("speed_vs_error.py: scene %s not found" % path, file=sys.stderr)
            sys.exit(2)
        try:
            scenes.append(load_scene(path, settings))
        except (OSError, ValueError, NarvalError) as e:
            print("speed_vs_error.py: cannot read scene %s: %s" % (path, e), file=sys.stderr)
            sys.exit(2)
    return scenes


def run(settings):
    started = time.monotonic()
    out = Path(settings.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    version = narval_version(settings)
    scenes = select_scenes(settings)
    scene_reports, all_rows, scene_entries = [], [], []
    device = None  # the name the renders report: the test renders', else the references'
    print("%s; %s; reference %d spp; %s" % (version, settings.resolution, settings.reference_spp,
                                          "references only" if settings.references_only
                                          else "methods " + ", ".join(settings.methods)), flush=True)
    for scene in scenes:
        print("[%s]" % scene["name"], flush=True)
        report = {"scene": scene}
        scene_reports.append(report)
        entry = {"name": scene["name"], "path": scene["path"], "skipped": scene["skip"]}
        scene_entries.append(entry)
        if scene["skip"]:
            print("  skipped: %s" % scene["skip"], flush=True)
            continue
        scene_out = out / scene["name"]
        scene_out.mkdir(parents=True, exist_ok=True)
        reference = ensure_reference(settings, scene, version, scene_out)
        if settings.references_only:
            continue
        bases = {m: base_parameters(settings, scene, m) for m in settings.methods}
        rows, render_device = measure_scene(settings, scene, reference, scene_out, bases)
        device = device or render_device or reference["device"]
        report.update(reference=reference, rows=rows, bases=bases, summary=summarise(rows, settings.jnd_threshold),
                      budget_picks=budget_picks(rows, settings.budgets_ms, settings.jnd_threshold),
                      plots=write_plots(out, scene["name"], rows, settings, reference))
        entry.update(display=scene["display"],
                     volumes=scene["volumes"],
                     reference={k: (str(v) if isinstance(v, Path) else v) for k, v in reference.items()},
                     base_parameters=bases, summary=report["summary"], budget_picks=report["budget_picks"],
                     plots=report["plots"])
        all_rows += rows
        for line in report["summary"]:
            print("  " + line, flush=True)
    if settings.references_only:
        return 0
    if not all_rows:
        print("speed_vs_error.py: every scene was skipped; nothing to report", file=sys.stderr)
        return 1
    header = {
        "generated": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "command": settings.command_line,
        "narval": version, "device": describe_device(settings, device), "quick": settings.quick,
        "resolution": settings.resolution, "reference_spp": settings.reference_spp, "base_spp": settings.base_spp,
        "frames": settings.frames, "jnd_threshold": settings.jnd_threshold, "budgets_ms": settings.budgets_ms,
        "methods": {m: {k: METHODS[m][k] for k in ("algorithm", "settings", "base")} for m in settings.methods},
        "sweeps": settings.sweeps,
        "wall_seconds": time.monotonic() - started,
    }
    write_results(out, header, scene_entries, all_rows)
    (out / "report.md").write_text(markdown_report(header, scene_reports), encoding="utf-8")
    thumbnail_width = max(96, min(240, int(settings.resolution.split("x")[0])))
    (out / "report.html").write_text(html_report(out, header, scene_reports, thumbnail_width), encoding="utf-8")
    print("wrote %s/{results.json,results.csv,report.md,report.html} and the plots in %.0f s" % (
        out, header["wall_seconds"]), flush=True)
    print_budget_picks(header, scene_reports)
    return 0


def main(argv):
    settings = parse_args(argv)
    try:
        return run(settings)
    except NarvalError as e:
        print("speed_vs_error.py: %s" % e, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("speed_vs_error.py: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
