#!/usr/bin/env bash
# bench/farm_scaling.sh [--scene S] [--resolution WxH] [--spp N] [--tasks "1 2 4 8"]
# What splitting a path-traced render into tasks costs (narval farm on a real one-node Slurm
# cluster, tests/farm/slurm_cluster.sh, started and stopped here): one plain `narval render` of the
# scene, then `narval farm --scheduler slurm --submit` with K tasks for each K. With K > 1 every task
# takes --threads 1, so Slurm runs as many at once as the node has CPUs. Prints a Markdown table:
# total wall time against the plain render's, the sum of the tasks' walls, their fixed cost (wall
# minus rendering: start-up, scene and grid load, program from the cache, upload, read-back and
# write), the merge; and checks each merged image against the plain render (mean ΔE76 must be 0:
# the pixels are the same bits, which tests/cli/farm_cli_test.cpp asserts). Not a test.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=build/narval
scene=scenes/disney_cloud.json
resolution=1200x600
spp=16
tasks="1 2 4 8"
. bench/bench_common.sh
bench_options "scene resolution spp tasks" "$@"
bench_init
chmod a+x "$work"  # munged wants every folder above its socket traversable
bash tests/farm/slurm_cluster.sh start "$work/cluster" >/dev/null
trap 'bash tests/farm/slurm_cluster.sh stop "$work/cluster" >/dev/null 2>&1; rm -rf "$work"' EXIT
export SLURM_CONF=$work/cluster/etc/slurm.conf

"$narval" render "$scene" --resolution "$resolution" --spp 1 -o "$work/warm.exr" -q  # program into the cache
start=$(date +%s.%N)
"$narval" render "$scene" --resolution "$resolution" --spp "$spp" -o "$work/plain.exr" -q \
  --stats-json "$work/plain.json"
plain=$(python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$start" "$(date +%s.%N)")
echo "| K | total s | over plain | tasks' walls s | fixed s per task (mean) | merge s | ΔE76 vs plain |"
echo "|---|---|---|---|---|---|---|"
echo "| plain render | $(printf %.1f "$plain") | 1.00 | | | | |"
for k in $tasks; do
  threads=()
  [ "$k" -gt 1 ] && threads=(--threads 1)
  "$narval" farm "$scene" --resolution "$resolution" --spp "$spp" --tasks "$k" --scheduler slurm \
    -o "$work/farm_$k.exr" "${threads[@]}" --submit > "$work/farm_$k.txt"
  de=$("$narval" compare "$work/plain.exr" "$work/farm_$k.exr" --json | python3 -c "import json,sys; print(json.load(sys.stdin)['mean_dE76'])")
  python3 - "$work/farm_$k.txt" "$k" "$plain" "$de" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
k, plain, de = int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
walls, fixed = [], []
for wall, render in re.findall(r"^task \d+ samples \[\d+, \d+\): ([\d.e+-]+) s \(rendering ([\d.e+-]+) s\)$", text, re.M):
    walls.append(float(wall)); fixed.append(float(wall) - float(render))
merge = float(re.search(r"^merge: ([\d.e+-]+) s$", text, re.M).group(1))
total = float(re.search(r"([\d.e+-]+) s from submission to merge", text).group(1))
print(f"| {k} | {total:.1f} | {total / plain:.2f} | {sum(walls):.1f} | {sum(fixed) / len(fixed):.2f} | {merge:.2f} | {de} |")
PY
done
echo
echo "$("$narval" devices | grep -m1 -i cpu || true); $resolution, $spp spp, $scene; plain render $(python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(f\"{s['samples_per_second']/1e6:.3f} Msamples/s\")" "$work/plain.json")"
