# bench/bench_common.sh: sourced by the bench scripts (from the repository root, after `narval` is
# set and the options are parsed). One place for what each of them did alike.

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
