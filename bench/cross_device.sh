#!/usr/bin/env bash
# bench/cross_device.sh [SCENE.json] [--devices "0,1,..."] [--spp N] [--resolution WxH] [--frames K]
#                       [--algorithm pathtrace|raymarch|lobe]
# Cross-device timing (issue 4): the same scene, parameters and seed on every OpenCL device that
# `narval devices --json` lists (or the given indices, in that order). Per device: one render for
# seconds and samples per second (after a tiny warm-up launch: the first launch at a new local size
# compiles again on PoCL), one `--frames K` run for the median ms per frame, and `narval compare`
# of its image against the first device's (mean ΔE76/ΔE2000 and % of pixels over 1 JND; the first
# device is compared with itself, which must give 0). Defaults: scenes/listing_4_1.json (else
# scenes/cloud.json), all devices, 16 spp, 320x160, 5 frames, pathtrace. On a CPU-only machine the
# table has one row. Prints a Markdown table for bench/RESULTS.md. Not a test: nothing is asserted.
set -euo pipefail
cd "$(dirname "$0")/.."

usage() { echo "cross_device.sh: $1" >&2; exit 2; }

scene=""
devices=""
spp=16
resolution=320x160
frames=5
algorithm=pathtrace
while [ $# -gt 0 ]; do
  case "$1" in
    --devices|--spp|--resolution|--frames|--algorithm)
      [ $# -ge 2 ] || usage "option $1 needs a value"
      case "$1" in
        --devices) devices=$2 ;;
        --spp) spp=$2 ;;
        --resolution) resolution=$2 ;;
        --frames) frames=$2 ;;
        --algorithm) algorithm=$2 ;;
      esac
      shift 2 ;;
    -*) usage "unknown option $1" ;;
    *)
      [ -z "$scene" ] || usage "more than one scene given ($scene, $1)"
      scene=$1; shift ;;
  esac
done
[[ $spp =~ ^[1-9][0-9]*$ ]] || usage "--spp wants a positive integer, got '$spp'"
[[ $frames =~ ^[1-9][0-9]*$ ]] || usage "--frames wants a positive integer, got '$frames'"
[[ $resolution =~ ^[1-9][0-9]*x[1-9][0-9]*$ ]] || usage "--resolution wants WIDTHxHEIGHT, got '$resolution'"
case "$algorithm" in pathtrace|raymarch|lobe) ;; *) usage "--algorithm wants pathtrace, raymarch or lobe, got '$algorithm'" ;; esac
if [ -n "$devices" ]; then
  [[ $devices =~ ^[0-9]+(,[0-9]+)*$ ]] || usage "--devices wants comma-separated indices like 0,1, got '$devices'"
fi
if [ -z "$scene" ]; then
  scene=scenes/listing_4_1.json
  [ -f "$scene" ] || scene=scenes/cloud.json
fi
[ -f "$scene" ] || usage "scene $scene not found"

[ -x build/narval ] || scripts/setup.sh >/dev/null
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The device list: "index<TAB>type<TAB>name" per line, in the order asked for.
build/narval devices --json >"$work/devices.json"
python3 - "$work/devices.json" "$devices" >"$work/devices.tsv" <<'PY' || exit 2
import json, sys
listed = {d["index"]: d for d in json.load(open(sys.argv[1]))}
if sys.argv[2]:
    wanted = [int(i) for i in sys.argv[2].split(",")]
else:
    wanted = sorted(listed)
if not wanted:
    sys.exit("cross_device.sh: no OpenCL device listed by narval devices")
seen = set()
for i in wanted:
    if i not in listed:
        sys.exit(f"cross_device.sh: no device {i} (narval devices lists {sorted(listed)})")
    if i in seen:
        sys.exit(f"cross_device.sh: device {i} given twice")
    seen.add(i)
    d = listed[i]
    print(f"{i}\t{d['type']}\t{d['name']}")
PY

first=""
rows=()
while IFS=$'\t' read -r -u 3 index type name; do
  [ -n "$first" ] || first=$index
  out="$work/dev_$index.exr"
  common=(--device "$index" --algorithm "$algorithm" --resolution "$resolution")
  # --spp applies to the path tracer only (narval refuses it for the real-time algorithms).
  warm_spp=() spp_flag=()
  if [ "$algorithm" = pathtrace ]; then warm_spp=(--spp 1) spp_flag=(--spp "$spp"); fi
  build/narval render "$scene" -o "$work/warm.exr" --device "$index" --algorithm "$algorithm" \
    "${warm_spp[@]}" --resolution 16x8 >/dev/null
  build/narval render "$scene" -o "$out" "${common[@]}" "${spp_flag[@]}" \
    --stats-json "$work/dev_$index.json" >/dev/null
  build/narval render "$scene" -o "$work/frames_$index.exr" "${common[@]}" --frames "$frames" \
    --stats-json "$work/frames_$index.json" >/dev/null
  build/narval compare "$work/dev_$first.exr" "$out" --json --tonemap none --exposure 0 >"$work/compare_$index.json"
  rows+=("$(python3 - "$index" "$type" "$name" "$work/dev_$index.json" "$work/frames_$index.json" \
    "$work/compare_$index.json" <<'PY'
import json, sys
index, type_, name, stats, frames, compare = sys.argv[1:]
s = json.load(open(stats))
f = json.load(open(frames))
c = json.load(open(compare))
print(f"| {index}: {name} | {type_} | {s['seconds']:.2f} | {s['samples_per_second'] / 1e6:.3f} | "
      f"{f['ms_per_frame']['median']:.1f} | {c['mean_dE76']:.3f} | {c['jnd76_pct']:.2f} | "
      f"{c['mean_dE2000']:.3f} | {c['jnd2000_pct']:.2f} |")
PY
  )")
done 3<"$work/devices.tsv"

# raymarch and lobe render one pass: report what narval rendered.
rendered_spp=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['spp'])" "$work/dev_$first.json")
echo "$(date -u '+%Y-%m-%d %H:%M UTC') — scene $scene, $algorithm, $rendered_spp spp, $resolution;" \
  "ms/frame: median kernel time of --frames $frames (narval sets the first frame apart);" \
  "ΔE and JND against device $first"
echo
echo "| device | type | seconds | Msamples/s | ms/frame (median) | mean ΔE76 | JND76% | mean ΔE2000 | JND2000% |"
echo "|---|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
