#!/usr/bin/env python3
"""bench/pathtrace_sampling.py: what each of the path tracer's sampling choices costs and buys.

For every scene: a converged reference (narval, every light sampled, no roulette, REF_SPP samples;
cached under --cache), then each configuration (renderer.pathtrace.lightSampling and
shadowRoulette, majorant resolution, ...) rendered --reps times at --spp samples with fresh seeds,
interleaved (config A, B, C, A, B, C, ...) so that load drifts hit all alike. Per configuration:
the median kernel seconds, the mean relMSE against the reference (`narval compare --json`), and
the efficiency 1 / (relMSE · seconds), the quantity an unbiased renderer's time at equal error is
inversely proportional to; reported relative to the first configuration. One more render per
configuration with --counters gives tentative and real collisions and density lookups per sample.

The reference's own noise adds relMSE_ref ≈ relMSE(first config) · spp / REF_SPP to every row
alike; the table shows relMSE with that estimate subtracted (and says so).

Usage: bench/pathtrace_sampling.py [--scenes a.json,b.json] [--resolution 160x120] [--spp 64]
       [--ref-spp 4096] [--reps 3] [--configs NAME=ARGS;NAME=ARGS] [--narval build/narval]
       [--cache build/bench-cache] [--json OUT.json]
Only the Python standard library; narval does the image arithmetic.
"""
import argparse
import json
import os
import shlex
import statistics
import sys
import tempfile
import time

from scene_env import NarvalError, key_table, run_narval

DEFAULT_SCENES = ["scenes/cloud.json", "scenes/disney_cloud.json", "scenes/disney_cloud_front.json",
                  "scenes/smoke.json", "scenes/dragon.json"]
NO_ROULETTE = "--set renderer.pathtrace.shadowRoulette=0"


def default_configs(narval):
    """The sampling choices; "roulette" is shadow-ray roulette at the loader's default (scene --keys)."""
    roulette = "--set renderer.pathtrace.shadowRoulette=%s" % json.dumps(
        key_table(narval)["renderer.pathtrace.shadowRoulette"]["defaults"][0])
    return [(name, f"--set renderer.pathtrace.lightSampling={mode} {roulette if rr else NO_ROULETTE}")
            for name, mode, rr in [("all", "all", 0), ("power", "power", 0), ("fluence", "fluence", 0),
                                   ("all+roulette", "all", 1), ("fluence+roulette", "fluence", 1)]]


def run(cmd):
    try:
        return run_narval(cmd[0], cmd[1:])
    except NarvalError as e:
        sys.exit(f"pathtrace_sampling: {e}")


def render(a, scene, out, spp, seed, extra, counters=False):
    stats = out + ".json"
    cmd = [a.narval, "render", scene, "--algorithm", "pathtrace", "--resolution", a.resolution, "--spp", str(spp),
           "--set", f"renderer.seed={seed}", "-o", out, "--stats-json", stats] + shlex.split(extra)
    if counters:
        cmd.append("--counters")
    run(cmd)
    with open(stats) as f:
        return json.load(f)


def rel_mse(a, ref, test):
    return json.loads(run([a.narval, "compare", ref, test, "--json"]))["rel_mse"]


def reference(a, scene):
    os.makedirs(a.cache, exist_ok=True)
    name = os.path.splitext(os.path.basename(scene))[0]
    path = os.path.join(a.cache, f"sampling_ref_{name}_{a.resolution}_{a.ref_spp}.exr")
    if not os.path.exists(path):
        t = time.time()
        render(a, scene, path, a.ref_spp, 1000, f"--set renderer.pathtrace.lightSampling=all {NO_ROULETTE}")
        print(f"  reference {path}: {time.time() - t:.0f} s", file=sys.stderr)
    return path


def counters_of(stats):
    samples = stats["width"] * stats["height"] * stats["spp"]
    return {"tentative": stats["collisions_tentative"] / samples, "real": stats["collisions_real"] / samples,
            "lookups": stats["density_lookups"] / samples}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--scenes", default=",".join(DEFAULT_SCENES))
    p.add_argument("--resolution", default="160x120")
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--ref-spp", type=int, default=4096)
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--configs", default="", help="NAME=narval options;NAME=options (default: the sampling choices)")
    p.add_argument("--narval", default="build/narval")
    p.add_argument("--cache", default="build/bench-cache")
    p.add_argument("--json", default="")
    a = p.parse_args()
    configs = ([tuple(c.split("=", 1)) if "=" in c else (c, "") for c in a.configs.split(";")] if a.configs
               else default_configs(a.narval))
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for scene in a.scenes.split(","):
            ref = reference(a, scene)
            rows = {name: {"seconds": [], "rel_mse": []} for name, _ in configs}
            for rep in range(a.reps):
                for i, (name, extra) in enumerate(configs):
                    out = os.path.join(tmp, f"{i}_{rep}.exr")
                    s = render(a, scene, out, a.spp, 1 + rep, extra)
                    rows[name]["seconds"].append(s["kernel_seconds"])
                    rows[name]["rel_mse"].append(rel_mse(a, ref, out))
            for i, (name, extra) in enumerate(configs):
                rows[name]["counters"] = counters_of(render(a, scene, os.path.join(tmp, f"c{i}.exr"), a.spp, 99, extra, True))
            first = configs[0][0]
            ref_noise = statistics.mean(rows[first]["rel_mse"]) * a.spp / a.ref_spp
            print(f"\n{scene} ({a.resolution}, {a.spp} spp x {a.reps} reps; reference {a.ref_spp} spp, its relMSE "
                  f"share estimated {ref_noise:.3g} and subtracted)")
            print(f"| configuration | kernel s (median) | relMSE | efficiency vs {first} | tentative/sample | real/sample | lookups/sample |")
            print("|---|---|---|---|---|---|---|")
            base_eff = None
            for name, _ in configs:
                r = rows[name]
                sec = statistics.median(r["seconds"])
                err = max(statistics.mean(r["rel_mse"]) - ref_noise, 1e-12)
                eff = 1.0 / (err * sec)
                base_eff = base_eff or eff
                r.update(median_seconds=sec, rel_mse_corrected=err, efficiency=eff / base_eff)
                c = r["counters"]
                print(f"| {name} | {sec:.3f} | {err:.4g} | {eff / base_eff:.2f} | {c.get('tentative', 0):.1f} | "
                      f"{c.get('real', 0):.2f} | {c.get('lookups', 0):.1f} |")
            results[scene] = rows
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"args": vars(a), "results": results}, f, indent=1)


if __name__ == "__main__":
    main()
