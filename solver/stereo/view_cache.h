// The views a refinement window's correlation blocks compare (photometric_residuals.h),
// each sampled once per evaluation point instead of once per block that uses it.
//
// A view is one patch (face of level ℓ) seen by one camera at one frame: its samples'
// intensities and their Jacobian with respect to the increments of the patch's support
// vertices at that frame (SampleView, ncc_cost.h). The stereo block of (patch, frame)
// compares the views of its cameras at that frame, and the temporal blocks of the frame
// steps (t, t + 1) and (t − 1, t) compare the same cameras' views at both frames, so each
// view is shared by up to three blocks. The cache is the problem's Ceres
// EvaluationCallback: before Ceres evaluates the blocks at new parameters it samples every
// view (in parallel, on the union of the rows its blocks compare), and the blocks
// (PatchCorrelationCost built on SampledView pointers) only normalize and difference.
// Every number is computed exactly as a block sampling its own views would: the results
// are the same to the bit.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include <ceres/evaluation_callback.h>

#include "solver/stereo/ncc_cost.h"

namespace subflow::solver {

class ViewCache final : public ceres::EvaluationCallback {
 public:
  // Views of frames [first_frame, first_frame + frames), cameras [0, cameras), faces
  // [0, faces); increments of size `dof` per support vertex.
  ViewCache(int first_frame, int frames, int cameras, int faces, int dof);

  // The entry of (frame, camera, face), made by make_view() the first time (its
  // first_block is ignored: `increments` are the support vertices' parameter blocks at the
  // frame, in stencil column order); `rows` (stencil rows) are added to those sampled.
  // The pointer stays valid for the cache's life. Throws subflow::Error out of range or
  // on sizes that disagree with the stencil.
  const SampledView* Add(int frame, int camera, int face, const PatchStencil& stencil,
                         const std::function<PatchView()>& make_view, std::vector<const double*> increments,
                         const std::vector<int>& rows);

  // Samples every view at the current parameter values (with Jacobians when asked, or
  // when only the Jacobians are missing at the same point).
  void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

  int size() const { return static_cast<int>(entries_.size()); }

 private:
  struct Entry {
    PatchView view;
    const PatchStencil* stencil = nullptr;
    std::vector<const double*> increments;
    std::vector<int> rows;  // sorted
    SampledView sampled;
  };
  int first_frame_, frames_, cameras_, faces_, dof_;
  std::vector<int> index_;  // (frame, camera, face) → entry, −1 = none
  std::vector<std::unique_ptr<Entry>> entries_;
  bool sampled_ = false;            // intensities at the current point
  bool sampled_jacobians_ = false;  // and Jacobians
};

}  // namespace subflow::solver
