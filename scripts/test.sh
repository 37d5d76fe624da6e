#!/usr/bin/env bash
# The one test command (CI runs it): installs the dependencies, then builds every test with
# AddressSanitizer + UndefinedBehaviorSanitizer (clang, build-asan/, scripts/sanitize.sh) and
# runs them all (CTest + GoogleTest; the command tests run an instrumented `subflow`), then
# each reader's fuzz harness for a short fixed time (scripts/fuzz.sh, SUBFLOW_FUZZ_SECONDS,
# default 10). Measured on a fresh clone with 2 cores: ~40 min in all (README).
# SUBFLOW_TEST_RELEASE_ONLY=1 instead builds build/ (Release, gcc: what the README's main
# command runs) and runs every test there: a quicker local run, no sanitizers, no fuzzing.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
stage() { echo "test.sh: $1 ($(date -u +%H:%M:%S), ${SECONDS}s so far)"; }
if [ "${SUBFLOW_TEST_RELEASE_ONLY:-0}" = 1 ]; then
  stage "release build"
  bash "$root/scripts/build.sh"
  stage "release tests"
  (cd "$root/build" && ctest --output-on-failure --parallel "$(nproc)" --timeout 900)
  stage "done"
  exit 0
fi
stage "dependencies"
bash "$root/scripts/install_deps.sh"
stage "sanitizer build and tests"
bash "$root/scripts/sanitize.sh"
stage "fuzz smoke"
bash "$root/scripts/fuzz.sh" "${SUBFLOW_FUZZ_SECONDS:-10}"
stage "done"
