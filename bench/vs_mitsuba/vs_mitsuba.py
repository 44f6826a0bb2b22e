#!/usr/bin/env python3
"""vs_mitsuba.py: narval's path tracer against Mitsuba 3 (a bench tool, never a test dependency).

  translate SCENE.json OUT_DIR      narval scene -> Mitsuba 3 scene (OUT_DIR/mitsuba_scene.json, the
                                    dict for mi.load_dict with 4x4 matrices as lists, + .vol grids)
  compare SCENE.json [--spp N] [--seeds K] [--resolution WxH]
                                    K renders per renderer; image means, standard errors, z and a
                                    per-tile chi^2; exit 1 when they disagree
  race SCENE.json [--narval-args "..."]
                                    time at equal relMSE against a cached converged narval reference
  check                             two tiny analytic scenes (and a tiny grid) through `compare`;
                                    exit 77 when the Mitsuba environment does not exist

Run it with the environment of setup.sh (build/mitsuba-venv, or $NARVAL_MITSUBA_VENV); started by
another interpreter it re-executes itself with that one. README.md beside this file explains the
conventions matched and the statistics.
"""
import argparse
import hashlib
import json
import math
import os
import re
import shlex
import signal
import struct
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))  # bench/: what the bench scripts share
from scene_env import resolved_scene, run_narval, volume_path  # noqa: E402
DEFAULT_VENV = os.path.join(REPO, "build", "mitsuba-venv")
DEFAULT_NARVAL = os.path.join(REPO, "build", "narval")
WORK_DIR = os.path.join(REPO, "build", "vs_mitsuba")
EXIT_SKIP = 77  # ctest's / automake's "skipped"

# ---- decision thresholds (compare) ------------------------------------------------------------
# Each channel's image-mean difference is a z score against the combined standard error. Under
# agreement z is close to standard normal (the image mean averages W*H*K*spp independent paths),
# so |z| > 4 has a two-sided probability of 6.3e-5 per channel, 1.9e-4 for the three channels.
Z_LIMIT = 4.0
# The 4x4 tiles give a chi^2 of the tile differences against their standard errors (each tile one
# degree of freedom: the mean of its three channels' z^2, see tile_chi2); disagreement when its
# upper tail probability is below 1e-4.
# Together: a false alarm on agreeing renderers about 3 times in 10^4 (99.97% confidence), while a
# mirrored image or a misplaced grid moves the tiles by tens of standard errors.
CHI2_P_LIMIT = 1e-4
TILES = 4
# Deliberate mistakes in the translation (compare --perturb NAME), to show that compare can fail.
PERTURBATIONS = {
    "mirror": "camera image mirrored left-right (camera x along +right in Mitsuba's left-handed x)",
    "hg_sign": "Henyey-Greenstein g negated",
    "light_back": "rectangle lights emit along +z local (narval: -z)",
    "depth": "max_depth = bounces (one scattering event fewer)",
    "no_pad": "grid not padded: Mitsuba's clamp-to-edge repeats the outer voxels up to the box faces",
    "half_voxel": "voxel centres at i instead of i + 0.5 (grid shifted by half a voxel)",
    "rotation_order": "rotation applied Z, Y, X instead of narval's X, Y, Z",
}
PERTURB = set()
# Differences below this fraction of a tile's (or the image's) mean are float arithmetic, not a
# convention: narval and Mitsuba both compute in float32 (different orders and exp/pow), which
# moves noise-free values by 1e-7..1e-5 relative (measured: a background of 0.05 comes back as
# 0.04999997 from Mitsuba). It is added in quadrature to every standard error.
NUMERIC_TOLERANCE = 1e-4


# ================================================================================================
# Environment: run under the venv's interpreter, with a libLLVM that Dr.Jit's backend can use.
# ================================================================================================

def venv_dir():
    return os.environ.get("NARVAL_MITSUBA_VENV") or DEFAULT_VENV


def ensure_environment(command):
    """Re-executes under the venv's python when needed. Returns None when Mitsuba can be imported,
    else a one-line reason (the caller exits 77 for `check`, 2 otherwise)."""
    venv = venv_dir()
    py = os.path.join(venv, "bin", "python")
    if not os.path.exists(py):
        return "no Mitsuba environment at %s (run bench/vs_mitsuba/setup.sh)" % venv
    llvm_file = os.path.join(venv, "drjit_libllvm_path")
    if "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm_file):
        with open(llvm_file) as f:
            os.environ["DRJIT_LIBLLVM_PATH"] = f.read().strip()
    # sys.prefix is the venv's root when this interpreter runs inside it (once: no exec loop).
    if os.path.realpath(sys.prefix) != os.path.realpath(venv) and not os.environ.get("NARVAL_VS_MITSUBA_EXEC"):
        os.environ["NARVAL_VS_MITSUBA_EXEC"] = "1"
        os.execv(py, [py, os.path.abspath(__file__)] + sys.argv[1:])
    try:
        import mitsuba  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        return "the environment at %s cannot import Mitsuba (%s; run bench/vs_mitsuba/setup.sh)" % (venv, e)
    return None


_mi = None


def mitsuba():
    """The mitsuba module, with the llvm_ad_rgb variant and two worker threads (the bench machine has
    two cores, and narval's PoCL device uses both)."""
    global _mi
    if _mi is None:
        import drjit as dr
        import mitsuba as mi
        mi.set_variant("llvm_ad_rgb")
        dr.set_thread_count(int(os.environ.get("NARVAL_MITSUBA_THREADS", "2")))
        _mi = mi
    return _mi


try:
    import numpy as np  # the venv's (Debian's numpy, which pyopenvdb is built against)
except ImportError:  # another interpreter: main() re-executes under the venv before numpy is used
    np = None


# ================================================================================================
# narval's scene, as `narval scene --resolved` writes it: every default the loader took filled in
# ================================================================================================

def scene_overrides(narval_args):
    """The scene changes among narval render options: --set PATH=VALUE... and --bounces N, so the
    Mitsuba side renders the same scene."""
    out, i = [], 0
    while i < len(narval_args):
        a = narval_args[i]
        if a.startswith("--set="):
            out.append(a[len("--set="):])
        elif a == "--set":
            while i + 1 < len(narval_args) and not narval_args[i + 1].startswith("-") and "=" in narval_args[i + 1]:
                i += 1
                out.append(narval_args[i])
        elif a == "--bounces" and i + 1 < len(narval_args):
            i += 1
            out.append("renderer.bounces=" + narval_args[i])
        elif a.startswith("--bounces="):
            out.append("renderer.bounces=" + a[len("--bounces="):])
        i += 1
    return out


