#!/usr/bin/env bash
# bench/large_grid.sh [--resolution N] [--seed S] [--image WxH] [--spp N] [--frames K]
#                     [--storages "auto bricks"] [--device SPEC] [--keep DIR]
# Large grids (issue 6, item 6): generates an N³ procedural cloud (default 1024: `narval make-cloud`;
# the .vdb holds its active bounding box, which the loader crops to, about 0.8N on the longest
# axis), then renders it with the path tracer (small image, few spp) and the ray marcher (K frames)
# in each storage of --storages (renderer.storage; "auto" falls back to sparse bricks only when
# one buffer or image cannot hold the grid, and says so in a warning), and prints per step:
# wall seconds, kernel seconds, the peak resident memory of the process (GNU time's maximum RSS)
# and of the process tree (the VDB reader child and its shared memory included, sampled every
# 0.1 s), and from --stats-json the storage used, the bricks occupied and the grid's bytes on the
# device. Minutes and several GiB of memory at N = 1024: not part of ctest.
# NARVAL=path/to/narval picks the binary (default build/narval).
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
resolution=1024
seed=1
image=160x90
spp=4
frames=3
storages="auto bricks"
device=""
keep=""
. bench/bench_common.sh
bench_options "resolution seed image spp frames storages device keep" "$@"
if [ "$narval" = build/narval ] && [ ! -x build/narval ]; then scripts/setup.sh >/dev/null; fi
[ -x /usr/bin/time ] || { echo "needs GNU time (/usr/bin/time): apt-get install time" >&2; exit 1; }
if [ -n "$keep" ]; then
  work=$keep
  mkdir -p "$work"
else
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
fi

# measure NAME COMMAND...: runs COMMAND under GNU time with a sampler of the process tree's RSS;
# leaves NAME.time (time -v), NAME.err (stderr) and NAME.tree (peak tree RSS, KiB).
measure() {
  local name=$1
  shift
  /usr/bin/time -v -o "$work/$name.time" "$@" >"$work/$name.out" 2>"$work/$name.err" &
  local pid=$!
  python3 - "$pid" "$work/$name.tree" <<'PY' &
import os, sys, time
root, out = int(sys.argv[1]), sys.argv[2]
def children(pid):
    try:
        with open(f"/proc/{pid}/task/{pid}/children") as f:
            return [int(c) for c in f.read().split()]
    except OSError:
        return []
def rss(pid):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return 0
peak = 0
while os.path.exists(f"/proc/{root}"):
    total, todo = 0, [root]
    while todo:
        p = todo.pop()
        total += rss(p)
        todo += children(p)
    peak = max(peak, total)
    time.sleep(0.1)
open(out, "w").write(str(peak))
PY
  local sampler=$!
  local rc=0
  wait "$pid" || rc=$?
  wait "$sampler" || true
  if [ "$rc" -ne 0 ]; then
    echo "$name failed (exit $rc):" >&2
    cat "$work/$name.err" >&2
    exit "$rc"
  fi
}

vdb="$work/cloud_$resolution.vdb"
measure make-cloud "$narval" make-cloud "$vdb" --resolution "$resolution" --seed "$seed"
python3 - "$vdb" "$work/scene.json" <<'PY'
import json, sys
s = json.load(open("scenes/cloud.json"))
for m in s["materials"]:
    if m.get("type") == "volume":
        m["path"] = sys.argv[1]
json.dump(s, open(sys.argv[2], "w"), indent=1)
PY

steps=(make-cloud)
for storage in $storages; do
  # shellcheck disable=SC2086
  measure "pathtrace-$storage" "$narval" render "$work/scene.json" -o "$work/pathtrace-$storage.exr" \
    --algorithm pathtrace --resolution "$image" --spp "$spp" $device --set "renderer.storage=\"$storage\"" \
    --stats-json "$work/pathtrace-$storage.json"
  # shellcheck disable=SC2086
  measure "raymarch-$storage" "$narval" render "$work/scene.json" -o "$work/raymarch-$storage.exr" \
    --algorithm raymarch --resolution "$image" --frames "$frames" $device --set "renderer.storage=\"$storage\"" \
    --stats-json "$work/raymarch-$storage.json"
  steps+=("pathtrace-$storage" "raymarch-$storage")
done

python3 - "$work" "$resolution" "$seed" "$image" "$spp" "$frames" "$vdb" "${steps[@]}" <<'PY'
import json, os, re, sys
work, res, seed, image, spp, frames, vdb = sys.argv[1:8]
steps = sys.argv[8:]
def timev(name):
    t = open(os.path.join(work, name + ".time")).read()
    rss = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", t).group(1))
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): ([\d:.]+)", t).group(1)
    secs = 0.0
    for part in wall.split(":"):
        secs = secs * 60 + float(part)
    return secs, rss
def gib(kib):
    return "%.2f GiB" % (kib / 1024.0 / 1024.0)
print(f"cloud {res}^3 (seed {seed}), file {os.path.getsize(vdb) / 2**20:.1f} MiB; image {image}, pathtrace {spp} spp, raymarch {frames} frames")
for name in steps:
    for line in open(os.path.join(work, name + ".err")):
        if "warning" in line:
            print(f"  {name}: {line.strip()}")
print()
print("| step | storage | wall s | kernel s | peak RSS | peak tree RSS | bricks occupied / total | grid on device |")
print("|---|---|---|---|---|---|---|---|")
for name in steps:
    secs, rss = timev(name)
    tree = int(open(os.path.join(work, name + ".tree")).read() or 0)
    storage, kernel, bricks, grid = "", "", "", ""
    stats = os.path.join(work, name + ".json")
    if os.path.exists(stats):
        s = json.load(open(stats))
        storage = s.get("storage", "")
        kernel = "%.2f" % s.get("kernel_seconds", 0)
        if "ms_per_frame" in s:
            kernel += " (median frame %.0f ms)" % s["ms_per_frame"]["median"]
        b = s.get("bricks")
        if b and b.get("total"):
            bricks = "%d / %d (%.1f%%)" % (b["occupied"], b["total"], 100.0 * b["occupied"] / b["total"])
        elif b is None:
            bricks = "n/a (stats lack 'bricks')"
        if "grid_bytes" in s:
            grid = "%.1f MiB" % (s["grid_bytes"] / 2**20)
    print(f"| {name} | {storage} | {secs:.1f} | {kernel} | {gib(rss)} | {gib(tree)} | {bricks} | {grid} |")
PY
