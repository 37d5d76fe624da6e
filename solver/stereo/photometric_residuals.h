// The photometric residual families of a refinement window (refinement_window.h), per
// patch (face of level ℓ) and frame t; each adds its blocks to a Ceres problem over the
// window's increments. With √W the pair weight and x̂ the normalized intensity vectors
// of the patch's samples (ncc_cost.h):
//   stereo     one block per patch and frame: √W(i,j) (x̂_i − x̂_j) for every pair of the
//              max_cameras cameras that see the patch best (CamerasOfPatch), on the
//              samples usable in both, W = (cos θ_i cos θ_j)^p, p = angle_weight_power;
//   temporal   one block per patch and frame step (t, t + 1), and (t − 1, t) at the
//              window's first frame: for each of those cameras, the patch at t against the
//              same patch at the other frame (eq. 25's second sum, Δt = 1), weight
//              temporal_weight · cos^{2p} θ — what refines the motion along the surface;
//   silhouette from level silhouette_from_level on (0, every level, by default),
//              one block per patch, frame and camera with a silhouette in which the
//              patch's middle sample lies outside, on or within half a pixel of the
//              outline: w · max(0, D(p(X))), D the signed distance (one-sided: no point is
//              pushed outside the outline, and a sample near but not on the contour
//              generator projects inside it, which a two-sided term would bias outwards);
//   rim        instead, where the camera's silhouette is the object's own outline (a
//              mask) and the patch straddles the camera's contour generator: w · D(p(X))
//              at the patch's sample nearest the contour generator, two-sided, when that
//              sample projects within rim_band pixels inside the outline (or outside) and
//              no other part of the surface lies just beyond it in the image. What draws
//              a surface out to the outline: the correlation stops outline_margin pixels
//              inside it.
#pragma once

#include <optional>
#include <vector>

#include <ceres/ceres.h>

#include "solver/stereo/ncc_cost.h"
#include "solver/stereo/refinement_window.h"

namespace subflow::solver {

// A block of the stereo or silhouette family, for the figures before and after the solve.
struct ResidualRecord {
  ceres::ResidualBlockId id = nullptr;
  int frame = 0;
  const PatchCorrelationCost* correlation = nullptr;  // null: a silhouette block
};

// The cameras that see a patch at a frame best: those with at least max(min_samples, m/2)
// usable samples, by decreasing mean cos θ (normal · direction to the camera), at most
// max_cameras.
struct PatchCameras {
  std::vector<int> cameras;     // best-facing first
  std::vector<double> cosines;  // mean cos θ over the usable samples
};
PatchCameras CamerasOfPatch(const RefinementWindow& window, int frame, int face);

// The stereo block of `face` at `frame` (none when no pair has min_samples common samples).
std::optional<ResidualRecord> AddStereoResidual(RefinementWindow& window, int frame, int face,
                                                const PatchCameras& seen, ceres::LossFunction* loss,
                                                ceres::Problem* problem);

// The temporal blocks of `face` at `frame`; returns how many were added.
int AddTemporalResiduals(RefinementWindow& window, int frame, int face, const PatchCameras& seen,
                         ceres::LossFunction* loss, ceres::Problem* problem);

// The silhouette blocks of `face` at `frame`, appended to `records`.
void AddSilhouetteResiduals(RefinementWindow& window, int frame, int face, ceres::Problem* problem,
                            std::vector<ResidualRecord>* records);

}  // namespace subflow::solver
