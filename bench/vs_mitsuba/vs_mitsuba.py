#!/usr/bin/env python3
"""vs_mitsuba.py: narval's path tracer against Mitsuba 3 (a bench tool, never a test dependency).

  compare SCENE.json  K renders per renderer of the scene translated into a Mitsuba 3 scene (written to
                      OUT/mitsuba/mitsuba_scene.json): image means, standard errors, z and a per-tile
                      chi^2; exit 1 when they disagree
  race SCENE.json     time at equal relMSE against a cached converged narval reference
  picture DIR OUT.png a compare run's mean images (narval's, Mitsuba's) and their difference, side by side
It runs in setup.sh's environment (build/mitsuba-venv, or $NARVAL_MITSUBA_VENV), re-executing itself
there. README.md beside this file explains the conventions matched and the statistics.
"""
import argparse
import functools
import hashlib
import json
import math
import os
import shlex
import signal
import struct
import sys
import time
from pathlib import Path

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))  # bench/: what the bench scripts share
from scene_env import montage, need_pillow, options, resolved_scene, run_json, run_narval, volume_path  # noqa: E402
WORK_DIR = os.path.join(REPO, "build", "vs_mitsuba")
# compare disagrees when a channel's image-mean |z| exceeds Z_LIMIT (two-sided 6.3e-5 per channel) or
# the 4x4 tiles' chi^2 has an upper tail below CHI2_P_LIMIT: about 3 false alarms in 10^4 in all.
Z_LIMIT, CHI2_P_LIMIT, TILES = 4.0, 1e-4, 4
# Float arithmetic, not a convention: both renderers compute in float32 in different orders, which
# moves noise-free values by 1e-7..1e-5 relative. Added in quadrature to every standard error.
NUMERIC_TOLERANCE = 1e-4
# Deliberate mistakes in the translation (compare --perturb NAME, README.md), to show that compare can fail.
PERTURBATIONS = ("mirror", "hg_sign", "light_back", "depth", "no_pad", "half_voxel", "rotation_order")
PERTURB = set()

try:
    import numpy as np  # the venv's (Debian's numpy, which pyopenvdb is built against)
except ImportError:  # another interpreter: main() re-executes under the venv before numpy is used
    np = None


def ensure_environment():
    """Re-executes under the venv's python when needed. None when Mitsuba can be imported, else why not."""
    venv = os.environ.get("NARVAL_MITSUBA_VENV") or os.path.join(REPO, "build", "mitsuba-venv")
    py = os.path.join(venv, "bin", "python")
    if not os.path.exists(py):
        return "no Mitsuba environment at %s (run bench/vs_mitsuba/setup.sh)" % venv
    llvm_file = os.path.join(venv, "drjit_libllvm_path")  # the libLLVM setup.sh found to work
    if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm_file):
        os.environ["DRJIT_LIBLLVM_PATH"] = Path(llvm_file).read_text().strip()
    if os.path.realpath(sys.prefix) != os.path.realpath(venv) and not os.environ.get("NARVAL_VS_MITSUBA_EXEC"):
        os.environ["NARVAL_VS_MITSUBA_EXEC"] = "1"  # once: no exec loop
        os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:])
    try:
        import mitsuba  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        return "the environment at %s cannot import Mitsuba (%s; run bench/vs_mitsuba/setup.sh)" % (venv, e)
    return None


@functools.cache
def mitsuba():
    """The mitsuba module: the llvm_ad_rgb variant on two worker threads (as narval's PoCL device)."""
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    dr.set_thread_count(int(os.environ.get("NARVAL_MITSUBA_THREADS", "2")))
    return mi


def load_narval_scene(narval, path, resolution=None, overrides=()):
    """What the path tracer uses, as narval resolves it: materials by name (a volume's grid path found
    as the loader finds it), primitives with their material, camera, size, spp, bounces, background."""
    sets = list(overrides) + (["renderer.resolution=[%d,%d]" % tuple(resolution)] if resolution else [])
    doc = resolved_scene(narval, path, sets)
    materials = {}
    for m in doc["materials"]:
        mat = materials[m["name"]] = dict(m)
        if m["type"] == "volume":
            g = float(m["g"]) if m["phaseFunction"] == "hg" else 0.0
            mat["g"] = math.copysign(0.9999, g) if abs(g) == 1 else g  # narval clamps |g| = 1
            mat["path"] = str(volume_path(path, m["path"])) if "path" in m else None
            mat["emission"], mat["density"] = m.get("emission"), float(m["density"])
    floats = lambda obj: {k: [float(x) for x in v] if isinstance(v, list) else float(v)  # noqa: E731
                          for k, v in obj.items()}
    prims = [dict(floats(p["transform"]), type=p["type"], material=materials[p["materialName"]])
             for p in doc["primitives"]]
    r = doc["renderer"]
    return {"path": os.path.abspath(path), "materials": materials, "primitives": prims,
            "camera": floats(doc["camera"]), "background": doc["background"],
            "width": r["resolution"][0], "height": r["resolution"][1], "spp": r["spp"], "bounces": r["bounces"]}


