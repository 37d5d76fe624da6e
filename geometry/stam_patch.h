// Stam's exact evaluation of a Loop patch with one extraordinary corner (Stam 1998,
// "Evaluation of Loop subdivision surfaces"), built numerically from the local
// subdivision rules (geometry/loop_local_patch.h) rather than typed-in tables.
//
// Patch (C0, C1, C2) with C0 of valence N ≠ 6 and C1, C2 regular; its K = N + 6 control
// points in canonical order (CanonicalPatch): C0, C0's ring from C1, then the 5 further
// vertices of C1's and C2's rings. One subdivision step maps them to the K control points
// of the corner sub-patch (C0', m01, m20), which has the same structure:
//     c^{n} = A c^{n−1},   A: K × K, the patch's subdivision matrix;
// and to the 12 control points of each of the three regular sub-patches
//     k = 1 (m01, C1', m12), 2 (m20, m12, C2'), 3 (m01, m12, m20):  P_k Ā c, P_k Ā: 12 × K.
// A point with u + v ∈ [2^−n, 2^−n+1] lies in sub-patch k of level n, so
//     s(u, v) = b(u', v')ᵀ P_k Ā A^{n−1} c,
// with (u', v') the point's parameters in that sub-patch (loop_local_patch.h's child maps
// applied to 2^{n−1}(u, v)) and b the box-spline basis (loop_box_spline.h).
//
// Stam applies A^{n−1} through an eigendecomposition A = V Λ V⁻¹. For Loop's A that is
// not reliable: A is defective for N = 3 (eigenvalue 1/16 has algebraic multiplicity 3,
// geometric 2), and for repeated eigenvalues (every N has pairs) a numerical eigensolver
// may return a singular V. We apply A^{n−1} instead with the binary powers of the deflated
// matrix  A_d = A − 1 lᵀ  (l the limit mask, lᵀ A = lᵀ, lᵀ 1 = 1; A_d^m = A^m − 1 lᵀ):
//     bᵀ P_k Ā A^{n−1} = lᵀ + bᵀ P_k Ā A_d^{n−1}          (bᵀ P_k Ā 1 = 1)
// and for derivative rows (which sum to 0) only the A_d term. A_d^m decays like λ₁^m, so
// near C0 the stencils keep full relative accuracy instead of cancelling against the
// limit point. Cost: O(K² log n) per point; the powers A_d^{2^i}, i ≤ 10, cover every
// n a double can reach (u + v ≥ 2^−1074).
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

#include "geometry/loop_local_patch.h"

namespace subflow::geometry::loop_patch {

struct StamPatch {
  int valence = 0;                         // N, the valence of C0
  Eigen::MatrixXd subdivision;             // A, K × K
  std::array<Eigen::MatrixXd, 3> picking;  // P_k Ā for sub-patches k = 1, 2, 3: 12 × K
  Eigen::RowVectorXd limit;                // lᵀ: the limit position of C0
  Eigen::RowVectorXd corner_du, corner_dv; // tangents at C0 (AddIrregularCornerWeights)
  std::vector<Eigen::MatrixXd> deflated_powers;  // A_d^(2^i), i = 0 … 10
};

// Builds the patch from `canonical` = CanonicalPatch(p) of a patch p whose corner 0 is
// interior and irregular and whose corners 1 and 2 are regular. Returns false when one
// subdivision step does not reproduce the structure (e.g. C1 or C2 on the boundary, or
// rings that overlap on a tiny mesh); such patches need local refinement first.
bool BuildStamPatch(const LocalPatch& canonical, StamPatch* patch);

// Weights over the K canonical control points of the point (u, v) of the patch and of
// its derivatives ∂/∂u, ∂/∂v (0 ≤ u, v; u + v ≤ 1). At u = v = 0 the limit position and
// the corner tangents. Row vectors of length K.
void StamPatchWeights(const StamPatch& patch, double u, double v, Eigen::RowVectorXd* position,
                      Eigen::RowVectorXd* du, Eigen::RowVectorXd* dv);

}  // namespace subflow::geometry::loop_patch
