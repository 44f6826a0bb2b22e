#!/usr/bin/env python3
"""bench/pathtrace_sampling.py: what each of the path tracer's sampling choices costs and buys: kernel
time, relMSE against a converged reference and their product's inverse (the efficiency), with the
collision counts per sample. Details: bench/README.md. Not a test."""
import json
import os
import shlex
import statistics

import scene_env as b

DEFAULT_SCENES = "scenes/cloud.json,scenes/disney_cloud.json,scenes/disney_cloud_front.json,scenes/smoke.json," \
                 "scenes/dragon.json"
NO_ROULETTE = "--set renderer.pathtrace.shadowRoulette=0"
p = b.parser(__doc__)
b.options(p, scenes=DEFAULT_SCENES, resolution="160x120", spp=64, ref_spp=4096, reps=3)
p.add_argument("--configs", default="", help="NAME=narval options;NAME=options (default: the sampling choices)")
p.add_argument("--cache", default="build/bench-cache")
p.add_argument("--json", default="", help="also write every measurement to this file")
a = b.parse(p)


def default_configs():
    """The sampling choices; "roulette" is shadow-ray roulette at the loader's default (scene --keys)."""
    default = b.key_table(a.narval)["renderer.pathtrace.shadowRoulette"]["defaults"][0]
    roulette = "--set renderer.pathtrace.shadowRoulette=%s" % json.dumps(default)
    return [(name, "--set renderer.pathtrace.lightSampling=%s %s" % (mode, roulette if rr else NO_ROULETTE))
            for name, mode, rr in [("all", "all", 0), ("power", "power", 0), ("fluence", "fluence", 0),
                                   ("all+roulette", "all", 1), ("fluence+roulette", "fluence", 1)]]


def render(scene, out, seed, extra, *more):
    return b.render(a, scene, "--algorithm", "pathtrace", "--resolution", a.resolution, "--spp", a.spp,
                    "--set", "renderer.seed=%d" % seed, *shlex.split(extra), *more, out=out)


def measure():
    configs = [tuple(c.split("=", 1)) if "=" in c else (c, "") for c in a.configs.split(";")] if a.configs \
        else default_configs()
    os.makedirs(a.cache, exist_ok=True)
    results = {}
    for scene in a.scenes.split(","):
        ref = os.path.join(a.cache, "sampling_ref_%s_%s_%d.exr" % (b.scene_name(scene), a.resolution, a.ref_spp))
        b.reference(a, scene, ref, a.ref_spp, "--resolution", a.resolution, "--set", "renderer.seed=1000",
                    "--set", "renderer.pathtrace.lightSampling=all", *shlex.split(NO_ROULETTE))
        rows = {name: {"seconds": [], "rel_mse": []} for name, _ in configs}
        for rep in range(a.reps):
            for i, (name, extra) in enumerate(configs):
                out = a.work / ("%d_%d.exr" % (i, rep))
                rows[name]["seconds"].append(render(scene, out, 1 + rep, extra)["kernel_seconds"])
                rows[name]["rel_mse"].append(b.compare(a, ref, out)["rel_mse"])
        for i, (name, extra) in enumerate(configs):  # collisions and lookups per sample
            s = render(scene, a.work / ("c%d.exr" % i), 99, extra, "--counters")
            n = s["width"] * s["height"] * s["spp"]
            rows[name]["counters"] = {"tentative": s["collisions_tentative"] / n, "real": s["collisions_real"] / n,
                                      "lookups": s["density_lookups"] / n}
        first = configs[0][0]
        ref_noise = statistics.mean(rows[first]["rel_mse"]) * a.spp / a.ref_spp
        print("\n%s (%s, %d spp x %d reps; reference %d spp, its relMSE share estimated %.3g and subtracted)"
              % (scene, a.resolution, a.spp, a.reps, a.ref_spp, ref_noise))
        b.header("configuration", "kernel s (median)", "relMSE", "efficiency vs " + first, "tentative/sample",
                 "real/sample", "lookups/sample")
        base = None
        for name, _ in configs:
            r = rows[name]
            seconds = statistics.median(r["seconds"])
            error = max(statistics.mean(r["rel_mse"]) - ref_noise, 1e-12)
            base = base or 1.0 / (error * seconds)
            r.update(median_seconds=seconds, rel_mse_corrected=error, efficiency=1.0 / (error * seconds) / base)
            c = r["counters"]
            b.row(name, "%.3f" % seconds, "%.4g" % error, "%.2f" % r["efficiency"], "%.1f" % c["tentative"],
                  "%.2f" % c["real"], "%.1f" % c["lookups"])
        results[scene] = rows
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"args": {k: str(v) for k, v in vars(a).items()}, "results": results}, f, indent=1)


b.main(measure)
