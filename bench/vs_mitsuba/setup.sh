#!/usr/bin/env bash
# bench/vs_mitsuba/setup.sh: the virtual environment vs_mitsuba.py runs in (default build/mitsuba-venv;
# NARVAL_MITSUBA_VENV overrides): Mitsuba 3 from PyPI on Debian's /usr/bin/python3 with its
# python3-openvdb (the OpenVDB narval links), and the first libLLVM with which Dr.Jit's LLVM backend
# renders, recorded in $VENV/drjit_libllvm_path. Why each step: README.md beside this file.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
venv="${NARVAL_MITSUBA_VENV:-$repo/build/mitsuba-venv}"
source "$repo/scripts/apt_packages.sh"
apt_install_missing "vs_mitsuba setup" python3-venv python3-openvdb libllvm19
if [ ! -x "$venv/bin/python" ]; then
  echo "vs_mitsuba setup: creating $venv"
  /usr/bin/python3 -m venv --system-site-packages "$venv"
fi
# Debian's numpy when present: pyopenvdb is built against its ABI.
if "$venv/bin/python" -c "import numpy" 2>/dev/null; then
  "$venv/bin/pip" install -q mitsuba
else
  "$venv/bin/pip" install -q mitsuba numpy
fi
found=""
for lib in "${DRJIT_LIBLLVM_PATH:-}" /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /usr/lib/llvm-19/lib/libLLVM.so.1 \
           /usr/lib/x86_64-linux-gnu/libLLVM-19.so /usr/lib/x86_64-linux-gnu/libLLVM-16.so.1 \
           /usr/lib/x86_64-linux-gnu/libLLVM-15.so.1 /usr/lib/x86_64-linux-gnu/libLLVM-14.so.1; do
  [ -n "$lib" ] && [ -e "$lib" ] || continue
  if DRJIT_LIBLLVM_PATH="$lib" "$venv/bin/python" - >/dev/null 2>&1 <<'PY'
import mitsuba as mi
mi.set_variant("llvm_ad_rgb")
medium = {"type": "homogeneous", "sigma_t": 1.0, "albedo": 0.5, "phase": {"type": "hg", "g": 0.5}}
scene = mi.load_dict({"type": "scene", "integrator": {"type": "volpath", "max_depth": 3},
                      "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4}},
                      "light": {"type": "constant"},
                      "cube": {"type": "cube", "bsdf": {"type": "null"}, "interior": medium,
                               "to_world": mi.ScalarTransform4f().translate([0, 0, 4])}})
assert float(mi.render(scene, spp=4).numpy().mean()) > 0
PY
  then found="$lib"; break; fi
done
[ -n "$found" ] || { echo "vs_mitsuba setup: no libLLVM works with Dr.Jit (install libllvm19)" >&2; exit 1; }
echo "$found" > "$venv/drjit_libllvm_path"
"$venv/bin/python" -c "import pyopenvdb" || { echo "vs_mitsuba setup: pyopenvdb not importable" >&2; exit 1; }
echo "vs_mitsuba setup: ready ($venv; DRJIT_LIBLLVM_PATH=$found)"
