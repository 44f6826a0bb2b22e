#!/usr/bin/env python3
"""Speed-versus-error report (issue 4, item 3): bench/speed_vs_error.py [SCENE.json ...] [options]

For each scene (default scenes/disney_cloud.json and scenes/listing_4_1.json; a scene whose volume
file is absent is skipped, saying why):
  1. a converged path-traced reference: `narval render SCENE --spp N --resolution R --seed 1`,
     cached under a hash of the scene file, its volume files (path, size, mtime), resolution, spp,
     bounces, the narval version and the reference format, so reruns skip it (the path tracer's pixels
     are pinned by its bitwise golden tests; --refresh-reference renders again after changing it);
  2. every algorithm across its quality parameters, one parameter at a time from the scene's
     defaults: pathtrace spp and bounces (seed 2, not the reference's), raymarch steps, shadowSteps
     and octaves, lobe lobePoints, depthFactor and shadowSteps. Time: the stats' `seconds` for
     pathtrace, the median of `--frames 3` (kernel time by profiling events) for raymarch and lobe;
     each algorithm gets one tiny warm-up render first (PoCL compiles again at the first launch);
  3. `narval compare REFERENCE TEST --json` under the scene's display transform (its exposure and
     tone mapping, as narval's PNG shows it) for mean ΔE76, JND76% (ΔE76 > 2.3), mean ΔE2000 and
     JND2000%.
Writes into --out (default build/speed_vs_error, git-ignored): results.json, results.csv, per scene
SCENE_time_vs_jnd.svg and SCENE_time_vs_de.svg (time on a log axis, one marker per algorithm, the
Pareto front as a step line), the renders and their PNGs under SCENE/, and report.md + report.html
(plots, summary, results table, labelled thumbnail grid).

Options: --resolution WxH (default 160x80), --reference-spp N (default 1024), --reference-bounces N
(default: the scene's bounces), --base-spp N (pathtrace spp while bounces vary, default 16),
--frames K (default 3), --device SPEC, --jnd-threshold P (default 5, for the summary),
--sweep ALGORITHM.PARAMETER=V1,V2,... (replace one sweep; repeatable), --refresh-reference,
--quick (smoke test: 48x24, reference 64 spp, two values per parameter, base spp 4),
--references-only (render or find the references, then stop).
Reference cache: $NARVAL_CACHE_DIR/speed_vs_error, else ~/.cache/narval/speed_vs_error;
NARVAL_CACHE_DIR=off renders the reference every time. Python 3 standard library only.
Not a test: nothing is asserted. Exit codes: 0 done, 1 a narval command failed, 2 bad usage,
130 interrupted.
"""

import argparse
import csv
import hashlib
import html
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
DEFAULT_SCENES = ["scenes/disney_cloud.json", "scenes/listing_4_1.json"]
ALGORITHMS = ["pathtrace", "raymarch", "lobe"]
REFERENCE_SEED = 1
REFERENCE_FORMAT = 2  # raise when the path tracer's output changes on purpose: cached references go stale
TEST_SEED = 2

# Quality parameters swept per algorithm, one at a time.
FULL_SWEEPS = {
    "pathtrace": {"spp": [1, 4, 16, 64, 256], "bounces": [1, 2, 4, 8]},
    "raymarch": {"steps": [15, 30, 60, 120], "shadowSteps": [5, 10, 20], "octaves": [1, 2, 4]},
    "lobe": {"lobePoints": [10, 30, 60], "depthFactor": [5, 20, 100], "shadowSteps": [25, 50, 100]},
}
QUICK_SWEEPS = {
    "pathtrace": {"spp": [1, 16], "bounces": [1, 4]},
    "raymarch": {"steps": [15, 60], "shadowSteps": [5, 20], "octaves": [1, 4]},
    "lobe": {"lobePoints": [10, 30], "depthFactor": [5, 100], "shadowSteps": [25, 100]},
}
# narval's defaults when the scene does not set renderer.raymarch / renderer.lobe (README).
REALTIME_DEFAULTS = {
    "raymarch": {"steps": 60, "shadowSteps": 10, "octaves": 1},
    "lobe": {"lobePoints": 30, "depthFactor": 20, "shadowSteps": 100},
}
# Marker shape and colour per algorithm, in plots and legends.
STYLE = {
    "pathtrace": ("circle", "#1f77b4"),
    "raymarch": ("square", "#d95f02"),
    "lobe": ("triangle", "#1b9e77"),
}


class NarvalError(Exception):
    """A narval command failed; the message carries the command and its stderr."""


# ---------------------------------------------------------------------------------------------
# Command line and settings
# ---------------------------------------------------------------------------------------------

