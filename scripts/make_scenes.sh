#!/usr/bin/env bash
# Regenerates the synthetic scenes of the fidelity baseline (issue 12) and the synthetic
# takes with real-capture difficulties (issue 13 item 5).
#   scripts/make_scenes.sh [OUT_DIR=/work/scenes] [SUBFLOW=build/cli/subflow] [SCENE...]
# Each scene is a dataset in the DATASET.md layout with ground truth; existing ones are
# replaced (--overwrite). Sizes are the moderate ones of the baseline (320×240, 24 frames):
# reconstructing one takes minutes. The `take_hd` scene is 1088×1920 and slow.
set -euo pipefail
OUT=${1:-/work/scenes}
SUBFLOW=${2:-build/cli/subflow}
shift $(( $# > 2 ? 2 : $# )) || true
ONLY=("$@")
mkdir -p "$OUT"

scene() {  # scene NAME ARGS...
  local name=$1; shift
  if [ ${#ONLY[@]} -gt 0 ] && [[ ! " ${ONLY[*]} " == *" $name "* ]]; then return; fi
  echo "== $name: subflow synth $*"
  "$SUBFLOW" synth "$@" --out "$OUT/$name" --overwrite | grep -v '^\s*$' | tail -3
}

# Head-like bust (3 mm ear plates, eye sockets, mouth, jaw opening), 11 cameras in front only,
# a textured room behind, soft shadows; masks and a background image.
scene bust_front   bust    --rig front --cameras 11 --environment room --shadows --frames 24
# Genus-1 mug that tumbles and bends, ring of 10, textured floor, shadows.
scene mug_ring     mug     --rig ring --cameras 10 --environment floor --shadows --frames 24
# Two figures moving independently, dome of 10, textured room.
scene pair_dome    pair    --rig dome --cameras 10 --environment room --frames 24
# Twisting animal-like critter, ring of 10, textured room and shadows; with masks (for the
# exact-mask hull) and the same images without masks (reconstructed from the background image).
scene critter_ring critter --rig ring --cameras 10 --environment room --shadows --frames 24
if [ ${#ONLY[@]} -eq 0 ] || [[ " ${ONLY[*]} " == *" critter_nomasks "* ]]; then
  echo "== critter_nomasks: critter_ring without masks/ (hard links)"
  rm -rf "$OUT/critter_nomasks" && cp -al "$OUT/critter_ring" "$OUT/critter_nomasks" && rm -rf "$OUT/critter_nomasks/masks"
fi
# Stills (one frame) of the bust's frame 30: with masks, and without masks or background.
scene bust_still   bust    --rig front --cameras 11 --environment room --shadows --frames 1 --start-frame 30
scene bust_still_bare bust --rig front --cameras 11 --environment room --shadows --frames 1 --start-frame 30 \
  --no-masks --no-background
# The same pair of stills on two wider rigs: the critter's ring of 10 and the pair's dome of 10
# (each camera with 1–2 sweep neighbours within 70°; docs/shape.md, "Still sets without masks").
scene critter_still critter --rig ring --cameras 10 --environment room --shadows --frames 1 --start-frame 12
scene critter_still_bare critter --rig ring --cameras 10 --environment room --shadows --frames 1 --start-frame 12 \
  --no-masks --no-background
scene pair_still   pair    --rig dome --cameras 10 --environment room --frames 1 --start-frame 12
scene pair_still_bare pair --rig dome --cameras 10 --environment room --frames 1 --start-frame 12 \
  --no-masks --no-background
# The three stills on the default plain dark backdrop (no room), with and without masks: the
# plain-backdrop evidence (docs/shape.md, "Still sets on a plain backdrop").
scene bust_dark_still bust --rig front --cameras 11 --frames 1 --start-frame 30
scene bust_dark_still_bare bust --rig front --cameras 11 --frames 1 --start-frame 30 --no-masks --no-background
scene critter_dark_still critter --rig ring --cameras 10 --frames 1 --start-frame 12
scene critter_dark_still_bare critter --rig ring --cameras 10 --frames 1 --start-frame 12 --no-masks --no-background
scene pair_dark_still pair --rig dome --cameras 10 --frames 1 --start-frame 12
scene pair_dark_still_bare pair --rig dome --cameras 10 --frames 1 --start-frame 12 --no-masks --no-background
# Takes like a real capture: 4 cameras, portrait, lens distortion, a walker outside the
# working volume and a ball crossing in front of cam00, MP4 videos, no masks, no background.
# take_small (272×480, 24 frames) is in the baseline; take_hd (1088×1920, 100 frames) is
# the full-size variant (slow to render: about a minute per image on 2 busy cores).
TAKE=(pair --rig ring --cameras 4 --distortion -0.12,0.03,0,0,0 --environment room --distractors both
      --video mp4 --no-masks --no-background)
scene take_small   "${TAKE[@]}" --width 272 --height 480 --frames 24
# Large motion far from the reference frame (the retrack's registration of lost frames:
# docs/shape.md, "The retrack registers the frames that lost their refined surface"): the
# take at 3x the motion per frame, and the pair's dome at 4x. Reconstruct all 24 frames.
scene take_fast    "${TAKE[@]}" --width 272 --height 480 --frames 24 --motion 3
scene pair_fast    pair    --rig dome --cameras 10 --environment room --frames 24 --motion 4
# On request only (by name): the full-size take, and two long small takes for the memory
# floor of issue 13 (a 1,000-frame take within 1.3x the memory of a 100-frame one).
if [[ " ${ONLY[*]} " == *" take_hd "* ]]; then
  scene take_hd    "${TAKE[@]}" --width 1088 --height 1920 --supersample 2 --frames 100
fi
for frames in 100 1000; do
  if [[ " ${ONLY[*]} " == *" take_$frames "* ]]; then
    scene "take_$frames" "${TAKE[@]}" --width 160 --height 288 --supersample 2 --frames "$frames"
  fi
done
