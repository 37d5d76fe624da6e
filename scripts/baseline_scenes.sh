#!/usr/bin/env bash
# The fidelity baseline (issue 12): for each scene of scripts/make_scenes.sh, runs
#   subflow reconstruct SCENE --out RUNS/SCENE/result          (defaults; /usr/bin/time -v)
#   subflow hull MASK_SCENE --out RUNS/SCENE/hull --evidence mask   (the exact-mask hull)
#   subflow eval SCENE RUNS/SCENE/result --json …/eval.json         (whole + observed surface)
#   subflow eval SCENE RUNS/SCENE/result --hull --json …/eval_result_hull.json  (the run's own hull)
#   subflow eval SCENE RUNS/SCENE/hull --hull --json …/eval_mask_hull.json
# one at a time, then prints the table (scripts/baseline_table.py).
#   scripts/baseline_scenes.sh [SCENES_DIR=/work/scenes] [RUNS_DIR=/work/scenes/runs] [SUBFLOW] [SCENE...]
# Environment: FRAMES=N reconstructs (and hulls) the first N frames only; SKIP_RECONSTRUCT=1
# keeps an existing result and only redoes the hull and the evaluations.
set -euo pipefail
SCENES=${1:-/work/scenes}
RUNS=${2:-/work/scenes/runs}
SUBFLOW=${3:-build/cli/subflow}
shift $(( $# > 3 ? 3 : $# )) || true
LIST=("$@")
[ ${#LIST[@]} -gt 0 ] || LIST=(bust_front mug_ring pair_dome critter_nomasks bust_still bust_still_bare take_small)

mask_scene() {  # the dataset with the same images and masks
  case $1 in
    critter_nomasks) echo critter_ring ;;
    *_still_bare) echo "${1%_bare}" ;;
    take_small|take_fast|take_hd) echo "" ;;
    *) echo "$1" ;;
  esac
}

for name in "${LIST[@]}"; do
  d="$SCENES/$name"; r="$RUNS/$name"
  [ -d "$d" ] || { echo "skip $name: no dataset $d"; continue; }
  mkdir -p "$r"
  range=()
  [ -z "${FRAMES:-}" ] || range=(--frames "$FRAMES")
  if [ -z "${SKIP_RECONSTRUCT:-}" ]; then
    echo "== $name: reconstruct ${range[*]}"
    /usr/bin/time -v "$SUBFLOW" reconstruct "$d" --out "$r/result" --overwrite "${range[@]}" > "$r/reconstruct.log" \
      2> "$r/reconstruct.time" || { echo "reconstruct failed: see $r/reconstruct.time"; continue; }
  fi
  m=$(mask_scene "$name")
  if [ -n "$m" ] && [ -d "$SCENES/$m/masks" ]; then
    echo "== $name: exact-mask hull from $m"
    /usr/bin/time -v "$SUBFLOW" hull "$SCENES/$m" --out "$r/hull" --evidence mask --overwrite "${range[@]}" \
      > "$r/hull.log" 2> "$r/hull.time"
    "$SUBFLOW" eval "$d" "$r/hull" --hull --json "$r/eval_mask_hull.json" > "$r/eval_mask_hull.txt" 2>/dev/null
  fi
  echo "== $name: eval"
  "$SUBFLOW" eval "$d" "$r/result" --json "$r/eval.json" > "$r/eval.txt" 2>/dev/null
  "$SUBFLOW" eval "$d" "$r/result" --hull --json "$r/eval_result_hull.json" > "$r/eval_result_hull.txt" 2>/dev/null
done
python3 "$(dirname "$0")/baseline_table.py" "$RUNS" "${LIST[@]}"
