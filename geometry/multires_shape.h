// The multi-resolution shape of one frame (method §3.2–3.4, eq. 18–22): base control
// points c⁰ and detail coefficients d¹ … dᵐ in local frames, on a LoopHierarchy.
//
//   SYNTHESIS  for i = 1..m:  p = C(i−1) c(i−1)                  (predicted, smooth)
//                             c(i) = p + F(i) d(i)                F(i) = frames of p
//   ANALYSIS   for i = n..1:  c(i−1) = Coarsening(i) c(i)         (Taubin H, even rows)
//                             d(i) = F(i)ᵀ (c(i) − C(i−1) c(i−1)) F(i) = frames of C c(i−1)
//
// d(i) is #V(i)×3 (over-complete, one detail per vertex of the finer level, eq. 19), each
// row (d_n, d_r, d_q) in the frame F(i)(v) = (n, r, q) of local_frames.h. The frames of
// level i are computed from the predicted points C c(i−1), not from c(i): synthesis knows
// them before it adds the details, which makes analysis followed by synthesis exact, and
// a rigid motion of c⁰ moves every level rigidly (the frames move with the surface).
//
// A shape may carry details for fewer levels than its hierarchy (m ≤ n, as when the
// optimizer adds levels coarse to fine); levels above m are plain refinement.
#pragma once

#include <vector>

#include "geometry/local_frames.h"
#include "geometry/loop_hierarchy.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

class MultiresShape {
 public:
  MultiresShape() = default;
  // Base control points c⁰ (#V(0)×3) and zero details on levels 1..detail_levels
  // (default: every level of the hierarchy).
  MultiresShape(const LoopHierarchy& hierarchy, Positions base, int detail_levels = -1);

  // Decomposes control points of the hierarchy's finest level (#V(n)×3) into c⁰ and
  // d¹ … dⁿ. Synthesize(hierarchy, n) gives them back up to rounding.
  static MultiresShape Analyze(const LoopHierarchy& hierarchy,
                               const Positions& finest_control_points);

  // Control points c(level), 0 ≤ level ≤ n. When `frames` is given it receives the frames
  // used on levels 1..level ((*frames)[i − 1] for level i; only levels ≤ detail_levels()
  // have frames, the others are left empty).
  Positions Synthesize(const LoopHierarchy& hierarchy, int level,
                       std::vector<LocalFrames>* frames = nullptr) const;
  // c(0) … c(level) in one pass.
  std::vector<Positions> SynthesizeLevels(const LoopHierarchy& hierarchy, int level) const;

  int detail_levels() const { return static_cast<int>(details_.size()); }
  const Positions& base() const { return base_; }
  Positions& base() { return base_; }
  // d(level), 1 ≤ level ≤ detail_levels(): #V(level)×3 in local frames.
  const Positions& Detail(int level) const { return details_.at(level - 1); }
  Positions& Detail(int level) { return details_.at(level - 1); }

  // Throws subflow::Error unless the base and details have the hierarchy's row counts.
  void Check(const LoopHierarchy& hierarchy) const;

 private:
  Positions base_;
  std::vector<Positions> details_;  // details_[i − 1] = d(i)
};

// One shape per frame of a sequence, all on one hierarchy (ARCHITECTURE: Trajectory).
using Trajectory = std::vector<MultiresShape>;

// Analysis / synthesis of every frame (in parallel over frames).
Trajectory AnalyzeTrajectory(const LoopHierarchy& hierarchy,
                             const std::vector<Positions>& finest_control_points);
std::vector<Positions> SynthesizeTrajectory(const LoopHierarchy& hierarchy,
                                            const Trajectory& trajectory, int level);

}  // namespace subflow::geometry
