#!/usr/bin/env python3
"""bench/scene_env_test.py NARVAL (ctest bench.scene_defaults): the bench scripts take a scene's values
from narval (`narval scene --resolved`, bench/scene_env.py), never from constants of their own. On a
scene without renderer.lobe: speed_vs_error's base viewSteps of lobe-corrected and shadowSteps of lobe-eq7
are the loader's defaults as `narval scene --keys` reports them (viewSteps per variant), the scene's
values win where it has them, and a narval that resolves viewSteps 1000 higher is followed; vs_mitsuba's
camera.vfov, renderer.spp and renderer.bounces likewise. Exit 0 when every check holds, else 1."""
import json
import os
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path[:0] = [str(BENCH), str(BENCH / "vs_mitsuba")]
import scene_env  # noqa: E402
import speed_vs_error  # noqa: E402
import vs_mitsuba  # noqa: E402

SCENE = {
    "materials": [{"name": "light", "type": "emitter", "albedo": [1, 1, 1]},
                  {"name": "fog", "type": "volume", "scattering": [1, 1, 1], "absorption": [0, 0, 0]}],
    "primitives": [{"type": "point", "materialName": "light", "transform": {"position": [0, 2, 0]}},
                   {"type": "volume", "materialName": "fog"}],
    "camera": {"position": [0, 0, -5], "lookAt": [0, 0, 0]},
    "renderer": {"algorithm": "lobe", "resolution": [8, 6]},
}
# A narval whose `scene --resolved` answers viewSteps 1000 higher than the real one's.
SHIFTED_NARVAL = """#!%s
import json, subprocess, sys
done = subprocess.run([%r] + sys.argv[1:], capture_output=True, text=True)
sys.stderr.write(done.stderr)
out = done.stdout
if done.returncode == 0 and sys.argv[1] == "scene" and "--resolved" in sys.argv:
    scene = json.loads(out)
    scene["renderer"]["lobe"]["viewSteps"] += 1000
    out = json.dumps(scene)
sys.stdout.write(out)
sys.exit(done.returncode)
"""
failures = []


def check(what, got, expected):
    print("%s %s: %r%s" % ("ok  " if got == expected else "FAIL", what, got,
                           "" if got == expected else " (expected %r)" % (expected,)))
    if got != expected:
        failures.append(what)


def bases(narval, scene_path):
    """(lobe-corrected's base viewSteps, lobe-eq7's base shadowSteps) in speed_vs_error."""
    settings = speed_vs_error.parse_args([str(scene_path), "--narval", str(narval), "--methods",
                                          "lobe-eq7,lobe-corrected"])
    scene = speed_vs_error.load_scene(scene_path, settings)
    return (speed_vs_error.base_parameters(settings, scene, "lobe-corrected")["viewSteps"],
            speed_vs_error.base_parameters(settings, scene, "lobe-eq7")["shadowSteps"])


def write(path, **changes):
    """SCENE with top-level sections updated by changes, as JSON at path."""
    path.write_text(json.dumps(dict(SCENE, **{k: dict(SCENE[k], **v) for k, v in changes.items()})))
    return path


def main(narval):
    keys = scene_env.key_table(narval)
    # scene --keys lists a key's defaults in the order the loader took them: the default variant's
    # first, then the other's (host/scene/scene_keys.cpp reads a scene of each).
    variants = [v.strip() for v in keys["renderer.lobe.variant"]["range"].split(",")]
    first = keys["renderer.lobe.variant"]["defaults"][0]
    other = next(v for v in variants if v != first)
    defaults = dict(zip([first, other], keys["renderer.lobe.viewSteps"]["defaults"]))
    check("scene --keys: renderer.lobe.viewSteps has a default per variant, and they differ",
          len(set(defaults.values())) == 2 and set(defaults) == {"eq7", "corrected"}, True)
    shadow_steps = keys["renderer.lobe.shadowSteps"]["defaults"]
    check("scene --keys: renderer.lobe.shadowSteps has one default", len(shadow_steps), 1)
    with tempfile.TemporaryDirectory(prefix="bench_scene_env_") as tmp:
        plain = write(Path(tmp) / "no_lobe.json")
        check("(lobe-corrected viewSteps, lobe-eq7 shadowSteps), scene without renderer.lobe (= scene --keys "
              "defaults, viewSteps corrected's)", bases(narval, plain), (defaults["corrected"], shadow_steps[0]))
        explicit = write(Path(tmp) / "lobe_set.json", renderer={"lobe": {"viewSteps": 7, "shadowSteps": 9}})
        check("(lobe-corrected viewSteps, lobe-eq7 shadowSteps), scene with viewSteps 7, shadowSteps 9",
              bases(narval, explicit), (7, 9))
        shifted = Path(tmp) / "narval_shifted"
        shifted.write_text(SHIFTED_NARVAL % (sys.executable, str(Path(narval).resolve())))
        shifted.chmod(0o755)
        check("lobe-corrected viewSteps through a narval that resolves 1000 more", bases(shifted, plain)[0],
              defaults["corrected"] + 1000)
        scene = vs_mitsuba.load_narval_scene(narval, str(plain))
        for key, got in (("camera.vfov", scene["camera"]["vfov"]), ("renderer.spp", scene["spp"]),
                         ("renderer.bounces", scene["bounces"])):
            check("vs_mitsuba %s, scene without it (= scene --keys default)" % key, got, keys[key]["defaults"][0])
        scene = vs_mitsuba.load_narval_scene(narval, str(write(Path(tmp) / "vfov_30.json", camera={"vfov": 30},
                                                               renderer={"bounces": 5})))
        check("vs_mitsuba camera.vfov and renderer.bounces, scene with vfov 30 and bounces 5",
              (scene["camera"]["vfov"], scene["bounces"]), (30, 5))
    for what in failures:
        print("scene_env_test: failed: %s" % what, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 2 or not os.access(sys.argv[1], os.X_OK):
        sys.exit("usage: bench/scene_env_test.py NARVAL (the narval binary)")
    sys.exit(main(sys.argv[1]))
