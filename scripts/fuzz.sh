#!/usr/bin/env bash
# Builds the libFuzzer harnesses of the readers (fuzz/, clang, ASan + UBSan) into
# build-fuzz/ and runs each for SECONDS (default 20) on a copy of its seed corpus
# fuzz/corpus/<harness>/. Usage: scripts/fuzz.sh [SECONDS] [HARNESS...]
# A crash, sanitizer report, uncaught exception, leak, timeout (> 10 s per input) or
# out-of-memory (> 2 GB) fails the run and leaves the input as build-fuzz/crash-* (make it
# a regression test in tests/ and a seed in the corpus). The last lines of each run give
# libFuzzer's executions and coverage (cov: edges, ft: features).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-fuzz"
seconds="${1:-20}"
shift || true
CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSUBFLOW_FUZZ=ON \
  ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER} > /dev/null
cmake --build "$build" --parallel "$(nproc)"
harnesses=("$@")
if [ ${#harnesses[@]} -eq 0 ]; then
  for source in "$root"/fuzz/*_fuzzer.cpp; do harnesses+=("$(basename "$source" .cpp)"); done
fi
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
for harness in "${harnesses[@]}"; do
  corpus="$(mktemp -d)"
  seeds="$root/fuzz/corpus/$harness"
  [ -d "$seeds" ] && cp -r "$seeds/." "$corpus/"
  echo "fuzz: $harness for $seconds s ($(ls "$corpus" | wc -l) seeds)"
  status=0
  (cd "$build" && "./fuzz/$harness" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -close_fd_mask=3 "$corpus" > "$build/$harness.log" 2>&1) || status=$?
  grep -E "^#[0-9]+.*(DONE|INITED)|stat::number_of_executed_units|stat::peak_rss_mb" "$build/$harness.log" | tail -3
  rm -rf "$corpus"
  if [ "$status" -ne 0 ]; then
    tail -40 "$build/$harness.log"
    echo "fuzz: $harness FAILED (input saved in $build/crash-* / timeout-* / oom-*)"
    exit 1
  fi
done
echo "fuzz: ${#harnesses[@]} harnesses ran $seconds s each without a finding"
