#!/usr/bin/env bash
# Installs the Debian dependencies (idempotent) and builds subflow into build/ (Release):
# everything, or the given targets (e.g. subflow_programs: the command and the benchmarks).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install_deps.sh"
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$root/build" --parallel "$(nproc)" ${1:+--target "$@"}
