// Local Loop subdivision around one triangle: the machinery behind exact limit evaluation
// (geometry/limit_evaluation.h) of patches that are not regular box-spline patches.
//
// A LocalPatch is a triangle (C0, C1, C2), counter-clockwise, with the ordered 1-ring of
// each corner (MeshTopology's convention: counter-clockwise; a boundary corner's ring runs
// from the neighbour across its outgoing boundary edge to the one across its incoming
// boundary edge). Its local vertices (the corners and their rings) are stencils over a
// fixed list of control vertices `support`:
//     position(local i) = reference + offsets.row(i)        (1 × #support weights)
// with rows of `offsets` summing to 0. Keeping a reference and small offsets rather than
// full rows keeps the stencils of deep sub-patches accurate to rounding *relative to the
// sub-patch size*, so derivatives (differences of nearby points) do not lose digits.
//
// RefinePatch applies Loop's rules (the paper's eq. 7–9; boundary: 1/2–1/2 odd,
// 3/4–1/8–1/8 even) and keeps the sub-triangle `child` with the rings of its corners:
//   child 0 (C0', m01, m20)   child 1 (m01, C1', m12)   child 2 (m20, m12, C2')
//   child 3 (m01, m12, m20)   (the middle one)
// where Ci' is the even copy of Ci and mij the odd vertex on edge CiCj. In barycentric
// parameters (point = (1 − u − v) C0 + u C1 + v C2) a child's parameters (u', v') are
//   child 0: (2u, 2v)   child 1: (2u − 1, 2v)   child 2: (2u, 2v − 1)
//   child 3: (2u + 2v − 1, 1 − 2u).
//
// A corner is "regular" when it is interior of valence 6 or on the boundary with 3 faces.
// A patch whose three corners are regular is evaluated exactly as a box-spline patch; a
// boundary corner's ring is completed by two ghost vertices, the parallelogram
// reflections g = C + r_3 − r_2 and g' = C + r_0 − r_1, which reproduce the boundary rules
// (1/2–1/2, 3/4–1/8–1/8) and are themselves reproduced by one subdivision step, so the
// ghost-extended box spline IS the limit surface of such a patch (derivation in
// limit_evaluation.h).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "geometry/mesh_topology.h"

namespace subflow::geometry::loop_patch {

// Rows are stencils; row-major so that refinement combines whole rows.
using StencilRows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

struct LocalPatch {
  std::vector<int> support;              // control vertex indices, distinct
  Eigen::RowVectorXd reference;          // 1 × #support
  StencilRows offsets;                   // #local × #support, rows sum to 0
  std::array<int, 3> corner{};           // local indices of C0, C1, C2
  std::array<std::vector<int>, 3> ring;  // local indices, ordered as described above
  std::array<bool, 3> boundary{};

  int local_count() const { return static_cast<int>(offsets.rows()); }
  // Weights over `support` of local vertex i.
  Eigen::RowVectorXd Position(int i) const { return reference + offsets.row(i); }
};

// Weights over a patch's local vertices of a point and of its derivatives along the
// patch's parameters (u, v). Position weights sum to 1, derivative weights to 0.
struct LocalWeights {
  Eigen::VectorXd position, du, dv;
  explicit LocalWeights(int local_count)
      : position(Eigen::VectorXd::Zero(local_count)),
        du(Eigen::VectorXd::Zero(local_count)),
        dv(Eigen::VectorXd::Zero(local_count)) {}
};

// The patch of `face` on the mesh's own level: support = its corners and their 1-rings.
LocalPatch PatchAroundFace(const MeshTopology& topology, int face);

bool IsRegularCorner(const LocalPatch& patch, int corner);
bool IsRegularPatch(const LocalPatch& patch);

// Corner i of the result is corner (i + rotation) % 3 of `patch`; in parameters,
// rotation 1: (u', v') = (v, 1 − u − v); rotation 2: (u', v') = (1 − u − v, u).
LocalPatch RotatePatch(const LocalPatch& patch, int rotation);

LocalPatch RefinePatch(const LocalPatch& patch, int child);

// Reorders the local vertices canonically: C0, C0's ring (from C1 if interior), then the
// vertices of C1's ring (from C2) and C2's ring (from C0) not listed yet. Drops nothing
// (every local vertex is a corner or in a ring). If `structure` is given, it receives a
// description of the corners' rings in canonical indices: two patches with equal
// structures are refined by the same matrix, entry for entry. `order` (optional)
// receives the old local index of each canonical local vertex.
LocalPatch CanonicalPatch(const LocalPatch& patch, std::vector<int>* structure = nullptr,
                          std::vector<int>* order = nullptr);

// Adds the box-spline weights of the regular patch at (u, v) (its own parameters).
// Requires IsRegularPatch(patch).
void AddBoxSplineWeights(const LocalPatch& patch, double u, double v, LocalWeights* weights);

// The 12 box-spline control points of a regular patch as combinations of local vertices:
// a 12 × #local matrix G (rows sum to 1), so that control points = G · local positions.
Eigen::MatrixXd BoxSplineControlMatrix(const LocalPatch& patch);

// The limit position at corner i when that corner is not regular, and tangents along the
// corner's two edges of the patch: `du` towards corner i+1, `dv` towards corner i+2.
// At such a corner the parametric derivatives are 0 or unbounded, so these are Loop's
// tangent masks scaled to unit edges of the planar characteristic configuration:
//   interior, valence K: t(j) = (2/K) Σ_k cos(2π(k − j)/K) r_k,  j the edge's ring index;
//   boundary, k ≥ 2 faces: t(j) = cos(jπ/k) t_along + sin(jπ/k) t_across with
//     t_along = (r_0 − r_k)/2 and t_across = (2/k)(a C + b (r_0 + r_k) + Σ sin(iπ/k) r_i),
//     the left eigenvectors of the boundary 1-ring subdivision matrix for 1/2 and
//     3/8 + cos(π/k)/4 (a, b solved from the eigen-equations);
//   boundary, 1 face: the two edge vectors r_0 − C and r_1 − C.
// Their cross product du × dv is the limit normal (oriented like the face).
void AddIrregularCornerWeights(const LocalPatch& patch, int corner, LocalWeights* weights);

}  // namespace subflow::geometry::loop_patch
