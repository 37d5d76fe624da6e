#!/usr/bin/env bash
# Builds the tests with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ (gcc,
# -O1 -g1: line tables for the reports' stack traces, a third less compile time than
# -O2 -g; no benchmarks) and runs them: any report fails the run (halt_on_error /
# abort_on_error, leaks included).
# Which tests: SUBFLOW_SANITIZE_FOLDERS, default "core geometry vision" (the test folders =
# CTest labels, see tests/CMakeLists.txt: the readers, writers and file mechanisms every
# input passes through, which need only those three libraries built); "all" builds and runs
# every test, the command tests with an instrumented `subflow` (on a fresh clone with 2
# cores: 391/391 passed with zero reports; build 21.5 min + run 17 min, which next to the
# Release build and tests does not fit CI's 45 minutes yet).
# Tests matching SUBFLOW_SANITIZE_EXCLUDE (a ctest -E regex) are left out.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-asan"
folders="${SUBFLOW_SANITIZE_FOLDERS:-core geometry vision}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DSUBFLOW_SANITIZE=ON \
  -DSUBFLOW_BUILD_BENCHMARKS=OFF ${CMAKE_CXX_COMPILER_LAUNCHER:+-DCMAKE_CXX_COMPILER_LAUNCHER=$CMAKE_CXX_COMPILER_LAUNCHER}
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:detect_stack_use_after_return=0:strict_string_checks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:print_suppressions=0"
labels=()
if [ "$folders" = all ]; then
  cmake --build "$build" --parallel "$(nproc)"
else
  targets=()
  for folder in $folders; do targets+=("subflow_tests_$folder"); labels+=("$folder"); done
  cmake --build "$build" --parallel "$(nproc)" --target "${targets[@]}"
fi
cd "$build"
exclude="${SUBFLOW_SANITIZE_EXCLUDE:-}"
label_regex=""
if [ ${#labels[@]} -gt 0 ]; then label_regex="^($(IFS='|'; echo "${labels[*]}"))\$"; fi
ctest --output-on-failure --parallel "$(nproc)" --timeout 1800 ${label_regex:+-L "$label_regex"} ${exclude:+-E "$exclude"}
