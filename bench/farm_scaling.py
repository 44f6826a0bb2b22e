#!/usr/bin/env python3
"""bench/farm_scaling.py: what splitting a path-traced render into farm tasks costs, on a one-node Slurm
cluster started here: wall times against a plain render, per-task fixed cost, merge. Details:
bench/README.md. Not a test."""
import atexit
import os
import re
import subprocess
import time

import scene_env as b

p = b.parser(__doc__, device=False)
b.options(p, scene="scenes/disney_cloud.json", resolution="1200x600", spp=16, tasks="1 2 4 8")
a = b.parse(p)
NUMBER = r"([\d.e+-]+)"


def slurm(command):
    subprocess.run(["bash", "tests/farm/slurm_cluster.sh", command, a.work / "cluster"], check=True,
                   stdout=subprocess.DEVNULL, stderr=None if command == "start" else subprocess.DEVNULL)


def measure():
    a.work.chmod(0o711)  # munged wants every folder above its socket traversable
    slurm("start")
    atexit.register(slurm, "stop")
    os.environ["SLURM_CONF"] = str(a.work / "cluster" / "etc" / "slurm.conf")
    size = ["--resolution", a.resolution, "--spp", a.spp]
    b.render(a, a.scene, "--resolution", a.resolution, "--spp", 1)  # the program into the cache
    start = time.monotonic()
    plain = b.render(a, a.scene, *size, out=a.work / "plain.exr")
    plain_seconds = time.monotonic() - start
    b.header("K", "total s", "over plain", "tasks' walls s", "fixed s per task (mean)", "merge s", "ΔE76 vs plain")
    b.row("plain render", "%.1f" % plain_seconds, "1.00", "", "", "", "")
    for k in map(int, a.tasks.split()):
        out = a.work / ("farm_%d.exr" % k)
        text = b.run_narval(a.narval, ["farm", a.scene, *size, "--tasks", k, "--scheduler", "slurm", "-o", out,
                                       "--submit"] + (["--threads", 1] if k > 1 else []))
        task = r"^task \d+ samples \[\d+, \d+\): %s s \(rendering %s s\)$" % (NUMBER, NUMBER)
        tasks = re.findall(task, text, re.M)
        walls = [float(wall) for wall, _ in tasks]
        fixed = [float(wall) - float(rendering) for wall, rendering in tasks]
        merge = float(re.search(r"^merge: %s s$" % NUMBER, text, re.M).group(1))
        total = float(re.search(r"%s s from submission to merge" % NUMBER, text).group(1))
        de = b.compare(a, a.work / "plain.exr", out)["mean_dE76"]
        b.row(k, "%.1f" % total, "%.2f" % (total / plain_seconds), "%.1f" % sum(walls),
              "%.2f" % (sum(fixed) / len(fixed)), "%.2f" % merge, de)
    cpu = next((line for line in b.run_narval(a.narval, ["devices"]).splitlines() if "cpu" in line.lower()), "")
    print("\n%s; %s, %d spp, %s; plain render %.3f Msamples/s" % (cpu, a.resolution, a.spp, a.scene,
                                                                  plain["samples_per_second"] / 1e6))


b.main(measure)
