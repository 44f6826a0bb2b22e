#!/usr/bin/env bash
# bench/pathtrace_throughput.sh [--device SPEC] [--spp N] [--resolution WxH]
# Path-tracing throughput (samples per second) on one device: the Disney cloud scene and generated
# clouds at 64³, 128³ and 256³, all at the same spp and resolution, one run each after a warm-up
# (the first launch at a new local size compiles again on PoCL: DESIGN.md, platform facts).
# Prints a Markdown table for bench/RESULTS.md. Not a test: no timing is asserted anywhere.
set -euo pipefail
cd "$(dirname "$0")/.."
device=""
spp=16
resolution=320x160
. bench/bench_common.sh
bench_options "device spp resolution" "$@"
narval=build/narval
bench_init

row() {  # name scene extra-args...
  local name=$1 scene=$2; shift 2
  # shellcheck disable=SC2086
  build/narval render "$scene" -o "$work/warm.exr" --spp 1 --resolution 16x8 $device "$@" >/dev/null
  # shellcheck disable=SC2086
  build/narval render "$scene" -o "$work/$name.exr" --spp "$spp" --resolution "$resolution" $device \
    --stats-json "$work/$name.json" "$@" >/dev/null
  python3 - "$name" "$work/$name.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[2]))
print(f"| {sys.argv[1]} | {s['width']}x{s['height']} | {s['spp']} | {s['bounces']} | {s['seconds']:.2f} | "
      f"{s['kernel_seconds']:.2f} | {s['samples_per_second'] / 1e6:.3f} |")
PY
}

echo "device: $(build/narval devices | sed -n 2p)"
echo
echo "| scene | resolution | spp | bounces | seconds | kernel s | Msamples/s |"
echo "|---|---|---|---|---|---|---|"
missing=$(bench_missing scenes/disney_cloud.json)
if [ -z "$missing" ]; then
  row disney_cloud scenes/disney_cloud.json
else
  echo "| disney_cloud | skipped: $missing absent | | | | | |"
fi
for n in 64 128 256; do
  build/narval make-cloud "$work/cloud_$n.vdb" --resolution "$n" --seed 1 >/dev/null
  row "generated_$n" scenes/cloud.json --set "materials.1.path=\"$work/cloud_$n.vdb\""
done
