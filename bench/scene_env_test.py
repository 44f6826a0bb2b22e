#!/usr/bin/env python3
"""bench/scene_env_test.py NARVAL (ctest bench.scene_defaults): the bench scripts take a scene's
values from narval (`narval scene --resolved`, bench/scene_env.py), never from constants of their own.

A scene without renderer.lobe (algorithm lobe), written into a temporary folder:
1. speed_vs_error's base viewSteps of the method lobe-corrected (variant "corrected" set by the
   method) is the loader's default for that variant as `narval scene --keys` reports it (it differs
   from eq7's: a variant-blind constant fails), and lobe-eq7's base shadowSteps is the loader's;
2. with renderer.lobe.viewSteps and shadowSteps in the scene, the scene's values win;
3. run through a narval whose --resolved reports viewSteps 1000 higher, the bench follows it: no
   constant in the bench stands in for narval's answer;
4. vs_mitsuba's scene (camera.vfov, renderer.spp, renderer.bounces) is likewise the loader's.
Exit 0 when every check holds, 1 otherwise (each failure on stderr).
"""
import json
import os
import stat
import sys
import tempfile
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))
sys.path.insert(0, str(BENCH / "vs_mitsuba"))
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
    ok = got == expected
    print("%s %s: %r%s" % ("ok  " if ok else "FAIL", what, got, "" if ok else " (expected %r)" % (expected,)))
    if not ok:
        failures.append(what)


def bases(narval, scene_path):
    """(lobe-corrected's base viewSteps, lobe-eq7's base shadowSteps) in speed_vs_error, as its
    renders and report use them."""
    settings = speed_vs_error.parse_args([str(scene_path), "--narval", str(narval), "--methods",
                                          "lobe-eq7,lobe-corrected"])
    scene = speed_vs_error.load_scene(scene_path, settings)
    return (speed_vs_error.base_parameters(settings, scene, "lobe-corrected")["viewSteps"],
            speed_vs_error.base_parameters(settings, scene, "lobe-eq7")["shadowSteps"])


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
    with tempfile.TemporaryDirectory(prefix="bench_scene_env_") as tmp:
        tmp = Path(tmp)
        plain = tmp / "no_lobe.json"
        plain.write_text(json.dumps(SCENE))
        shadow_steps = keys["renderer.lobe.shadowSteps"]["defaults"]
        check("scene --keys: renderer.lobe.shadowSteps has one default", len(shadow_steps), 1)
        check("(lobe-corrected viewSteps, lobe-eq7 shadowSteps), scene without renderer.lobe (= scene --keys "
              "defaults, viewSteps corrected's)", bases(narval, plain), (defaults["corrected"], shadow_steps[0]))

        explicit = tmp / "lobe_set.json"
        lobe = {"viewSteps": 7, "shadowSteps": 9}
        explicit.write_text(json.dumps(dict(SCENE, renderer=dict(SCENE["renderer"], lobe=lobe))))
        check("(lobe-corrected viewSteps, lobe-eq7 shadowSteps), scene with renderer.lobe %s" % json.dumps(lobe),
              bases(narval, explicit), (7, 9))

        shifted = tmp / "narval_shifted"
        shifted.write_text(SHIFTED_NARVAL % (sys.executable, str(Path(narval).resolve())))
        shifted.chmod(shifted.stat().st_mode | stat.S_IXUSR)
        check("lobe-corrected viewSteps through a narval that resolves 1000 more", bases(shifted, plain)[0],
              defaults["corrected"] + 1000)

        mitsuba_scene = vs_mitsuba.load_narval_scene(narval, str(plain))
        for key, got in (("camera.vfov", mitsuba_scene["camera"]["vfov"]), ("renderer.spp", mitsuba_scene["spp"]),
                         ("renderer.bounces", mitsuba_scene["bounces"])):
            check("vs_mitsuba %s, scene without it (= scene --keys default)" % key, got, keys[key]["defaults"][0])
        explicit = tmp / "vfov_30.json"
        explicit.write_text(json.dumps(dict(SCENE, camera=dict(SCENE["camera"], vfov=30),
                                            renderer=dict(SCENE["renderer"], bounces=5))))
        mitsuba_scene = vs_mitsuba.load_narval_scene(narval, str(explicit))
        check("vs_mitsuba camera.vfov and renderer.bounces, scene with vfov 30 and bounces 5",
              (mitsuba_scene["camera"]["vfov"], mitsuba_scene["bounces"]), (30, 5))
    for what in failures:
        print("scene_env_test: failed: %s" % what, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    if len(sys.argv) != 2 or not os.access(sys.argv[1], os.X_OK):
        sys.exit("usage: bench/scene_env_test.py NARVAL (the narval binary)")
    sys.exit(main(sys.argv[1]))
