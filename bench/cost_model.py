#!/usr/bin/env python3
"""bench/cost_model.py: how render time grows with each factor (issue 6, item 5), one at a time around a
base configuration of the generated cloud: exponents of log t = a + b·log x and the path tracer's work
model. Details: bench/README.md. Not a test."""
import contextlib
import hashlib
import io
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

import scene_env as b

p = b.parser(__doc__)
p.add_argument("--quick", action="store_true")
p.add_argument("--reps", type=int, help="repetitions (default 3; --quick 1)")
b.options(p, out="build/cost_model", scene="scenes/cloud.json", algorithms="pathtrace raymarch")
a = b.parse(p)
out = Path(a.out)
BASE = {"pathtrace": ("160x80", 16), "raymarch": ("320x160", None)}
VALUES = {"pixels": ["80x40", "160x80", "320x160", "640x320"], "spp": [4, 8, 16, 32, 64],
          "bounces": [1, 2, 4, 8, 16, 32], "density": [0.25, 0.5, 1, 2, 4, 8], "grid": [64, 128, 256, 512],
          "steps": [15, 30, 60, 120, 240]}
if a.quick:  # a smoke run: a smaller base, three points per series
    BASE = {"pathtrace": ("80x40", 4), "raymarch": ("80x40", None)}
    VALUES = {k: v[:3] for k, v in VALUES.items()}
FACTORS = {"pathtrace": ["pixels", "spp", "bounces", "density", "density-global", "grid"],
           "raymarch": ["pixels", "steps", "density", "grid"]}
# Two-sided 95% quantiles of Student's t by degrees of freedom (between entries: the one below).
T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262, 10: 2.228,
        12: 2.179, 15: 2.131, 20: 2.086, 30: 2.042}


def series(algorithm, factor, meta):
    """[(x, options, start-up options (8x4 pixels, 1 spp))]: the base configuration with the factor varied."""
    resolution, spp = BASE[algorithm]
    m, density = meta["material"], meta["density"]
    points = []
    for v in VALUES[factor.replace("-global", "")]:
        res, opts = v if factor == "pixels" else resolution, []
        if factor.startswith("density"):
            opts = ["--set", "materials.%d.density=%r" % (m, v * density)]
            opts += ["--majorant", "global"] if factor == "density-global" else []
        elif factor == "grid":
            opts = ["--set", "materials.%d.path=%s" % (m, a.work / ("cloud_%d.vdb" % v))]
        if algorithm == "pathtrace":
            opts = ["--bounces", v if factor == "bounces" else meta["bounces"]] + opts
        else:
            steps = v if factor == "steps" else meta["steps"]
            opts = ["--set", b.MARCH, "--set", "renderer.raymarch.steps=%d" % steps] + opts
        w, h = map(int, res.split("x"))
        x = w * h if factor == "pixels" else v ** 3 if factor == "grid" else v
        count = v if factor == "spp" else spp
        points.append((x, ["--resolution", res] + (["--spp", count] if count else []) + opts,
                       ["--resolution", "8x4"] + (["--spp", 1] if count else []) + opts))
    return points


def run(raw, algorithm, factor, x, rep, opts, counters=False):
    """One render, appended to raw.json. rep 0: the counting run, -1 the warm-up, -2 the start-up run."""
    start, cpu = time.monotonic(), b.cpu_seconds()
    stats = b.render(a, a.scene, "--algorithm", algorithm, *opts, *(["--counters"] if counters else []))
    print(json.dumps({"algorithm": algorithm, "factor": factor, "x": x, "rep": rep, "counters": counters,
                      "wall": time.monotonic() - start, "cpu": b.cpu_seconds() - cpu,
                      "options": list(map(str, opts)), "stats": stats}), file=raw, flush=True)