def read_grid(path, grid_name):
    """(data[x, y, z] float32, index_to_world 3x4), read as narval reads them (host/volume/vdb_io.cpp,
    vol_io.cpp). narval's voxel i covers [i, i+1]; a .vdb grid is its active bounding box copied densely,
    placed by the file's affine map shifted by bbox.min - 0.5."""
    if path.lower().endswith(".vol"):
        tokens = Path(path).read_text().split()  # the dissertation's text .vol: "X Y Z", then X*Y*Z floats, x fastest
        nx, ny, nz = (int(t) for t in tokens[:3])
        values = np.array(tokens[3:], dtype=np.float64).astype(np.float32)
        if values.size != nx * ny * nz:
            raise ValueError("%s: %d values for %dx%dx%d" % (path, values.size, nx, ny, nz))
        data, m = values.reshape(nz, ny, nx).transpose(2, 1, 0).copy(), np.hstack([np.eye(3), np.zeros((3, 1))])
    else:
        import pyopenvdb as vdb
        grid = vdb.read(path, grid_name)
        if not isinstance(grid, vdb.FloatGrid) or not grid.transform.isLinear:
            raise ValueError("%s: grid %r is not a float grid with an affine transform" % (path, grid_name))
        lo, hi = grid.evalActiveVoxelBoundingBox()
        data = np.zeros(tuple(h - l + 1 for l, h in zip(lo, hi)), dtype=np.float32)
        grid.copyToArray(data, ijk=lo)
        o = np.array(grid.transform.indexToWorld((0.0, 0.0, 0.0)))  # the affine map at the origin and axes
        linear = np.stack([np.array(grid.transform.indexToWorld(tuple(float(i == a) for i in range(3)))) - o
                           for a in range(3)], axis=1)
        m = np.hstack([linear, (o + linear @ (np.array(lo, dtype=np.float64) - 0.5))[:, None]])
    if not np.all(np.isfinite(data)) or (data < 0).any():
        raise ValueError("%s: densities must be finite and >= 0 (narval refuses this grid)" % path)
    return data, m


def rotation_matrix(deg):
    """narval's R = Rz . Ry . Rx (X first), angles in degrees, right-handed."""
    ax, ay, az = (math.radians(a) for a in deg)
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rx @ ry @ rz if "rotation_order" in PERTURB else rz @ ry @ rx


def affine(linear, translation):
    m = np.eye(4)
    m[:3, :3], m[:3, 3] = linear, translation
    return m


def rgb(v, unbounded=False):
    """A constant RGB; `unbounded` lets a coefficient exceed 1 (the srgb plugin itself)."""
    v = [float(x) for x in v]
    return {"type": "srgb", "color": v, "unbounded": True} if unbounded else {"type": "rgb", "value": v}


def translate_scene(scene, out_dir):
    """Writes OUT_DIR/mitsuba_scene.json (mi.load_dict's dict, every to_world a 4x4 list) and the grid
    as a Mitsuba .vol; the dict. The conventions matched: host/render/scene_upload.cpp, README.md's table."""
    os.makedirs(out_dir, exist_ok=True)
    # max_depth counts the camera vertex: `bounces` scattering events, then the continuation ray's
    # emitter or background; Russian roulette is put out of reach.
    d = {"type": "scene", "integrator": {"type": "volpath", "rr_depth": scene["bounces"] + 100,
                                         "max_depth": scene["bounces"] + (0 if "depth" in PERTURB else 1)}}
    medium_box = None
    for i, p in enumerate(scene["primitives"]):
        mat = p["material"]
        if p["type"] == "point":  # intensity I (W/sr): radiance I / d^2
            d["light_%d" % i] = {"type": "point", "position": p["position"], "intensity": rgb(mat["albedo"])}
        elif p["type"] == "rectangle":
            d["light_%d" % i] = rectangle_light(p, mat)
        elif p["type"] == "volume":
            d["medium"], medium_box, d["volume_box"] = translate_volume(p, mat, out_dir)
    if any(c > 0 for c in scene["background"]):
        d["background"] = {"type": "constant", "radiance": rgb(scene["background"])}
    d["sensor"] = translate_camera(scene, medium_box)
    Path(out_dir, "mitsuba_scene.json").write_text(json.dumps(d, indent=1))
    return d


