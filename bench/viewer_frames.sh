#!/usr/bin/env bash
# bench/viewer_frames.sh [--scenes "A.json B.json"] [--algorithms "raymarch lobe pathtrace"]
#                        [--target-ms MS] [--device SPEC] [--out DIR]
# Is `narval view` interactive on the shipped scenes? For each scene (at its own resolution, as a
# user opens it) and algorithm, a scripted session under Xvfb: 3 still frames, 8 frames each after a
# drag (the camera moving: the viewer drops to 1/2 or 1/4 resolution to meet --target-ms), 2 still
# frames. Reported from the viewer's --stats-json: the still (full-size) frames' median kernel ms
# and whole-frame ms (caches, launch, read-back, display transform), the moving frames' resolution
# and the same medians, and the median presentation (texture upload, draw, swap) through Mesa's
# software OpenGL. The first frame pays for the program build and is in the still medians only as
# one of 5. Defaults: every scenes/*.json whose volume is present; raymarch, lobe, pathtrace;
# --target-ms 50; DIR build/viewer_frames. Markdown to stdout and DIR/report.md. Not a test.
set -euo pipefail
cmdline="$0 $*"
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
scenes=$(ls scenes/*.json)
algorithms="raymarch lobe pathtrace"
target_ms=50
device=""
out=build/viewer_frames
. bench/bench_common.sh
bench_options "scenes algorithms target_ms device out" "$@"
bench_init
command -v xvfb-run > /dev/null || { echo "viewer_frames.sh: xvfb-run missing (scripts/setup.sh installs it)" >&2; exit 2; }
mkdir -p "$out"
{
  printf 'frames 3\n'
  for i in 1 2 3 4 5 6 7 8; do printf 'drag left 15 -3\nframes 1\n'; done
  printf 'frames 2\n'
} > "$out/orbit.txt"

report="$out/report.md"
{
  echo "$(date -u +%F) · \`$cmdline\` · target $target_ms ms"
  echo
  echo "| scene | algorithm | still: size, kernel / frame ms | moving: size, kernel / frame ms | present ms | device |"
  echo "|---|---|---|---|---|---|"
} > "$report"
for scene in $scenes; do
  name=$(basename "$scene" .json)
  for algorithm in $algorithms; do
    stats="$out/${name}_${algorithm}.json"
    echo "viewer_frames: $name $algorithm" >&2
    # The path tracer's still frames add a sample each (4 at most); the real-time ones redraw.
    if ! xvfb-run -a -s '-screen 0 1600x1200x24' "$narval" view "$scene" --algorithm "$algorithm" $device \
        --set renderer.spp=4 --script "$out/orbit.txt" --target-ms "$target_ms" --stats-json "$stats" \
        > "$out/${name}_${algorithm}.log" 2>&1; then
      echo "| $name | $algorithm | failed: $(tail -1 "$out/${name}_${algorithm}.log") | | | |" >> "$report"
      continue
    fi
    python3 - "$stats" "$name" "$algorithm" >> "$report" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
sizes = sorted(s["per_resolution"].items(), key=lambda kv: -int(kv[0].split("x")[0]))
def cell(kv):
    size, t = kv
    return "%s ×%d, %.1f / %.1f" % (size, t["frames"], t["kernel_ms_median"], t["frame_ms_median"])
still = cell(sizes[0])
moving = ", ".join(cell(kv) for kv in sizes[1:]) or "(full size)"
print("| %s | %s | %s | %s | %.2f | %s |" % (sys.argv[2], sys.argv[3], still, moving, s["present_ms_median"], s["device"]))
PY
  done
done
cat "$report"
