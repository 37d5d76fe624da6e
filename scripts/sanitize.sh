#!/usr/bin/env bash
# Builds the unit tests (and the `subflow` they run) with AddressSanitizer +
# UndefinedBehaviorSanitizer into build-asan/ (gcc, -O2 -g, no benchmarks) and runs them:
# any report fails the run (halt_on_error / abort_on_error, leaks included).
# Tests listed in SUBFLOW_SANITIZE_EXCLUDE (a ctest -E regex) run only in the release run
# of scripts/test.sh.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-asan"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSUBFLOW_SANITIZE=ON \
  -DSUBFLOW_BUILD_BENCHMARKS=OFF ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER}
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=0:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0"
cmake --build "$build" --parallel "$(nproc)"
cd "$build"
exclude="${SUBFLOW_SANITIZE_EXCLUDE:-}"
ctest --output-on-failure --parallel "$(nproc)" --timeout 1800 ${exclude:+-E "$exclude"}
