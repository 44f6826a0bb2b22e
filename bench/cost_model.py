#!/usr/bin/env python3
"""bench/cost_model.py DIR: fit and report the runs bench/cost_model.sh wrote to DIR.

Reads DIR/raw.json (one object per render: algorithm, factor, x, rep, counters, wall, stats; rep 0
is the counting run, rep -1 the warm-up, reps >= 1 the timed runs) and DIR/meta.json. Per point:
the median over the timed repetitions of kernel_seconds, seconds and the process wall time. Per
(algorithm, factor): least squares on the medians, log(time) = a + b·log(x), with the exponent b's
95% interval from the residuals (t distribution, n − 2 degrees of freedom) and R²; the same fit for
the path tracer's work counters per sample. Prints Markdown: the exponents, the work counters, the
raw medians. Standard library only.
"""
import json
import math
import statistics
import sys

# Two-sided 95% quantiles of Student's t, by degrees of freedom.
T975 = {1: 12.706, 2: 4.303, 3: 3.182, 4: 2.776, 5: 2.571, 6: 2.447, 7: 2.365, 8: 2.306, 9: 2.262,
        10: 2.228, 12: 2.179, 15: 2.131, 20: 2.086, 30: 2.042}


def t975(dof):
    if dof in T975:
        return T975[dof]
    below = [d for d in T975 if d < dof]
    return T975[max(below)] if dof <= 30 else 1.96


def fit(xs, ys):
    """log y = a + b log x. Returns dict(b, lo, hi, r2, n) (lo/hi None when n < 3)."""
    pts = [(math.log(x), math.log(y)) for x, y in zip(xs, ys) if x > 0 and y > 0]
    n = len(pts)
    if n < 2:
        return None
    mx = sum(p[0] for p in pts) / n
    my = sum(p[1] for p in pts) / n
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    syy = sum((p[1] - my) ** 2 for p in pts)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in pts)
    b = sxy / sxx
    a = my - b * mx
    ssr = sum((p[1] - a - b * p[0]) ** 2 for p in pts)
    r2 = 1 - ssr / syy if syy > 0 else 1.0
    lo = hi = None
    if n > 2:
        se = math.sqrt(ssr / (n - 2) / sxx)
        lo, hi = b - t975(n - 2) * se, b + t975(n - 2) * se
    return {"b": b, "a": a, "lo": lo, "hi": hi, "r2": r2, "n": n}


def local_slopes(xs, ys):
    return [math.log(ys[i + 1] / ys[i]) / math.log(xs[i + 1] / xs[i]) for i in range(len(xs) - 1)]


def solve(a, b):
    """Gaussian elimination with partial pivoting: a x = b for a small dense system."""
    n = len(b)
    m = [row[:] + [v] for row, v in zip(a, b)]
    for c in range(n):
        piv = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[piv] = m[piv], m[c]
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                m[r] = [x - f * y for x, y in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] for i in range(n)]


MODEL_TERMS = (("samples", "sample"), ("real", "real collision"), ("lookups", "density lookup"))


def term(p, name):
    return p["samples"] if name == "samples" else p["cnt"][name + "_total"]


def cost_model(points, metric):
    """kernel s ≈ Σ c_i·term_i (samples, real collisions, density lookups; no intercept), least
    squares on relative error (rows divided by the measured time). Returns the c_i or None."""
    rows = [([term(p, t) for t, _ in MODEL_TERMS], p[metric]) for p in points]
    m = len(MODEL_TERMS)
    if len(rows) <= m:
        return None
    ata = [[sum(r[0][i] * r[0][j] / r[1] ** 2 for r in rows) for j in range(m)] for i in range(m)]
    atb = [sum(r[0][i] / r[1] for r in rows) for i in range(m)]
    return solve(ata, atb)


def load(path):
    text = open(path).read()
    dec = json.JSONDecoder()
    i, out = 0, []
    while True:
        while i < len(text) and text[i].isspace():
            i += 1
        if i >= len(text):
            return out
        obj, i = dec.raw_decode(text, i)
        out.append(obj)


