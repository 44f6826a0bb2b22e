#!/usr/bin/env bash
# bench/cost_model.sh [--quick] [--reps R] [--out DIR] [--device SPEC] [--scene FILE]
#                     [--algorithms "pathtrace raymarch"]
# Cost model (issue 6, item 5): how render time grows with each factor, one factor at a time around
# a base configuration of scenes/cloud.json (generated 128³ cloud, density 5):
#   pathtrace (base 160x80, 16 spp, the scene's bounces): pixels 80x40..640x320, spp 4..64, bounces 1..32,
#             density multiplier ×0.25..×8 (materials.N.density), the same with --majorant global
#             (no DDA: delta tracking's textbook cost, for comparison), grid 64³..512³ (generated clouds);
#   raymarch  (base 320x160, the scene's steps and shadow steps): pixels, steps 15..240, density, grid.
# The scene's values (bounces, steps, the volume's density) are narval's: `narval scene --resolved`.
# Generated clouds: `narval make-cloud --resolution G` (default seed, as scenes/data/cloud_128.vdb)
# into a temporary folder, swapped in with `--set materials.N.path=...`.
# Per series: pathtrace points run once with --counters first (collisions_tentative,
# collisions_real, density_lookups: deterministic for the fixed seed, so once suffices; this also
# builds the counting program), then one warm-up run without counters (program cache, first
# launch), then R repetitions, each running every point of the series in turn so that all points see
# the same machine load. Recorded per run: kernel_seconds (profiling time of the launches: no build,
# no grid load/upload), seconds (narval's render time), the process's wall time (everything,
# including reading the .vdb) and its CPU time; one start-up run per point (8x4 pixels, 1 spp) gives
# the CPU time that is not rendering. /proc/loadavg is recorded at the start and end of every series.
# bench/cost_model.py fits log(time) = a + b·log(x) on the medians and prints Markdown tables.
# --quick: a small smoke run (smaller base, 3 points per series, 1 repetition; under a minute).
# Not a test: nothing is asserted. The binary: $NARVAL_BIN (or $NARVAL), default build/narval, copied
# to the temporary folder first so that a rebuild of a shared build folder cannot change it mid-run.
# Raw runs and the report go to --out (default build/cost_model): raw.json, meta.json, report.md.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL_BIN:-${NARVAL:-build/narval}}
quick=0
reps=3
out=build/cost_model
device=""
scene=scenes/cloud.json
algorithms="pathtrace raymarch"
. bench/bench_common.sh
bench_options "quick! reps out device scene algorithms" "$@"
if [ ! -x "$narval" ]; then
  echo "no narval binary at $narval (set NARVAL_BIN, or build: cmake --build build --target narval)" >&2
  exit 2
fi

if [ "$quick" = 1 ]; then
  pt_res=80x40; pt_spp=4; rm_res=80x40
  [ "$reps" = 3 ] && reps=1
  pixels="40x20 80x40 160x80"
  spps="2 4 8"
  bounces="1 4 16"
  mults="0.5 1 2"
  grids="32 64 128"
  steps="15 60 240"
else
  pt_res=160x80; pt_spp=16; rm_res=320x160
  pixels="80x40 160x80 320x160 640x320"
  spps="4 8 16 32 64"
  bounces="1 2 4 8 16 32"
  mults="0.25 0.5 1 2 4 8"
  grids="64 128 256 512"
  steps="15 30 60 120 240"
fi

mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# Run a private copy: a shared build folder may be rebuilt mid-run (a different binary, or none).
binary_info="$narval, $(stat -c '%y' "$narval" | cut -d. -f1), md5 $(md5sum "$narval" | cut -c1-12)"
cp "$narval" "$work/narval"
narval_src=$narval
narval=$work/narval
"$narval" render --help >/dev/null || { echo "$narval_src does not run (being rebuilt?)" >&2; exit 2; }
raw="$out/raw.json"
: >"$raw"
start=$(date +%s.%N)
load_start=$(cat /proc/loadavg)

