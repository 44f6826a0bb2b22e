#!/usr/bin/env python3
"""bench/majorant.py: the majorant grid (issue 6, item 1) against the global majorant: collisions and
lookups per configuration, kernel time, the ray marcher by cells. Details: bench/README.md. Not a test."""
import statistics

import scene_env as b

p = b.parser(__doc__)
b.options(p, scenes="scenes/disney_cloud.json scenes/cloud.json", resolution="160x80", spp=16, reps=3,
          cells="8 16 32 64", frames=5)
a = b.parse(p)


def render(scene, config, *more):
    majorant = ["global"] if config == "global" else ["grid", "--majorant-resolution", config]
    return b.render(a, scene, "--resolution", a.resolution, "--spp", a.spp, "--majorant", *majorant, *more)


def measure_scene(scene):
    configs = ["global"] + a.cells.split()
    counted = {c: render(scene, c, "--counters") for c in configs}
    stats = counted["global"]
    print("## %s at %s, %d spp\ndevice: %s, grid storage: %s\n" % (scene, a.resolution, a.spp, stats["device"],
                                                                   stats.get("storage", "?")))
    times = b.alternate(a.reps, {c: lambda c=c: render(scene, c)["kernel_seconds"] for c in configs})
    b.header("majorant", "cells", "tentative per real", "vs global", "density lookups",
             "kernel s (median of %d)" % a.reps, "speed-up vs global", "per repetition")
    per_real = {c: s["collisions_tentative"] / max(1, s["collisions_real"]) for c, s in counted.items()}
    median = {c: statistics.median(t) for c, t in times.items()}
    for c in configs:
        cells = "(1)" if c == "global" else "x".join(str(v) for v in counted[c]["majorant_cells"])
        per = ", ".join("%.2f" % (g / x) for g, x in zip(times["global"], times[c]))
        b.row("global" if c == "global" else "grid " + c, cells, "%.2f" % per_real[c],
              "%.2fx" % (per_real["global"] / per_real[c]), "{:,}".format(counted[c]["density_lookups"]),
              "%.3f" % median[c], "%.2fx" % (median["global"] / median[c]), per)
    # raymarch: the same cells skip empty space.
    ms = [b.render(a, scene, "--algorithm", "raymarch", "--set", b.MARCH, "--resolution", a.resolution,
                   "--frames", a.frames, "--majorant-resolution", c)["ms_per_frame"]["median"] for c in a.cells.split()]
    print("\nraymarch ms/frame (median of %d) by cells: %s\n" % (
        a.frames, " ".join("%s: %.2f" % x for x in zip(a.cells.split(), ms))))


def measure():
    for scene in a.scenes.split():
        try:
            b.render(a, scene, "--resolution", "4x2", "--spp", 1)
        except b.NarvalError as e:
            print("## %s: skipped (%s)\n" % (scene, str(e).split(": ", 1)[-1].splitlines()[0]))
            continue
        measure_scene(scene)


b.main(measure)