def fmt_x(factor, x):
    if factor == "pixels":
        return f"{int(x):,}"
    if factor == "grid":
        return f"{round(x ** (1 / 3))}³"
    if factor.startswith("density"):
        return f"×{x:g}"
    return f"{x:g}"


def fmt_b(f):
    return "—" if f is None else f"{f['b']:.3f}"


def fmt_ci(f):
    if f is None or f["lo"] is None:
        return "—"
    return f"[{f['lo']:.3f}, {f['hi']:.3f}]"


def shape(f):
    if f is None:
        return "?"
    lo, hi = (f["lo"], f["hi"]) if f["lo"] is not None else (f["b"] - 0.05, f["b"] + 0.05)
    if lo <= 0 <= hi and lo <= 1 <= hi:
        return "undetermined (interval spans 0 and 1)"
    if lo <= 0 <= hi or (abs(f["b"]) < 0.1 and hi - lo < 0.3):
        return "flat"
    if lo <= 1 <= hi:
        return "linear"
    if hi < 1:
        return "sub-linear"
    return "super-linear"


def follows(fk, fc, what):
    """Whether the time exponent fk agrees with the work exponent fc (within fk's interval)."""
    if fk["lo"] is not None and fk["lo"] <= fc["b"] <= fk["hi"]:
        return f"time follows the {what}"
    return f"time grows {'faster' if fk['b'] > fc['b'] else 'slower'} than the {what}"


def note(algo, factor, fk, pts, work, metric="kernel"):
    """A reading of one exponent from the data (shape) and the counters (why)."""
    s = shape(fk)
    sl = local_slopes([p["x"] for p in pts], [p[metric] for p in pts])
    unit = "CPU ns" if metric == "work" else "ns"
    slopes = "local " + ", ".join(f"{v:.2f}" for v in sl)
    tent = work.get("tentative") if work else None
    look = work.get("lookups") if work else None
    real = work.get("real") if work else None
    if factor in ("pixels", "spp"):
        what = "sample" if factor == "spp" else "pixel (same framing at every size)"
        if s == "linear":
            return f"linear as expected: the work is per {what}"
        if s == "sub-linear":
            return f"sub-linear: fixed per-launch cost weighs on the small end ({slopes})"
        return f"{s} ({slopes})"
    if factor == "steps":
        if s == "linear":
            return "linear as expected: steps × (1 + shadow steps) lookups per pixel"
        return f"{s}: steps × (1 + shadow steps) lookups, plus a fixed per-ray cost ({slopes})"
    if factor == "bounces":
        txt = f"{s} ({slopes})"
        if len(sl) >= 2 and sl[-1] < 0.5 * max(sl[0], 1e-9):
            txt += "; saturates"
        if real is not None:
            r = [p["cnt"]["real"] for p in pts]
            txt += (f"; real collisions/sample {r[0]:.2f} → {r[-1]:.2f} (∝ bounces^{real['b']:.2f}): paths leave "
                    f"the cloud or are absorbed before a high cap, so raising it costs little")
        return txt
    if factor.startswith("density"):
        if algo == "raymarch":
            if s == "flat":
                return "flat as expected: fixed steps per ray, density changes no loop count"
            return f"{s} ({slopes}): fixed steps per ray, so only per-lookup costs can move"
        txt = f"{s} ({slopes})"
        if tent is not None:
            ns = [p[metric] / p["cnt"]["lookups_total"] * 1e9 for p in (pts[0], pts[-1])]
            txt += (f"; tentative collisions/sample ∝ d^{tent['b']:.2f}, density lookups/sample ∝ "
                    f"d^{look['b']:.2f}: {follows(fk, look, 'lookups')} ({ns[0]:.0f} → {ns[1]:.0f} {unit} per lookup)")
            if factor == "density-global":
                txt += "; global majorant: no DDA, every tentative collision pays a lookup"
        return txt
    if factor == "grid":
        txt = f"{s} ({slopes})"
        mb = [4 * p["x"] / 2 ** 20 for p in (pts[0], pts[-1])]
        if look is not None:
            ns = [p[metric] / p["cnt"]["lookups_total"] * 1e9 for p in (pts[0], pts[-1])]
            txt += (f"; lookups/sample ∝ N³^{look['b']:.3f} (the same cloud, finer); {ns[0]:.0f} → {ns[1]:.0f} {unit} "
                    f"per lookup as the float grid grows {mb[0]:g} → {mb[1]:g} MB")
        else:
            txt += (f"; the same loop counts at every size (fixed steps), so any growth is the cost per lookup "
                    f"as the float grid grows {mb[0]:g} → {mb[1]:g} MB")
        return txt
    return s


