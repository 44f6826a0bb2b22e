#!/usr/bin/env bash
# scripts/fuzz.sh [SECONDS]: builds the libFuzzer targets for the scene parser and the .vol parser
# (fuzz/, clang with address and undefined-behaviour sanitizers) in build-fuzz/ and runs each for
# SECONDS (default: $NARVAL_FUZZ_SECONDS, else 30; 0 skips), both at once, starting from the seed
# corpus in fuzz/corpus/ copied into build-fuzz/corpus/ (the repository is not written to; the
# scratch corpus grows from run to run). Exits 1 on any finding (crash, sanitizer report, leak,
# timeout, allocation over the limit, or an error that is not one InputError line) and names the
# input that reproduces it:  build-fuzz/scene_parser_fuzz build-fuzz/findings/scene/crash-...
set -euo pipefail
cd "$(dirname "$0")/.."

seconds=${1:-${NARVAL_FUZZ_SECONDS:-30}}
if ! [[ $seconds =~ ^[0-9]+$ ]]; then
  echo "fuzz: SECONDS must be a whole number, got '$seconds'" >&2
  exit 2
fi
if [ "$seconds" -eq 0 ]; then
  echo "fuzz: skipped (NARVAL_FUZZ_SECONDS=0)"
  exit 0
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz: clang++ not found (scripts/setup.sh installs clang and libclang-rt-dev)" >&2
  exit 1
fi

build=build-fuzz
jobs=$(nproc 2>/dev/null || echo 2)
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
start=$SECONDS
mkdir -p "$build"
if ! { CC=clang CXX=clang++ cmake -S fuzz -B "$build" ${launcher[@]+"${launcher[@]}"} &&
       cmake --build "$build" -j"$jobs"; } >"$build/build.log" 2>&1; then
  tail -n 40 "$build/build.log" >&2
  echo "fuzz: building the fuzz targets failed (log: $build/build.log)" >&2
  exit 1
fi
echo "fuzz: built $build/scene_parser_fuzz and $build/vol_parser_fuzz in $((SECONDS - start)) s;" \
  "fuzzing each for $seconds s"

# Undefined behaviour aborts (-fno-sanitize-recover) with a stack; leaks are findings (ASan default).
export UBSAN_OPTIONS=print_stacktrace=1${UBSAN_OPTIONS:+:$UBSAN_OPTIONS}

targets=(scene vol)
pids=()
for t in "${targets[@]}"; do
  mkdir -p "$build/corpus/$t" "$build/findings/$t"
  cp -R "fuzz/corpus/$t/." "$build/corpus/$t/"
  "$build/${t}_parser_fuzz" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=512 \
    -dict="fuzz/$t.dict" -artifact_prefix="$build/findings/$t/" -print_final_stats=1 \
    "$build/corpus/$t" >"$build/fuzz-$t.log" 2>&1 &
  pids+=($!)
done

failed=0
for i in "${!targets[@]}"; do
  t=${targets[$i]}
  log=$build/fuzz-$t.log
  rc=0
  wait "${pids[$i]}" || rc=$?
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
  # The last status line: "#N DONE cov: C ft: F corp: K/SIZE ..."
  status=$(grep -E '^#[0-9]+.*cov:' "$log" | tail -n 1 | sed -E 's/.*(cov: [0-9]+ ft: [0-9]+ corp: [^ ]+ lim: [0-9]+ exec\/s: [0-9]+).*/\1/' || true)
  if [ "$rc" -eq 0 ]; then
    echo "fuzz: ${t}_parser_fuzz: ${runs:-?} runs, $status: no findings"
  else
    failed=1
    echo "fuzz: ${t}_parser_fuzz: FINDING (exit $rc) after ${runs:-?} runs; log $log:" >&2
    { grep -v -E '# Uses: |^(#[0-9]+|INFO:|stat::)|ecommended dictionary' "$log" || true; } | tail -n 40 >&2
    input=$(sed -n 's/.*Test unit written to //p' "$log" | tail -n 1)
    if [ -n "$input" ]; then
      echo "fuzz: the input is $input; reproduce with: $build/${t}_parser_fuzz $input" >&2
    fi
  fi
done
echo "fuzz: done in $((SECONDS - start)) s"
exit "$failed"
