#!/usr/bin/env bash
# bench/native_baseline.sh [SCENE] [--resolution WxH] [--spp N] [--frames K] [--reps R]
#                          [--algorithms "pathtrace raymarch"] [--threads N] [--device SPEC]
#                          [--set PATH=VALUE ...]
# Native baseline (issue 6, item 4; target: PoCL within 1.3x of native). The same scene and
# settings rendered by `narval render` (OpenCL; PoCL here) and by narval-native: the same
# kernels/shared/*.h compiled as C++ and run on host threads (bench/native/native_render.h), in up
# to three builds that give the same bits (bench/native/CMakeLists.txt): native (the project's
# flags), march (+ -march=native, the ISA PoCL compiles for), tuned (+ inline fminf/fmaxf).
# One warm-up of each program first (OpenCL program cache hot, first launch at the local size
# done), then R repetitions alternating PoCL, native, march, tuned, so all see the same load.
#   pathtrace: PoCL kernel_seconds (sum of the launches' profiling intervals; "PoCL wall" is the
#              sample loop's wall clock); native: wall clock from thread start to join.
#   raymarch/lobe: median ms per frame of K frames, the first frame of each run excluded (narval
#              render --frames; narval-native --frames likewise); PoCL by profiling events.
# Ratios: PoCL kernel time / native time, of the medians over the R repetitions ("min": of the
# fastest repetition of each, the one least disturbed by other load); per-repetition ratios follow.
# "CPU time": the ratio of the processes' user + sys CPU seconds (medians), less each program's
# set-up (the same command at 1x1): on a loaded machine a process waiting for a core accrues wall
# time but no CPU time, so this is the steadier figure (it counts all frames of a real-time run).
# Agreement: `narval compare --json` mean ΔE76 between the PoCL and native images of the last
# repetition, and the share of pixels equal bit for bit (narval-native --compare).
# Without SCENE: scenes/cloud.json at 320x180 (16 spp), scenes/listing_4_1.json at 240x120 (16 spp)
# and bench/native/homogeneous_fog.json at 320x180 (64 spp), each for pathtrace and raymarch;
# --resolution and --spp then apply to all. Not a test: nothing is asserted. Prints the load
# average before and after (these machines are shared: read the ratios with it).
# NARVAL, NATIVE, NATIVE_MARCH, NATIVE_TUNED pick the binaries (default build/narval,
# build/narval-native, build/narval-native-march, build/narval-native-tuned); "none" skips one.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
declare -A bin=([native]=${NATIVE:-build/narval-native} [march]=${NATIVE_MARCH:-build/narval-native-march}
                [tuned]=${NATIVE_TUNED:-build/narval-native-tuned})
scene=""
resolution=""
spp=""
frames=6
reps=3
threads=""
device=""
algorithms="pathtrace raymarch"
sets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --resolution) resolution=$2; shift 2 ;;
    --spp) spp=$2; shift 2 ;;
    --frames) frames=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    --threads) threads=$2; shift 2 ;;
    --device) device=$2; shift 2 ;;
    --algorithms) algorithms=$2; shift 2 ;;
    --set) sets+=(--set "$2"); shift 2 ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "unknown option $1" >&2; exit 2 ;;
    *) scene=$1; shift ;;
  esac
done
if [ ! -x "$narval" ] || [ ! -x "${bin[native]}" ]; then
  echo "missing $narval or ${bin[native]}: cmake --build build --target narval narval-native" \
       "narval-native-march narval-native-tuned" >&2
  exit 2
fi
variants=(native)
for v in march tuned; do [ -x "${bin[$v]}" ] && variants+=("$v"); done
if [ "$frames" -lt 2 ]; then echo "--frames must be at least 2 (the first frame is excluded)" >&2; exit 2; fi
if [ ! -f scenes/data/cloud_128.vdb ]; then "$narval" make-cloud scenes/data/cloud_128.vdb >/dev/null; fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if [ -n "$scene" ]; then
  cases=("$scene|$resolution|$spp")
else
  cases=("scenes/cloud.json|${resolution:-320x180}|${spp:-16}"
         "scenes/listing_4_1.json|${resolution:-240x120}|${spp:-16}"
         "bench/native/homogeneous_fog.json|${resolution:-320x180}|${spp:-64}")
fi

