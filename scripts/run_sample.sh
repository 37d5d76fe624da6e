#!/usr/bin/env bash
# Installs, builds, and runs the main job on generated sample data:
#   1. `subflow synth blob` renders a 10-camera, 24-frame deforming blob with ground truth;
#   2. `subflow reconstruct` runs the main job: shape initialization (visual hull → base
#      mesh → subdivision surface on one connectivity), motion initialization (normal
#      flow), spatio-temporal stereo refinement (Ceres) and the rigid / non-rigid split;
#   3. `subflow eval` scores the result against the ground truth;
#   4. what users open: `subflow export` (blob.glb, blob.pc2 + blob.obj), `subflow view`
#      (viewer.html) and `subflow render` (pictures/).
# Everything goes to out/sample/ (replaced on each run of this script).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/build.sh"
subflow="$root/build/cli/subflow"
out="$root/out/sample"
rm -rf "$out"
mkdir -p "$out"
"$subflow" synth blob --out "$out/dataset"
"$subflow" reconstruct "$out/dataset" --out "$out/result"
"$subflow" eval "$out/dataset" "$out/result" --json "$out/eval.json"
"$subflow" export "$out/result" --format glb --color flow --out "$out/blob.glb"
"$subflow" export "$out/result" --format pc2 --out "$out/blob.pc2"
"$subflow" view "$out/result" --out "$out/viewer.html"
"$subflow" render "$out/result" --out "$out/pictures" --views 8
echo "sample run done: $out (result/meshes, result/report.json, eval.json, blob.glb, blob.pc2 + blob.obj,"
echo "  viewer.html, pictures/)"