def rectangle_light(p, mat):
    """narval's unit quad [-0.5,0.5]^2 in local XY, one-sided along R.(0,0,-1), opaque with a black
    back; Mitsuba's rectangle is [-1,1]^2 with normal +z: to_world = T.R.diag(|sx|/2, -|sy|/2, -1), and
    a black diffuse BSDF (Mitsuba's default would reflect 50%)."""
    flip = 1.0 if "light_back" in PERTURB else -1.0
    scale = np.diag([0.5 * abs(p["scale"][0]), 0.5 * abs(p["scale"][1]) * flip, flip])
    to_world = affine(rotation_matrix(p["rotation"]) @ scale, p["position"])
    return {"type": "rectangle", "to_world": to_world.tolist(),
            "emitter": {"type": "area", "radiance": rgb(mat["albedo"])},
            "bsdf": {"type": "diffuse", "reflectance": rgb([0, 0, 0])}}


def translate_volume(p, mat, out_dir):
    """(medium, (index_to_world 4x4, dims), the box shape holding it)."""
    if mat.get("emission"):
        raise ValueError("the volume emits (emission): not translated (Mitsuba's medium emission is another "
                         "model; compare scenes without emission)")
    density, sig_a, sig_s = mat["density"], np.array(mat["absorption"]), np.array(mat["scattering"])
    k = sig_a + sig_s  # sigma_t per unit density, per channel
    albedo = np.where(k > 0, sig_s / np.where(k > 0, k, 1), 0.0)
    grey = bool(np.all(sig_a == sig_a[0]) and np.all(sig_s == sig_s[0]))
    g = -mat["g"] if "hg_sign" in PERTURB else mat["g"]
    phase = {"type": "hg", "g": g} if mat["phaseFunction"] == "hg" and g != 0 else {"type": "isotropic"}
    m = affine(rotation_matrix(p["rotation"]) @ np.diag(p["scale"]), p["position"])  # M = T.R.S
    if mat["path"] is None:  # homogeneous: the unit cube itself (index box [0,1]^3 -> [-0.5,0.5]^3)
        dims = np.array([1.0, 1.0, 1.0])
        index_to_world = m @ affine(np.eye(3), [-0.5, -0.5, -0.5])
        medium = {"type": "homogeneous", "sigma_t": rgb(k, unbounded=True), "albedo": rgb(albedo),
                  "scale": density, "phase": phase, "sample_emitters": True}
    else:
        data, file_map = read_grid(mat["path"], mat["grid"])
        dims = np.array(data.shape, dtype=np.float64)
        if mat["gridSpace"] == "file":  # the file's own placement, then M on top
            index_to_world = m @ np.vstack([file_map, [0, 0, 0, 1]])
        else:  # "unit": the index box [0, n] fills the primitive's unit cube
            index_to_world = m @ affine(np.diag(1.0 / dims), [-0.5, -0.5, -0.5])
            lin = file_map[:, :3]
            if abs(lin - np.diag(np.diag(lin))).max() > 1e-9 * abs(lin).max():
                print("note: the grid's file transform rotates or shears; unit grid space drops it (as narval)")
        # gridvolume clamps at its edge where narval reads 0 beyond the outer voxels: one zero voxel
        # of padding on every side, the padded grid over the index box [-1, n+1].
        padded, pad_box = np.pad(data, 1), affine(np.diag(dims + 2), [-1, -1, -1])
        if "no_pad" in PERTURB:
            padded, pad_box = data, affine(np.diag(dims), [0, 0, 0])
        if "half_voxel" in PERTURB:
            pad_box = affine(np.eye(3), [0.5, 0.5, 0.5]) @ pad_box
        values, scale = ((padded[..., None], density * float(k[0])) if grey
                         else (padded[..., None] * k.astype(np.float32)[None, None, None, :], density))
        vol_path = os.path.join(out_dir, "density.vol")  # Mitsuba's binary .vol: x fastest, box [0,1]^3
        with open(vol_path, "wb") as f:
            f.write(b"VOL\x03" + struct.pack("<5i6f", 1, *values.shape, 0, 0, 0, 1, 1, 1))
            f.write(np.ascontiguousarray(values.transpose(2, 1, 0, 3), dtype="<f4").tobytes())
        medium = {"type": "heterogeneous", "scale": scale, "phase": phase, "sample_emitters": True,
                  "has_spectral_extinction": not grey,  # spectral tracking only where sigma_t is chromatic
                  "sigma_t": {"type": "gridvolume", "filename": vol_path, "filter_type": "trilinear", "raw": True,
                              "to_world": (index_to_world @ pad_box).tolist()},
                  "albedo": {"type": "constvolume", "value": rgb(albedo)}}
    # The box [0, dims] in index space; Mitsuba's cube is [-1,1]^3. A reflecting map would swap the
    # cube's interior and exterior, so it is composed with x -> -x, which maps the cube onto itself.
    cube_to_world = index_to_world @ affine(np.diag(dims / 2), dims / 2)
    if np.linalg.det(cube_to_world[:3, :3]) < 0:
        cube_to_world = cube_to_world @ np.diag([-1.0, 1, 1, 1])
    box = {"type": "cube", "to_world": cube_to_world.tolist(), "bsdf": {"type": "null"},
           "interior": {"type": "ref", "id": "medium"}}
    return medium, (index_to_world, dims), box


