#!/usr/bin/env bash
# bench/realtime_frames.sh [--device SPEC] [--frames K] [--resolutions "320x240 1280x720"]
#                          [--scenes "A.json B.json"] [--ref-spp N] [--ref-resolutions "320x240"]
#                          [--out DIR] [--quick]
# Real-time kernels with and without the light-transmittance cache (renderer.lightCache). For each
# scene, resolution and kernel (raymarch, lobe): the median kernel ms per frame of K frames after
# the first (build and warm-up reported apart by narval itself) with the cache off
# (renderer.lightCache.resolution=0: exact shadow marching) and on (the scene's setting, as narval
# resolves it); the cache's build time (light_cache_ms, apart from the frames), cells and builds; mean
# ΔE76 and JND% of the cache-on image against the cache-off image of the same kernel (what the
# cache costs) and against a path-traced reference (REF_SPP spp, the scene's bounces) at the same
# resolution. References are rendered once per scene and resolution listed in --ref-resolutions and
# kept in DIR; later runs reuse them (`narval render --resume`: a finished file renders nothing, a
# file from other settings is rendered again). Then a second table: lobe/raymarch (cache on) and
# cache off/on per kernel. ΔE: `narval compare --tonemap none --exposure 0` (linear
# values clipped to [0, 1]), as in the rest of bench/RESULTS.md.
# Defaults: scenes listing_4_1, disney_cloud, cloud, smoke; 320x240 and 1280x720; 7 frames;
# references at 320x240 only, 256 spp; DIR build/realtime_frames (every image and stats file of
# the run stays there). A scene whose volume file is absent gets a row saying so.
# --quick: a smoke test (160x120 only, 2 frames, references 16 spp at every resolution); options
# given explicitly win over it. Progress goes to stderr, the report (Markdown) to stdout and to
# DIR/report.md, one JSON line per row to DIR/rows.jsonl. NARVAL=path/to/narval picks the binary.
# Not a test: nothing is asserted.
set -euo pipefail
cmdline=$0
for a in "$@"; do
  if [[ $a =~ ^[A-Za-z0-9_./=:,+-]+$ ]]; then cmdline+=" $a"; else cmdline+=" ${a@Q}"; fi
done
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}

usage() { echo "realtime_frames.sh: $1" >&2; exit 2; }

device=()
unset frames resolutions scenes ref_spp ref_resolutions out  # unset: not given (empty is a value)
quick=0
while [ $# -gt 0 ]; do
  case "$1" in
    --quick) quick=1; shift ;;
    --device|--frames|--resolutions|--scenes|--ref-spp|--ref-resolutions|--out)
      [ $# -ge 2 ] || usage "option $1 needs a value"
      case "$1" in
        --device) device=(--device "$2") ;;
        --frames) frames=$2 ;;
        --resolutions) resolutions=$2 ;;
        --scenes) scenes=$2 ;;
        --ref-spp) ref_spp=$2 ;;
        --ref-resolutions) ref_resolutions=$2 ;;
        --out) out=$2 ;;
      esac
      shift 2 ;;
    *) usage "unknown option $1" ;;
  esac
done
# Options given explicitly win over --quick's values.
if [ "$quick" = 1 ]; then
  : "${resolutions=160x120}" "${frames=2}" "${ref_spp=16}" "${ref_resolutions=$resolutions}"
fi
: "${resolutions=320x240 1280x720}" "${frames=7}" "${ref_spp=256}" "${ref_resolutions=320x240}"
: "${scenes=scenes/listing_4_1.json scenes/disney_cloud.json scenes/cloud.json scenes/smoke.json}"
: "${out=build/realtime_frames}"
[ -n "$out" ] || usage "--out is empty"
if ! [[ $frames =~ ^[1-9][0-9]*$ ]] || [ "$frames" -lt 2 ]; then
  usage "--frames wants an integer >= 2 (the first frame is not timed), got '$frames'"
