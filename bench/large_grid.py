#!/usr/bin/env python3
"""bench/large_grid.py: large grids (issue 6, item 6): an N³ generated cloud rendered in each grid
storage: wall and kernel seconds, peak RSS, bricks and bytes on the device. Details: bench/README.md."""
import json
import os
import subprocess
import time
from pathlib import Path

import scene_env as b

p = b.parser(__doc__)
b.options(p, resolution=1024, seed=1, image="160x90", spp=4, frames=3, storages="auto bricks")
a = b.parse(p)


def measure(name, *args):
    """Runs narval ARGS; (wall s, peak RSS KiB (as GNU time reports it: wait4's ru_maxrss), stderr)."""
    start = time.monotonic()
    process = subprocess.Popen([a.narval, *map(str, args)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    err = process.stderr.read()
    _, status, usage = os.wait4(process.pid, 0)
    if os.waitstatus_to_exitcode(status):
        raise b.NarvalError("%s failed (exit %d): %s" % (name, os.waitstatus_to_exitcode(status), err.strip()))
    return time.monotonic() - start, usage.ru_maxrss, err


def run():
    vdb = a.work / ("cloud_%d.vdb" % a.resolution)
    steps = [("make-cloud", None, measure("make-cloud", "make-cloud", vdb, "--resolution", a.resolution,
                                          "--seed", a.seed))]
    scene = json.loads(Path("scenes/cloud.json").read_text())
    for m in scene["materials"]:
        if m.get("type") == "volume":
            m["path"] = str(vdb)
    (a.work / "scene.json").write_text(json.dumps(scene, indent=1))
    for storage in a.storages.split():
        for algorithm, count in (("pathtrace", ["--spp", a.spp]),
                                 ("raymarch", ["--frames", a.frames, "--set", b.MARCH])):
            name = "%s-%s" % (algorithm, storage)
            stats, exr = a.work / (name + ".json"), a.work / (name + ".exr")
            steps.append((name, stats, measure(name, "render", a.work / "scene.json", "-o", exr,
                                               "--algorithm", algorithm, "--resolution", a.image, *count,
                                               *(["--device", a.device] if a.device else []),
                                               "--set", "renderer.storage=" + storage, "--stats-json", stats)))
    print("cloud %d^3 (seed %d), file %.1f MiB; image %s, pathtrace %d spp, raymarch %d frames" % (
        a.resolution, a.seed, vdb.stat().st_size / 2 ** 20, a.image, a.spp, a.frames))
    print("".join("  %s: %s\n" % (name, line.strip()) for name, _, (_, _, err) in steps
                  for line in err.splitlines() if "warning" in line))
    b.header("step", "storage", "wall s", "kernel s", "peak RSS", "bricks occupied / total", "grid on device")
    for name, stats_path, (wall, rss, _) in steps:
        storage = kernel = bricks = grid = ""
        if stats_path:
            s = json.loads(stats_path.read_text())
            storage, kernel = s.get("storage", ""), "%.2f" % s.get("kernel_seconds", 0)
            if "ms_per_frame" in s:
                kernel += " (median frame %.0f ms)" % s["ms_per_frame"]["median"]
            if s.get("bricks") and s["bricks"].get("total"):
                occupied, total = s["bricks"]["occupied"], s["bricks"]["total"]
                bricks = "%d / %d (%.1f%%)" % (occupied, total, 100.0 * occupied / total)
            if "grid_bytes" in s:
                grid = "%.1f MiB" % (s["grid_bytes"] / 2 ** 20)
        b.row(name, storage, "%.1f" % wall, kernel, "%.2f GiB" % (rss / 2 ** 20), bricks, grid)


b.main(run)
