#!/usr/bin/env bash
# bench/realtime_frames.sh [--device SPEC] [--frames K]
# Milliseconds per frame of the Lobe Estimator, the ray marcher and one path-tracing pass (1 spp)
# on the Listing 4.1 scene and the Disney-cloud scene, at 1200x600 and 320x240 (issue 3; the
# dissertation's Table 6.1: lobe 55.5 ms, raymarch 125 ms, ratio 0.44). Median of K frames after the
# first (build and warm-up reported apart by narval itself). Prints a Markdown table.
set -euo pipefail
cd "$(dirname "$0")/.."
device=""
frames=7
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="--device $2"; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    *) echo "unknown option $1" >&2; exit 2 ;;
  esac
done
[ -x build/narval ] || scripts/setup.sh >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

ms() {  # scene resolution algorithm -> median kernel ms per frame
  # shellcheck disable=SC2086
  build/narval render "$1" -o "$work/f.exr" --resolution "$2" --algorithm "$3" --frames "$frames" $device \
    --stats-json "$work/f.json" >/dev/null
  python3 -c "import json,sys; print('%.1f' % json.load(open(sys.argv[1]))['ms_per_frame']['median'])" "$work/f.json"
}

echo "device: $(build/narval devices | sed -n 2p)"
echo
echo "| scene | resolution | lobe ms | raymarch ms | pathtrace pass ms | lobe/raymarch |"
echo "|---|---|---|---|---|---|"
data=${NARVAL_DATA_DIR:-../shared/data/volumes}
for scene in scenes/listing_4_1.json scenes/disney_cloud.json; do
  if [ "$scene" = scenes/disney_cloud.json ] && [ ! -f "$data/wdas_cloud_sixteenth.vdb" ]; then
    echo "| disney_cloud | skipped: $data/wdas_cloud_sixteenth.vdb absent | | | | |"
    continue
  fi
  for res in 1200x600 320x240; do
    lobe=$(ms "$scene" "$res" lobe)
    march=$(ms "$scene" "$res" raymarch)
    pt=$(ms "$scene" "$res" pathtrace)
    ratio=$(python3 -c "print('%.2f' % ($lobe / $march))")
    echo "| $(basename "$scene" .json) | $res | $lobe | $march | $pt | $ratio |"
  done
done