def parse_args(argv):
    p = argparse.ArgumentParser(
        prog="speed_vs_error.py",
        description="Speed versus error of every narval algorithm against a converged path-traced "
                    "reference; writes results, SVG plots and a Markdown/HTML report.")
    p.add_argument("scenes", nargs="*", metavar="SCENE.json",
                   help="scenes (default: %s)" % " ".join(DEFAULT_SCENES))
    p.add_argument("--resolution", help="WIDTHxHEIGHT (default 160x80; --quick 48x24)")
    p.add_argument("--reference-spp", type=int, help="reference samples per pixel (default 1024; --quick 64)")
    p.add_argument("--reference-bounces", type=int, help="reference bounces (default: the scene's)")
    p.add_argument("--base-spp", type=int, help="pathtrace spp while bounces vary (default 16; --quick 4)")
    p.add_argument("--frames", type=int, default=3, help="frames per real-time render; median taken (default 3)")
    p.add_argument("--device", help="narval --device for every render")
    p.add_argument("--jnd-threshold", type=float, default=5.0, help="JND76%% bound for the summary (default 5)")
    p.add_argument("--sweep", action="append", default=[], metavar="ALGORITHM.PARAMETER=V1,V2",
                   help="replace one sweep, e.g. pathtrace.spp=1,8,64 (repeatable)")
    p.add_argument("--out", help="output folder (default build/speed_vs_error)")
    p.add_argument("--narval", default=str(REPO / "build" / "narval"), help="narval binary (default build/narval)")
    p.add_argument("--refresh-reference", action="store_true", help="render the references again, ignoring the cache")
    p.add_argument("--quick", action="store_true", help="tiny configuration for smoke testing")
    p.add_argument("--references-only", action="store_true",
                   help="render (or find cached) the references and stop: nothing else is timed")
    args = p.parse_args(argv)

    if args.resolution is None:
        args.resolution = "48x24" if args.quick else "160x80"
    if not re.fullmatch(r"[1-9][0-9]*x[1-9][0-9]*", args.resolution):
        p.error("--resolution wants WIDTHxHEIGHT, got '%s'" % args.resolution)
    if args.reference_spp is None:
        args.reference_spp = 64 if args.quick else 1024
    if args.base_spp is None:
        args.base_spp = 4 if args.quick else 16
    for name in ("reference_spp", "base_spp", "frames"):
        if getattr(args, name) < 1:
            p.error("--%s wants a positive integer" % name.replace("_", "-"))
    if args.reference_bounces is not None and args.reference_bounces < 0:
        p.error("--reference-bounces wants a non-negative integer")
    if args.out is None:
        args.out = str(REPO / "build" / "speed_vs_error")
    if not args.scenes:
        args.scenes = [str(REPO / s) for s in DEFAULT_SCENES]
        args.default_scenes = True
    else:
        args.default_scenes = False
    try:
        args.sweeps = build_sweeps(args.quick, args.sweep)
    except ValueError as e:
        p.error(str(e))
    if not os.access(args.narval, os.X_OK):
        p.error("narval binary %s not found: build it (cmake --build build --target narval)" % args.narval)
    return args


def parse_number(text):
    """'16' -> 16, '2.5' -> 2.5; ValueError otherwise."""
    value = float(text)
    if not math.isfinite(value):
        raise ValueError("not a finite number: %s" % text)
    return int(value) if value == int(value) and "." not in text and "e" not in text.lower() else value


def build_sweeps(quick, overrides):
    sweeps = json.loads(json.dumps(QUICK_SWEEPS if quick else FULL_SWEEPS))  # a deep copy
    for item in overrides:
        m = re.fullmatch(r"(\w+)\.(\w+)=(.+)", item)
        if not m:
            raise ValueError("--sweep wants ALGORITHM.PARAMETER=V1,V2,..., got '%s'" % item)
        algorithm, parameter, values = m.groups()
        if algorithm not in sweeps or parameter not in sweeps[algorithm]:
            known = ", ".join("%s.%s" % (a, q) for a in sweeps for q in sweeps[a])
            raise ValueError("--sweep: unknown parameter %s.%s (known: %s)" % (algorithm, parameter, known))
        try:
            sweeps[algorithm][parameter] = [parse_number(v) for v in values.split(",")]
        except ValueError:
            raise ValueError("--sweep %s: expected comma-separated numbers" % item)
    return sweeps


def format_value(value):
    return str(value) if isinstance(value, int) else "%g" % value


# ---------------------------------------------------------------------------------------------
# Scenes
# ---------------------------------------------------------------------------------------------

