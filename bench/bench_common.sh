# bench/bench_common.sh: sourced by the bench scripts (from the repository root, after `narval` is
# set and the options are parsed). One place for what each of them did alike.

# bench_options "NAME ..." "$@": --NAME VALUE sets $NAME (dashes read as underscores) for each NAME
# listed, --NAME sets NAME=1 for a NAME listed as NAME!, and --device SPEC sets device="--device
# SPEC"; anything else is one line on stderr and exit 2.
bench_options() {
  local names=" $1 " name
  shift
  while [ $# -gt 0 ]; do
    name=${1#--} && name=${name//-/_}
    if [[ $1 == --* && $names == *" $name! "* ]]; then
      printf -v "$name" 1 && shift
    elif [[ $1 == --* && $names == *" $name "* && $# -ge 2 ]]; then
      if [ "$name" = device ]; then device="--device $2"; else printf -v "$name" '%s' "$2"; fi
      shift 2
    else
      echo "$(basename "$0"): unknown option $1$([[ $names == *" $name "* ]] && echo " (it needs a value)")" >&2
      exit 2
    fi
  done
}

# Builds narval when the default binary is missing; a scratch folder $work, removed on exit.
bench_init() {
  if [ "$narval" = build/narval ] && [ ! -x build/narval ]; then scripts/setup.sh >/dev/null; fi
  work=$(mktemp -d)
  trap 'rm -rf "$work"' EXIT
}

# bench_seconds STATS.json ALGORITHM: the render's time from --stats-json: the launches' kernel
# seconds for pathtrace, the median kernel seconds per frame (--frames) for the real-time kernels.
bench_seconds() {
  python3 - "$1" "$2" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
print(s["kernel_seconds"] if sys.argv[2] == "pathtrace" else s["ms_per_frame"]["median"] / 1e3)
PY
}

# bench_device STATS.json: the device name a render ran on.
bench_device() { python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['device'])" "$1"; }

# bench_missing SCENE: the scene's absent volume files, one a line (nothing when all are there),
# found as narval's loader finds them (bench/scene_env.py).
bench_missing() { python3 bench/scene_env.py missing "$1"; }

# bench_time SCENE ALGORITHM [OPTIONS...]: renders SCENE at $resolution ($spp spp for pathtrace,
# else --frames $frames) on $device into $work/out.exr; prints its seconds (bench_seconds).
bench_time() {
  local scene=$1 alg=$2 n=(--frames "$frames")
  shift 2
  [ "$alg" = pathtrace ] && n=(--spp "$spp")
  # shellcheck disable=SC2086
  "$narval" render "$scene" -o "$work/out.exr" --algorithm "$alg" --resolution "$resolution" "${n[@]}" $device \
    "$@" --stats-json "$work/s.json" >/dev/null
  bench_seconds "$work/s.json" "$alg"
}

# bench_ab ROW DIGITS RATIO_DIGITS RUN "A ARGS" "B ARGS" [inverse]: one warm-up of `RUN A ARGS` and
# of `RUN B ARGS` (word-split; RUN prints seconds), then $reps alternating repetitions (A, B, A, B,
# ...) so both see the same machine load. Prints "| ROW | median A | median B | A/B | per-repetition
# A/B |" (B/A with inverse), medians to DIGITS decimals, ratios to RATIO_DIGITS.
bench_ab() {
  local - a="" b=""
  set -f  # the arguments are split on spaces, never globbed (materials[1].g=...)
  # shellcheck disable=SC2086
  { $4 $5 >/dev/null; $4 $6 >/dev/null; }
  for _ in $(seq "$reps"); do
    # shellcheck disable=SC2086
    a+=" $($4 $5)" b+=" $($4 $6)"
  done
  python3 - "$1" "$2" "$3" "$a" "$b" "${7:-}" <<'PY'
import statistics, sys
row, d, rd, a, b, inverse = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], sys.argv[5], sys.argv[6]
a, b = [float(x) for x in a.split()], [float(x) for x in b.split()]
ma, mb = statistics.median(a), statistics.median(b)
(n, m), pairs = ((mb, ma), zip(b, a)) if inverse else ((ma, mb), zip(a, b))
per = ", ".join("%.*f" % (rd, x / y) for x, y in pairs)
print("| %s | %.*f | %.*f | %.*f | %s |" % (row, d, ma, d, mb, rd, n / m, per))
PY
}

# bench_reference OUT.exr SCENE [render options...]: a path-traced reference kept at OUT.exr.
# narval's --resume renders it when absent, completes an interrupted one, leaves a finished one as
# it is, and refuses one from other settings, which is then rendered again.
bench_reference() {
  local out=$1 scene=$2 err
  shift 2
  err=$("$narval" render "$scene" -o "$out" --algorithm pathtrace "$@" --resume 2>&1 >/dev/null) && return
  echo "  ${err##*$'\n'}: rendering $out again" >&2
  "$narval" render "$scene" -o "$out" --algorithm pathtrace "$@" >/dev/null
}
