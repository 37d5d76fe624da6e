// Exact evaluation of the Loop limit surface at any barycentric point of any face
// (method eq. 11–12): s(f; u, v) = b(u, v)ᵀ c(r), a fixed linear combination of control
// points c (rows of a #V×3 Positions matrix), together with ∂s/∂u and ∂s/∂v. Stacked
// over a set of samples this is the limit matrix L (#samples × #V) with s = L c, and
// ∂s/∂t = L ∂c/∂t (eq. 13).
//
// Conventions
//   A face f with corners (C0, C1, C2) = (F(f,0), F(f,1), F(f,2)), counter-clockwise:
//   the parameter point (u, v) is   (1 − u − v)·C0 + u·C1 + v·C2,   u, v ≥ 0, u + v ≤ 1
//   (sums up to 1 + 1e−12 are accepted and rescaled onto the edge). du, dv are the
//   derivatives of s with respect to these u and v; du × dv is an outward normal on a
//   closed, consistently oriented mesh. The subdivision rules are Loop's original ones
//   (α(K) = 5/8 − (3 + 2cos(2π/K))²/64, odd 3/8–1/8) with the boundary rules 1/2–1/2
//   (odd) and 3/4–1/8–1/8 (even) — the rules of CGAL's Loop_subdivision and LoopHierarchy.
//
// How each face is evaluated (all exact up to rounding)
//   * Regular patch (three interior corners of valence 6): Loop's quartic box spline,
//     12 control points (geometry/loop_box_spline.h).
//   * One interior extraordinary corner (valence N ≠ 6), two interior regular corners:
//     Stam's method (geometry/stam_patch.h): the sub-patch level n = ⌊1 − log2(u + v)⌋,
//     the patch's subdivision matrix A (N+6 square) raised to n − 1, the picking matrices
//     of the three regular sub-patches. Powers of A, not an eigendecomposition: A is not
//     diagonalizable for N = 3.
//   * Everything else — faces with two or three extraordinary corners (only on a mesh that
//     was never subdivided; after one Loop step extraordinary vertices are isolated) and
//     faces touching the boundary: local refinement (geometry/loop_local_patch.h). The
//     face's neighbourhood (its corners' 1-rings) is subdivided with Loop's rules, keeping
//     the sub-triangle that holds (u, v), until that sub-triangle is a regular patch,
//     which is then evaluated exactly. A boundary corner with 3 faces counts as regular:
//     completing its ring with the ghost vertices C + r_3 − r_2 and C + r_0 − r_1 (the
//     parallelogram reflections across its boundary edges) turns the boundary rules into
//     the interior ones — 3/8(a + b) + 1/8(p + (a + b − p)) = 1/2(a + b) on a boundary
//     edge, 5/8 C + 1/16(Σ r + ghosts) = 3/4 C + 1/8(r_0 + r_3) at the vertex — and one
//     subdivision step maps ghosts to the ghosts of the refined vertices, so the
//     ghost-extended box spline is the limit surface there, exactly. The sub-triangle is
//     regular once it no longer touches an irregular vertex (interior valence ≠ 6,
//     boundary vertex with ≠ 3 faces), so the depth is ≈ 1 + log2(1/d) for a point at
//     parametric distance d from the nearest irregular corner: no truncation anywhere.
//     Cost (2 GHz core): ~10–20 µs for a point in the face's interior (1–2 levels), plus
//     ~5–10 µs per further level: ~0.1–0.3 ms at 1e−6 from an irregular corner.
//   * Exactly at an irregular corner (u = v = 0 on an irregular C0, etc.) the position is
//     Loop's limit mask ((1 − Kχ) C + χ Σ r, χ = 1/(3/(8β) + K), β = α(K)/K; on the
//     boundary 2/3 C + 1/6 (r_0 + r_k)). The parametric derivatives do not exist there
//     (they tend to 0 or ∞ like r^{log2(1/λ)−1}); du, dv are then the tangents of Loop's
//     tangent masks along the face's two edges, scaled like unit edges of the planar
//     characteristic configuration (loop_patch::AddIrregularCornerWeights): their cross
//     product is the limit normal, their lengths are conventional.
//
// The evaluator keeps a reference to `topology`, which must outlive it. Evaluation is
// const and thread-safe.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/Sparse>

