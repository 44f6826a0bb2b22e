#!/usr/bin/env bash
# bench/majorant.sh [--device SPEC] [--scenes "A.json B.json"] [--resolution WxH] [--spp N]
#                   [--reps R] [--cells "8 16 32 64"] [--frames K]
# The majorant grid (issue 6, item 1) against the global majorant, through the CLI:
# - pathtrace, per scene: `--majorant global` and `--majorant grid --majorant-resolution N` for each
#   N in --cells (cells along the grid's longest axis). One `--counters` run per configuration gives
#   collisions_tentative / collisions_real (delta tracking's tentative collisions per real one) and
#   density_lookups (delta + ratio tracking) from --stats-json; the counts are deterministic (fixed
#   seed), so one run suffices. Then R timed runs without counters (the kernel the user gets),
#   alternating the configurations within each repetition so all see the same machine load, after
#   one warm-up of each (program build, first launch). Reported: median kernel seconds and the
#   speed-up over global (global s / config s; the per-repetition ratios beside it).
# - the cost of counting: the default grid with and without --counters, same alternation.
# - raymarch (empty-space skipping with the same cells): median kernel ms per frame of K frames.
# Not a test: nothing is asserted. NARVAL=path/to/narval picks the binary (default build/narval).
# The Disney cloud scene reads its grid where scenes/disney_cloud.json says; a scene whose data is
# absent is skipped with a note.
set -euo pipefail
cd "$(dirname "$0")/.."
narval=${NARVAL:-build/narval}
device=""
scenes="scenes/disney_cloud.json scenes/cloud.json"
resolution=160x80
spp=16
reps=3
cells="8 16 32 64"
frames=5
. bench/bench_common.sh
bench_options "device scenes resolution spp reps cells frames" "$@"
bench_init

# config name -> CLI options
opts() {
  case "$1" in
    global) echo "--majorant global" ;;
    grid-*) echo "--majorant grid --majorant-resolution ${1#grid-}" ;;
  esac
}

# scene config [extra...] -> writes $work/s.json
render() {
  local scene=$1 config=$2
  shift 2
  # shellcheck disable=SC2046,SC2086
  "$narval" render "$scene" -o "$work/out.exr" --resolution "$resolution" --spp "$spp" $device $(opts "$config") \
    "$@" --stats-json "$work/s.json" >/dev/null
}
field() { python3 -c "import json,sys; s=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$work/s.json" "$1"; }

configs="global"
for c in $cells; do configs="$configs grid-$c"; done

for scene in $scenes; do
  # shellcheck disable=SC2086
  if ! "$narval" render "$scene" -o "$work/out.exr" --resolution 4x2 --spp 1 $device 2>"$work/err" >/dev/null; then
    echo "## $scene: skipped ($(head -n 1 "$work/err"))"
    echo
    continue
  fi
  # Counts (one run each) and warm-up of every program.
  declare -A perReal lookups cellText
  for c in $configs; do
    render "$scene" "$c" --counters
    perReal[$c]=$(field '"%.2f" % (s["collisions_tentative"] / max(1, s["collisions_real"]))')
    lookups[$c]=$(field 's["density_lookups"]')
    cellText[$c]=$(field '"x".join(str(v) for v in s["majorant_cells"])')
    render "$scene" "$c"
  done
  echo "## $scene at $resolution, $spp spp"
  echo "device: $(field 's["device"]'), grid storage: $(field 's.get("storage", "?")')"
  echo
  declare -A times
  for c in $configs; do times[$c]=""; done
  for _ in $(seq "$reps"); do
    for c in $configs; do
      render "$scene" "$c"
      times[$c]="${times[$c]} $(field 's["kernel_seconds"]')"
    done
  done
  echo "| majorant | cells | tentative per real | vs global | density lookups | kernel s (median of $reps) | speed-up vs global | per repetition |"
  echo "|---|---|---|---|---|---|---|---|"
  for c in $configs; do
    python3 - "$c" "${cellText[$c]}" "${perReal[$c]}" "${perReal[global]}" "${lookups[$c]}" "${times[$c]}" \
      "${times[global]}" <<'PY'
import statistics, sys
c, cells, pr, prg, lk, t, tg = sys.argv[1:8]
t = [float(x) for x in t.split()]
tg = [float(x) for x in tg.split()]
name = "global" if c == "global" else "grid " + c.split("-")[1]
per = ", ".join("%.2f" % (g / x) for g, x in zip(tg, t))
print(f"| {name} | {cells if c != 'global' else '(1)'} | {float(pr):.2f} | {float(prg) / float(pr):.2f}x | {int(lk):,} "
      f"| {statistics.median(t):.3f} | {statistics.median(tg) / statistics.median(t):.2f}x | {per} |")
PY
  done
  echo
  # The cost of counting: the default grid (automatic cells) with and without --counters.
  plain=""
  counted=""
  render "$scene" "grid-0"
  render "$scene" "grid-0" --counters
  for _ in $(seq "$reps"); do
    render "$scene" "grid-0"
    plain="$plain $(field 's["kernel_seconds"]')"
    render "$scene" "grid-0" --counters
    counted="$counted $(field 's["kernel_seconds"]')"
  done
  python3 - "$plain" "$counted" <<'PY'
import statistics, sys
p = [float(x) for x in sys.argv[1].split()]
c = [float(x) for x in sys.argv[2].split()]
print(f"counting (default grid): {statistics.median(p):.3f} s without, {statistics.median(c):.3f} s with --counters "
      f"({statistics.median(c) / statistics.median(p):.3f}x)")
PY
  # raymarch: the same cells skip empty space.
  line="raymarch ms/frame (median of $frames) by cells:"
  for c in $cells; do
    # shellcheck disable=SC2086
    "$narval" render "$scene" -o "$work/rm.exr" --algorithm raymarch --resolution "$resolution" --frames "$frames" \
      $device --majorant-resolution "$c" --stats-json "$work/s.json" >/dev/null
    line="$line $c: $(field '"%.2f" % s["ms_per_frame"]["median"]')"
  done
  echo "$line"
  echo
  unset perReal lookups cellText times
done
