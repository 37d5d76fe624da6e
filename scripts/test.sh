#!/usr/bin/env bash
# The one test command (CI runs it): installs, builds and runs every test (CTest +
# GoogleTest) in build/ (Release); then the tests of core/, geometry/ and vision/ built with
# ASan + UBSan in build-asan/ (scripts/sanitize.sh; SUBFLOW_SANITIZE_FOLDERS=all for every
# test); then each reader's fuzz harness for a short fixed time (scripts/fuzz.sh,
# SUBFLOW_FUZZ_SECONDS, default 10). Set SUBFLOW_TEST_RELEASE_ONLY=1 to skip the last two
# (a quick local run).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
stage() { echo "test.sh: $1 ($(date -u +%H:%M:%S), ${SECONDS}s so far)"; }
stage "release build"
bash "$root/scripts/build.sh"
stage "release tests"
(cd "$root/build" && ctest --output-on-failure --parallel "$(nproc)" --timeout 900)
if [ "${SUBFLOW_TEST_RELEASE_ONLY:-0}" = 1 ]; then exit 0; fi
stage "sanitizer build and tests"
bash "$root/scripts/sanitize.sh"
stage "fuzz smoke"
bash "$root/scripts/fuzz.sh" "${SUBFLOW_FUZZ_SECONDS:-10}"
stage "done"
