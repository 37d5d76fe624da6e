// One temporal window of one level of the stereo refinement (stereo_refinement.h): what
// its residuals are built from (photometric_residuals.h, regularization_residuals.h) and
// what window_solve.h solves. Frames [first, last] are solved; frames first − 1 and
// last + 1, where they exist, enter with their current values as constants.
//
// Per frame t of the window and its context frames (FrameState):
//   c(ℓ)       the level-ℓ control points of the current shape (#V(ℓ)×3)
//   B_v        per level-ℓ vertex v, the 3×3 basis of its increment e_v: the Hoppe frame
//              (n, r, q) of C c(ℓ−1) at v for details (ℓ > 0); for base control points
//              (ℓ = 0) the limit normal and, for dof 3, two tangents; the first `dof`
//              columns are used
//   X, n       per sample (LevelSampling), the position and unit normal of the current
//              finest limit surface
//   usable     per camera and sample: visible (VisibilityTester) and, where the camera has
//              a silhouette, at least outline_margin pixels inside it
//   e          the unknowns, #V(ℓ) × dof, zero at the start: parameter block of vertex v
//              at frame t = Increment(t, v)
#pragma once

#include <cstdint>
#include <limits>
#include <map>
#include <memory>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "geometry/loop_hierarchy.h"
#include "geometry/multires_shape.h"
#include "solver/observation/image_derivatives.h"
#include "solver/observation/sample_visibility.h"
#include "solver/stereo/level_sampling.h"
#include "solver/stereo/ncc_cost.h"
#include "vision/image_sequence.h"

namespace subflow::solver {

struct StereoRefinementOptions;
class ViewCache;

// Per camera and sample: visible or not (SampleVisibility::visible).
using SampleVisibilityFlags = std::vector<std::vector<std::uint8_t>>;

// What a frame's z-buffers decided: per camera and sample, visible or not; per camera whose
// silhouette is the object's outline (for the rim term), where the surface covers the image.
struct FrameVisibility {
  SampleVisibilityFlags visible;
  std::vector<cv::Mat> coverage;  // empty Mats for the other cameras
};

// What the windows of a level share per frame: the images a window needs, smoothed (σ =
// image_sigma), the silhouettes' signed distances, and the visibility of the level's
// samples; each computed once and released when no later window needs it.
//
// A frame's visibility is kept for the next window of the same level and round while the
// frame's shape has not changed: the context frame after a window (held constant there)
// is the next window's frame, and its z-buffers are not rendered again. A frame a window
// solved is decided again on its new shape (reusing the old decision instead changed the
// results: docs/speed.md).
class FrameImageCache {
 public:
  FrameImageCache(const vision::ImageSequence& images, double sigma);

  // Per camera: the smoothed gray image of `frame`.
  const std::vector<SmoothedImage>& Gray(int frame);
  // Per camera: the signed distance to the silhouette's outline at `frame`, or null.
  const std::vector<std::unique_ptr<SignedDistanceImage>>& Silhouettes(int frame);
  // Whether camera `camera`'s silhouette is the object's own outline
  // (vision::ImageSequence::tight_outline).
  bool TightOutline(int camera) const {
    return images_.tight_outline.empty() || images_.tight_outline.at(camera) != 0;
  }
  // The visibility of the current level's samples at `frame` as decided for the finest
  // control points `control`, or null when it was not (or for another shape).
  const FrameVisibility* Visibility(int frame, const geometry::Positions& control) const;
  void KeepVisibility(int frame, const geometry::Positions& control, FrameVisibility visible);
  // Forgets every frame's visibility (a new level or round).
  void ForgetVisibility() { visibility_cache_.clear(); }
  // Forgets the frames before `first_kept` and after `last_kept`.
  void Release(int first_kept, int last_kept = std::numeric_limits<int>::max());

