#!/usr/bin/env python3
"""bench/native_baseline.py [SCENE] [options]: the native baseline (issue 6, item 4; target: PoCL within
1.3x of native): PoCL's time against the same kernel code as native C++ on host threads, by kernel and
CPU time, and how far their images differ. Details: bench/README.md. Not a test."""
import json
import os
import statistics

import scene_env as b

p = b.parser(__doc__)
p.add_argument("scene", nargs="?")
p.add_argument("--resolution")
p.add_argument("--spp", type=int)
b.options(p, frames=6, reps=3)
p.add_argument("--threads", type=int)
p.add_argument("--algorithms", default="pathtrace raymarch")
p.add_argument("--set", action="append", default=[], help="PATH=VALUE, to both renderers (repeatable)")
a = b.parse(p)
binaries = {v: os.path.abspath(os.environ.get("NATIVE" + e, "build/narval-native" + e.lower().replace("_", "-")))
            for v, e in (("native", ""), ("march", "_MARCH"), ("tuned", "_TUNED"))}
if not os.access(binaries["native"], os.X_OK):
    p.error("missing %s: cmake --build build --target narval-native narval-native-march narval-native-tuned"
            % binaries["native"])
if a.frames < 2:
    p.error("--frames must be at least 2 (the first frame is excluded)")
variants = [v for v in binaries if os.access(binaries[v], os.X_OK)]
# The native build has no multiple-scattering cache: both draw the dissertation's march.
sets = [x for s in [b.MARCH] + a.set for x in ("--set", s)]


def run(program, scene, algorithm, resolution, spp, tag, *more):
    """One render; (seconds, PoCL wall seconds, CPU seconds, stats)."""
    options = ["--resolution", resolution] if resolution else []
    if algorithm != "pathtrace":
        options += ["--frames", a.frames]
    elif spp:
        options += ["--spp", spp]
    options += ["--algorithm", algorithm, "-o", a.work / (tag + ".exr"), "--stats-json", a.work / (tag + ".json")]
    before = b.cpu_seconds()
    if program == "pocl":
        b.run_narval(a.narval, ["render", scene] + options + sets + (["--device", a.device] if a.device else []))
    else:
        b.run_narval(binaries[program], [scene] + options + sets + list(more)
                     + (["--threads", a.threads] if a.threads else []))
    cpu = b.cpu_seconds() - before
    s = json.loads((a.work / (tag + ".json")).read_text())
    if program != "pocl":
        return s["seconds"], None, cpu, s
    wall = s["seconds"] if algorithm == "pathtrace" else s["ms_per_frame"]["wall"]["median"] / 1e3
    return b.seconds(s), wall, cpu, s


def measure_case(scene, algorithm, resolution, spp):
    tag = b.scene_name(scene) + "-" + algorithm
    # Warm-up. The PoCL run also says which majorant (pathtrace) and majorant grid the device driver
    # chose: narval-native is given the same, so both take the same random streams and do the same work.
    pocl = run("pocl", scene, algorithm, resolution, spp, tag + "-pocl")[3]
    cells = max(pocl.get("majorant_cells") or [0])
    more = (["--majorant-resolution", cells] if cells > 1 else []) + (
        ["--majorant", pocl["majorant"]] if algorithm == "pathtrace" else [])
    native = {v: run(v, scene, algorithm, resolution, spp, tag + "-" + v, *more)[3] for v in variants}["native"]
    if cells > 1 and native["majorant_cells"] != pocl["majorant_cells"]:
        print("warning: %s: PoCL and native majorant grids differ (%s vs %s): not the same work"
              % (tag, pocl["majorant_cells"], native["majorant_cells"]))
    # CPU time of the set-up (process start, scene and grid, OpenCL context, program cache, EXR).
    base_pocl = run("pocl", scene, algorithm, "1x1", spp, tag + "-pocl-base")[2]
    base_native = run("native", scene, algorithm, "1x1", spp, tag + "-native-base", *more)[2]
    runs = {v: [] for v in ["pocl"] + variants}
    for rep in range(a.reps):
        runs["pocl"].append(run("pocl", scene, algorithm, resolution, spp, tag + "-pocl"))
        for v in variants:  # the last repetition also compares with PoCL's image bit for bit
            check = ["--compare", a.work / (tag + "-pocl.exr")] if v == "native" and rep == a.reps - 1 else []
            runs[v].append(run(v, scene, algorithm, resolution, spp, tag + "-" + v, *more, *check))
    kernel, wall, cpu_pocl, _ = zip(*runs["pocl"])
    times = {v: [r[0] for r in runs[v]] for v in variants}
    cpu_native, compared = [r[2] for r in runs["native"]], runs["native"][-1][3]
    de = b.compare(a, a.work / (tag + "-pocl.exr"), a.work / (tag + "-native.exr"), *b.LINEAR)["mean_dE76"]
    m = statistics.median
    size = "%dx%d%s" % (pocl["width"], pocl["height"], ", %d spp" % pocl["spp"] if algorithm == "pathtrace" else "")
    cells = [scene, algorithm, size, "%.3f" % m(kernel), "%.3f" % m(wall), "%.3f" % m(times["native"]),
             "**%.2f**" % (m(kernel) / m(times["native"])), "%.2f" % (min(kernel) / min(times["native"])),
             "%.2f" % ((m(cpu_pocl) - base_pocl) / (m(cpu_native) - base_native))]
    cells += [x for v in variants[1:] for x in ("%.3f" % m(times[v]), "%.2f" % (m(kernel) / m(times[v])))]
    cells.append(", ".join("%.2f" % (x / y) for x, y in zip(kernel, times["native"])))
    b.row(*cells, "%.1f%%" % compared["compare"]["pixels_bitwise_identical_pct"], "%.2g" % de)


def measure():
    if not os.path.isfile("scenes/data/cloud_128.vdb"):
        b.run_narval(a.narval, ["make-cloud", "scenes/data/cloud_128.vdb"])
    cases = [(a.scene, a.resolution, a.spp)] if a.scene else [
        ("scenes/cloud.json", a.resolution or "320x180", a.spp or 16),
        ("scenes/listing_4_1.json", a.resolution or "240x120", a.spp or 16),
        ("bench/native/homogeneous_fog.json", a.resolution or "320x180", a.spp or 64)]
    print("load average (1, 5, 15 min) before: %s; %d cores" % (b.load_average(), os.cpu_count()))
    for v in ["pocl"] + variants:
        print("- %s: %s" % (v, run(v, cases[0][0], "pathtrace", "16x16", 1, "probe")[3]["device"]))
    print("%d alternating repetitions (PoCL, %s) after a warm-up of each." % (a.reps, ", ".join(variants)))
    print("pathtrace: whole render; real-time: median per frame of %d frames (first excluded).\n" % a.frames)
    others = [c % v for v in variants[1:] for c in ("%s s", "PoCL/%s")]
    b.header("scene", "algorithm", "size, spp", "PoCL kernel s", "PoCL wall s", "native s", "**PoCL/native**",
             "PoCL/native (min)", "PoCL/native CPU time", *others, "per-rep PoCL/native", "bitwise-equal pixels",
             "mean ΔE76")
    for scene, resolution, spp in cases:
        for algorithm in a.algorithms.split():
            measure_case(scene, algorithm, resolution, spp)
    print("\nload average after: %s" % b.load_average())


b.main(measure)
