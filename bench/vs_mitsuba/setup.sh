#!/usr/bin/env bash
# bench/vs_mitsuba/setup.sh: the Python environment for vs_mitsuba.py (a bench tool only: never a
# build or test dependency of narval).
#
# Makes a virtual environment (default build/mitsuba-venv; NARVAL_MITSUBA_VENV overrides) with
# Mitsuba 3 and numpy from PyPI. It is created from Debian's /usr/bin/python3 with
# --system-site-packages so that Debian's python3-openvdb (`import pyopenvdb`) reads .vdb grids
# with the same OpenVDB library narval links (the same copyToDense over the active bounding box).
#
# What was needed on Debian 12 (2026-12, mitsuba 3.9.1, drjit 1.5.0):
# - python3-venv, python3-openvdb (apt).
# - A newer libLLVM than Debian 12's default: Dr.Jit's LLVM backend (the llvm_ad_rgb variant, CPU)
#   loads libLLVM 14/15 but then aborts in code generation ("LLVM ERROR: Cannot select ...
#   fminimum"); libllvm19 (bookworm's 1:19.1.7-3~deb12u1) works. Dr.Jit finds a libLLVM by name,
#   so the one that works is recorded in $VENV/drjit_libllvm_path and vs_mitsuba.py exports it as
#   DRJIT_LIBLLVM_PATH before importing Mitsuba.
# Installs the apt packages when run as root (or with passwordless sudo); otherwise prints the line.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="${NARVAL_MITSUBA_VENV:-$repo/build/mitsuba-venv}"

source "$repo/scripts/apt_packages.sh"
apt_install_missing "vs_mitsuba setup" python3-venv python3-openvdb libllvm19

# Debian's interpreter, not a pyenv or conda one: python3-openvdb is built for it.
py=/usr/bin/python3
if [ ! -x "$venv/bin/python" ]; then
  echo "vs_mitsuba setup: creating $venv"
  "$py" -m venv --system-site-packages "$venv"
fi
# numpy comes from Debian (python3-numpy, pulled by python3-openvdb) when present: pyopenvdb's
# copyToArray is compiled against that numpy's ABI, and a pip numpy 2.x beside it breaks it.
if "$venv/bin/python" -c "import numpy" 2>/dev/null; then
  "$venv/bin/pip" install -q mitsuba
else
  "$venv/bin/pip" install -q mitsuba numpy
fi

# The first libLLVM with which a tiny llvm_ad_rgb render works (newest first).
found=""
for lib in "${DRJIT_LIBLLVM_PATH:-}" /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /usr/lib/llvm-19/lib/libLLVM.so.1 \
           /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/x86_64-linux-gnu/libLLVM-16.so.1 \
           /usr/lib/x86_64-linux-gnu/libLLVM-15.so.1 /usr/lib/x86_64-linux-gnu/libLLVM-14.so.1; do
  [ -n "$lib" ] && [ -e "$lib" ] || continue
  if DRJIT_LIBLLVM_PATH="$lib" "$venv/bin/python" - >/dev/null 2>&1 <<'EOF'
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
scene = mi.load_dict({"type": "scene", "integrator": {"type": "volpath", "max_depth": 3},
                      "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4}},
                      "light": {"type": "constant"},
                      "cube": {"type": "cube", "bsdf": {"type": "null"},
                               "interior": {"type": "homogeneous", "sigma_t": 1.0, "albedo": 0.5,
                                            "phase": {"type": "hg", "g": 0.5}},
                               "to_world": mi.ScalarTransform4f().translate([0, 0, 4])}})
img = mi.render(scene, spp=4)
assert float(img.numpy().mean()) > 0
EOF
  then found="$lib"; break; fi
done
if [ -z "$found" ]; then
  echo "vs_mitsuba setup: no libLLVM works with Dr.Jit's LLVM backend (install libllvm19 and retry)" >&2
  exit 1
fi
echo "$found" > "$venv/drjit_libllvm_path"
"$venv/bin/python" -c "import pyopenvdb" || { echo "vs_mitsuba setup: pyopenvdb not importable" >&2; exit 1; }
echo "vs_mitsuba setup: ready ($venv; DRJIT_LIBLLVM_PATH=$found)"
echo "  $venv/bin/python $here/vs_mitsuba.py check"