def translate_camera(scene, medium_box):
    """narval: forward = normalize(lookAt - position), right = normalize(forward x up), up' = right x
    forward, image x along right, vfov vertical. Mitsuba's camera x points to the image's left: to_world's
    columns are (-right, up', forward, position). A box filter weighs samples uniformly in the pixel."""
    c = scene["camera"]
    unit = lambda v: v / np.linalg.norm(v)  # noqa: E731
    pos = np.array(c["position"])
    fwd = unit(np.array(c["lookAt"]) - pos)
    right = unit(np.cross(fwd, np.array(c["up"])))
    x = right if "mirror" in PERTURB else -right
    m = affine(np.column_stack([x, np.cross(right, fwd), fwd]), pos)
    sensor = {"type": "perspective", "fov": c["vfov"], "fov_axis": "y", "to_world": m.tolist(),
              "near_clip": 1e-4, "far_clip": 1e7,  # near the first voxel: Mitsuba starts rays at the near plane
              "film": {"type": "hdrfilm", "width": scene["width"], "height": scene["height"],
                       "rfilter": {"type": "box"}, "pixel_format": "rgb", "sample_border": False},
              "sampler": {"type": "independent", "sample_count": 1}}
    if c["aperture"] > 0:  # thin lens: lens radius and the focal plane's distance
        sensor.update({"type": "thinlens", "aperture_radius": c["aperture"], "focus_distance": c["focus"]})
    if medium_box is not None:
        index_to_world, dims = medium_box
        u = np.linalg.solve(index_to_world[:3, :3], pos - index_to_world[:3, 3])
        if np.all(u > 0) and np.all(u < dims):
            sensor["medium"] = {"type": "ref", "id": "medium"}  # the camera sits inside the medium
    return sensor


def load_mitsuba_scene(scene, out_dir):
    """The translated scene, loaded (every to_world as a ScalarTransform4f)."""
    objects = lambda v: {k: mitsuba().ScalarTransform4f(x) if k == "to_world" else objects(x)  # noqa: E731
                         for k, x in v.items()} if isinstance(v, dict) else v
    return mitsuba().load_dict(objects(translate_scene(scene, out_dir)))


