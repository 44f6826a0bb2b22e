#!/usr/bin/env python3
"""bench/viewer_frames.py: is `narval view` interactive on the shipped scenes? Still and moving frame
times of scripted sessions under Xvfb (logs and stats in --out). Details: bench/README.md."""
import glob
import json
import shlex
import shutil
import subprocess
import sys
import time
from pathlib import Path

import scene_env as b

p = b.parser(__doc__)
b.options(p, scenes=" ".join(sorted(glob.glob("scenes/*.json", root_dir=b.REPO))), algorithms="raymarch lobe pathtrace")
p.add_argument("--target-ms", type=float, default=50)
p.add_argument("--out", default="build/viewer_frames")
a = b.parse(p)
if not shutil.which("xvfb-run"):
    p.error("xvfb-run missing (scripts/setup.sh installs it)")


def measure():
    cell = lambda size, t: "%s ×%d, %.1f / %.1f" % (  # noqa: E731
        size, t["frames"], t["kernel_ms_median"], t["frame_ms_median"])
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    orbit = out / "orbit.txt"
    orbit.write_text("frames 3\n" + "drag left 15 -3\nframes 1\n" * 8 + "frames 2\n")
    print("%s · `%s` · target %g ms\n" % (time.strftime("%Y-%m-%d", time.gmtime()),
                                        shlex.join(["bench/viewer_frames.py"] + sys.argv[1:]), a.target_ms))
    b.header("scene", "algorithm", "still: size, kernel / frame ms", "moving: size, kernel / frame ms",
             "present ms", "device")
    for scene in a.scenes.split():
        for algorithm in a.algorithms.split():
            name = "%s_%s" % (b.scene_name(scene), algorithm)
            command = ["xvfb-run", "-a", "-s", "-screen 0 1600x1200x24", a.narval, "view", scene, "--algorithm",
                       algorithm, "--set", "renderer.spp=4", "--script", orbit, "--target-ms", a.target_ms,
                       "--stats-json", out / (name + ".json")] + (["--device", a.device] if a.device else [])
            with open(out / (name + ".log"), "w") as f:
                failed = subprocess.run(list(map(str, command)), stdout=f, stderr=subprocess.STDOUT).returncode
            if failed:
                last = ((out / (name + ".log")).read_text().splitlines() or [""])[-1]
                b.row(b.scene_name(scene), algorithm, "failed: " + last, "", "", "")
                continue
            s = json.loads((out / (name + ".json")).read_text())
            sizes = sorted(s["per_resolution"].items(), key=lambda kv: -int(kv[0].split("x")[0]))
            b.row(b.scene_name(scene), algorithm, cell(*sizes[0]), ", ".join(cell(*kv) for kv in sizes[1:]) or
                  "(full size)", "%.2f" % s["present_ms_median"], s["device"])


b.main(measure)