# The volume material of the scene (the one the volume primitive uses), its density, the scene's
# bounces and the ray marcher's steps, as narval resolves them.
read -r mat density0 pt_bounces rm_steps < <(python3 - "$narval" "$scene" <<'PY'
import sys
sys.path.insert(0, "bench")
from scene_env import resolved_scene
s = resolved_scene(sys.argv[1], sys.argv[2])
name = next(p["materialName"] for p in s["primitives"] if p["type"] == "volume")
i = next(i for i, m in enumerate(s["materials"]) if m["name"] == name)
print(i, s["materials"][i]["density"], s["renderer"]["bounces"], s["renderer"]["raymarch"]["steps"])
PY
)

echo "cost model: $narval_src on $scene (material $mat, density $density0), reps $reps, out $out" >&2
echo "load average at start: $load_start" >&2
gen_start=$(date +%s.%N)
for g in $grids; do "$narval" make-cloud "$work/cloud_$g.vdb" --resolution "$g" >/dev/null; done
gen_seconds=$(python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$gen_start" "$(date +%s.%N)")

# run ALGO FACTOR X REP COUNTERS(0/1) [options...]: one render, appended to raw.json.
# REP 0 is the counting run, -1 the warm-up, -2 the start-up run; all kept in raw.json, none timed
# by the fit. Recorded besides the stats: the process's wall time and its CPU time (user + sys, from
# the shell's `times`): PoCL runs the kernels on this process's threads, so CPU time measures the
# work even when other processes take the cores (kernel_seconds then stretches, CPU time does not).
run() {
  local algo=$1 factor=$2 x=$3 rep=$4 counters=$5
  shift 5
  local extra=()
  [ "$counters" = 1 ] && extra=(--counters)
  local t0 t1
  t0=$(date +%s%N)
  times >"$work/c0"  # builtin, no fork: this shell's children's CPU so far (second line)
  # shellcheck disable=SC2086
  if ! "$narval" render "$scene" -o "$work/out.exr" --algorithm "$algo" $device "$@" "${extra[@]}" \
      --stats-json "$work/s.json" >/dev/null 2>"$work/err"; then
    echo "failed: $algo $factor=$x: $(head -n 3 "$work/err")" >&2
    exit 1
  fi
  times >"$work/c1"
  t1=$(date +%s%N)
  {
    printf '{"algorithm": "%s", "factor": "%s", "x": %s, "rep": %s, "counters": %s, "wall": %s, "cpu_before": "%s", "cpu_after": "%s", "options": "%s", "stats": ' \
      "$algo" "$factor" "$x" "$rep" "$counters" "$(( (t1 - t0) / 1000 ))e-6" "$(sed -n 2p "$work/c0")" \
      "$(sed -n 2p "$work/c1")" "$*"
    cat "$work/s.json"
    echo "}"
  } >>"$raw"
}

# Series: each line "X OPTIONS..." (the base configuration with one option varied).
series() {
  local algo=$1 factor=$2
  local res spp=$pt_spp nb=$pt_bounces st=$rm_steps dens=$density0 path="" r n m g
  if [ "$algo" = pathtrace ]; then res=$pt_res; else res=$rm_res; fi
  opts() {  # the options of one point from the variables above
    if [ "$algo" = pathtrace ]; then echo -n "--resolution $res --spp $spp --bounces $nb"
    else echo -n "--resolution $res --set renderer.raymarch.steps=$st"; fi
    [ "$dens" != "$density0" ] && echo -n " --set materials.$mat.density=$dens"
    [ -n "$path" ] && echo -n " --set materials.$mat.path=$path"
    echo
  }
  case "$factor" in
    pixels) for r in $pixels; do res=$r; echo "$((${r%x*} * ${r#*x})) $(opts)"; done; res="" ;;
    spp) for n in $spps; do spp=$n; echo "$n $(opts)"; done ;;
    bounces) for n in $bounces; do nb=$n; echo "$n $(opts)"; done ;;
    steps) for n in $steps; do st=$n; echo "$n $(opts)"; done ;;
    density|density-global)
      for m in $mults; do
        dens=$(python3 -c "import sys; print(float(sys.argv[1]) * float(sys.argv[2]))" "$m" "$density0")
        echo "$m $(opts)$( [ "$factor" = density-global ] && echo " --majorant global")"
      done ;;
    grid) for g in $grids; do path=$work/cloud_$g.vdb; echo "$((g * g * g)) $(opts)"; done ;;
  esac
}