def expand_environment(text):
    """${NAME} and ${NAME:-default} (nested), as narval's scene loader expands volume paths."""
    out = ""
    i = 0
    while i < len(text):
        if not text.startswith("${", i):
            out += text[i]
            i += 1
            continue
        depth, j = 1, i + 2
        while j < len(text) and depth > 0:
            if text.startswith("${", j):
                depth += 1
                j += 2
                continue
            if text[j] == "}":
                depth -= 1
            j += 1
        if depth:
            raise ValueError("unterminated ${ in '%s'" % text)
        body = text[i + 2:j - 1]
        m = re.match(r"[A-Za-z_][A-Za-z0-9_]*", body)
        if not m:
            raise ValueError("bad variable reference ${%s}" % body)
        name, rest = m.group(0), body[m.end():]
        if rest and not rest.startswith(":-"):
            raise ValueError("bad variable reference ${%s}" % body)
        if os.environ.get(name):
            out += os.environ[name]
        elif rest:
            out += expand_environment(rest[2:])
        else:
            raise ValueError("environment variable %s is not set" % name)
        i = j
    return out


def display_transform(renderer):
    """The scene's display (exposure, tone mapping) as `narval compare` options.

    narval's PNG applies renderer.exposure (default 0) and renderer.toneMapping (true = aces,
    false = none, or a name; default true), so ΔE is measured on what the PNG shows."""
    exposure = renderer.get("exposure", 0)
    tone = renderer.get("toneMapping", True)
    if tone is True:
        tone = "aces"
    elif tone is False:
        tone = "none"
    options = ["--tonemap", str(tone)]
    if exposure:
        options += ["--exposure", str(exposure)]
    return {"exposure": exposure, "tonemap": str(tone), "options": options}


def load_scene(path):
    """What the report needs from a scene file, or a 'skip' reason when it cannot be rendered."""
    scene = {"path": str(Path(path).resolve()), "name": Path(path).stem, "skip": None}
    with open(path, "rb") as f:
        scene["bytes"] = f.read()
    data = json.loads(scene["bytes"])
    renderer = data.get("renderer", {})
    scene["bounces"] = renderer.get("bounces", 3)
    scene["display"] = display_transform(renderer)
    scene["realtime_defaults"] = {
        algorithm: {k: renderer.get(algorithm, {}).get(k, v) for k, v in defaults.items()}
        for algorithm, defaults in REALTIME_DEFAULTS.items()
    }
    scene["volumes"] = []
    for material in data.get("materials", []):
        if material.get("type") != "volume" or "path" not in material:
            continue
        try:
            volume = Path(expand_environment(material["path"]))
        except ValueError as e:
            scene["skip"] = "volume path of material %s: %s" % (material.get("name"), e)
            continue
        if not volume.is_absolute():
            volume = Path(scene["path"]).parent / volume
        volume = Path(os.path.normpath(volume))
        if not volume.is_file():
            scene["skip"] = "volume file %s is absent (set NARVAL_DATA_DIR)" % volume
            continue
        stat = volume.stat()
        scene["volumes"].append({"path": str(volume), "size": stat.st_size, "mtime_ns": stat.st_mtime_ns})
    return scene


# ---------------------------------------------------------------------------------------------
# Running narval
# ---------------------------------------------------------------------------------------------

def run_narval(settings, arguments):
    """Runs narval with the arguments; returns stdout; raises NarvalError with stderr on failure."""
    command = [settings.narval] + [str(a) for a in arguments]
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if result.returncode != 0:
        raise NarvalError("%s (exit %d): %s" % (" ".join(command), result.returncode, result.stderr.strip()))
    return result.stdout


def narval_version(settings):
    """The version string. Not the binary's hash: every commit rebuilds it, and a converged reference
    costs tens of minutes on 2 cores; the path tracer's pixels are pinned by its golden tests."""
    return run_narval(settings, ["--version"]).strip()


def device_options(settings):
    return ["--device", settings.device] if settings.device else []


def warm_up(settings, scene, algorithm):
    """One tiny render per algorithm, thrown away: PoCL compiles again at a kernel's first launch."""
    with tempfile.TemporaryDirectory(prefix="speed_vs_error_") as scratch:
        run_narval(settings, ["render", scene["path"], "-o", Path(scratch) / "warm_up.exr", "--algorithm",
                              algorithm, "--spp", 1, "--resolution", "16x8"] + device_options(settings))


# ---------------------------------------------------------------------------------------------
# Reference (cached)
# ---------------------------------------------------------------------------------------------