#include "geometry/mesh_topology.h"
#include "geometry/stam_patch.h"
#include "geometry/triangle_mesh.h"

namespace subflow::geometry {

// Row-major, so that L * c (c #V×3 row-major) streams rows of L (as in loop_operators.h).
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// A point of the limit surface given by a face and barycentric parameters (see above).
struct FaceSample {
  int face = 0;
  double u = 0.0;
  double v = 0.0;
};

// s = Σ_i position[i] · c(vertices[i]); ∂s/∂u, ∂s/∂v likewise with du, dv. Indices may
// repeat (a patch that wraps around a tiny mesh); weights of a repeated index add up.
// Position weights sum to 1, derivative weights to 0.
struct LimitStencil {
  std::vector<int> vertices;
  std::vector<double> position, du, dv;

  int size() const { return static_cast<int>(vertices.size()); }
  void Clear();
};

struct LimitPoint {
  Eigen::RowVector3d position = Eigen::RowVector3d::Zero();
  Eigen::RowVector3d du = Eigen::RowVector3d::Zero();
  Eigen::RowVector3d dv = Eigen::RowVector3d::Zero();
  // du × dv, normalized (zero if degenerate).
  Eigen::RowVector3d Normal() const;
};

struct LimitEvaluatorOptions {
  // Evaluate patches with one extraordinary corner by Stam's method (precomputed per
  // valence). false: by local refinement like every other irregular patch — same
  // values to rounding, slower; useful to cross-check the two.
  bool use_stam_patches = true;
};

enum class LimitPatchKind { kRegular, kStam, kLocalRefinement };

class LoopLimitEvaluator {
 public:
  // Classifies every face and precomputes its control indices (12 for a regular patch,
  // N + 6 for a Stam patch) and one Stam patch per extraordinary valence. Throws
  // subflow::Error if an interior vertex has valence < 3.
  explicit LoopLimitEvaluator(const MeshTopology& topology,
                              const LimitEvaluatorOptions& options = {});

  const MeshTopology& topology() const { return *topology_; }

  // Weights of the limit point of `face` at (u, v) and of its derivatives. Throws
  // subflow::Error for a face out of range or (u, v) outside the triangle.
  void Stencil(int face, double u, double v, LimitStencil* stencil) const;
  LimitStencil Stencil(int face, double u, double v) const;

  // The limit point and derivatives for control points `control` (#V×3).
  LimitPoint Evaluate(int face, double u, double v, const Positions& control) const;

  // L (#samples × #V) with s = L c; optionally ∂s/∂u = L_u c and ∂s/∂v = L_v c.
  // Built in parallel; each row's columns sorted, duplicates merged.
  SparseMatrix LimitMatrix(const std::vector<FaceSample>& samples, SparseMatrix* d_du = nullptr,
                           SparseMatrix* d_dv = nullptr) const;

  LimitPatchKind PatchKind(int face) const;
  // The Stam patch used for `face` (PatchKind(face) == kStam): its subdivision matrix A,
  // picking matrices and limit row, over ControlIndices(face) in that order.
  const loop_patch::StamPatch& StamPatchOf(int face) const;
  // Control vertex indices of a kRegular (12, loop_box_spline.h order) or kStam (N + 6,
  // canonical order) face; empty for kLocalRefinement.
  std::vector<int> ControlIndices(int face) const;
  int StamPatchCount() const { return static_cast<int>(stam_patches_.size()); }

 private:
  struct FaceRecord {
    LimitPatchKind kind = LimitPatchKind::kLocalRefinement;
    int rotation = 0;    // kStam: corner `rotation` of the face is the extraordinary one
    int stam_patch = -1;
    int offset = 0;      // into indices_
  };

  void CheckSample(int face, double* u, double* v) const;

  const MeshTopology* topology_;
  std::vector<FaceRecord> faces_;
  std::vector<int> indices_;
  std::vector<loop_patch::StamPatch> stam_patches_;
};

}  // namespace subflow::geometry
