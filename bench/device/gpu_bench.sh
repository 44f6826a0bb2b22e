#!/usr/bin/env bash
# bench/device/gpu_bench.sh [OUTDIR]: on the GPU machine (after `source bench/device/setup.sh`): path
# tracing and real-time frames per grid storage and majorant, then bench/realtime.py frames and
# bench/speed_vs_error.py at 1280x720 (bench/README.md). Not a test.
set -u
cd "$(dirname "$0")/../.."
N=$PWD/build/narval
out=${1:-/tmp/narval-gpu-bench}
mkdir -p "$out"
for sc in cloud listing_4_1 disney_cloud; do
  S=$PWD/scenes/$sc.json
  "$N" render "$S" -o "$out/warm.exr" --resolution 64x32 --spp 4 >/dev/null 2>&1  # fills the program cache
  for st in image buffer; do
    for mj in grid global; do
      "$N" render "$S" -o "$out/pt_${sc}_${st}_${mj}.exr" --resolution 1200x600 --spp 256 --storage $st \
        --majorant $mj --stats-json "$out/pt_${sc}_${st}_${mj}.json" >/dev/null 2>&1 || echo "failed: pt $sc $st $mj" >&2
    done
    for alg in raymarch lobe; do  # the ray marcher as the dissertation's single-scattering march
      "$N" render "$S" -o "$out/${alg}_${sc}_${st}.exr" --algorithm $alg --resolution 1200x600 --frames 20 \
        --set 'renderer.raymarch.multipleScattering="none"' --storage $st --stats-json "$out/${alg}_${sc}_${st}.json" >/dev/null 2>&1 || echo "failed: $alg $sc $st" >&2
    done
  done
done
python3 - "$out" <<'PY'
import glob, json, os, sys
print("| run | storage | majorant | seconds | Msamples/s | median ms/frame |\n|---|---|---|---|---|---|")
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f))
    ms = "%.2f" % j["ms_per_frame"]["median"] if "ms_per_frame" in j else ""
    print("| %s | %s | %s | %.3f | %.1f | %s |" % (os.path.basename(f)[:-5], j.get("storage"),
                                                    j.get("majorant", ""), j["seconds"],
                                                    j["samples_per_second"] / 1e6, ms))
PY
python3 bench/realtime.py frames --resolutions 1280x720 --ref-resolutions "" --frames 20 --out "$out/realtime"
NARVAL_CACHE_DIR="$out/cache" python3 bench/speed_vs_error.py --resolution 1280x720 --frames 20 \
  --out "$out/speed_vs_error" || echo "failed: speed_vs_error" >&2