def measure():
    binary = a.work / "narval"
    shutil.copy(a.narval, binary)
    meta = {"binary": "%s, md5 %s" % (a.narval, hashlib.md5(binary.read_bytes()).hexdigest()[:12]),
            "scene": a.scene, "quick": a.quick, "reps": a.reps or (1 if a.quick else 3), "cpus": os.cpu_count(),
            "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()), "loadavg_start": b.load_average(),
            "commit": subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                                     text=True).stdout.strip() or "unknown"}
    a.narval = str(binary)
    s = b.resolved_scene(a.narval, a.scene, [b.MARCH])
    volume = next(q["materialName"] for q in s["primitives"] if q["type"] == "volume")
    meta["material"] = next(i for i, m in enumerate(s["materials"]) if m["name"] == volume)
    meta["density"] = s["materials"][meta["material"]]["density"]
    meta["bounces"], meta["steps"] = s["renderer"]["bounces"], s["renderer"]["raymarch"]["steps"]
    meta["pathtrace_base"] = dict(zip(("resolution", "spp"), BASE["pathtrace"]), bounces=meta["bounces"])
    meta["raymarch_base"] = {"resolution": BASE["raymarch"][0], "steps": meta["steps"]}
    start = time.monotonic()
    for g in VALUES["grid"]:
        b.run_narval(a.narval, ["make-cloud", a.work / ("cloud_%d.vdb" % g), "--resolution", g])
    meta["cloud_generation_seconds"] = time.monotonic() - start
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "raw.json", "w") as raw:
        for algorithm in a.algorithms.split():
            for factor in FACTORS[algorithm]:
                points = series(algorithm, factor, meta)
                print("  %s %s (%d points; load %s)" % (algorithm, factor, len(points), b.load_average()),
                      file=sys.stderr)
                for rep in ([0] if algorithm == "pathtrace" else []) + [-2, -1] + list(range(1, meta["reps"] + 1)):
                    for x, opts, startup in points[:1] if rep == -1 else points:
                        run(raw, algorithm, factor, x, rep, startup if rep == -2 else opts, counters=rep == 0)
    meta.update(seconds=time.monotonic() - start, loadavg_end=b.load_average())
    (out / "meta.json").write_text(json.dumps(meta, indent=1))
    report()