def load_narval_scene(narval, path, resolution=None, overrides=()):
    """The parts of the scene the path tracer uses, as narval resolves it (`narval scene --resolved`,
    `overrides` being --set PATH=VALUE strings), as plain dicts: materials by name (a volume's grid
    path found as the loader finds it), primitives with their material, camera, size, bounces."""
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
    floats = lambda obj: {k: [float(x) for x in v] if isinstance(v, list) else float(v) for k, v in obj.items()}
    prims = [dict(floats(p["transform"]), name=p.get("name", ""), type=p["type"], material=materials[p["materialName"]])
             for p in doc["primitives"]]
    r = doc["renderer"]
    return {"path": os.path.abspath(path), "materials": materials, "primitives": prims, "camera": floats(doc["camera"]),
            "width": r["resolution"][0], "height": r["resolution"][1], "spp": r["spp"], "bounces": r["bounces"],
            "background": doc["background"]}


# ================================================================================================
# ================================================================================================
# Grids, read as narval reads them (host/volume/vdb_io.cpp, vol_io.cpp)
# ================================================================================================

def read_grid(path, grid_name):
    """(data[x, y, z] float32, index_to_world 3x4 float64). narval's index space: voxel i covers
    [i, i+1], centre i + 0.5; a .vdb grid is its active voxel bounding box copied densely
    (openvdb::tools::copyToDense: inactive voxels inside the box keep their value), placed in the file's
    world by the file's affine map composed with the shift by bbox.min - 0.5."""
    if path.lower().endswith(".vol"):
        return read_vol_text(path), np.hstack([np.eye(3), np.zeros((3, 1))])
    import pyopenvdb as vdb
    grid = vdb.read(path, grid_name)
    if not isinstance(grid, vdb.FloatGrid):
        raise ValueError("%s: grid %r is not a float grid" % (path, grid_name))
    if not grid.transform.isLinear:
        raise ValueError("%s: grid %r has a non-affine transform (narval refuses it too)" % (path, grid_name))
    lo, hi = grid.evalActiveVoxelBoundingBox()
    dims = tuple(h - l + 1 for l, h in zip(lo, hi))
    data = np.zeros(dims, dtype=np.float32)
    grid.copyToArray(data, ijk=lo)
    # The file's affine map, read off at the origin and the unit axes of vdb index space.
    o = np.array(grid.transform.indexToWorld((0.0, 0.0, 0.0)))
    axes = [np.array(grid.transform.indexToWorld(tuple(float(i == a) for i in range(3)))) - o for a in range(3)]
    linear = np.stack(axes, axis=1)
    shift = np.array(lo, dtype=np.float64) - 0.5  # our u -> vdb ijk = u - 0.5 + bbox.min
    m = np.hstack([linear, (o + linear @ shift)[:, None]])
    check_density(data, path)
    return data, m


def read_vol_text(path):
    """The dissertation's text .vol: "X Y Z", then X*Y*Z floats, x fastest."""
    with open(path) as f:
        tokens = f.read().split()
    nx, ny, nz = (int(t) for t in tokens[:3])
    values = np.array(tokens[3:], dtype=np.float64).astype(np.float32)
    if values.size != nx * ny * nz:
        raise ValueError("%s: %d values for %dx%dx%d" % (path, values.size, nx, ny, nz))
    data = values.reshape(nz, ny, nx).transpose(2, 1, 0).copy()
    check_density(data, path)
    return data


def check_density(data, path):
    if not np.all(np.isfinite(data)) or (data < 0).any():
        raise ValueError("%s: densities must be finite and >= 0 (narval refuses this grid)" % path)


def write_mitsuba_vol(path, data_xyzc):
    """Mitsuba's binary .vol (version 3, float32): header, then values x fastest, channels innermost.
    The bounding box in the header is [0,1]^3: gridvolume's to_world places it (use_grid_bbox off)."""
    nx, ny, nz, nc = data_xyzc.shape
    with open(path, "wb") as f:
        f.write(b"VOL" + bytes([3]))
        f.write(struct.pack("<iiiii", 1, nx, ny, nz, nc))
        f.write(struct.pack("<6f", 0, 0, 0, 1, 1, 1))
        f.write(np.ascontiguousarray(data_xyzc.transpose(2, 1, 0, 3), dtype="<f4").tobytes())


# ================================================================================================
# Transforms (host/render/scene_upload.cpp)
# ================================================================================================

def rotation_matrix(deg):
    """narval's R = Rz . Ry . Rx (X first), angles in degrees, right-handed."""
    ax, ay, az = (math.radians(a) for a in deg)
    cx, sx, cy, sy, cz, sz = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay), math.cos(az), math.sin(az)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    if "rotation_order" in PERTURB:
        return rx @ ry @ rz
    return rz @ ry @ rx


def affine(linear, translation):
    m = np.eye(4)
    m[:3, :3] = linear
    m[:3, 3] = translation
    return m


def primitive_matrix(p):
    """M = T . R . S (scene.h Transform)."""
    return affine(rotation_matrix(p["rotation"]) @ np.diag(p["scale"]), p["position"])


def as3x4(m):
    return np.vstack([m, [0, 0, 0, 1]]) if m.shape == (3, 4) else m


# ================================================================================================
# translate: narval scene -> Mitsuba 3 scene description
# ================================================================================================

def rgb(v, unbounded=False):
    """A constant RGB (exact in the rgb variants). `unbounded` lets a coefficient exceed 1
    (Mitsuba's check for reflectances)."""
    if unbounded:  # the `srgb` plugin itself: the {"type": "rgb"} shorthand takes no options
        return {"type": "srgb", "color": [float(x) for x in v], "unbounded": True}
    return {"type": "rgb", "value": [float(x) for x in v]}


def translate_scene(scene, out_dir):
    """Writes OUT_DIR/mitsuba_scene.json (mi.load_dict's dict; every "to_world" a 4x4 list) and the
    grid as a Mitsuba .vol; returns the dict. Only what narval's path tracer uses."""
    os.makedirs(out_dir, exist_ok=True)
    d = {"type": "scene",
         # max_depth counts the camera vertex: narval's `bounces` real scattering events each with
         # next-event estimation, then the continuation ray's emitter or background, is depth
         # bounces + 1. Russian roulette (rr_depth) is put out of reach: depth never exceeds max_depth.
         "integrator": {"type": "volpath", "max_depth": scene["bounces"] + (0 if "depth" in PERTURB else 1),
                        "rr_depth": scene["bounces"] + 100}}
    medium_box = None  # (4x4 index->world of the medium's box, dims)
    notes = []
    n_light = 0
    for p in scene["primitives"]:
        mat = p["material"]
        if p["type"] == "point":
            # A point light of intensity I (W/sr): radiance I / d^2 at distance d (light.h).
            d["light_%d" % n_light] = {"type": "point", "position": p["position"], "intensity": rgb(mat["albedo"])}
            n_light += 1
        elif p["type"] == "rectangle":
            d["light_%d" % n_light] = rectangle_light(p, mat)
            n_light += 1
        elif p["type"] == "volume":
            medium, box, extra = translate_volume(p, mat, out_dir)
            medium_box = box
            d["medium"] = medium
            d["volume_box"] = extra
            notes += medium.pop("_notes", [])
    if any(c > 0 for c in scene["background"]):
        d["background"] = {"type": "constant", "radiance": rgb(scene["background"])}
    d["sensor"] = translate_camera(scene, medium_box)
    with open(os.path.join(out_dir, "mitsuba_scene.json"), "w") as f:
        json.dump(d, f, indent=1)
    return d, notes


