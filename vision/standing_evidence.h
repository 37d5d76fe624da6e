// Evidence of what stands (almost) still in a take without masks and background images:
// the person who waits beside the treadmill while another walks (issue 13, item 5).
//
// The background estimated from the video (vision/silhouettes.h: EstimateBackground) is
// the per-pixel median over the frames where the pixel is free of motion evidence; a person
// who barely moves is free almost everywhere, so the median keeps her and the difference
// to it never shows her. What tells her from the lab around her is that she is alive: she
// sways, breathes, shifts her weight and moves her hands, while furniture, floor and walls
// stay put up to sensor and compression noise. The spread of the free samples,
//     s(p) = median_g |I_g(p) − median_g' I_g'(p)|        (g, g' frames where p is free)
// (EstimatedBackground::instability), is that noise on the static scene and more where
// something sways. The standing silhouette of a camera is
//     s(p) > noise_factor · median_p s(p)       (the median over the known pixels: the
//                                                 noise, most of an image being static),
// never below min_threshold, cleaned as motion evidence is (closing, small regions
// removed, holes filled, no opening: vision/silhouettes.h ThresholdAndClean). A sway shows
// as thin bands along the person's outline and texture; the closing and the hole filling
// make them a region. Shape initialization adds it to each frame's silhouette of that camera
// (the union: moving parts by the difference to the estimated background, standing parts
// by their sway); voxel carving then keeps only what the cameras agree on, so the sway
// of things outside the working volume (people in the back of the room) or the flicker
// of a single camera's view does not become a body.
//
// Why not photo-consistency here: on the 4-camera pose2sim take (neighbouring cameras
// 49° and 67° apart), plane-sweep NCC trusted 5–6 k of ~130 k pixels per camera and found
// no support plane (vision/still_evidence.h is for still sets of denser rigs).
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "vision/silhouettes.h"

namespace subflow::vision {

struct StandingEvidenceOptions {
  // Add the standing silhouettes to the silhouettes from an estimated background. Off by
  // default: on the synthetic take take_small (scripts/make_scenes.sh, 8 frames, a walker
  // in the room) it took the run's hull from 18.9 mm / 0.37 to 36.0 mm / 0.07 and the
  // result from 14.9 mm / 0.45 to 31.6 mm / 0.15 (observed accuracy P90 / completeness):
  // the threshold (noise_factor, set on one real take) is not yet a general rule.
  bool enabled = false;
  // Threshold = noise_factor × the median instability (the noise of the static scene).
  // On ../shared/data/pose2sim_multiperson (H.264, median instability 0.0019–0.0035 of
  // the gray range per camera) 4 keeps floor patches where the walking man's shadow and
  // reflections pass; 8 keeps the standing woman's outline and little else.
  double noise_factor = 8.0;
  // The threshold never goes below this (gray levels in [0, 1]; 0.004 ≈ 1 level of 8 bits).
  double min_threshold = 0.004;

  void Check() const;  // throws subflow::Error naming the field
};

// The standing silhouette of one camera from its estimated background (valid(), with
// `instability`); an empty silhouette (source kBackground) when the estimate is invalid.
// Cleaning as `silhouettes` says (close_radius, fill_holes, min_region_pixels; no opening).
Silhouette StandingSilhouette(const EstimatedBackground& background, const SilhouetteOptions& silhouettes,
                              const StandingEvidenceOptions& options = {});

// Adds standing[k] (when non-empty) to silhouettes[k]: the union of the masks and of the
// evidence, object_pixels and empty updated, source and measure kept. Sizes must agree.
void AddStandingEvidence(const std::vector<Silhouette>& standing, std::vector<Silhouette>* silhouettes);

}  // namespace subflow::vision