def cache_root():
    """$NARVAL_CACHE_DIR/speed_vs_error, else ~/.cache/narval/speed_vs_error; None for 'off'."""
    base = os.environ.get("NARVAL_CACHE_DIR")
    if base == "off":
        return None
    if not base:
        base = str(Path.home() / ".cache" / "narval")
    return Path(base) / "speed_vs_error"


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
    """Renders the reference into folder/reference.exr (+ .png, stats.json); returns its stats."""
    folder.mkdir(parents=True, exist_ok=True)
    run_narval(settings, ["render", scene["path"], "-o", folder / "reference.exr", "--algorithm", "pathtrace",
                          "--spp", settings.reference_spp, "--bounces", bounces, "--resolution", settings.resolution,
                          "--seed", REFERENCE_SEED, "--stats-json", folder / "stats.json"] + device_options(settings))
    with open(folder / "stats.json") as f:
        return json.load(f)


def ensure_reference(settings, scene, version, scene_out):
    """The reference for this scene in scene_out (reference.exr/.png), from the cache when possible."""
    bounces = settings.reference_bounces if settings.reference_bounces is not None else scene["bounces"]
    key, description = reference_key(scene, settings, bounces, version)
    root = cache_root()
    cached = root / key[:24] if root else None
    from_cache = bool(cached and (cached / "reference.exr").is_file() and (cached / "stats.json").is_file()
                      and not settings.refresh_reference)
    if from_cache:
        print("  reference: cached (%s)" % cached, flush=True)
    else:
        print("  reference: pathtrace %d spp, %d bounces, %s ..." % (settings.reference_spp, bounces,
                                                                    settings.resolution), flush=True)
        if cached:
            staging = root / (key[:24] + ".partial")
            shutil.rmtree(staging, ignore_errors=True)
            render_reference(settings, scene, bounces, staging)
            with open(staging / "key.json", "w") as f:
                json.dump(description, f, indent=2, sort_keys=True)
            shutil.rmtree(cached, ignore_errors=True)
            staging.rename(cached)
        else:
            render_reference(settings, scene, bounces, scene_out / "reference_render")
            cached = scene_out / "reference_render"
    with open(cached / "stats.json") as f:
        stats = json.load(f)
    for name in ("reference.exr", "reference.png"):
        shutil.copyfile(cached / name, scene_out / name)
    if not from_cache:
        print("  reference: %.1f s" % stats["seconds"], flush=True)
    return {"exr": scene_out / "reference.exr", "png": "reference.png", "spp": settings.reference_spp,
            "bounces": bounces, "seed": REFERENCE_SEED, "seconds": stats["seconds"], "device": stats["device"],
            "cached": from_cache, "key": key, "cache_folder": str(cached)}


# ---------------------------------------------------------------------------------------------
# Configurations
# ---------------------------------------------------------------------------------------------

def default_parameters(scene, settings):
    """Per algorithm, the values the parameters keep while another one varies."""
    defaults = {"pathtrace": {"spp": settings.base_spp, "bounces": scene["bounces"]}}
    defaults.update(scene["realtime_defaults"])
    return defaults


def configuration_id(algorithm, parameters):
    """File-name-safe identity of one effective parameter set, e.g. raymarch_octaves1_shadowSteps10_steps60."""
    return algorithm + "_" + "_".join("%s%s" % (k, format_value(v)) for k, v in sorted(parameters.items()))


def render_arguments(algorithm, parameters):
    """narval render options that set the parameters."""
    if algorithm == "pathtrace":
        return ["--spp", parameters["spp"], "--bounces", parameters["bounces"]]
    options = []
    for name, value in sorted(parameters.items()):
        options += ["--set", "renderer.%s.%s=%s" % (algorithm, name, format_value(value))]
    return options


def build_configurations(scene, settings):
    """One entry per (algorithm, parameter, value); entries with equal parameters share one render."""
    defaults = default_parameters(scene, settings)
    configurations = []
    for algorithm in ALGORITHMS:
        for parameter, values in settings.sweeps[algorithm].items():
            for value in values:
                parameters = dict(defaults[algorithm])
                parameters[parameter] = value
                if algorithm == "pathtrace" and parameter == "spp":
                    parameters["bounces"] = scene["bounces"]
                configurations.append({
                    "algorithm": algorithm,
                    "parameter": parameter,
                    "value": value,
                    "parameters": parameters,
                    "id": configuration_id(algorithm, parameters),
                    "is_default": parameters == defaults[algorithm],
                })
    return configurations