def fit(xs, ys):
    """log y = a + b log x: {b, lo, hi (None when n < 3), r2}."""
    us, vs = zip(*[(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0])
    slope, intercept = statistics.linear_regression(us, vs)
    n, ssr = len(us), sum((v - intercept - slope * u) ** 2 for u, v in zip(us, vs))
    r2 = statistics.correlation(us, vs) ** 2 if len(set(vs)) > 1 else 1.0
    result = {"b": slope, "lo": None, "hi": None, "r2": r2}
    if n > 2:
        t = T975[max(d for d in T975 if d <= n - 2)] if n - 2 <= 30 else 1.96
        half = t * math.sqrt(ssr / (n - 2) / ((n - 1) * statistics.variance(us)))
        result.update(lo=slope - half, hi=slope + half)
    return result


def fitted(f):
    return "%.3f" % f["b"] + (" [%.3f, %.3f]" % (f["lo"], f["hi"]) if f["lo"] is not None else "")


def work_model(points, metric):
    """t ≈ c1·samples + c2·real collisions + c3·density lookups, least squares on relative error."""
    rows = [([q["samples"], q["cnt"]["real_total"], q["cnt"]["lookups_total"]], q[metric]) for q in points]
    ata = [[sum(r[i] * r[j] / t ** 2 for r, t in rows) for j in range(3)] for i in range(3)]
    atb = [sum(r[i] / t for r, t in rows) for i in range(3)]
    for c in range(3):  # Gaussian elimination
        for r in range(3):
            if r != c:
                f = ata[r][c] / ata[c][c]
                ata[r] = [x - f * y for x, y in zip(ata[r], ata[c])]
                atb[r] -= f * atb[c]
    return [atb[i] / ata[i][i] for i in range(3)]


def load_series():
    """{(algorithm, factor): [point]}, each point with the medians of its timed repetitions."""
    groups = {}
    for line in open(out / "raw.json"):
        r = json.loads(line)
        s = r["stats"]
        q = groups.setdefault((r["algorithm"], r["factor"]), {}).setdefault(r["x"], {
            "x": r["x"], "k": [], "c": [], "cnt": None, "startup": None})
        samples = s["width"] * s["height"] * s["spp"]
        if r["counters"]:
            q["cnt"] = {"tentative": s["collisions_tentative"] / samples, "real": s["collisions_real"] / samples,
                        "lookups": s["density_lookups"] / samples, "lookups_total": s["density_lookups"],
                        "real_total": s["collisions_real"]}
        elif r["rep"] == -2:
            q["startup"] = r["cpu"]
        elif r["rep"] >= 1:
            q["samples"] = samples
            q["k"].append(s["kernel_seconds"])
            q["c"].append(r["cpu"])
    result = {}
    for key, by_x in groups.items():
        pts = sorted(by_x.values(), key=lambda q: q["x"])
        startup = statistics.median(q["startup"] for q in pts)
        for q in pts:  # the start-up depends on the grid only: elsewhere the series' median
            q.update(kernel=statistics.median(q["k"]), cpu=statistics.median(q["c"]))
            q["startup"] = q["startup"] if key[1] == "grid" else startup
            q["work"] = max(q["cpu"] - q["startup"], 1e-3)  # CPU of the rendering itself (floored at 1 ms)
        result[key] = pts
    return result


def fmt_x(factor, x):
    if factor == "pixels":
        return "{:,}".format(x)
    if factor == "grid":
        return "%d³" % round(x ** (1 / 3))
    return ("×%g" if factor.startswith("density") else "%g") % x


def report():
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        print_report(json.loads((out / "meta.json").read_text()), load_series())
    print(text.getvalue(), end="")
    (out / "report.md").write_text(text.getvalue())


def print_report(meta, series_):
    print("## Cost model%s\n" % (" (quick smoke run)" if meta["quick"] else ""))
    print("`bench/cost_model.py%s`, %s, commit %s, binary `%s`; %d cores; scene `%s` (material %d, density %g);"
          " base: path tracer %s, %s spp, %s bounces; ray marcher %s, %s steps; %d repetition(s), median; whole "
          "run %.0f s (clouds %.1f s); load average %s at start, %s at end.\n" % (
              " --quick" if meta["quick"] else "", meta["date"], meta["commit"], meta["binary"], meta["cpus"],
              meta["scene"], meta["material"], meta["density"], *meta["pathtrace_base"].values(),
              *meta["raymarch_base"].values(), meta["reps"], meta["seconds"], meta["cloud_generation_seconds"],
              meta["loadavg_start"], meta["loadavg_end"]))
    b.header("algorithm", "factor", "range", "n", "b (kernel s) [95% CI]", "R²", "b (CPU − start-up) [95% CI]",
             "R² (CPU)")
    for (algorithm, factor), pts in series_.items():
        xs = [q["x"] for q in pts]
        fk, fc = fit(xs, [q["kernel"] for q in pts]), fit(xs, [q["work"] for q in pts])
        b.row(algorithm, factor, "%s – %s" % (fmt_x(factor, xs[0]), fmt_x(factor, xs[-1])), len(pts), fitted(fk),
              "%.4f" % fk["r2"], fitted(fc), "%.4f" % fc["r2"])
    print("\nPath-tracer work per sample (`--counters`), exponents of the same fit; CPU ns per lookup:\n")
    b.header("factor", "tentative/sample b", "real/sample b", "lookups/sample b", "CPU ns per lookup (first → last)")
    for (algorithm, factor), pts in series_.items():
        if all(q["cnt"] for q in pts):
            xs, ns = [q["x"] for q in pts], [q["work"] / q["cnt"]["lookups_total"] * 1e9 for q in pts]
            b.row(factor, *[fitted(fit(xs, [q["cnt"][k] for q in pts])) for k in ("tentative", "real", "lookups")],
                  "%.1f → %.1f" % (ns[0], ns[-1]))
    model = [q for (algorithm, factor), pts in series_.items() if algorithm == "pathtrace"
             and factor in ("pixels", "spp", "bounces", "density") for q in pts if q["cnt"]]
    for metric, what in (("work", "CPU time less start-up"), ("kernel", "kernel time")):
        if len(model) <= 3:
            break
        c = work_model(model, metric)
        predict = lambda q: (c[0] * q["samples"] + c[1] * q["cnt"]["real_total"]  # noqa: E731
                             + c[2] * q["cnt"]["lookups_total"])
        errors = [q[metric] / predict(q) - 1 for q in model]
        print("\nWork model of the path tracer's %s on %d points: **t ≈ %.0f ns × samples + %.0f ns × real "
              "collisions + %.0f ns × density lookups** (rms %.0f%%, largest %.0f%%)." % (
                  what, len(model), c[0] * 1e9, c[1] * 1e9, c[2] * 1e9,
                  100 * math.sqrt(statistics.fmean(e * e for e in errors)), 100 * max(map(abs, errors))), end="")
        for factor in ("grid", "density-global"):
            sel = [q for q in series_.get(("pathtrace", factor), []) if q["cnt"]]
            if sel:
                print(" Measured/predicted, %s: %s." % (factor, ", ".join(
                    "%s %.2f" % (fmt_x(factor, q["x"]), q[metric] / predict(q)) for q in sel)), end="")
        print()


b.main(measure)