json() {  # FILE EXPR: a value of a JSON file (EXPR: Python over `j`)
  python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print($2)" "$1"
}

# run PROG SCENE ALG RES SPP TAG [options...]: renders, prints seconds (PoCL: "kernel wall")
run() {
  local prog=$1 sc=$2 alg=$3 res=$4 n=$5 tag=$6 opts=("${@:7}")
  if [ -n "$res" ]; then opts+=(--resolution "$res"); fi
  if [ "$alg" = pathtrace ]; then
    if [ -n "$n" ]; then opts+=(--spp "$n"); fi
  else
    opts+=(--frames "$frames")
  fi
  opts+=(--algorithm "$alg" -o "$work/$tag.exr" --stats-json "$work/$tag.json" ${sets[@]+"${sets[@]}"})
  if [ "$prog" = pocl ]; then
    if [ -n "$device" ]; then opts+=(--device "$device"); fi
    times >"$work/$tag.t0"
    "$narval" render "$sc" "${opts[@]}" >/dev/null
    times >"$work/$tag.t1"
    if [ "$alg" = pathtrace ]; then
      json "$work/$tag.json" '"%r %r" % (j["kernel_seconds"], j["seconds"])'
    else
      json "$work/$tag.json" '"%r %r" % (j["ms_per_frame"]["median"] / 1e3, j["ms_per_frame"]["wall"]["median"] / 1e3)'
    fi
  else
    if [ -n "$threads" ]; then opts+=(--threads "$threads"); fi
    times >"$work/$tag.t0"
    "${bin[$prog]}" "$sc" "${opts[@]}" >/dev/null
    times >"$work/$tag.t1"
    json "$work/$tag.json" 'j["seconds"]'
  fi
}

# cpu TAG: user + sys CPU seconds of the program the last `run ... TAG` started (bash's `times`,
# children's line, after minus before; no extra process in between).
cpu() {
  python3 - "$work/$1.t0" "$work/$1.t1" <<'PY'
import re, sys
def children(path):  # second line of `times`: children's user and sys, e.g. "0m1.234s 0m0.010s"
    line = open(path).read().splitlines()[1]
    return sum(int(m) * 60 + float(s) for m, s in re.findall(r"(\d+)m([\d.]+)s", line))
print(children(sys.argv[2]) - children(sys.argv[1]))
PY
}

load() { cut -d' ' -f1-3 /proc/loadavg; }
echo "load average (1, 5, 15 min) before: $(load); $(nproc) cores"
probe="${cases[0]%%|*}"
run pocl "$probe" pathtrace 16x16 1 probe >/dev/null
echo "- PoCL: $(json "$work/probe.json" 'j["device"]')"
for v in "${variants[@]}"; do
  run "$v" "$probe" pathtrace 16x16 1 probe >/dev/null
  echo "- $v: $(json "$work/probe.json" 'j["device"]')"