def render_configuration(settings, scene, configuration, renders):
    """Renders one configuration into renders/ID.exr (+ .png); returns its time in seconds."""
    algorithm = configuration["algorithm"]
    exr = renders / (configuration["id"] + ".exr")
    stats_path = renders / (configuration["id"] + ".json")
    arguments = ["render", scene["path"], "-o", exr, "--algorithm", algorithm, "--resolution", settings.resolution,
                 "--seed", TEST_SEED, "--stats-json", stats_path] + device_options(settings)
    arguments += render_arguments(algorithm, configuration["parameters"])
    if algorithm != "pathtrace":
        arguments += ["--frames", settings.frames]
    run_narval(settings, arguments)
    with open(stats_path) as f:
        stats = json.load(f)
    if algorithm == "pathtrace":
        return stats["seconds"]
    return stats["ms_per_frame"]["median"] / 1000.0


def compare_images(settings, scene, reference_exr, test_exr):
    """narval compare under the scene's display transform; returns its JSON."""
    output = run_narval(settings, ["compare", reference_exr, test_exr, "--json"] + scene["display"]["options"])
    return json.loads(output)


def measure_scene(settings, scene, reference, scene_out):
    """Renders and compares every configuration; returns result rows (one per configuration entry)."""
    renders = scene_out / "renders"
    renders.mkdir(parents=True, exist_ok=True)
    measured = {}  # configuration id -> (seconds, comparison)
    rows = []
    warmed = set()
    for configuration in build_configurations(scene, settings):
        algorithm = configuration["algorithm"]
        if algorithm not in warmed:
            warm_up(settings, scene, algorithm)
            warmed.add(algorithm)
        if configuration["id"] not in measured:
            seconds = render_configuration(settings, scene, configuration, renders)
            comparison = compare_images(settings, scene, reference["exr"], renders / (configuration["id"] + ".exr"))
            measured[configuration["id"]] = (seconds, comparison)
            note = ""
        else:
            note = " (same render as above)"
        seconds, comparison = measured[configuration["id"]]
        row = {
            "scene": scene["name"],
            "algorithm": algorithm,
            "parameter": configuration["parameter"],
            "value": configuration["value"],
            "seconds": seconds,
            "mean_dE76": comparison["mean_dE76"],
            "jnd76_pct": comparison["jnd76_pct"],
            "mean_dE2000": comparison["mean_dE2000"],
            "jnd2000_pct": comparison["jnd2000_pct"],
            "p95_dE76": comparison["p95_dE76"],
            "configuration": configuration["id"],
            "parameters": configuration["parameters"],
            "is_default": configuration["is_default"],
            "image": "%s/renders/%s.png" % (scene["name"], configuration["id"]),
        }
        rows.append(row)
        print("  %-9s %-11s %-5s %9.3f s  mean ΔE76 %6.2f  JND76 %6.2f%%%s" % (
            algorithm, configuration["parameter"], format_value(configuration["value"]), seconds,
            row["mean_dE76"], row["jnd76_pct"], note), flush=True)
    return rows


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
    """'spp=16', or 'defaults' for the configuration every sweep of the algorithm passes through."""
    if row["is_default"]:
        return "defaults"
    return "%s=%s" % (row["parameter"], format_value(row["value"]))


def full_label(row):
    return "%s %s" % (row["algorithm"], ", ".join("%s %s" % (k, format_value(v))
                                                   for k, v in sorted(row["parameters"].items())))


def summarise(rows, threshold):
    """Lines of plain text: per algorithm the fastest configuration under the JND bound and the most
    accurate one; the overall fastest under the bound; the Pareto front."""
    lines = []
    points = unique_configurations(rows)
    for algorithm in ALGORITHMS:
        mine = [p for p in points if p["algorithm"] == algorithm]
        if not mine:
            continue
        within = [p for p in mine if p["jnd76_pct"] <= threshold]
        most_accurate = min(mine, key=lambda p: (p["jnd76_pct"], p["seconds"]))
        accurate_text = "%s in %.3f s (JND %.2f%%, mean ΔE76 %.2f)" % (
            full_label(most_accurate), most_accurate["seconds"], most_accurate["jnd76_pct"],
            most_accurate["mean_dE76"])
        if within:
            fastest = min(within, key=lambda p: (p["seconds"], p["jnd76_pct"]))
            lines.append("%s: fastest under JND %g%%: %s in %.3f s (JND %.2f%%, mean ΔE76 %.2f); lowest JND: %s" % (
                algorithm, threshold, full_label(fastest), fastest["seconds"], fastest["jnd76_pct"],
                fastest["mean_dE76"], accurate_text))
        else:
            lines.append("%s: none under JND %g%%; lowest JND: %s" % (algorithm, threshold, accurate_text))
    within = [p for p in points if p["jnd76_pct"] <= threshold]
    if within:
        best = min(within, key=lambda p: (p["seconds"], p["jnd76_pct"]))
        lines.append("Fastest of all under JND %g%%: %s, %.3f s" % (threshold, full_label(best), best["seconds"]))
    else:
        lines.append("No configuration of any algorithm reaches JND %g%%." % threshold)
    front = pareto_front(points, "jnd76_pct")
    lines.append("Pareto front (time, JND76%%): %s" % "; ".join(
        "%s %s (%.3f s, %.2f%%)" % (p["algorithm"], short_label(p), p["seconds"], p["jnd76_pct"]) for p in front))
    return lines


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