def rectangle_light(p, mat):
    """narval: the unit quad [-0.5,0.5]^2 in local XY under T.R.S, one-sided, emitting along
    R.(0,0,-1) (the rotation alone; scene_upload.cpp buildLight), radiance = albedo, opaque with a black
    back (pathtrace.h). Mitsuba: `rectangle` is [-1,1]^2 with normal +z (the normal transforms by the
    inverse transpose), an `area` emitter is one-sided along it. to_world = T.R.diag(|sx|/2, -|sy|/2,
    -1): the same point set (the quad is symmetric), normal R.(0,0,-1), no reflection, narval's z
    scale ignored as narval ignores it. A black diffuse BSDF makes it opaque and dark behind, as
    narval's rectangles are (Mitsuba's default BSDF would reflect 50%)."""
    sx, sy = abs(p["scale"][0]), abs(p["scale"][1])
    flip = 1.0 if "light_back" in PERTURB else -1.0
    m = affine(rotation_matrix(p["rotation"]) @ np.diag([0.5 * sx, 0.5 * sy * flip, flip]), p["position"])
    return {"type": "rectangle", "to_world": m.tolist(),
            "emitter": {"type": "area", "radiance": rgb(mat["albedo"])},
            "bsdf": {"type": "diffuse", "reflectance": rgb([0, 0, 0])}}


def translate_volume(p, mat, out_dir):
    if mat.get("emission"):
        raise ValueError("the volume emits (emission): not translated (Mitsuba's medium emission is another "
                         "model; compare scenes without emission)")
    D = mat["density"]
    sig_a, sig_s = np.array(mat["absorption"]), np.array(mat["scattering"])
    k = sig_a + sig_s  # sigma_t per unit density before D, per channel (scene_upload.cpp)
    albedo = np.where(k > 0, sig_s / np.where(k > 0, k, 1), 0.0)
    grey = bool(np.all(sig_a == sig_a[0]) and np.all(sig_s == sig_s[0]))
    g = -mat["g"] if "hg_sign" in PERTURB else mat["g"]
    phase = {"type": "hg", "g": g} if mat["phaseFunction"] == "hg" and g != 0 else {"type": "isotropic"}
    M = primitive_matrix(p)
    notes = []
    if mat["path"] is None:
        # Homogeneous: the unit cube itself, density 1 (index box [0,1]^3 -> [-0.5,0.5]^3).
        dims = np.array([1.0, 1.0, 1.0])
        index_to_world = M @ affine(np.eye(3), [-0.5, -0.5, -0.5])
        medium = {"type": "homogeneous", "sigma_t": rgb(k, unbounded=True), "albedo": rgb(albedo), "scale": D,
                  "phase": phase, "sample_emitters": True}
    else:
        data, file_map = read_grid(mat["path"], mat["grid"])
        dims = np.array(data.shape, dtype=np.float64)
        if mat["gridSpace"] == "file":
            # The file's own placement (a .vol's is the identity: index = world), then M on top.
            index_to_world = M @ as3x4(file_map)
        else:
            # "unit": the grid's index box [0, n] fills the primitive's unit cube.
            index_to_world = M @ affine(np.diag(1.0 / dims), [-0.5, -0.5, -0.5])
            lin = file_map[:, :3]
            if abs(lin - np.diag(np.diag(lin))).max() > 1e-9 * abs(lin).max():
                notes.append("the grid's file transform rotates or shears; unit grid space drops it, as narval does")
        # Mitsuba's gridvolume clamps at its edge (dr.Texture, wrap_mode clamp) where narval reads 0
        # beyond the outermost voxels: pad one zero voxel on every side and place the padded grid
        # over the index box [-1, n+1], so trilinear lookups agree everywhere inside [0, n].
        padded = np.pad(data, 1)
        pad_box = affine(np.diag(dims + 2), [-1, -1, -1])
        if "no_pad" in PERTURB:
            padded, pad_box = data, affine(np.diag(dims), [0, 0, 0])
        if "half_voxel" in PERTURB:
            pad_box = affine(np.eye(3), [0.5, 0.5, 0.5]) @ pad_box
        if grey:
            values, scale = padded[..., None], D * float(k[0])
        else:
            values, scale = padded[..., None] * k.astype(np.float32)[None, None, None, :], D
        vol_path = os.path.join(out_dir, "density.vol")
        write_mitsuba_vol(vol_path, values.astype(np.float32))
        grid_to_world = index_to_world @ pad_box
        medium = {"type": "heterogeneous", "scale": scale, "phase": phase, "sample_emitters": True,
                  # Spectral tracking only where sigma_t differs per channel (otherwise the same
                  # estimate with one channel's majorant).
                  "has_spectral_extinction": not grey,
                  "sigma_t": {"type": "gridvolume", "filename": vol_path, "to_world": grid_to_world.tolist(),
                              "filter_type": "trilinear", "raw": True},
                  "albedo": {"type": "constvolume", "value": rgb(albedo)}}
    # The boundary is the box [0, dims] in index space: Mitsuba's `cube` is [-1,1]^3. A reflecting
    # transform (negative determinant) would turn the cube's normals inwards and swap interior and
    # exterior, so it is composed with x -> -x, which maps the cube onto itself.
    to_box = affine(np.diag(dims / 2), dims / 2)
    cube_to_world = index_to_world @ to_box
    if np.linalg.det(cube_to_world[:3, :3]) < 0:
        cube_to_world = cube_to_world @ np.diag([-1.0, 1, 1, 1])
    medium["_notes"] = notes
    box = {"type": "cube", "to_world": cube_to_world.tolist(), "bsdf": {"type": "null"},
           "interior": {"type": "ref", "id": "medium"}}
    return medium, (index_to_world, dims), box