declare -a loads=()
for algo in $algorithms; do
  if [ "$algo" = pathtrace ]; then factors="pixels spp bounces density density-global grid"; else factors="pixels steps density grid"; fi
  for factor in $factors; do
    mapfile -t points < <(series "$algo" "$factor")
    l0=$(cut -d' ' -f1-3 /proc/loadavg)
    echo "  $algo $factor (${#points[@]} points; load $l0)" >&2
    if [ "$algo" = pathtrace ]; then
      for p in "${points[@]}"; do
        # shellcheck disable=SC2086
        run "$algo" "$factor" ${p%% *} 0 1 ${p#* }
      done
    fi
    # Start-up cost per point (process, device, scene and grid load, cached program; tiny image):
    # subtracted from the CPU time by cost_model.py.
    for p in "${points[@]}"; do
      o=$(echo "${p#* }" | sed -e 's/--resolution [0-9x]*/--resolution 8x4/' -e 's/--spp [0-9]*/--spp 1/')
      # shellcheck disable=SC2086
      run "$algo" "$factor" ${p%% *} -2 0 $o
    done
    # shellcheck disable=SC2086
    run "$algo" "$factor" ${points[0]%% *} -1 0 ${points[0]#* }
    for rep in $(seq "$reps"); do
      for p in "${points[@]}"; do
        # shellcheck disable=SC2086
        run "$algo" "$factor" ${p%% *} "$rep" 0 ${p#* }
      done
    done
    l1=$(cut -d' ' -f1-3 /proc/loadavg)
    loads+=("{\"algorithm\": \"$algo\", \"factor\": \"$factor\", \"before\": \"$l0\", \"after\": \"$l1\"}")
  done
done

load_end=$(cat /proc/loadavg)
echo "load average at end: $load_end" >&2
end=$(date +%s.%N)
{
  echo "{"
  echo "  \"binary\": \"$binary_info\", \"scene\": \"$scene\", \"material\": $mat, \"density\": $density0,"
  echo "  \"quick\": $quick, \"reps\": $reps,"
  echo "  \"pathtrace_base\": {\"resolution\": \"$pt_res\", \"spp\": $pt_spp, \"bounces\": $pt_bounces},"
  echo "  \"raymarch_base\": {\"resolution\": \"$rm_res\", \"steps\": $rm_steps},"
  echo "  \"grids\": \"$grids\", \"density_multipliers\": \"$mults\","
  echo "  \"commit\": \"$(git rev-parse --short HEAD 2>/dev/null || echo unknown)\","
  echo "  \"date\": \"$(date -u +%Y-%m-%dT%H:%M:%SZ)\", \"cpus\": $(nproc),"
  echo "  \"cloud_generation_seconds\": $gen_seconds,"
  echo "  \"seconds\": $(python3 -c "import sys; print(float(sys.argv[2]) - float(sys.argv[1]))" "$start" "$end"),"
  echo "  \"loadavg_start\": \"$load_start\", \"loadavg_end\": \"$load_end\","
  echo "  \"series_load\": [$(IFS=,; echo "${loads[*]}")]"
  echo "}"
} >"$out/meta.json"
python3 bench/cost_model.py "$out" | tee "$out/report.md"