def svg_marker(shape, colour, x, y, size=5.5):
    if shape == "circle":
        return '<circle cx="%.1f" cy="%.1f" r="%.1f" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
            x, y, size, colour)
    if shape == "square":
        return '<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
            x - size * 0.9, y - size * 0.9, size * 1.8, size * 1.8, colour)
    return '<polygon points="%.1f,%.1f %.1f,%.1f %.1f,%.1f" fill="%s" fill-opacity="0.85" stroke="white" stroke-width="0.8"/>' % (
        x, y - size * 1.15, x - size * 1.05, y + size * 0.8, x + size * 1.05, y + size * 0.8, colour)


def svg_scatter(title, points, error_key, error_label, threshold=None):
    """Time (log x, decade ticks) against an error (linear y from 0); markers per algorithm, the
    Pareto front as a step line, an optional dashed threshold. Returns the SVG text."""
    width, height = 760, 460
    left, right, top, bottom = 72, 190, 44, 56
    plot_w, plot_h = width - left - right, height - top - bottom
    times = [max(p["seconds"], 1e-6) for p in points]
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
    out.append('<text x="%.1f" y="%d" text-anchor="middle">time per image (s, log scale)</text>' % (
        left + plot_w / 2, height - 14))
    out.append('<text transform="translate(18 %.1f) rotate(-90)" text-anchor="middle">%s</text>' % (
        top + plot_h / 2, html.escape(error_label)))
    if threshold is not None:
        y = y_of(threshold)
        out.append('<line x1="%d" y1="%.1f" x2="%d" y2="%.1f" stroke="#c00" stroke-dasharray="6 4"/>' % (
            left, y, left + plot_w, y))
    # Pareto front: the lowest error reachable within a time, a step function.
    front = pareto_front(points, error_key)
    path = "M %.1f %.1f" % (x_of(front[0]["seconds"]), y_of(front[0][error_key]))
    for point in front[1:]:
        path += " H %.1f V %.1f" % (x_of(point["seconds"]), y_of(point[error_key]))
    path += " H %d" % (left + plot_w)
    out.append('<path d="%s" fill="none" stroke="#444" stroke-width="1.6" stroke-dasharray="5 3"/>' % path)
    # Markers, with the full configuration as a tooltip; Pareto points labelled.
    for point in points:
        shape, colour = STYLE[point["algorithm"]]
        x, y = x_of(point["seconds"]), y_of(point[error_key])
        tip = "%s: %.3f s, %s %.3f" % (full_label(point), point["seconds"], error_label, point[error_key])
        out.append('<g><title>%s</title>%s</g>' % (html.escape(tip), svg_marker(shape, colour, x, y)))
    # Labels alternate above and below the step line so that neighbours overlap less.
    for index, point in enumerate(front):
        x, y = x_of(point["seconds"]), y_of(point[error_key])
        dy = -8 if index % 2 == 0 else 16
        out.append('<text x="%.1f" y="%.1f" font-size="10" fill="%s">%s</text>' % (
            x + 6, y + dy, STYLE[point["algorithm"]][1], html.escape(short_label(point))))
    # Legend.
    lx, ly = left + plot_w + 18, top + 10
    for algorithm in ALGORITHMS:
        if not any(p["algorithm"] == algorithm for p in points):
            continue
        shape, colour = STYLE[algorithm]
        out.append(svg_marker(shape, colour, lx + 6, ly))
        out.append('<text x="%d" y="%d">%s</text>' % (lx + 18, ly + 4, algorithm))
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
                           "pixels over 1 JND (ΔE76 > 2.3), %", settings.jnd_threshold),
        "de": svg_scatter(subtitle + ": time vs mean ΔE", points, "mean_dE76", "mean ΔE76"),
    }
    names = {}
    for kind, text in plots.items():
        names[kind] = "%s_time_vs_%s.svg" % (scene_name, kind)
        (out / names[kind]).write_text(text, encoding="utf-8")
    return names


# ---------------------------------------------------------------------------------------------
# Results files
# ---------------------------------------------------------------------------------------------