def translate_camera(scene, medium_box):
    """narval (scene_upload.cpp buildCamera, camera.h): forward = normalize(lookAt - position),
    right = normalize(forward x up), up' = right x forward; pixel (0,0) top left, image x along right;
    vfov vertical. Mitsuba's camera space has +x to the image's left, +y up, +z forward, so
    to_world's columns are (-right, up', forward, position). A box filter of radius 0.5 weighs each
    sample uniformly in its own pixel, as narval's uniform jitter does (Mitsuba's default is a
    Gaussian)."""
    c = scene["camera"]
    pos = np.array(c["position"])
    fwd = np.array(c["lookAt"]) - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, np.array(c["up"]))
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = (right if "mirror" in PERTURB else -right), up, fwd, pos
    sensor = {"type": "perspective", "fov": c["vfov"], "fov_axis": "y", "to_world": m.tolist(),
              # Mitsuba starts camera rays at the near plane: keep it well inside the first voxel.
              "near_clip": 1e-4, "far_clip": 1e7,
              "film": {"type": "hdrfilm", "width": scene["width"], "height": scene["height"],
                       "rfilter": {"type": "box"}, "pixel_format": "rgb", "sample_border": False},
              "sampler": {"type": "independent", "sample_count": 1}}
    if c["aperture"] > 0:
        # Thin lens: lens radius and a focal plane at `focus` along the view axis (camera.h).
        sensor.update({"type": "thinlens", "aperture_radius": c["aperture"], "focus_distance": c["focus"]})
    if medium_box is not None:
        index_to_world, dims = medium_box
        u = np.linalg.solve(index_to_world[:3, :3], pos - index_to_world[:3, 3])
        if np.all(u > 0) and np.all(u < dims):
            sensor["medium"] = {"type": "ref", "id": "medium"}  # the camera sits inside the medium
    return sensor


def to_mitsuba_objects(d):
    """The JSON form (4x4 lists) -> what mi.load_dict takes: transforms as ScalarTransform4f; the
    medium declared once at the top level and referenced by the box (and a camera inside it)."""
    mi = mitsuba()

    def conv(v):
        if isinstance(v, dict):
            return {k: (mi.ScalarTransform4f(x) if k == "to_world" else conv(x)) for k, x in v.items()}
        return v
    return conv(d)


def load_mitsuba_scene(scene, out_dir):
    d, notes = translate_scene(scene, out_dir)
    mi = mitsuba()
    return mi.load_dict(to_mitsuba_objects(d)), notes


# Mitsuba renders all samples of a call as one wavefront (a few hundred bytes of state per lane):
# past this many lanes (W*H*spp) a render is split into passes of fewer samples.
MAX_WAVEFRONT = 1 << 24


