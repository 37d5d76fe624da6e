#!/usr/bin/env bash
# The one test command (CI runs it): installs the dependencies, builds `subflow` and the
# benchmarks in build/ (Release), then builds EVERY test with AddressSanitizer +
# UndefinedBehaviorSanitizer in build-asan/ and runs them all there (scripts/sanitize.sh:
# any report fails its test), then each reader's fuzz harness for a short fixed time
# (scripts/fuzz.sh, SUBFLOW_FUZZ_SECONDS, default 10).
# The tests run once, instrumented: building and running them a second time in Release as
# well does not fit CI's 45 minutes on 2 cores (README: Robustness checks).
#   SUBFLOW_TEST_RELEASE=1       also build and run every test in Release (build/) first
#   SUBFLOW_TEST_RELEASE_ONLY=1  only that: the quick local run, no sanitizers, no fuzzing
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
stage() { echo "test.sh: $1 ($(date -u +%H:%M:%S), ${SECONDS}s so far)"; }
release_tests() {
  stage "release build with the tests"
  bash "$root/scripts/build.sh"
  stage "release tests"
  (cd "$root/build" && ctest --output-on-failure --parallel "$(nproc)" --timeout 900)
}
if [ "${SUBFLOW_TEST_RELEASE_ONLY:-0}" = 1 ]; then
  release_tests
  exit 0
fi
if [ "${SUBFLOW_TEST_RELEASE:-0}" = 1 ]; then
  release_tests
else
  stage "release build of the programs (subflow, benchmarks)"
  bash "$root/scripts/build.sh" subflow_programs
fi
stage "every test, built and run with ASan + UBSan"
bash "$root/scripts/sanitize.sh"
stage "fuzz smoke"
bash "$root/scripts/fuzz.sh" "${SUBFLOW_FUZZ_SECONDS:-10}"
stage "done"
