#!/usr/bin/env bash
# bench/device/gpu_bench.sh [OUTDIR]: on the GPU machine (after `source bench/device/setup.sh`):
# the three shipped scenes at 1200x600, path tracing 256 spp per grid storage and majorant, and
# 20 frames of raymarch and lobe per storage; prints a Markdown table; then bench/realtime_frames.sh
# at 1280x720, and bench/speed_vs_error.py at 1280x720 (every real-time option against 2048-spp
# references rendered there). Not a test.
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
    for alg in raymarch lobe; do
      "$N" render "$S" -o "$out/${alg}_${sc}_${st}.exr" --algorithm $alg --resolution 1200x600 --frames 20 \
        --storage $st --stats-json "$out/${alg}_${sc}_${st}.json" >/dev/null 2>&1 || echo "failed: $alg $sc $st" >&2
    done
  done
done
python3 - "$out" <<'PY'
import glob, json, os, sys
print("| run | storage | majorant | seconds | Msamples/s | median ms/frame |")
print("|---|---|---|---|---|---|")
for f in sorted(glob.glob(os.path.join(sys.argv[1], "*.json"))):
    j = json.load(open(f))
    ms = j.get("ms_per_frame", {}).get("median", "")
    ms = f"{ms:.2f}" if ms != "" else ""
    print(f"| {os.path.basename(f)[:-5]} | {j.get('storage')} | {j.get('majorant', '')} | {j['seconds']:.3f} "
          f"| {j['samples_per_second'] / 1e6:.1f} | {ms} |")
PY
# The real-time kernels at 1280x720 with the light-transmittance cache off and on, on the four
# shipped scenes (the 2 ms per frame GPU budget; no path-traced references here).
bench/realtime_frames.sh --resolutions 1280x720 --ref-resolutions "" --frames 20 --out "$out/realtime"
# Every real-time option against path-traced references at 1280x720 (the 16 ms targets): the
# references (2048 spp) are rendered on the GPU too, into a cache beside the output, then the
# methods' sweeps; the report and its budget picks land in $out/speed_vs_error.
NARVAL_CACHE_DIR="$out/cache" python3 bench/speed_vs_error.py --resolution 1280x720 --frames 20 \
  --out "$out/speed_vs_error" || echo "failed: speed_vs_error" >&2
