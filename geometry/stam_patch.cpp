#include "geometry/stam_patch.h"

#include <cmath>

#include "core/error.h"
#include "geometry/loop_box_spline.h"

namespace subflow::geometry::loop_patch {
namespace {

constexpr int kPowerCount = 11;  // A_d^(2^i) for i < 11: exponents up to 2047 ≥ 1074

// Full stencils (reference + offsets) of a patch's local vertices: #local × #support.
Eigen::MatrixXd Positions(const LocalPatch& patch) {
  return patch.offsets.rowwise() + patch.reference;
}

}  // namespace

bool BuildStamPatch(const LocalPatch& canonical, StamPatch* patch) {
  if (canonical.boundary[0] || IsRegularCorner(canonical, 0) || !IsRegularCorner(canonical, 1) ||
      !IsRegularCorner(canonical, 2) || canonical.boundary[1] || canonical.boundary[2])
    return false;
  const int k = canonical.local_count();
  const int valence = static_cast<int>(canonical.ring[0].size());
  if (k != valence + 6) return false;

  // Express everything over the canonical control points themselves.
  LocalPatch unit = canonical;
  unit.support.resize(k);
  for (int i = 0; i < k; ++i) unit.support[i] = i;
  unit.reference = Eigen::RowVectorXd::Unit(k, unit.corner[0]);
  unit.offsets = StencilRows::Identity(k, k);
  unit.offsets.col(unit.corner[0]).array() -= 1.0;

  std::vector<int> structure, child_structure;
  CanonicalPatch(unit, &structure);
  const LocalPatch corner_child = CanonicalPatch(RefinePatch(unit, 0), &child_structure);
  if (structure != child_structure) return false;

  patch->valence = valence;
  patch->subdivision = Positions(corner_child);
  for (int c = 1; c <= 3; ++c) {
    const LocalPatch sub_patch = RefinePatch(unit, c);
    if (!IsRegularPatch(sub_patch)) return false;
    patch->picking[c - 1] = BoxSplineControlMatrix(sub_patch) * Positions(sub_patch);
  }
  LocalWeights corner(k);
  AddIrregularCornerWeights(unit, 0, &corner);
  patch->limit = corner.position.transpose();
  patch->corner_du = corner.du.transpose();
  patch->corner_dv = corner.dv.transpose();

  // lᵀ must be A's left eigenvector for 1 (it is Loop's limit mask); check, since the
  // deflation below relies on it.
  const double residual = (patch->limit * patch->subdivision - patch->limit).cwiseAbs().maxCoeff();
  SUBFLOW_CHECK(residual < 1e-13, "limit mask is not a left eigenvector of the patch matrix");

  patch->deflated_powers.resize(kPowerCount);
  patch->deflated_powers[0] =
      patch->subdivision - Eigen::VectorXd::Ones(k) * patch->limit;
  for (int i = 1; i < kPowerCount; ++i)
    patch->deflated_powers[i] = patch->deflated_powers[i - 1] * patch->deflated_powers[i - 1];
  return true;
}

void StamPatchWeights(const StamPatch& patch, double u, double v, Eigen::RowVectorXd* position,
                      Eigen::RowVectorXd* du, Eigen::RowVectorXd* dv) {
  const double sum = u + v;
  if (sum <= 0.0) {
    *position = patch.limit;
    *du = patch.corner_du;
    *dv = patch.corner_dv;
    return;
  }
  // Level n of the sub-patch ring holding (u, v): 2^−n ≤ u + v ≤ 2^−n+1 (n ≥ 1).
  int exponent = 0;
  const double mantissa = std::frexp(sum, &exponent);  // sum = mantissa · 2^exponent
  const int n = std::max(1, mantissa == 0.5 ? 2 - exponent : 1 - exponent);
  const double us = std::ldexp(u, n - 1), vs = std::ldexp(v, n - 1);  // us + vs ∈ [1/2, 1]

  // Sub-patch and its parameters; d(u', v')/d(us, vs) = 2 J.
  int k;
  double u1, v1;
  Eigen::Matrix2d jacobian;
  if (us >= 0.5) {
    k = 0, u1 = 2 * us - 1, v1 = 2 * vs, jacobian.setIdentity();
  } else if (vs >= 0.5) {
    k = 1, u1 = 2 * us, v1 = 2 * vs - 1, jacobian.setIdentity();
  } else {
    k = 2, u1 = 2 * us + 2 * vs - 1, v1 = 1 - 2 * us;
    jacobian << 1, 1, -1, 0;
  }
  std::array<double, 12> b, b_du, b_dv;
  LoopBoxSplineBasis(u1, v1, &b, &b_du, &b_dv);
  const Eigen::Map<const Eigen::RowVectorXd> b_row(b.data(), 12), b_du_row(b_du.data(), 12),
      b_dv_row(b_dv.data(), 12);
  const Eigen::MatrixXd& picking = patch.picking[k];
  Eigen::RowVectorXd rows[3] = {b_row * picking, b_du_row * picking, b_dv_row * picking};

  const int m = n - 1;
  if (m > 0) {
    rows[0] -= patch.limit;  // the A_d part of the position row (its A part is lᵀ)
    for (int bit = 0; bit < kPowerCount; ++bit) {
      if (!((m >> bit) & 1)) continue;
      for (Eigen::RowVectorXd& row : rows) row = row * patch.deflated_powers[bit];
    }
    rows[0] += patch.limit;
  }
  *position = rows[0];
  // Chain rule: ∂/∂u = 2^n (J₀₀ ∂/∂u' + J₁₀ ∂/∂v'), ∂/∂v = 2^n (J₀₁ ∂/∂u' + J₁₁ ∂/∂v').
  *du = jacobian(0, 0) * rows[1] + jacobian(1, 0) * rows[2];
  *dv = jacobian(0, 1) * rows[1] + jacobian(1, 1) * rows[2];
  for (Eigen::Index i = 0; i < du->size(); ++i) {
    (*du)[i] = std::ldexp((*du)[i], n);
    (*dv)[i] = std::ldexp((*dv)[i], n);
  }
}

}  // namespace subflow::geometry::loop_patch