def render_mitsuba(mscene, spp, seed, timings=None):
    """Mitsuba's image (HxWx3) of spp samples per pixel. With `timings` (a dict) it also records the
    wall seconds of mi.render + dr.eval and the seconds its JIT kernels ran (Dr.Jit's kernel
    history, which excludes tracing and compilation)."""
    mi = mitsuba()
    import drjit as dr
    w, h = mscene.sensors()[0].film().crop_size()
    passes = max(1, -(-w * h * spp // MAX_WAVEFRONT))
    per = [spp // passes + (1 if i < spp % passes else 0) for i in range(passes)]
    total = None
    wall = kernel = 0.0
    if timings is not None:
        dr.set_flag(dr.JitFlag.KernelHistory, True)
        dr.kernel_history()  # drop what earlier work left
    for i, n in enumerate(per):
        t = time.perf_counter()
        img = mi.render(mscene, spp=n, seed=seed + 7919 * i)  # distinct seeds per pass
        dr.eval(img)
        dr.sync_thread()
        wall += time.perf_counter() - t
        arr = np.array(img, dtype=np.float64)[..., :3] * (n / spp)
        total = arr if total is None else total + arr
    if timings is not None:
        kernel = sum(k.get("execution_time", 0.0) for k in dr.kernel_history()) * 1e-3
        dr.set_flag(dr.JitFlag.KernelHistory, False)
        timings.update({"wall_seconds": wall, "kernel_seconds": kernel, "passes": passes})
    return total


# ================================================================================================
# narval
# ================================================================================================

def read_exr_rgb(path):
    mi = mitsuba()
    bmp = mi.Bitmap(path)
    for name, layer in bmp.split():
        if name == "<root>":
            return np.array(layer, dtype=np.float64)[..., :3]
    raise ValueError("%s: no RGB layer" % path)


def render_narval(narval, scene_path, spp, seed, resolution, out_exr, extra_args=(), stats=True):
    """narval render --algorithm pathtrace; returns (image HxWx3, stats dict)."""
    stats_path = out_exr[:-4] + ".stats.json"
    # A failure raises scene_env.NarvalError, a RuntimeError.
    run_narval(narval, ["render", scene_path, "--algorithm", "pathtrace", "--spp", spp, "--resolution",
                        "%dx%d" % resolution, "--seed", seed, "-o", out_exr, "-q"]
               + (["--stats-json", stats_path] if stats else []) + list(extra_args))
    st = {}
    if stats:
        with open(stats_path) as f:
            st = json.load(f)
        if any(st.get("status", {}).values()):
            print("warning: narval status flags %s" % st["status"], file=sys.stderr)
    return read_exr_rgb(out_exr), st


# ================================================================================================
# Statistics
# ================================================================================================

def chi2_sf(x, k):
    """Upper tail P(X > x) of chi^2 with k degrees of freedom: the regularised upper incomplete gamma
    Q(k/2, x/2), by its power series below a + 1 and its continued fraction above."""
    if x <= 0:
        return 1.0
    if math.isinf(x):
        return 0.0
    a, z = 0.5 * k, 0.5 * x
    log_pre = a * math.log(z) - z - math.lgamma(a)
    if z < a + 1:
        term = total = 1.0 / a
        n = 0
        while abs(term) > 1e-15 * abs(total) and n < 10000:
            n += 1
            term *= z / (a + n)
            total += term
        return max(0.0, 1.0 - math.exp(log_pre) * total)
    # Continued fraction for Q (modified Lentz).
    tiny = 1e-300
    b = z + 1 - a
    c, dd = 1 / tiny, 1 / b
    h = dd
    for i in range(1, 10000):
        an = -i * (i - a)
        b += 2
        dd = an * dd + b
        dd = tiny if abs(dd) < tiny else dd
        c = b + an / c
        c = tiny if abs(c) < tiny else c
        dd = 1 / dd
        delta = dd * c
        h *= delta
        if abs(delta - 1) < 1e-15:
            break
    return math.exp(log_pre) * h


def pooled_stats(images):
    """images: K renders (K x H x W x 3) of one renderer with independent seeds.
    Returns the per-pixel mean over the renders and the per-pixel variance of that mean (per RGB
    channel). Pixels are independent estimates (each pixel's paths have their own random numbers),
    so the variance of any average of n pixels is the sum of their variances over n^2: estimated
    from each pixel's spread over the K renders it has n*(K-1) degrees of freedom, far more than
    the K-1 of the spread of K image means (that one is reported too, for information)."""
    images = np.asarray(images, dtype=np.float64)
    k = images.shape[0]
    return images.mean(axis=0), images.var(axis=0, ddof=1) / k


def region_stats(mean, var, sl):
    """Mean (3) of the pixels in slice `sl` and the variance (3) of that mean."""
    m = mean[sl].reshape(-1, 3)
    v = var[sl].reshape(-1, 3)
    n = m.shape[0]
    return m.mean(axis=0), v.sum(axis=0) / (n * n)


def tile_slices(h, w, tiles=TILES):
    ys = np.linspace(0, h, tiles + 1).round().astype(int)
    xs = np.linspace(0, w, tiles + 1).round().astype(int)
    return [(slice(ys[j], ys[j + 1]), slice(xs[i], xs[i + 1])) for j in range(tiles) for i in range(tiles)
            if ys[j + 1] > ys[j] and xs[i + 1] > xs[i]]


def tile_chi2(diff, var, scale):
    """(q, dof) of one tile: q = the mean over RGB of z_c^2, z_c = diff_c / sqrt(var_c + tolerance^2).
    The channels of a tile are correlated (the same paths carry all three; a grey scene makes them
    identical), and some colour directions carry heavy-tailed noise that a few seeds underestimate
    (narval's spectral-tracking weights: measured 10-100x the variance seen at 4 seeds x 64 spp in
    the colour direction of a chromatic slab), so a full 3x3 Mahalanobis form raised false alarms.
    The mean of the three z^2 has mean 1 and a tail no heavier than chi^2 with 1 degree of freedom
    (reached when the channels are identical), so each tile counts as one degree of freedom: a
    conservative test. A tile with no noise at all (background only) counts no degree of freedom,
    but a difference beyond the numeric tolerance still adds to q."""
    tol2 = (NUMERIC_TOLERANCE * scale) ** 2 + 1e-300
    q = float(np.mean(diff ** 2 / (np.maximum(var, 0.0) + tol2)))
    return q, int(np.any(var > tol2))


def compare_images(narval_imgs, mitsuba_imgs):
    """z of the image-mean difference per channel, and chi^2 of the 4x4 tiles' mean differences."""
    mn, vn = pooled_stats(narval_imgs)
    mm, vm = pooled_stats(mitsuba_imgs)
    h, w = mn.shape[:2]
    whole = (slice(0, h), slice(0, w))
    mean_n, var_n = region_stats(mn, vn, whole)
    mean_m, var_m = region_stats(mm, vm, whole)
    se_n, se_m = np.sqrt(var_n), np.sqrt(var_m)
    # Across-seed standard errors (K-1 degrees of freedom), for information.
    seed_means_n = np.array([img.reshape(-1, 3).mean(axis=0) for img in narval_imgs])
    seed_means_m = np.array([img.reshape(-1, 3).mean(axis=0) for img in mitsuba_imgs])
    se_seed_n = seed_means_n.std(axis=0, ddof=1) / math.sqrt(len(narval_imgs))
    se_seed_m = seed_means_m.std(axis=0, ddof=1) / math.sqrt(len(mitsuba_imgs))
    z = []
    for c in range(3):
        # The numeric tolerance in quadrature (see tile_chi2): float rounding is not noise.
        se = math.sqrt(se_n[c] ** 2 + se_m[c] ** 2 + (NUMERIC_TOLERANCE * max(abs(mean_n[c]), abs(mean_m[c]))) ** 2)
        diff = mean_n[c] - mean_m[c]
        z.append(diff / se if se > 0 else 0.0)
    chi2, dof, worst = 0.0, 0, None
    for t, (sy, sx) in enumerate(tile_slices(h, w)):
        tn, tvn = region_stats(mn, vn, (sy, sx))
        tm, tvm = region_stats(mm, vm, (sy, sx))
        d = tn - tm
        c2, k = tile_chi2(d, tvn + tvm, max(np.abs(tn).max(), np.abs(tm).max()))
        chi2 += c2
        dof += k
        se = np.sqrt(tvn + tvm)
        tz = [float(d[c] / se[c]) if se[c] > 0 else 0.0 for c in range(3)]
        if worst is None or c2 / max(k, 1) > worst["chi2"] / max(worst["dof"], 1):
            worst = {"tile": [t % TILES, t // TILES], "chi2": float(c2), "dof": k, "z": tz}
    p = chi2_sf(chi2, dof) if dof else 1.0
    z = [float(x) for x in z]
    agree = bool(all(abs(x) <= Z_LIMIT for x in z) and p >= CHI2_P_LIMIT)
    return {"narval_mean": mean_n.tolist(), "mitsuba_mean": mean_m.tolist(),
            "narval_se": se_n.tolist(), "mitsuba_se": se_m.tolist(),
            "narval_se_across_seeds": se_seed_n.tolist(), "mitsuba_se_across_seeds": se_seed_m.tolist(),
            "relative_difference": [float((a - b) / b) if b else 0.0 for a, b in zip(mean_n, mean_m)],
            "z": z, "chi2": float(chi2), "dof": dof, "chi2_per_dof": float(chi2 / dof) if dof else 0.0,
            "chi2_p": p, "worst_tile": worst, "z_limit": Z_LIMIT, "chi2_p_limit": CHI2_P_LIMIT, "agree": agree}


# ================================================================================================
# compare
# ================================================================================================

def parse_resolution(text):
    m = re.fullmatch(r"(\d+)x(\d+)", text or "")
    if not m:
        raise argparse.ArgumentTypeError("expected WIDTHxHEIGHT, got %r" % text)
    return int(m.group(1)), int(m.group(2))


def scene_tag(path):
    return os.path.splitext(os.path.basename(path))[0]


def run_compare(scene_path, spp, seeds, resolution, narval, out_dir, narval_args=(), seed_offset=0, quiet=False):
    scene = load_narval_scene(narval, scene_path, resolution, scene_overrides(narval_args))
    res = (scene["width"], scene["height"])
    os.makedirs(out_dir, exist_ok=True)
    t0 = time.time()
    mscene, notes = load_mitsuba_scene(scene, os.path.join(out_dir, "mitsuba"))
    narval_imgs, mitsuba_imgs = [], []
    t_narval = t_mitsuba = 0.0
    for s in range(seeds):
        t = time.time()
        img, _ = render_narval(narval, scene_path, spp, seed_offset + s + 1, res,
                               os.path.join(out_dir, "narval_%d.exr" % s), narval_args, stats=False)
        t_narval += time.time() - t
        narval_imgs.append(img)
        t = time.time()
        mitsuba_imgs.append(render_mitsuba(mscene, spp, 1000 + seed_offset + s))
        t_mitsuba += time.time() - t
    result = compare_images(narval_imgs, mitsuba_imgs)
    result.update({"scene": os.path.abspath(scene_path), "resolution": list(res), "spp": spp, "seeds": seeds,
                   "seed_offset": seed_offset,
                   "bounces": scene["bounces"], "narval_args": list(narval_args), "notes": notes,
                   "perturbations": sorted(PERTURB),
                   "seconds": {"narval": t_narval, "mitsuba": t_mitsuba, "total": time.time() - t0}})
    np.save(os.path.join(out_dir, "narval_mean.npy"), np.mean(narval_imgs, axis=0).astype(np.float32))
    np.save(os.path.join(out_dir, "mitsuba_mean.npy"), np.mean(mitsuba_imgs, axis=0).astype(np.float32))
    with open(os.path.join(out_dir, "compare.json"), "w") as f:
        json.dump(result, f, indent=1)
    text = compare_summary(result)
    with open(os.path.join(out_dir, "compare.txt"), "w") as f:
        f.write(text + "\n")
    if not quiet:
        print(text)
    return result


def compare_summary(r):
    lines = ["%s at %dx%d, %d spp x %d seeds, bounces %d%s: %s" % (
        os.path.basename(r["scene"]), r["resolution"][0], r["resolution"][1], r["spp"], r["seeds"], r["bounces"],
        " (Mitsuba side perturbed: %s)" % ", ".join(r["perturbations"]) if r.get("perturbations") else "",
        "AGREE" if r["agree"] else "DISAGREE")]
    for c in range(3):
        lines.append("  %s  narval %.6g +- %.2g   mitsuba %.6g +- %.2g   rel diff %+.2e   z %+.2f" % (
            "RGB"[c], r["narval_mean"][c], r["narval_se"][c], r["mitsuba_mean"][c], r["mitsuba_se"][c],
            r["relative_difference"][c], r["z"][c]))
    wt = r["worst_tile"]
    lines.append("  tiles %dx%d: chi2 %.1f / %d dof = %.2f, p = %.3g%s" % (
        TILES, TILES, r["chi2"], r["dof"], r["chi2_per_dof"], r["chi2_p"],
        "; worst tile (%d,%d): chi2 %.1f / %d, z RGB %s" % (wt["tile"][0], wt["tile"][1], wt["chi2"], wt["dof"],
                                                          " ".join("%+.1f" % x for x in wt["z"])) if wt else ""))
    lines.append("  limits: |z| <= %.1f per channel, chi2 p >= %.0e" % (Z_LIMIT, CHI2_P_LIMIT))
    for n in r.get("notes", []):
        lines.append("  note: " + n)
    return "\n".join(lines)


# ================================================================================================
# race
# ================================================================================================

def rel_mse(img, ref):
    """pbrt/Mitsuba relMSE: mean over pixels and channels of (x - ref)^2 / (ref^2 + 1e-2)."""
    return float(np.mean((img - ref) ** 2 / (ref ** 2 + 1e-2)))


def file_identity(path):
    st = os.stat(path)
    return "%s:%d:%d" % (os.path.abspath(path), st.st_size, int(st.st_mtime))


def reference(scene_path, scene, res, ref_spp, narval, cache_dir):
    """A converged narval render, cached on disk keyed by the scene file's content, its grid files,
    the resolution, the bounces and the spp. Rendered as two halves with independent seeds: their
    difference estimates the reference's own noise, Var(ref) = E[(a - b)^2] / 4 per pixel."""
    h = hashlib.sha256()
    with open(scene_path, "rb") as f:
        h.update(f.read())
    for m in scene["materials"].values():
        if m.get("path"):
            h.update(file_identity(m["path"]).encode())
    h.update(("%dx%d:%d:%d" % (res[0], res[1], scene["bounces"], ref_spp)).encode())
    key = "%s_%dx%d_%dspp_%s" % (scene_tag(scene_path), res[0], res[1], ref_spp, h.hexdigest()[:12])
    os.makedirs(cache_dir, exist_ok=True)
    halves = []
    for i, seed in enumerate((900001, 900002)):
        path = os.path.join(cache_dir, "%s_%d.exr" % (key, i))
        if not os.path.exists(path):
            print("reference: rendering %s (narval, %d spp)" % (path, ref_spp // 2), flush=True)
            tmp = path[:-4] + ".tmp.exr"
            render_narval(narval, scene_path, ref_spp // 2, seed, res, tmp, stats=False)
            os.replace(tmp, path)
            os.remove(tmp[:-4] + ".png")  # narval's display image beside it: not needed
        halves.append(read_exr_rgb(path))
    a, b = halves
    ref = 0.5 * (a + b)
    ref_var = 0.25 * (a - b) ** 2
    return ref, ref_var, key


def run_race(args):
    scene = load_narval_scene(args.narval, args.scene, args.resolution)
    res = (scene["width"], scene["height"])
    ladder = [int(x) for x in args.ladder.split(",")]
    narval_args = shlex.split(args.narval_args or "")
    out_dir = args.out or os.path.join(WORK_DIR, "race_" + scene_tag(args.scene))
    os.makedirs(out_dir, exist_ok=True)
    ref, ref_var, key = reference(args.scene, scene, res, args.ref_spp, args.narval,
                                  os.path.join(WORK_DIR, "reference_cache"))
    denom = ref ** 2 + 1e-2
    # E[(x - ref)^2] = Var(x) + Bias^2 + Var(ref): the reference's own share is subtracted.
    ref_share = float(np.mean(ref_var / denom))
    mscene, notes = load_mitsuba_scene(scene, os.path.join(out_dir, "mitsuba"))
    # Warm-ups: Mitsuba traces and compiles its kernel on the first render at a size (Dr.Jit caches
    # it in memory and on disk); narval's first launch builds the program (PoCL caches it on disk).
    for n in ladder:
        render_mitsuba(mscene, n, 7)
    render_narval(args.narval, args.scene, ladder[0], 7, res, os.path.join(out_dir, "warmup.exr"), narval_args)
    rows = {"narval": {n: [] for n in ladder}, "mitsuba": {n: [] for n in ladder}}
    for rep in range(args.reps):
        for n in ladder:
            seed = 1000 * (rep + 1) + n
            img, st = render_narval(args.narval, args.scene, n, seed, res, os.path.join(out_dir, "rung.exr"),
                                    narval_args)
            rows["narval"][n].append({"seconds": st["kernel_seconds"], "wall_seconds": st["seconds"],
                                      "kernel_seconds": st["kernel_seconds"], "rel_mse": rel_mse(img, ref)})
            tm = {}
            img = render_mitsuba(mscene, n, seed, tm)
            rows["mitsuba"][n].append({"seconds": tm["wall_seconds"], "wall_seconds": tm["wall_seconds"],
                                       "kernel_seconds": tm["kernel_seconds"], "rel_mse": rel_mse(img, ref)})
            print("rep %d  %4d spp  narval %.3fs relMSE %.3g   mitsuba %.3fs relMSE %.3g" % (
                rep, n, rows["narval"][n][-1]["seconds"], rows["narval"][n][-1]["rel_mse"],
                rows["mitsuba"][n][-1]["seconds"], rows["mitsuba"][n][-1]["rel_mse"]), flush=True)
    summary = {}
    for name, per in rows.items():
        rungs = []
        for n in ladder:
            t = float(np.median([r["seconds"] for r in per[n]]))
            tk = float(np.median([r["kernel_seconds"] for r in per[n]]))
            e_raw = float(np.mean([r["rel_mse"] for r in per[n]]))
            e = e_raw - ref_share
            rungs.append({"spp": n, "seconds": t, "kernel_seconds": tk,
                          "wall_seconds": float(np.median([r["wall_seconds"] for r in per[n]])),
                          "rel_mse_raw": e_raw, "rel_mse": e,
                          # The reference's own noise is most of what was measured: not used.
                          "reference_limited": e <= 0.1 * e_raw,
                          "rel_mse_x_seconds": e * t if e > 0 else None,
                          "rel_mse_x_kernel_seconds": e * tk if e > 0 else None})
        summary[name] = {"rungs": rungs,
                         "rel_mse_x_seconds": efficiency(rungs, "rel_mse_x_seconds"),
                         "rel_mse_x_kernel_seconds": efficiency(rungs, "rel_mse_x_kernel_seconds")}

    def ratio_of(key):
        a, b = summary["narval"][key], summary["mitsuba"][key]
        return a / b if a and b else None
    ratio = ratio_of("rel_mse_x_seconds")
    ratio_kernel = ratio_of("rel_mse_x_kernel_seconds")
    interp = interpolated_ratios(summary)
    result = {"scene": os.path.abspath(args.scene), "resolution": list(res), "bounces": scene["bounces"],
              "ladder": ladder, "reps": args.reps, "reference": {"key": key, "spp": args.ref_spp,
                                                                 "rel_mse_share": ref_share},
              "narval_args": narval_args, "narval_time": "kernel_seconds of --stats-json (OpenCL events)",
              "mitsuba_time": "wall time of mi.render + dr.eval after a warm-up render at that spp",
              "kernel_times": "narval: the same; Mitsuba: its JIT kernels' execution (Dr.Jit kernel history)",
              "threads": int(os.environ.get("NARVAL_MITSUBA_THREADS", "2")),
              "summary": summary, "time_ratio_narval_over_mitsuba": ratio,
              "kernel_time_ratio_narval_over_mitsuba": ratio_kernel, "interpolated": interp,
              "notes": notes, "date": time.strftime("%Y-%m-%d"), "raw": {k: {str(n): v for n, v in per.items()}
                                                                          for k, per in rows.items()}}
    with open(os.path.join(out_dir, "race.json"), "w") as f:
        json.dump(result, f, indent=1)
    md = race_markdown(result)
    with open(os.path.join(out_dir, "race.md"), "w") as f:
        f.write(md)
    print(md)
    return result


def efficiency(rungs, key):
    """relMSE x time is constant for an unbiased estimator whose time grows in proportion to its
    samples (1/relMSE and time both proportional to spp): its geometric mean over the rungs the
    reference does not dominate. The time at relMSE e is then that constant / e."""
    good = [r[key] for r in rungs if r[key] and not r["reference_limited"]]
    return float(np.exp(np.mean(np.log(good)))) if good else None


def interpolated_ratios(summary):
    """narval's time at Mitsuba's relMSE per rung, interpolated on log-log between narval's rungs."""
    n = [(r["rel_mse"], r["seconds"]) for r in summary["narval"]["rungs"] if r["rel_mse"] > 0]
    n.sort()
    out = []
    for r in summary["mitsuba"]["rungs"]:
        e = r["rel_mse"]
        if e <= 0 or len(n) < 2 or not (n[0][0] <= e <= n[-1][0]):
            continue
        for (e0, t0), (e1, t1) in zip(n, n[1:]):
            if e0 <= e <= e1:
                f = 0.0 if e1 == e0 else (math.log(e) - math.log(e0)) / (math.log(e1) - math.log(e0))
                tn = math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
                out.append({"mitsuba_spp": r["spp"], "rel_mse": e, "mitsuba_seconds": r["seconds"],
                            "narval_seconds": tn, "ratio": tn / r["seconds"]})
                break
    return out


def race_markdown(r):
    lines = ["%s, %dx%d, bounces %d, reference narval %d spp (its own relMSE share %.2e subtracted); "
             "narval: kernel seconds; Mitsuba 3 llvm_ad_rgb volpath, %d threads: render wall seconds after "
             "warm-up; median of %d interleaved repetitions%s" % (
                 os.path.basename(r["scene"]), r["resolution"][0], r["resolution"][1], r["bounces"],
                 r["reference"]["spp"], r["reference"]["rel_mse_share"], r["threads"], r["reps"],
                 (", narval args `%s`" % " ".join(r["narval_args"])) if r["narval_args"] else ""),
             "",
             "| renderer | spp | seconds | kernel s | relMSE | relMSE x s |",
             "|---|---:|---:|---:|---:|---:|"]
    for name in ("narval", "mitsuba"):
        for g in r["summary"][name]["rungs"]:
            lines.append("| %s | %d | %.3f | %.3f | %.3g%s | %s |" % (
                name, g["spp"], g["seconds"], g["kernel_seconds"], g["rel_mse"],
                " (ref.-limited)" if g["reference_limited"] else "",
                "%.3g" % g["rel_mse_x_seconds"] if g["rel_mse_x_seconds"] else "-"))

    def fmt(x, f="%.3g"):
        return f % x if x else "n/a"
    lines.append("")
    lines.append("Time at equal relMSE, narval / Mitsuba: **%s** (relMSE x seconds: narval %s, Mitsuba %s); "
                 "kernel time against kernel time: %s" % (
                     fmt(r["time_ratio_narval_over_mitsuba"], "%.2f"),
                     fmt(r["summary"]["narval"]["rel_mse_x_seconds"]),
                     fmt(r["summary"]["mitsuba"]["rel_mse_x_seconds"]),
                     fmt(r["kernel_time_ratio_narval_over_mitsuba"], "%.2f")))
    if r["interpolated"]:
        lines.append("Interpolated (log-log) at Mitsuba's rungs: " + ", ".join(
            "%d spp %.2f" % (x["mitsuba_spp"], x["ratio"]) for x in r["interpolated"]))
    return "\n".join(lines) + "\n"


# ================================================================================================
# check
# ================================================================================================

CHECK_SCENES = [
    # (scene, resolution, spp, seeds)
    ("absorption_box.json", (48, 36), 128, 8),
    ("point_slab.json", (48, 36), 128, 8),
    ("grid_backlit.json", (48, 36), 128, 8),
]


def run_check(args):
    failures = []
    for name, res, spp, seeds in CHECK_SCENES:
        path = os.path.join(HERE, "scenes", name)
        r = run_compare(path, spp, seeds, res, args.narval, os.path.join(WORK_DIR, "check", scene_tag(name)))
        if not r["agree"]:
            failures.append(name)
    if failures:
        print("check: DISAGREE on %s" % ", ".join(failures))
        return 1
    print("check: narval and Mitsuba agree on %d scenes" % len(CHECK_SCENES))
    return 0


# ================================================================================================

def srgb(v):
    """The sRGB transfer function on values in [0, 1] (kernels/shared/tonemap.h)."""
    import numpy as np
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)


def display(x):
    """narval's default display transform (kernels/shared/tonemap.h): Narkowicz's ACES fit, clamped,
    then the sRGB curve."""
    import numpy as np
    x = np.clip(x, 0.0, 1e4)
    return srgb(np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0))


def write_picture(compare_dir, out, diff_scale):
    """narval's mean image, Mitsuba's, and |narval - Mitsuba| x diff_scale (linear, clipped, sRGB)
    side by side, from a compare run's folder."""
    import numpy as np
    narval = np.load(os.path.join(compare_dir, "narval_mean.npy"))
    mitsuba_img = np.load(os.path.join(compare_dir, "mitsuba_mean.npy"))
    diff = srgb(np.clip(np.abs(narval - mitsuba_img) * diff_scale, 0.0, 1.0))
    gap = np.ones((narval.shape[0], 4, 3))
    panel = np.concatenate([display(narval), gap, display(mitsuba_img), gap, diff], axis=1)
    pixels = np.ascontiguousarray((np.clip(panel, 0.0, 1.0) * 255 + 0.5).astype(np.uint8))
    mitsuba().Bitmap(pixels).write(out)


def main():
    if hasattr(signal, "SIGPIPE"):
        signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `... | head` ends quietly
    # --narval on every subcommand, and no abbreviations (--narval must not read as --narval-args).
    common = argparse.ArgumentParser(add_help=False, allow_abbrev=False)
    common.add_argument("--narval", default=os.environ.get("NARVAL_BINARY", DEFAULT_NARVAL),
                        help="narval binary (default: $NARVAL_BINARY, else build/narval)")
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter,
                                 allow_abbrev=False)
    sub = ap.add_subparsers(dest="command", required=True)
    t = sub.add_parser("translate", help="narval scene -> Mitsuba 3 scene", parents=[common], allow_abbrev=False)
    t.add_argument("scene")
    t.add_argument("out_dir")
    c = sub.add_parser("compare", help="narval against Mitsuba within noise", parents=[common], allow_abbrev=False)
    c.add_argument("scene")
    c.add_argument("--spp", type=int, default=32)
    c.add_argument("--seeds", type=int, default=4)
    c.add_argument("--resolution", type=parse_resolution, default=(64, 48))
    c.add_argument("--narval-args", default="", help="extra narval render options (quoted)")
    c.add_argument("--seed-offset", type=int, default=0,
                   help="seeds narval OFFSET+1..OFFSET+K, Mitsuba 1000+OFFSET.. (default 0): repeat a compare "
                        "with other samples")
    c.add_argument("--out", help="output folder (default build/vs_mitsuba/compare_SCENE)")
    c.add_argument("--perturb", choices=sorted(PERTURBATIONS), action="append", default=[],
                   help="translate with a deliberate mistake, to see the compare fail: " +
                        "; ".join("%s: %s" % kv for kv in sorted(PERTURBATIONS.items())))
    r = sub.add_parser("race", help="time at equal relMSE", parents=[common], allow_abbrev=False)
    r.add_argument("scene")
    r.add_argument("--resolution", type=parse_resolution, default=(160, 120))
    r.add_argument("--ladder", default="4,8,16,32,64,128")
    r.add_argument("--reps", type=int, default=3)
    r.add_argument("--ref-spp", type=int, default=8192)
    r.add_argument("--narval-args", default="", help="extra narval render options (quoted), e.g. \"--majorant global\"")
    r.add_argument("--out", help="output folder (default build/vs_mitsuba/race_SCENE)")
    sub.add_parser("check", help="the convention check on tiny analytic scenes (exit 77: no Mitsuba environment)",
                   parents=[common], allow_abbrev=False)
    pic = sub.add_parser("picture", help="a compare run's mean images and their difference as one PNG",
                         parents=[common], allow_abbrev=False)
    pic.add_argument("compare_dir", help="a compare output folder (build/vs_mitsuba/compare_SCENE)")
    pic.add_argument("out", help="the PNG to write")
    pic.add_argument("--diff-scale", type=float, default=10.0, help="the difference panel shows |narval - Mitsuba| x this")
    args = ap.parse_args()

    reason = ensure_environment(args.command)
    if reason:
        print("vs_mitsuba: skipped: " + reason if args.command == "check" else "vs_mitsuba: " + reason)
        return EXIT_SKIP if args.command == "check" else 2
    if args.command == "picture":
        write_picture(args.compare_dir, args.out, args.diff_scale)
        print("wrote %s" % args.out)
        return 0
    if not os.access(args.narval, os.X_OK):
        print("vs_mitsuba: no narval binary at %s (--narval or $NARVAL_BINARY)" % args.narval, file=sys.stderr)
        return 2
    if args.command == "translate":
        d, notes = translate_scene(load_narval_scene(args.narval, args.scene), args.out_dir)
        print("wrote %s" % os.path.join(args.out_dir, "mitsuba_scene.json"))
        for n in notes:
            print("note: " + n)
        return 0
    if args.command == "compare":
        PERTURB.update(args.perturb)
        out = args.out or os.path.join(WORK_DIR, "compare_" + scene_tag(args.scene) +
                                       "".join("_" + x for x in sorted(args.perturb)))
        r = run_compare(args.scene, args.spp, args.seeds, args.resolution, args.narval, out,
                        shlex.split(args.narval_args), args.seed_offset)
        print("wrote %s and compare.txt" % os.path.join(out, "compare.json"))
        return 0 if r["agree"] else 1
    if args.command == "race":
        run_race(args)
        return 0
    if args.command == "check":
        return run_check(args)
    return 2


if __name__ == "__main__":
    try:
        sys.exit(main())
    except (ValueError, OSError, KeyError) as e:  # a scene or grid narval would refuse, a missing file
        print("vs_mitsuba: error: %s%s" % (type(e).__name__ + ": " if isinstance(e, KeyError) else "", e),
              file=sys.stderr)
        sys.exit(2)
    except RuntimeError as e:  # narval or Mitsuba failed
        print("vs_mitsuba: error: %s" % e, file=sys.stderr)
        sys.exit(1)