done
echo "$reps alternating repetitions (PoCL then $(IFS=,; echo "${variants[*]}")) after one warm-up of each; medians."
echo "pathtrace: whole render; real-time: median per frame of $frames frames (first excluded)."
echo
header="| scene | algorithm | size, spp | PoCL kernel s | PoCL wall s | native s | **PoCL/native** | PoCL/native (min) | PoCL/native CPU time"
rule="|---|---|---|---|---|---|---|---|---"
for v in "${variants[@]:1}"; do header+=" | $v s | PoCL/$v"; rule+="|---|---"; done
echo "$header | per-rep PoCL/native | bitwise-equal pixels | mean ΔE76 |"
echo "$rule|---|---|---|"
for c in "${cases[@]}"; do
  IFS='|' read -r sc res n <<<"$c"
  for alg in $algorithms; do
    tag=$(basename "$sc" .json)-$alg
    # Warm-up. The PoCL run also says which majorant (pathtrace) and majorant grid the device driver
    # chose (its defaults may differ from buildDeviceScene's): narval-native is given the same, so
    # both take the same random streams and do the same work.
    run pocl "$sc" "$alg" "$res" "$n" "$tag-pocl" >/dev/null
    mopts=()
    cells=$(json "$work/$tag-pocl.json" 'max(j.get("majorant_cells", [0]))')
    if [ "$cells" -gt 1 ]; then mopts+=(--majorant-resolution "$cells"); fi
    if [ "$alg" = pathtrace ]; then mopts+=(--majorant "$(json "$work/$tag-pocl.json" 'j["majorant"]')"); fi
    for v in "${variants[@]}"; do run "$v" "$sc" "$alg" "$res" "$n" "$tag-$v" "${mopts[@]}" >/dev/null; done
    # CPU time of the set-up (process start, scene and grid, OpenCL context and program cache, EXR):
    # the same command at 1x1, subtracted from each run's CPU time below.
    run pocl "$sc" "$alg" 1x1 "$n" "$tag-pocl-base" >/dev/null
    run native "$sc" "$alg" 1x1 "$n" "$tag-native-base" "${mopts[@]}" >/dev/null
    base_pocl=$(cpu "$tag-pocl-base") base_native=$(cpu "$tag-native-base")
    pc="" nc=""
    same=$(python3 -c 'import json,sys; a,b=(json.load(open(f)) for f in sys.argv[1:]); print(int(a["majorant_cells"]==b["majorant_cells"]))' \
           "$work/$tag-pocl.json" "$work/$tag-native.json")
    if [ "$same" != 1 ] && [ "$cells" -gt 1 ]; then
      echo "warning: $tag: PoCL and native majorant grids differ ($(json "$work/$tag-pocl.json" 'j["majorant_cells"]') vs" \
           "$(json "$work/$tag-native.json" 'j["majorant_cells"]')): not the same work" >&2
    fi
    declare -A times=()
    pk="" pw=""
    for rep in $(seq "$reps"); do
      read -r k w < <(run pocl "$sc" "$alg" "$res" "$n" "$tag-pocl")
      pk+=" $k" pw+=" $w" pc+=" $(cpu "$tag-pocl")"
      for v in "${variants[@]}"; do
        cmp=()  # the last repetition also compares with PoCL's image bit for bit (after its timing)
        if [ "$v" = native ] && [ "$rep" = "$reps" ]; then cmp=(--compare "$work/$tag-pocl.exr"); fi
        times[$v]+=" $(run "$v" "$sc" "$alg" "$res" "$n" "$tag-$v" "${mopts[@]}" ${cmp[@]+"${cmp[@]}"})"
        if [ "$v" = native ]; then nc+=" $(cpu "$tag-native")"; fi
      done
    done
    "$narval" compare "$work/$tag-pocl.exr" "$work/$tag-native.exr" --json --tonemap none --exposure 0 >"$work/$tag-de.json"
    size=$(json "$work/$tag-pocl.json" '"%dx%d" % (j["width"], j["height"]) + (", %d spp" % j["spp"] if j["algorithm"] == "pathtrace" else "")')
    others=""
    for v in "${variants[@]:1}"; do others+="$v:${times[$v]}|"; done
    python3 - "$sc" "$alg" "$size" "$pk" "$pw" "${times[native]}" "$others" "$work/$tag-native.json" "$work/$tag-de.json" \
      "$pc" "$nc" "$base_pocl" "$base_native" <<'PY'
import json, statistics, sys
sc, alg, size, pk, pw, nt, others, cmp_json, de_json, pc, nc, bp, bn = sys.argv[1:14]
f = lambda s: [float(x) for x in s.split()]
pk, pw, nt, pc, nc = f(pk), f(pw), f(nt), f(pc), f(nc)
m = statistics.median
cpu_ratio = (m(pc) - float(bp)) / (m(nc) - float(bn))
row = [sc, alg, size, "%.3f" % m(pk), "%.3f" % m(pw), "%.3f" % m(nt), "**%.2f**" % (m(pk) / m(nt)),
       "%.2f" % (min(pk) / min(nt)), "%.2f" % cpu_ratio]
for item in filter(None, others.split("|")):
    name, ts = item.split(":")
    t = f(ts)
    row += ["%.3f" % m(t), "%.2f" % (m(pk) / m(t))]
row.append(", ".join("%.2f" % (a / b) for a, b in zip(pk, nt)))
cmp = json.load(open(cmp_json))["compare"]
de = json.load(open(de_json))
row += ["%.1f%%" % cmp["pixels_bitwise_identical_pct"], "%.2g" % de["mean_dE76"]]
print("| " + " | ".join(row) + " |")
PY
    unset times
  done
done
echo
echo "load average after: $(load)"