CSV_COLUMNS = ["scene", "algorithm", "parameter", "value", "seconds", "mean_dE76", "jnd76_pct",
               "mean_dE2000", "jnd2000_pct"]


def write_results(out, header, scenes, rows):
    with open(out / "results.json", "w") as f:
        json.dump({"run": header, "scenes": scenes, "results": rows}, f, indent=2)
        f.write("\n")
    with open(out / "results.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(CSV_COLUMNS)
        for row in rows:
            writer.writerow([row[c] for c in CSV_COLUMNS])


# ---------------------------------------------------------------------------------------------
# Reports
# ---------------------------------------------------------------------------------------------

def sweep_groups(rows):
    """[(algorithm, parameter, [rows in sweep order])] in the order measured."""
    groups = []
    for row in rows:
        if not groups or groups[-1][0] != row["algorithm"] or groups[-1][1] != row["parameter"]:
            groups.append((row["algorithm"], row["parameter"], []))
        groups[-1][2].append(row)
    return groups


def cell_caption(row):
    return "%.3f s · JND %.1f%% · ΔE %.2f" % (row["seconds"], row["jnd76_pct"], row["mean_dE76"])


def reference_sentence(scene, reference):
    how = "from the cache" if reference["cached"] else "rendered in %.1f s" % reference["seconds"]
    return ("Reference: pathtrace, %d spp, %d bounces, seed %d (%s). ΔE under the scene's display: "
            "tone mapping %s, exposure %g." % (reference["spp"], reference["bounces"], reference["seed"], how,
                                               scene["display"]["tonemap"], scene["display"]["exposure"]))


def method_lines(header):
    return [
        "Each algorithm is swept one quality parameter at a time from its defaults (the scene's, else "
        "narval's; pathtrace at %d spp while bounces vary) and compared with a converged path-traced "
        "reference by `narval compare` (CIELAB ΔE76, JND = ΔE76 > 2.3)." % header["base_spp"],
        "Time per image: `--stats-json` seconds for pathtrace (seed %d); the median of `--frames %d` "
        "(kernel time by profiling events) for raymarch and lobe, after one warm-up render per "
        "algorithm." % (TEST_SEED, header["frames"]),
        "Plots: one marker per distinct configuration (hover for its parameters); the dashed step line "
        "is the Pareto front (no other configuration is both faster and more accurate), labelled.",
    ]


def markdown_report(header, scene_reports):
    lines = ["# narval: speed versus error", "",
             "Generated %s by `bench/speed_vs_error.py%s` in %.0f s; %s on %s; %s; reference %d spp." % (
                 header["generated"], " --quick" if header["quick"] else "", header["wall_seconds"],
                 header["narval"], header["device"], header["resolution"], header["reference_spp"]), ""]
    lines += ["- " + line for line in method_lines(header)] + [""]
    for report in scene_reports:
        scene = report["scene"]
        lines += ["## %s" % scene["name"], ""]
        if scene["skip"]:
            lines += ["Skipped: %s." % scene["skip"], ""]
            continue
        reference = report["reference"]
        lines += ["`%s`. %s" % (scene["path"], reference_sentence(scene, reference)), ""]
        lines += ["- " + line for line in report["summary"]] + [""]
        lines += ["![time vs JND](%s)" % report["plots"]["jnd"], "", "![time vs mean ΔE](%s)" % report["plots"]["de"], ""]
        lines += ["| algorithm | parameter | value | seconds | mean ΔE76 | JND76% | mean ΔE2000 | JND2000% |",
                  "|---|---|---|---|---|---|---|---|"]
        for row in report["rows"]:
            lines.append("| %s | %s | %s | %.3f | %.3f | %.2f | %.3f | %.2f |" % (
                row["algorithm"], row["parameter"], format_value(row["value"]) + (" (default)" if row["is_default"] else ""),
                row["seconds"], row["mean_dE76"], row["jnd76_pct"], row["mean_dE2000"], row["jnd2000_pct"]))
        lines += ["", "### Thumbnails", "", "Reference: ![reference](%s/%s)" % (scene["name"], reference["png"]), ""]
        groups = sweep_groups(report["rows"])
        columns = max(len(g[2]) for g in groups)
        lines.append("| sweep |" + " |" * columns)
        lines.append("|---|" + "---|" * columns)
        for algorithm, parameter, group in groups:
            cells = ["%s=%s<br>![](%s)<br>%s" % (parameter, format_value(r["value"]), r["image"], cell_caption(r))
                     for r in group]
            cells += [""] * (columns - len(cells))
            lines.append("| %s %s | %s |" % (algorithm, parameter, " | ".join(cells)))
        lines.append("")
    return "\n".join(lines)


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


def html_report(out, header, scene_reports, thumbnail_width):
    esc = html.escape
    parts = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8"><title>narval: speed versus error</title>',
             "<style>%s</style></head><body>" % (HTML_STYLE % thumbnail_width),
             "<h1>narval: speed versus error</h1>",
             "<p>Generated %s by <code>bench/speed_vs_error.py%s</code> in %.0f s; %s on %s; %s; reference %d spp.</p>" % (
                 esc(header["generated"]), " --quick" if header["quick"] else "", header["wall_seconds"],
                 esc(header["narval"]), esc(header["device"]), esc(header["resolution"]), header["reference_spp"]),
             "<ul>%s</ul>" % "".join("<li>%s</li>" % esc(line).replace("`", "") for line in method_lines(header))]
    for report in scene_reports:
        scene = report["scene"]
        parts.append("<h2>%s</h2>" % esc(scene["name"]))
        if scene["skip"]:
            parts.append("<p>Skipped: %s.</p>" % esc(scene["skip"]))
            continue
        reference = report["reference"]
        parts.append("<p><code>%s</code>. %s</p>" % (esc(scene["path"]), esc(reference_sentence(scene, reference))))
        parts.append("<ul>%s</ul>" % "".join("<li>%s</li>" % esc(line) for line in report["summary"]))
        parts.append('<div class="plots">%s%s</div>' % (inline_svg(out / report["plots"]["jnd"]),
                                                      inline_svg(out / report["plots"]["de"])))
        parts.append("<table><tr><th>algorithm</th><th>parameter</th><th>value</th><th>seconds</th><th>mean ΔE76</th>"
                     "<th>JND76%</th><th>mean ΔE2000</th><th>JND2000%</th></tr>")
        for row in report["rows"]:
            parts.append('<tr><td>%s</td><td>%s</td><td class="num">%s</td><td class="num">%.3f</td>'
                         '<td class="num">%.3f</td><td class="num">%.2f</td><td class="num">%.3f</td>'
                         '<td class="num">%.2f</td></tr>' % (
                             row["algorithm"], row["parameter"],
                             format_value(row["value"]) + (" (default)" if row["is_default"] else ""),
                             row["seconds"], row["mean_dE76"], row["jnd76_pct"], row["mean_dE2000"], row["jnd2000_pct"]))
        parts.append("</table>")
        parts.append("<h3>Thumbnails</h3>")
        parts.append('<table class="thumbs"><tr><th>reference</th><td><img src="%s/%s" alt="reference">pathtrace %d spp</td></tr>' % (
            esc(scene["name"]), esc(reference["png"]), reference["spp"]))
        for algorithm, parameter, group in sweep_groups(report["rows"]):
            cells = "".join('<td><img src="%s" alt="%s">%s=%s<br>%s</td>' % (
                esc(r["image"]), esc(full_label(r)), esc(parameter), format_value(r["value"]), esc(cell_caption(r)))
                for r in group)
            parts.append("<tr><th>%s<br>%s</th>%s</tr>" % (esc(algorithm), esc(parameter), cells))
        parts.append("</table>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


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
            scenes.append(load_scene(path))
        except (OSError, ValueError) as e:
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
    device = "?"
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
        device = reference["device"]
        if settings.references_only:
            continue
        rows = measure_scene(settings, scene, reference, scene_out)
        report.update(reference=reference, rows=rows, summary=summarise(rows, settings.jnd_threshold),
                      plots=write_plots(out, scene["name"], rows, settings, reference))
        entry.update(display={k: scene["display"][k] for k in ("exposure", "tonemap")},
                     volumes=scene["volumes"],
                     reference={k: (str(v) if isinstance(v, Path) else v) for k, v in reference.items()},
                     summary=report["summary"], plots=report["plots"])
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
        "narval": version, "device": device, "quick": settings.quick, "resolution": settings.resolution,
        "reference_spp": settings.reference_spp, "base_spp": settings.base_spp, "frames": settings.frames,
        "jnd_threshold": settings.jnd_threshold, "sweeps": settings.sweeps,
        "wall_seconds": time.monotonic() - started,
    }
    write_results(out, header, scene_entries, all_rows)
    (out / "report.md").write_text(markdown_report(header, scene_reports), encoding="utf-8")
    thumbnail_width = max(96, min(240, int(settings.resolution.split("x")[0])))
    (out / "report.html").write_text(html_report(out, header, scene_reports, thumbnail_width), encoding="utf-8")
    print("wrote %s/{results.json,results.csv,report.md,report.html} and the plots in %.0f s" % (
        out, header["wall_seconds"]), flush=True)
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
