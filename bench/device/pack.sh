#!/usr/bin/env bash
# bench/device/pack.sh: packs what a run on the lent GPU machine needs into .devrun/ (ignored via
# .git/info/exclude; name it in the device tool's `carry`): the built binaries, their shared libraries,
# an ICD file naming NVIDIA's libnvidia-opencl.so.1, the Disney cloud and the smoke (bench/README.md).
set -euo pipefail
cd "$(dirname "$0")/../.."
[ -x build/narval ] || scripts/setup.sh >/dev/null
grep -qx '/.devrun/' .git/info/exclude 2>/dev/null || { mkdir -p .git/info; echo '/.devrun/' >>.git/info/exclude; }
rm -rf .devrun && mkdir -p .devrun/bin .devrun/icd .devrun/data .devrun/lib
cp build/narval build/tests/narval_render_tests build/tests/narval_device_tests build/tests/narval_cli_tests .devrun/bin/
strip .devrun/bin/*
# Every shared library the binaries use except the C/C++ runtime (newer there).
for lib in $(ldd .devrun/bin/* | awk '/=>/ {print $3}' | sort -u); do
  case $(basename "$lib") in libc.so*|libm.so*|libstdc++*|libgcc_s*|ld-linux*) ;; *) cp -L "$lib" .devrun/lib/ ;; esac
done
strip --strip-unneeded .devrun/lib/* 2>/dev/null || true
tar -C .devrun -cJf .devrun/lib.tar.xz lib && rm -rf .devrun/lib
echo libnvidia-opencl.so.1 >.devrun/icd/nvidia.icd
for g in $(python3 bench/scene_env.py volumes scenes/disney_cloud.json; python3 bench/scene_env.py volumes scenes/smoke.json); do
  [ -f "$g" ] && cp "$g" .devrun/data/
done
du -sh .devrun