def cpu_seconds(line):
    """`times` output for the children: "0m0.530s 0m0.010s" -> user + sys seconds."""
    total = 0.0
    for part in line.split():
        m, sec = part.rstrip("s").split("m")
        total += 60 * float(m) + float(sec)
    return total


def main():
    d = sys.argv[1]
    meta = json.load(open(f"{d}/meta.json"))
    runs = load(f"{d}/raw.json")
    first = runs[0]["stats"] if runs else {}

    # Group: (algo, factor) -> x -> point
    order = []
    series = {}
    for r in runs:
        key = (r["algorithm"], r["factor"])
        if key not in series:
            series[key] = {}
            order.append(key)
        st = r["stats"]
        p = series[key].setdefault(r["x"], {"x": r["x"], "k": [], "s": [], "w": [], "c": [], "cnt": None,
                                             "startup": None,
                                             "cells": st.get("majorant_cells")
                                             if st.get("majorant") != "global" else None})
        cpu = cpu_seconds(r["cpu_after"]) - cpu_seconds(r["cpu_before"]) if "cpu_after" in r else None
        if r["counters"]:
            samples = st["width"] * st["height"] * st["spp"]
            p["cnt"] = {"tentative": st["collisions_tentative"] / samples,
                        "real": st["collisions_real"] / samples,
                        "lookups": st["density_lookups"] / samples,
                        "lookups_total": st["density_lookups"],
                        "real_total": st["collisions_real"]}
        elif r["rep"] == -2:
            p["startup"] = cpu
        elif r["rep"] >= 1:
            p["samples"] = st["width"] * st["height"] * st["spp"]
            p["k"].append(st["kernel_seconds"])
            p["s"].append(st["seconds"])
            p["w"].append(r["wall"])
            if cpu is not None:
                p["c"].append(cpu)
    for key in order:
        pts = sorted(series[key].values(), key=lambda p: p["x"])
        # The start-up depends on the grid only: outside the grid series all points share it, so they
        # share the series' median start-up (one run each is noisy at the ±10 ms level).
        ups = [p["startup"] for p in pts if p["startup"] is not None]
        if key[1] != "grid" and len(ups) == len(pts):
            for p in pts:
                p["startup"] = statistics.median(ups)
        for p in pts:
            p["kernel"] = statistics.median(p["k"])
            p["seconds"] = statistics.median(p["s"])
            p["wall"] = statistics.median(p["w"])
            p["cpu"] = statistics.median(p["c"]) if p["c"] else None
            # CPU of the rendering itself: the run's CPU less the start-up run's (floored at 1 ms).
            p["work"] = max(p["cpu"] - p["startup"], 1e-3) if p["cpu"] is not None and p["startup"] is not None else None
        series[key] = pts
    have_cpu = all(p["work"] is not None for pts in series.values() for p in pts)
    metric = "work" if have_cpu else "kernel"

    pb, rb = meta["pathtrace_base"], meta["raymarch_base"]
    print(f"## Cost model (issue 6, item 5){' — quick smoke run' if meta['quick'] else ''}")
    print()
    print(f"`bench/cost_model.sh{' --quick' if meta['quick'] else ''}` ({meta['date']}, commit {meta['commit']} "
          f"with the working tree's edits, binary `{meta['binary']}`). Device: {first.get('device', '?')}, "
          f"{meta['cpus']} cores; grid storage `{first.get('storage', '?')}`, majorant "
          f"`{first.get('majorant', '?')}`. Scene `{meta['scene']}` (material {meta['material']}, density "
          f"{meta['density']:g}). Base: path tracer {pb['resolution']}, {pb['spp']} spp, {pb['bounces']} bounces, "
          f"generated 128³ cloud; ray marcher {rb['resolution']}, {rb['steps']} steps. One factor varied at a "
          f"time; grids by `narval make-cloud --resolution G` (default seed). Per point: warm-up first, then "
          f"{meta['reps']} repetition(s) interleaved across the series' points, median. Fit: "
          f"log t = a + b·log x on the medians, 95% interval of b from the residuals (t, n − 2 dof). "
          f"x: pixels = W·H, grid = voxels (N³; per side multiply b by 3). Time measures: `kernel_seconds` "
          f"(the launches' profiling time), the same on the fastest repetition, and the process's CPU time "
          f"(user + sys) less that of a start-up run at 8x4 pixels, 1 spp (per point for the grid series, the median over the series' points elsewhere): PoCL runs the "
          f"kernels on the process's own threads, so CPU time counts the work even when other processes "
          f"hold the cores, where kernel_seconds stretches with the load."
          + (" The notes read the CPU exponent." if have_cpu else ""))
    print(f"Whole run {meta['seconds']:.0f} s (clouds generated in {meta['cloud_generation_seconds']:.1f} s). "
          f"Load average (/proc/loadavg) at start `{meta['loadavg_start']}`, at end `{meta['loadavg_end']}`: "
          f"the machine was shared with other engineers' builds and tests, so absolute times are inflated "
          f"and noisy; the interleaving spreads that load over the points of each series.")
    print()
    print("| algorithm | factor | range | n | exponent b (kernel s) | 95% CI | R² | b (fastest rep.) [95% CI] "
          "| b (CPU − start-up) [95% CI] | R² (CPU) | b (seconds) | b (process wall) | note |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    works = {}
    for key in order:
        algo, factor = key
        pts = series[key]
        xs = [p["x"] for p in pts]
        fk = fit(xs, [p["kernel"] for p in pts])
        fm = fit(xs, [min(p["k"]) for p in pts])
        fc = fit(xs, [p["work"] for p in pts]) if have_cpu else None
        fs = fit(xs, [p["seconds"] for p in pts])
        fw = fit(xs, [p["wall"] for p in pts])
        work = None
        if all(p["cnt"] for p in pts):
            work = {k: fit(xs, [p["cnt"][k] for p in pts]) for k in ("tentative", "real", "lookups")}
            works[key] = work
        rng = f"{fmt_x(factor, xs[0])} – {fmt_x(factor, xs[-1])}"
        if factor.startswith("density"):
            rng += f" (density {xs[0] * meta['density']:g} – {xs[-1] * meta['density']:g})"
        cpu_cols = f"{fmt_b(fc)} {fmt_ci(fc)} | {fc['r2']:.4f}" if fc else "— | —"
        print(f"| {algo} | {factor} | {rng} | {len(pts)} | {fmt_b(fk)} | {fmt_ci(fk)} | {fk['r2']:.4f} | "
              f"{fmt_b(fm)} {fmt_ci(fm)} | {cpu_cols} | {fmt_b(fs)} | {fmt_b(fw)} | "
              f"{note(algo, factor, fc or fk, pts, work, metric)} |")
    print()

    unit = "CPU ns" if have_cpu else "ns"
    if works:
        print(f"Path-tracer work per sample (`--counters`, one deterministic run per point), exponents of the "
              f"same fit; {unit} per lookup from the timed runs' medians:")
        print()
        print(f"| factor | tentative/sample b [95% CI] | real/sample b [95% CI] | lookups/sample b [95% CI] | {unit} per lookup (first → last) |")
        print("|---|---|---|---|---|")
        for key, w in works.items():
            pts = series[key]
            ns = [p[metric] / p["cnt"]["lookups_total"] * 1e9 for p in pts]
            cells = " | ".join(f"{w[k]['b']:.3f} {fmt_ci(w[k])}" for k in ("tentative", "real", "lookups"))
            print(f"| {key[1]} | {cells} | {ns[0]:.1f} → {ns[-1]:.1f} |")
        print()

    model_pts = [p for key in order if key[0] == "pathtrace" and key[1] in ("pixels", "spp", "bounces", "density")
                 for p in series[key] if p["cnt"]]
    for m in (["work", "kernel"] if have_cpu else ["kernel"]):
        c = cost_model(model_pts, m)
        if not c:
            continue
        pred = lambda p: sum(ci * term(p, t) for ci, (t, _) in zip(c, MODEL_TERMS))
        errs = [p[m] / pred(p) - 1 for p in model_pts]
        rms = math.sqrt(sum(e * e for e in errs) / len(errs))
        terms = " + ".join(f"{ci * 1e9:.0f} ns × {what}s" for ci, (_, what) in zip(c, MODEL_TERMS))
        what = "CPU time (core-seconds, less start-up)" if m == "work" else "kernel time (wall, under this load)"
        print(f"Work model of the path tracer's {what}, grid majorant, fitted by relative least squares on the "
              f"{len(model_pts)} pixels/spp/bounces/density medians: **t ≈ {terms}** (rms deviation "
              f"{rms * 100:.0f}%, largest {max(abs(e) for e in errs) * 100:.0f}%).", end="")
        for f in ("grid", "density-global"):
            sel = [p for key in order if key == ("pathtrace", f) for p in series[key] if p["cnt"]]
            if sel:
                print(f" Measured/predicted on the {f} series: " + ", ".join(
                    f"{fmt_x(f, p['x'])} {p[m] / pred(p):.2f}" for p in sel) + ".", end="")
        print()
        print()

    print("Raw medians (kernel s, seconds, wall and CPU: median of the timed repetitions; min–max of kernel s "
          "beside it; start-up: CPU of the 8x4-pixel run):")
    print()
    print(f"| algorithm | factor | value | kernel s | kernel min–max | seconds | wall s | CPU s | start-up CPU s "
          f"| tentative/sample | real/sample | lookups/sample | {unit}/lookup | majorant cells |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for key in order:
        algo, factor = key
        for p in series[key]:
            c = p["cnt"]
            cnt = (f"{c['tentative']:.2f} | {c['real']:.2f} | {c['lookups']:.1f} | "
                   f"{p[metric] / c['lookups_total'] * 1e9:.1f}") if c else "— | — | — | —"
            val = fmt_x(factor, p["x"])
            if factor.startswith("density"):
                val += f" ({p['x'] * meta['density']:g})"
            cells = "x".join(str(v) for v in p["cells"]) if p["cells"] else "global"
            cpu = f"{p['cpu']:.3f} | {p['startup']:.3f}" if p["work"] is not None else "— | —"
            print(f"| {algo} | {factor} | {val} | {p['kernel']:.4f} | {min(p['k']):.4f}–{max(p['k']):.4f} | "
                  f"{p['seconds']:.4f} | {p['wall']:.3f} | {cpu} | {cnt} | {cells} |")
    print()
    print("Load average per series (1, 5, 15 min; before → after):")
    print()
    print("| algorithm | factor | before | after |")
    print("|---|---|---|---|")
    for l in meta["series_load"]:
        print(f"| {l['algorithm']} | {l['factor']} | {l['before']} | {l['after']} |")


if __name__ == "__main__":
    main()