 private:
  const vision::ImageSequence& images_;
  double sigma_;
  std::map<int, std::vector<SmoothedImage>> gray_cache_;
  std::map<int, std::vector<std::unique_ptr<SignedDistanceImage>>> silhouette_cache_;
  std::map<int, std::pair<geometry::Positions, FrameVisibility>> visibility_cache_;
};

struct FrameState {
  geometry::Positions level_control;   // c(ℓ), #V(ℓ)×3
  std::vector<Eigen::Matrix3d> basis;  // per level-ℓ vertex: B_v (see the file comment)
  geometry::Positions positions, normals;  // per sample (finest limit surface), #S×3
  // usable[k][s]: visible in camera k and, where camera k has a silhouette, at least
  // `outline_margin` pixels inside it: the smoothed intensity of a sample near the outline
  // mixes in the background, which biases the correlation towards shrinking the surface.
  std::vector<std::vector<std::uint8_t>> usable;
  // Per camera whose silhouette is the object's outline (FrameImageCache::TightOutline),
  // for the rim term: where the frame's current surface covers the image (CV_8UC1); empty
  // for the other cameras and when the rim term is off.
  std::vector<cv::Mat> coverage;
  std::vector<double> increments;  // e: #V(ℓ) × dof, zero at the start
};

struct RefinementWindow {
  const StereoRefinementOptions* options = nullptr;
  const std::vector<vision::Camera>* cameras = nullptr;
  const geometry::LoopHierarchy* hierarchy = nullptr;
  const geometry::Trajectory* trajectory = nullptr;  // the current shapes of all frames
  const LevelSampling* sampling = nullptr;
  FrameImageCache* images = nullptr;
  int level = 0;
  int dof = 1;            // unknowns per vertex: 3, or 1 (normal only)
  int first = 0, last = 0;  // the frames solved
  int frame_count = 0;    // frames of the sequence
  // The frames the window may read (its context frames lie within): the whole sequence,
  // or the half of it that a chain of windows refines while another refines the rest.
  // span_last −1: the sequence's last frame (SpanLast()).
  int span_first = 0, span_last = -1;
  double h = 0.0;         // mean edge length of the level: the unit of steps and weights
  std::vector<char> active_faces;     // #F(ℓ): refined at this level (adaptivity)
  std::vector<char> active_vertices;  // #V(ℓ): corners of active faces
  std::map<int, FrameState> states;   // frames max(span_first, first − 1) … min(span_last, last + 1)
  // Where the correlation blocks' views are sampled once per evaluation point (the
  // problem's evaluation callback, view_cache.h); null: each block samples its own.
  ViewCache* views = nullptr;
  // The increment blocks that a measured outline's block moves (options
  // tangential_only_at_outlines): filled as the silhouette residuals are added.
  std::unordered_set<const double*> sliding;

  int SpanLast() const { return span_last < 0 ? frame_count - 1 : span_last; }
  double* Increment(int frame, int vertex) {
    return states.at(frame).increments.data() + static_cast<std::ptrdiff_t>(vertex) * dof;
  }
  // B_v at `frame`, its first dof columns (3×dof).
  Eigen::MatrixXd Basis(int frame, int vertex) const {
    return states.at(frame).basis[vertex].leftCols(dof);
  }
};

// What every window of one level shares.
struct RefinementLevel {
  int level = 0;
  int dof = 1;
  double h = 0.0;  // mean edge length of level ℓ at the reference (middle) frame
  LevelSampling sampling;
  std::unique_ptr<VisibilityTester> visibility;  // of the finest level's limit surface
  std::vector<char> active_faces;                // #F(ℓ)
  std::vector<char> active_vertices;             // #V(ℓ): corners of active faces
};

// Level ℓ of the refinement of `trajectory` (its middle frame is the reference): dof by
// normal_only_from_level, samples and h at the reference frame.
RefinementLevel PrepareLevel(const geometry::LoopHierarchy& hierarchy, const std::vector<vision::Camera>& cameras,
                             const StereoRefinementOptions& options, const geometry::Trajectory& trajectory,
                             int level, std::vector<char> active_faces);

// The window [first, last] of `level`: the states of its frames and context frames from the
// current shapes (`trajectory`, finest control points `control`, all frames). Context
// frames only within [span_first, span_last] (−1: the sequence's first or last frame).
RefinementWindow OpenWindow(const RefinementLevel& level, const geometry::LoopHierarchy& hierarchy,
                            const std::vector<vision::Camera>& cameras, const StereoRefinementOptions& options,
                            const geometry::Trajectory& trajectory, const std::vector<geometry::Positions>& control,
                            FrameImageCache* images, int first, int last, int span_first = -1,
                            int span_last = -1);

// The state of one frame at level ℓ: `shape` and `finest_control` are the frame's current
// multires shape and finest control points; `silhouettes` its signed distances per camera.
// The samples' visibility (and the coverage of the cameras with coverage_of[k]) is `known`
// when given, else decided by `tester` on the current shape (and then written to `decided`
// when given).
FrameState MakeFrameState(const geometry::LoopHierarchy& hierarchy, int level, int dof,
                          const geometry::MultiresShape& shape, const geometry::Positions& finest_control,
                          const LevelSampling& sampling, const VisibilityTester& tester,
                          const std::vector<vision::Camera>& cameras,
                          const std::vector<std::unique_ptr<SignedDistanceImage>>& silhouettes,
                          const std::vector<char>& coverage_of, double outline_margin,
                          const FrameVisibility* known = nullptr, FrameVisibility* decided = nullptr);

}  // namespace subflow::solver
