#!/usr/bin/env python3
"""bench/kernel_ab.py specialisation|storage|emission [options]: one kernel build against another
(specialised/generic, image/buffer storage, with/without emission code), alternating repetitions.
Details: bench/README.md. Not a test."""
import atexit
import json
import os
from pathlib import Path

import scene_env as b

DEFAULTS = {  # scenes, resolution, algorithms; the table's names for A, B and their ratio
    "specialisation": ("scenes/cloud.json scenes/listing_4_1.json scenes/disney_cloud.json", "160x80",
                       "pathtrace raymarch", ("specialised", "generic", "speed-up generic/specialised")),
    "storage": ("scenes/cloud.json", "160x90", "pathtrace raymarch", ("image", "buffer", "image/buffer")),
    "emission": ("scenes/cloud.json scenes/smoke.json scenes/disney_cloud.json", "160x120",
                 "pathtrace raymarch lobe", ("with emission code", "without", "ratio with/without"))}
p = b.parser(__doc__)
p.add_argument("experiment", choices=DEFAULTS)
p.add_argument("--scenes", help="default: the experiment's")
p.add_argument("--resolution")
b.options(p, spp=16, frames=5, reps=3)
p.add_argument("--algorithms")
a = b.parse(p)
scenes, resolution, algorithms, names = DEFAULTS[a.experiment]
a.scenes, a.resolution, a.algorithms = a.scenes or scenes, a.resolution or resolution, a.algorithms or algorithms
generic = dict(os.environ, NARVAL_GENERIC="1")


def pairs():
    """(label, A, B, ratio B/A), A and B as (scene, options, environment)."""
    if a.experiment == "specialisation":
        return [(s, (s, [], None), (s, [], generic), True) for s in a.scenes.split()]
    if a.experiment == "storage":
        image, buffer = ["--set", "renderer.storage=image"], ["--set", "renderer.storage=buffer"]
        return [(s, (s, image, None), (s, buffer, None), False) for s in a.scenes.split()]
    # The fire without its emission, beside the original (so that its relative volume path holds).
    fire, no_emission = json.loads(Path("scenes/fire.json").read_text()), Path("scenes/.fire_no_emission.json")
    for m in fire["materials"]:
        m.pop("emission", None)
    no_emission.write_text(json.dumps(fire, indent=2))
    atexit.register(no_emission.unlink, True)
    result = [("fire: emitting / emission removed", ("scenes/fire.json", [], None), (no_emission, [], None), False)]
    for s in a.scenes.split():
        k = next(i for i, m in enumerate(json.loads(Path(s).read_text())["materials"]) if m["type"] == "volume")
        code_on = ["--set", 'materials[%d].emission={"color":[0,0,0]}' % k]
        result.append(("%s: emission code on (Le = 0) / specialised" % s, (s, code_on, None), (s, [], None), False))
    return result


def measure():
    print("device: %s" % b.render(a, a.scenes.split()[0], "--resolution", "16x8", "--spp", 1)["device"])
    print("load average at start: %s on %d cores" % (b.load_average(), os.cpu_count()))
    print("%s; pathtrace: %d spp, kernel seconds; real-time: median kernel s per frame of %d frames; %d "
          "alternating repetitions after a warm-up of each\n" % (a.resolution, a.spp, a.frames, a.reps))
    b.header("scene", "algorithm", names[0] + " s (median)", names[1] + " s (median)", names[2], "per-repetition")
    for label, first, second, inverse in pairs():
        for algorithm in a.algorithms.split():  # kernel seconds: the path tracer's, else the median frame's
            count = ["--spp", a.spp] if algorithm == "pathtrace" else ["--frames", a.frames, "--set", b.MARCH]
            common = ["--algorithm", algorithm, "--resolution", a.resolution, *count]
            runs = {i: (lambda s=s, o=o, e=e: b.seconds(b.render(a, s, *common, *o, env=e)))
                    for i, (s, o, e) in enumerate((first, second))}
            t = b.alternate(a.reps, runs)
            b.row(label, algorithm, *b.ab_cells(t[0], t[1], inverse=inverse))
    print("\nload average at end: %s" % b.load_average())


b.main(measure)