fi
[[ $ref_spp =~ ^[1-9][0-9]*$ ]] || usage "--ref-spp wants a positive integer, got '$ref_spp'"
read -r -a res_list <<<"$resolutions"
read -r -a ref_res_list <<<"$ref_resolutions"
read -r -a scene_list <<<"$scenes"
[ ${#res_list[@]} -gt 0 ] || usage "--resolutions is empty"
[ ${#scene_list[@]} -gt 0 ] || usage "--scenes is empty"
for r in "${res_list[@]}" "${ref_res_list[@]}"; do
  [[ $r =~ ^[1-9][0-9]*x[1-9][0-9]*$ ]] || usage "resolutions want WIDTHxHEIGHT, got '$r'"
done

. bench/bench_common.sh
bench_init
mkdir -p "$out"
rows="$work/rows.jsonl"
: >"$rows"

# in_list WORD LIST...: whether WORD is one of LIST.
in_list() { local w=$1 x; shift; for x in "$@"; do [ "$x" = "$w" ] && return 0; done; return 1; }

# render_rt SCENE RES ALG MODE(on|off) STEM: K frames into $out/STEM.exr, stats in $out/STEM.json.
render_rt() {
  local extra=()
  [ "$4" = off ] && extra=(--set renderer.lightCache.resolution=0)
  echo "  $(basename "$1" .json) $2 $3 cache $4" >&2
  "$narval" render "$1" -o "$out/$5.exr" --algorithm "$3" --resolution "$2" --frames "$frames" \
    "${device[@]}" "${extra[@]}" --stats-json "$out/$5.json" >/dev/null
}

# reference SCENE RES STEM: the path-traced reference $out/STEM.exr (bench_reference: kept between
# runs, completed when interrupted, rendered again when it came from other settings).
reference() {
  echo "  $(basename "$1" .json) $2 reference: pathtrace $ref_spp spp (reused when it is there)" >&2
  bench_reference "$out/$3.exr" "$1" --spp "$ref_spp" --resolution "$2" "${device[@]}"
}

# compare REF TEST JSON: narval compare's statistics into JSON, linear (no tone mapping, exposure 0:
# the transform the recorded results used; compare's default is now the scene's, from the EXRs).
compare() { "$narval" compare "$1" "$2" --json --tonemap none --exposure 0 >"$3"; }

for scene in "${scene_list[@]}"; do
  name=$(basename "$scene" .json)
  if [ ! -f "$scene" ]; then
    python3 -c 'import json,sys; print(json.dumps({"scene": sys.argv[1], "skip": sys.argv[2]}))' \
      "$name" "skipped: $scene absent" >>"$rows"
    continue
  fi
  missing=$(bench_missing "$scene")
  if [ -n "$missing" ]; then
    python3 -c 'import json,sys; print(json.dumps({"scene": sys.argv[1], "skip": sys.argv[2]}))' \
      "$name" "skipped: $(echo "$missing" | paste -sd, -) absent" >>"$rows"
    continue
  fi
  for res in "${res_list[@]}"; do
    ref=""
    if in_list "$res" "${ref_res_list[@]}"; then
      ref="$out/ref-$name-$res-${ref_spp}spp.exr"
      reference "$scene" "$res" "ref-$name-$res-${ref_spp}spp"
    fi
    for alg in raymarch lobe; do
      stem="$name-$res-$alg"
      render_rt "$scene" "$res" "$alg" off "$stem-cacheoff"
      render_rt "$scene" "$res" "$alg" on "$stem-cacheon"
      compare "$out/$stem-cacheoff.exr" "$out/$stem-cacheon.exr" "$out/$stem-on-vs-off.json"
      vsref=""
      if [ -n "$ref" ]; then
        compare "$ref" "$out/$stem-cacheon.exr" "$out/$stem-on-vs-ref.json"
        vsref="$out/$stem-on-vs-ref.json"
      fi
      python3 - "$name" "$res" "$alg" "$out/$stem-cacheoff.json" "$out/$stem-cacheon.json" \
        "$out/$stem-on-vs-off.json" "$vsref" >>"$rows" <<'PY'
import json, sys
name, res, alg, off, on, vsoff, vsref = sys.argv[1:8]
off, on, vsoff = (json.load(open(f)) for f in (off, on, vsoff))
vsref = json.load(open(vsref)) if vsref else None
print(json.dumps({
    "scene": name, "resolution": res, "algorithm": alg, "device": on["device"],
    "off_ms": off["ms_per_frame"]["median"], "on_ms": on["ms_per_frame"]["median"],
    "cache_ms": on.get("light_cache_ms", 0.0), "cells": on.get("light_cache_cells", [0, 0, 0]),
    "builds": on.get("light_cache_builds", 0),
    "off_cache_builds": off.get("light_cache_builds", 0),
    "de_off": vsoff["mean_dE76"], "jnd_off": vsoff["jnd76_pct"],
    "de_ref": vsref["mean_dE76"] if vsref else None, "jnd_ref": vsref["jnd76_pct"] if vsref else None,
}))
PY
    done
  done
done

cp "$rows" "$out/rows.jsonl"
python3 - "$rows" "$cmdline" "$frames" "$ref_spp" "$ref_resolutions" "$out" <<'PY' | tee "$out/report.md"
import json, sys
rows_file, cmdline, frames, ref_spp, ref_res, out = sys.argv[1:7]
rows = [json.loads(l) for l in open(rows_file) if l.strip()]
done = [r for r in rows if "skip" not in r]
def ms(v):
    return "%.2f" % v if v < 10 else "%.1f" % v
def de(v, j):
    return ("—", "—") if v is None else ("%.2f" % v, "%.1f%%" % j)
print("device: %s" % (done[0]["device"] if done else "(nothing rendered)"))
print("command: %s" % cmdline)
print()
print("| scene | resolution | kernel | ms cache off | ms cache on | cache build ms | cache cells | builds "
      "| ΔE76 on vs off | JND% on vs off | ΔE76 on vs ref | JND% on vs ref |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|")
missing_ref = set()
for r in rows:
    if "skip" in r:
        print("| %s | %s | | | | | | | | | | |" % (r["scene"], r["skip"]))
        continue
    cells = "x".join(str(c) for c in r["cells"]) if any(r["cells"]) else "off"
    dro, jro = de(r["de_off"], r["jnd_off"])
    drr, jrr = de(r["de_ref"], r["jnd_ref"])
    if r["de_ref"] is None:
        missing_ref.add(r["resolution"])
    print("| %s | %s | %s | %s | %s | %s | %s | %d | %s | %s | %s | %s |" % (
        r["scene"], r["resolution"], r["algorithm"], ms(r["off_ms"]), ms(r["on_ms"]),
        ms(r["cache_ms"]), cells, r["builds"], dro, jro, drr, jrr))
print()
print("ms: median kernel ms per frame (OpenCL profiling events) of the %d frame(s) after the first "
      "(`--frames %s`; the first pays for the build and warm-up); cache off: "
      "`--set renderer.lightCache.resolution=0` (exact shadow marching), cache on: the scene's setting "
      "(as narval resolves it). Cache build ms (`light_cache_ms`, all builds of one render, not in the frame times), "
      "cells (x×y×z) and builds (`light_cache_builds`) are the cache-on render's. ΔE76: mean over pixels, "
      "JND%%: pixels with ΔE76 > 2.3, by `narval compare` with its default display transform (none: linear "
      "values clipped to [0, 1]). on vs off: the cache-on image against the cache-off image of the same "
      "kernel; on vs ref: against a path-traced reference (%s spp, the scene's bounces) at the same "
      "resolution, kept in %s." % (int(frames) - 1, frames, ref_spp, out))
if any(r["off_cache_builds"] for r in done):
    print("WARNING: a cache-off render reports cache builds (light_cache_builds > 0).")
if missing_ref:
    print("—: no reference rendered at %s (%s)." % (", ".join(sorted(missing_ref)),
          "references only at --ref-resolutions \"%s\"" % ref_res if ref_res.strip() else "--ref-resolutions is empty"))
print()
print("| scene | resolution | lobe/raymarch (cache on) | raymarch off/on | lobe off/on |")
print("|---|---|---|---|---|")
groups = {}
for r in done:
    groups.setdefault((r["scene"], r["resolution"]), {})[r["algorithm"]] = r
for (scene, res), g in groups.items():
    rm, lb = g.get("raymarch"), g.get("lobe")
    ratio = lambda a, b: "%.2f" % (a / b) if b > 0 else "—"
    print("| %s | %s | %s | %s | %s |" % (
        scene, res, ratio(lb["on_ms"], rm["on_ms"]) if rm and lb else "—",
        ratio(rm["off_ms"], rm["on_ms"]) if rm else "—", ratio(lb["off_ms"], lb["on_ms"]) if lb else "—"))
print()
print("off/on: speed-up of the frames from the cache (its build time not counted).")
PY