def render_mitsuba(mscene, spp, seed, timings=None):
    """Mitsuba's image (HxWx3) of spp samples per pixel, one wavefront of W*H*spp lanes. With `timings` (a
    dict) also the wall seconds of mi.render + dr.eval and the seconds its JIT kernels ran."""
    import drjit as dr
    if timings is not None:
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        dr.kernel_history()  # drop what earlier work left
    t = time.perf_counter()
    img = mitsuba().render(mscene, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    if timings is not None:
        timings.update(wall_seconds=time.perf_counter() - t,
                       kernel_seconds=sum(k.get("execution_time", 0.0) for k in dr.kernel_history()) * 1e-3)
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    return np.array(img, dtype=np.float64)[..., :3]


def read_exr_rgb(path):
    for name, layer in mitsuba().Bitmap(path).split():
        if name == "<root>":
            return np.array(layer, dtype=np.float64)[..., :3]
    raise ValueError("%s: no RGB layer" % path)


def write_exr_rgb(path, image):
    mitsuba().Bitmap(np.ascontiguousarray(image, dtype=np.float32)).write(path)


def render_narval(narval, scene_path, spp, seed, resolution, out_exr, extra_args=()):
    """narval render --algorithm pathtrace into out_exr; its --stats-json."""
    stats_path = out_exr[:-4] + ".stats.json"
    run_narval(narval, ["render", scene_path, "--algorithm", "pathtrace", "--spp", spp, "--resolution",
                        "%dx%d" % resolution, "--seed", seed, "-o", out_exr, "-q", "--stats-json", stats_path]
               + list(extra_args))
    st = json.loads(Path(stats_path).read_text())
    if any(st.get("status", {}).values()):
        print("warning: narval status flags %s" % st["status"], file=sys.stderr)
    return st


def chi2_sf(x, k):
    """P(X > x) for X ~ chi^2 with k degrees of freedom: Q(k/2, x/2) by Q(a + 1, z) = Q(a, z) +
    z^a e^-z / Gamma(a + 1) from Q(1, z) = e^-z or Q(1/2, z) = erfc(sqrt z)."""
    if x <= 0:
        return 1.0
    z = 0.5 * x
    a, q = (1.0, math.exp(-z)) if k % 2 == 0 else (0.5, math.erfc(math.sqrt(z)))
    while a < 0.5 * k:
        q += math.exp(a * math.log(z) - z - math.lgamma(a + 1))
        a += 1
    return min(1.0, q)


def region_stats(mean, var, sl):
    """Mean (3) of the pixels in slice `sl` and the variance (3) of that mean: pixels are independent
    estimates, so it is the sum of their variances over n^2."""
    m, v = mean[sl].reshape(-1, 3), var[sl].reshape(-1, 3)
    return m.mean(axis=0), v.sum(axis=0) / m.shape[0] ** 2


def compare_images(narval_imgs, mitsuba_imgs):
    """z of the image-mean difference per channel, and chi^2 of the TILES x TILES tiles' mean differences
    (one degree of freedom per tile that sees noise: q = the mean over RGB of z^2; README.md, "Statistics")."""
    # Per pixel, the mean over the K renders and the variance of that mean.
    per_pixel = lambda imgs: (imgs.mean(axis=0), imgs.var(axis=0, ddof=1) / imgs.shape[0])  # noqa: E731
    (mn, vn), (mm, vm) = (per_pixel(np.asarray(i, dtype=np.float64)) for i in (narval_imgs, mitsuba_imgs))
    (mean_n, var_n), (mean_m, var_m) = region_stats(mn, vn, np.s_[:, :]), region_stats(mm, vm, np.s_[:, :])
    tol = NUMERIC_TOLERANCE * np.maximum(abs(mean_n), abs(mean_m))
    se = np.sqrt(var_n + var_m + tol ** 2)
    z = [float(x) for x in np.where(se > 0, (mean_n - mean_m) / np.where(se > 0, se, 1), 0.0)]
    ys, xs = (np.linspace(0, n, TILES + 1).round().astype(int) for n in mn.shape[:2])
    chi2, dof, worst = 0.0, 0, None
    for j, i in np.ndindex(TILES, TILES):
        sl = np.s_[ys[j]:ys[j + 1], xs[i]:xs[i + 1]]
        if ys[j + 1] <= ys[j] or xs[i + 1] <= xs[i]:
            continue
        (tn, tvn), (tm, tvm) = region_stats(mn, vn, sl), region_stats(mm, vm, sl)
        diff, var = tn - tm, tvn + tvm
        tol2 = (NUMERIC_TOLERANCE * max(np.abs(tn).max(), np.abs(tm).max())) ** 2 + 1e-300
        q, k = float(np.mean(diff ** 2 / (np.maximum(var, 0.0) + tol2))), int(np.any(var > tol2))
        chi2, dof = chi2 + q, dof + k
        if worst is None or q / max(k, 1) > worst["chi2"] / max(worst["dof"], 1):
            tz = [float(d / s) if s > 0 else 0.0 for d, s in zip(diff, np.sqrt(var))]
            worst = {"tile": [i, j], "chi2": q, "dof": k, "z": tz}
    p = chi2_sf(chi2, dof) if dof else 1.0
    return {"narval_mean": mean_n.tolist(), "mitsuba_mean": mean_m.tolist(),
            "narval_se": np.sqrt(var_n).tolist(), "mitsuba_se": np.sqrt(var_m).tolist(),
            "relative_difference": [float((x - y) / y) if y else 0.0 for x, y in zip(mean_n, mean_m)],
            "z": z, "chi2": chi2, "dof": dof, "chi2_per_dof": chi2 / dof if dof else 0.0, "chi2_p": p,
            "worst_tile": worst, "z_limit": Z_LIMIT, "chi2_p_limit": CHI2_P_LIMIT,
            "agree": bool(all(abs(x) <= Z_LIMIT for x in z) and p >= CHI2_P_LIMIT)}


def run_compare(scene_path, spp, seeds, resolution, narval, out_dir, sets=(), seed_offset=0):
    """sets: PATH=VALUE scene overrides for both renderers."""
    scene = load_narval_scene(narval, scene_path, resolution, sets)
    narval_args = [x for v in sets for x in ("--set", v)]
    res = (scene["width"], scene["height"])
    os.makedirs(out_dir, exist_ok=True)
    mscene = load_mitsuba_scene(scene, os.path.join(out_dir, "mitsuba"))
    narval_imgs, mitsuba_imgs = [], []
    for s in range(seeds):
        exr = os.path.join(out_dir, "narval_%d.exr" % s)
        render_narval(narval, scene_path, spp, seed_offset + s + 1, res, exr, narval_args)
        narval_imgs.append(read_exr_rgb(exr))
        mitsuba_imgs.append(render_mitsuba(mscene, spp, 1000 + seed_offset + s))
    r = compare_images(narval_imgs, mitsuba_imgs)
    for name, images in (("narval", narval_imgs), ("mitsuba", mitsuba_imgs)):  # for `picture`
        np.save(os.path.join(out_dir, name + "_mean.npy"), np.mean(images, axis=0).astype(np.float32))
    r.update({"scene": os.path.abspath(scene_path), "resolution": list(res), "spp": spp, "seeds": seeds,
              "seed_offset": seed_offset, "bounces": scene["bounces"], "sets": list(sets),
              "perturbations": sorted(PERTURB)})
    Path(out_dir, "compare.json").write_text(json.dumps(r, indent=1))
    perturbed = " (Mitsuba side perturbed: %s)" % ", ".join(r["perturbations"]) if r["perturbations"] else ""
    print("%s at %dx%d, %d spp x %d seeds, bounces %d%s: %s" % (os.path.basename(scene_path), *res, spp, seeds,
                                                                scene["bounces"], perturbed,
                                                                "AGREE" if r["agree"] else "DISAGREE"))
    for c in range(3):
        print("  %s  narval %.6g +- %.2g   mitsuba %.6g +- %.2g   rel diff %+.2e   z %+.2f" % (
            "RGB"[c], r["narval_mean"][c], r["narval_se"][c], r["mitsuba_mean"][c], r["mitsuba_se"][c],
            r["relative_difference"][c], r["z"][c]))
    wt = r["worst_tile"]
    print("  tiles %dx%d: chi2 %.1f / %d dof = %.2f, p = %.3g; worst tile (%d,%d): chi2 %.1f / %d, z RGB %s" % (
        TILES, TILES, r["chi2"], r["dof"], r["chi2_per_dof"], r["chi2_p"], *wt["tile"], wt["chi2"], wt["dof"],
        " ".join("%+.1f" % x for x in wt["z"])))
    return r


def reference(scene_path, scene, res, ref_spp, narval):
    """A converged narval render in two halves of independent seeds, cached in WORK_DIR, keyed by the
    scene file's content, its grid files, the resolution, the bounces and the spp; (the mean of the
    halves as an EXR, mean image, per-pixel variance of that mean = (a - b)^2 / 4, key)."""
    h = hashlib.sha256(open(scene_path, "rb").read())
    for m in scene["materials"].values():
        if m.get("path"):
            st = os.stat(m["path"])
            h.update(("%s:%d:%d" % (os.path.abspath(m["path"]), st.st_size, int(st.st_mtime))).encode())
    h.update(("%dx%d:%d:%d" % (res[0], res[1], scene["bounces"], ref_spp)).encode())
    key = "%s_%dx%d_%dspp_%s" % (os.path.splitext(os.path.basename(scene_path))[0], *res, ref_spp, h.hexdigest()[:12])
    cache = os.path.join(WORK_DIR, "reference_cache")
    os.makedirs(cache, exist_ok=True)
    halves = []
    for i, seed in enumerate((900001, 900002)):
        path = os.path.join(cache, "%s_%d.exr" % (key, i))
        if not os.path.exists(path):
            print("reference: rendering %s (narval, %d spp)" % (path, ref_spp // 2), flush=True)
            tmp = path[:-4] + ".tmp"
            render_narval(narval, scene_path, ref_spp // 2, seed, res, tmp + ".exr")
            os.replace(tmp + ".exr", path)
            for extra in (tmp + ".png", tmp + ".stats.json"):  # the display image and stats: not needed
                os.remove(extra)
        halves.append(read_exr_rgb(path))
    mean_exr = os.path.join(cache, key + "_mean.exr")
    write_exr_rgb(mean_exr, 0.5 * (halves[0] + halves[1]))
    return mean_exr, 0.5 * (halves[0] + halves[1]), 0.25 * (halves[0] - halves[1]) ** 2, key


def run_race(args):
    """narval's time against Mitsuba's at equal relMSE over the spp ladder (README.md, "Race"); race.json."""
    scene = load_narval_scene(args.narval, args.scene, args.resolution)
    res = (scene["width"], scene["height"])
    ladder = [int(x) for x in args.ladder.split(",")]
    narval_args = shlex.split(args.narval_args or "")
    out_dir = args.out or os.path.join(WORK_DIR, "race_" + os.path.splitext(os.path.basename(args.scene))[0])
    os.makedirs(out_dir, exist_ok=True)
    ref_exr, ref, ref_var, key = reference(args.scene, scene, res, args.ref_spp, args.narval)
    # relMSE = mean (x - ref)^2 / (ref^2 + 1e-2) (`narval compare`'s rel_mse); E[(x - ref)^2] =
    # Var(x) + Bias^2 + Var(ref): the reference's own share is subtracted.
    ref_share = float(np.mean(ref_var / (ref ** 2 + 1e-2)))
    rel_mse = lambda exr: run_json(args.narval, ["compare", ref_exr, exr, "--json"])["rel_mse"]  # noqa: E731
    mscene = load_mitsuba_scene(scene, os.path.join(out_dir, "mitsuba"))
    # Warm-ups: Mitsuba traces and compiles its kernel at each size; narval builds its program.
    for n in ladder:
        render_mitsuba(mscene, n, 7)
    render_narval(args.narval, args.scene, ladder[0], 7, res, os.path.join(out_dir, "warmup.exr"), narval_args)
    rows = {"narval": {n: [] for n in ladder}, "mitsuba": {n: [] for n in ladder}}
    rung, mitsuba_rung = os.path.join(out_dir, "rung.exr"), os.path.join(out_dir, "rung_mitsuba.exr")
    record = lambda t, wall, kernel, exr: {"seconds": t, "wall_seconds": wall,  # noqa: E731
                                           "kernel_seconds": kernel, "rel_mse": rel_mse(exr)}
    for rep in range(args.reps):
        for n in ladder:  # time: narval's kernel seconds, Mitsuba's wall seconds (and its kernel seconds)
            seed = 1000 * (rep + 1) + n
            st, tm = render_narval(args.narval, args.scene, n, seed, res, rung, narval_args), {}
            write_exr_rgb(mitsuba_rung, render_mitsuba(mscene, n, seed, tm))
            narval = record(st["kernel_seconds"], st["seconds"], st["kernel_seconds"], rung)
            other = record(tm["wall_seconds"], tm["wall_seconds"], tm["kernel_seconds"], mitsuba_rung)
            rows["narval"][n].append(narval)
            rows["mitsuba"][n].append(other)
            print("rep %d  %4d spp  narval %.3fs relMSE %.3g   mitsuba %.3fs relMSE %.3g" % (
                rep, n, narval["seconds"], narval["rel_mse"], other["seconds"], other["rel_mse"]), flush=True)
    summary = {}
    for name, per in rows.items():
        rungs = []
        for n in ladder:
            med = lambda k: float(np.median([r[k] for r in per[n]]))  # noqa: E731
            raw = float(np.mean([r["rel_mse"] for r in per[n]]))
            e, t, tk = raw - ref_share, med("seconds"), med("kernel_seconds")
            rungs.append({"spp": n, "seconds": t, "kernel_seconds": tk, "wall_seconds": med("wall_seconds"),
                          "rel_mse_raw": raw, "rel_mse": e,
                          "reference_limited": e <= 0.1 * raw,  # the reference's noise is most of it: unused
                          "rel_mse_x_seconds": e * t if e > 0 else None,
                          "rel_mse_x_kernel_seconds": e * tk if e > 0 else None})
        # relMSE x time is constant for an unbiased estimator whose time grows with its samples: its
        # geometric mean over the rungs the reference does not dominate.
        summary[name] = {"rungs": rungs}
        for key in ("rel_mse_x_seconds", "rel_mse_x_kernel_seconds"):
            good = [r[key] for r in rungs if r[key] and not r["reference_limited"]]
            summary[name][key] = float(np.exp(np.mean(np.log(good)))) if good else None
    ratio = {k: summary["narval"][k] / summary["mitsuba"][k] if summary["narval"][k] and summary["mitsuba"][k]
             else None for k in ("rel_mse_x_seconds", "rel_mse_x_kernel_seconds")}
    result = {"scene": os.path.abspath(args.scene), "resolution": list(res), "bounces": scene["bounces"],
              "ladder": ladder, "reps": args.reps, "narval_args": narval_args,
              "reference": {"key": key, "spp": args.ref_spp, "rel_mse_share": ref_share},
              "threads": int(os.environ.get("NARVAL_MITSUBA_THREADS", "2")), "summary": summary,
              "time_ratio_narval_over_mitsuba": ratio["rel_mse_x_seconds"],
              "kernel_time_ratio_narval_over_mitsuba": ratio["rel_mse_x_kernel_seconds"],
              "interpolated": interpolated_ratios(summary), "date": time.strftime("%Y-%m-%d"),
              "raw": {k: {str(n): v for n, v in per.items()} for k, per in rows.items()}}
    Path(out_dir, "race.json").write_text(json.dumps(result, indent=1))
    lines = ["| renderer | spp | seconds | kernel s | relMSE | relMSE x s |", "|---|---:|---:|---:|---:|---:|"]
    lines += ["| %s | %d | %.3f | %.3f | %.3g%s | %s |" % (
                  name, g["spp"], g["seconds"], g["kernel_seconds"], g["rel_mse"],
                  " (ref.-limited)" if g["reference_limited"] else "",
                  "%.3g" % g["rel_mse_x_seconds"] if g["rel_mse_x_seconds"] else "-")
              for name in ("narval", "mitsuba") for g in summary[name]["rungs"]]
    fmt = lambda x, f="%.3g": f % x if x else "n/a"  # noqa: E731
    at_rungs = ", ".join("%d spp %.2f" % (x["mitsuba_spp"], x["ratio"]) for x in result["interpolated"])
    lines.append("\nTime at equal relMSE, narval / Mitsuba: **%s** (relMSE x seconds: narval %s, Mitsuba %s; "
                 "reference share %.2e subtracted); kernel time against kernel time: %s; interpolated at "
                 "Mitsuba's rungs: %s" % (fmt(ratio["rel_mse_x_seconds"], "%.2f"),
                                          fmt(summary["narval"]["rel_mse_x_seconds"]),
                                          fmt(summary["mitsuba"]["rel_mse_x_seconds"]), ref_share,
                                          fmt(ratio["rel_mse_x_kernel_seconds"], "%.2f"), at_rungs))
    print("\n" + "\n".join(lines))
    return result


def interpolated_ratios(summary):
    """narval's time at Mitsuba's relMSE per rung, interpolated on log-log between narval's rungs."""
    n = sorted((r["rel_mse"], r["seconds"]) for r in summary["narval"]["rungs"] if r["rel_mse"] > 0)
    out = []
    for r in summary["mitsuba"]["rungs"]:
        e = r["rel_mse"]
        for (e0, t0), (e1, t1) in zip(n, n[1:]):
            if e > 0 and e0 <= e <= e1:
                f = 0.0 if e1 == e0 else math.log(e / e0) / math.log(e1 / e0)
                tn = math.exp(math.log(t0) + f * math.log(t1 / t0))
                out.append({"mitsuba_spp": r["spp"], "rel_mse": e, "mitsuba_seconds": r["seconds"],
                            "narval_seconds": tn, "ratio": tn / r["seconds"]})
                break
    return out


def write_picture(compare_dir, out, diff_scale):
    """narval's mean image and Mitsuba's through narval's default display transform (Narkowicz's ACES fit,
    then the sRGB curve: kernels/shared/tonemap.h) and |narval - Mitsuba| x diff_scale (the sRGB curve)."""
    narval, other = (np.load(os.path.join(compare_dir, n + "_mean.npy")) for n in ("narval", "mitsuba"))
    aces = lambda x: np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0, 1)  # noqa: E731
    srgb = lambda v: np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)  # noqa: E731
    panels = [aces(np.clip(narval, 0, 1e4)), aces(np.clip(other, 0, 1e4)),
              np.clip(abs(narval - other) * diff_scale, 0, 1)]
    montage([[((srgb(x) * 255 + 0.5).astype(np.uint8), "") for x in panels]], out, gap=4)


def main():
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `... | head` ends quietly
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    # No abbreviations: --narval must not read as race's --narval-args.
    c, r = (sub.add_parser(name, allow_abbrev=False) for name in ("compare", "race"))
    for q, size in ((c, "64x48"), (r, "160x120")):
        q.add_argument("scene")
        q.add_argument("--narval", default=os.environ.get("NARVAL_BINARY", os.path.join(REPO, "build", "narval")),
                       help="narval binary (default: $NARVAL_BINARY, else build/narval)")
        q.add_argument("--resolution", type=lambda t: tuple(int(v) for v in t.split("x")), default=size)
        q.add_argument("--out", help="output folder (default build/vs_mitsuba/%s_SCENE)" % q.prog.split()[-1])
    c.add_argument("--set", action="append", default=[], help="PATH=VALUE: a scene override, for both renderers")
    options(c, spp=32, seeds=4)
    c.add_argument("--seed-offset", type=int, default=0, help="narval seeds OFFSET+1.., Mitsuba 1000+OFFSET..")
    c.add_argument("--perturb", choices=PERTURBATIONS, action="append", default=[],
                   help="translate with this deliberate mistake (README.md)")
    r.add_argument("--narval-args", default="", help='options of narval\'s rung renders ("--majorant global")')
    options(r, ladder="4,8,16,32,64,128", reps=3, ref_spp=8192)
    pic = sub.add_parser("picture")
    pic.add_argument("compare_dir", help="a compare run's folder (build/vs_mitsuba/compare_SCENE)")
    pic.add_argument("out", help="the PNG to write")
    pic.add_argument("--diff-scale", type=float, default=10.0, help="shows |narval - Mitsuba| x this")
    args = ap.parse_args()
    reason = ensure_environment()
    if args.command == "picture" and not reason:
        need_pillow("vs_mitsuba.py")
        return write_picture(args.compare_dir, args.out, args.diff_scale)
    if reason or not os.access(args.narval, os.X_OK):
        print("vs_mitsuba: " + (reason or "no narval binary at %s (--narval or $NARVAL_BINARY)" % args.narval),
              file=sys.stderr)
        return 2
    if args.command == "race":
        run_race(args)
        return 0
    PERTURB.update(args.perturb)
    name = os.path.splitext(os.path.basename(args.scene))[0]
    out = args.out or os.path.join(WORK_DIR, "compare_" + name + "".join("_" + x for x in sorted(args.perturb)))
    return 0 if run_compare(args.scene, args.spp, args.seeds, args.resolution, args.narval, out, args.set,
                            args.seed_offset)["agree"] else 1


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (ValueError, OSError, KeyError, RuntimeError) as e:
        print("vs_mitsuba: error: %s%s" % (type(e).__name__ + ": " if isinstance(e, KeyError) else "", e),
              file=sys.stderr)
        # 2: a scene or grid narval would refuse, a missing file; 1: narval or Mitsuba failed
        sys.exit(1 if isinstance(e, RuntimeError) else 2)
