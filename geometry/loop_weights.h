// Loop's subdivision weights (method eq. 7–10): the one source of the rules that the
// refinement operator C (loop_operators.cpp), the local patches of exact limit evaluation
// (loop_local_patch.cpp) and the synthesis kernels (refine_and_add_details.cpp) apply.
//
//   interior even  (1 − α(K)) c(v) + (α(K)/K) Σ_k c(r_k),   K the valence
//   boundary even  3/4 c(v) + 1/8 (c(r_0) + c(r_k))           (cubic B-spline crease)
//   interior odd   3/8 (c(a) + c(b)) + 1/8 (c(o) + c(o'))     a, b the edge's ends,
//                                                             o, o' the opposite vertices
//   boundary odd   1/2 (c(a) + c(b))
//
// Loop's original even weight (eq. 9): α(K) = 5/8 − (3 + 2 cos(2π/K))² / 64. The even rule
// of eq. 7–8, c⁺(v) = (a(K) c(v) + Σ_k c(r_k)) / (a(K) + K) with a(K) = K(1 − α)/α, is the
// same as the interior even rule above.
//
// Limit positions (the left eigenvector of the subdivision matrix for eigenvalue 1):
//   interior  (ω c(v) + Σ_k c(r_k)) / (ω + K),  ω = 3 / (8 β), β = α(K)/K
//   boundary  2/3 c(v) + 1/6 (c(r_0) + c(r_k))
#pragma once

#include <cmath>

namespace subflow::geometry {

inline constexpr double kLoopOddEdgeWeight = 3.0 / 8.0;      // on a and b
inline constexpr double kLoopOddOppositeWeight = 1.0 / 8.0;  // on o and o'
inline constexpr double kLoopBoundaryOddWeight = 1.0 / 2.0;
inline constexpr double kLoopBoundaryEvenCenterWeight = 3.0 / 4.0;
inline constexpr double kLoopBoundaryEvenNeighbourWeight = 1.0 / 8.0;
inline constexpr double kLoopBoundaryLimitCenterWeight = 2.0 / 3.0;
inline constexpr double kLoopBoundaryLimitNeighbourWeight = 1.0 / 6.0;

// α(K), the total weight of the ring in the interior even rule (K ≥ 3).
inline double LoopAlpha(int valence) {
  constexpr double kPi = 3.14159265358979323846;
  const double c = 3.0 + 2.0 * std::cos(2.0 * kPi / valence);
  return 5.0 / 8.0 - c * c / 64.0;
}

// The interior limit position's weights: ω/(ω + K) on the centre, 1/(ω + K) on each ring
// vertex, ω = 3 / (8 β), β = α(K)/K.
struct LoopLimitWeights {
  double center = 0.0;
  double ring = 0.0;
};
inline LoopLimitWeights LoopInteriorLimitWeights(int valence) {
  const double beta = LoopAlpha(valence) / valence;
  const double omega = 3.0 / (8.0 * beta);
  return {omega / (omega + valence), 1.0 / (omega + valence)};
}

}  // namespace subflow::geometry
