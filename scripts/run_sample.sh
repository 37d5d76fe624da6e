#!/usr/bin/env bash
# Installs, builds, and runs the main job on generated sample data:
#   1. `subflow synth blob` renders a 10-camera, 24-frame deforming blob with ground truth;
#   2. `subflow hull` runs shape initialization (visual hull → base mesh → subdivision
#      surface fitted to every frame on one connectivity);
#   3. `subflow eval` scores the result against the ground truth.
# Everything goes to out/sample/ (replaced on each run of this script).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/build.sh"
subflow="$root/build/cli/subflow"
out="$root/out/sample"
rm -rf "$out"
mkdir -p "$out"
"$subflow" synth blob --out "$out/dataset"
"$subflow" hull "$out/dataset" --out "$out/hull"
"$subflow" eval "$out/dataset" "$out/hull" --json "$out/eval.json"
echo "sample run done: $out (hull/report.json, eval.json)"
