// Rotations as calibration files print them: with 6–8 significant digits, so RᵀR − I is
// ~1e-6 rather than 0. NearestRotation accepts such a near-rotation and returns the
// nearest rotation in the Frobenius norm (R̂ = U Vᵀ from the SVD M = U Σ Vᵀ, Higham
// 1988); only a clear non-rotation is an error.
#pragma once

#include <string>

#include <Eigen/Core>

namespace subflow::vision {

// |σᵢ − 1| above this (any singular value σᵢ of M) is "scaled, not a rotation": an error.
inline constexpr double kRotationScaleTolerance = 1e-2;
// A correction max |M − R̂| above this is reported as a warning (spdlog) by callers: more
// than printing M with 6 significant digits explains (≤ 5e-7 per entry, ~1.5e-6 on RᵀR).
inline constexpr double kRotationWarningTolerance = 1e-5;

struct NearestRotationResult {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();  // R̂: R̂ᵀR̂ = I, det R̂ = +1
  double correction = 0;  // max |M − R̂| over the nine entries
};

// The rotation nearest to M (M itself when max |MᵀM − I| ≤ 1e-14, i.e. exact to
// rounding, so that exact rotations pass bit for bit). Throws subflow::Error "<source>: <field>: ..." when M is not
// finite, is mirrored (det M < 0: a reflection), or is scaled or sheared (a singular value
// off 1 by more than kRotationScaleTolerance), quoting M, det M and the singular values.
NearestRotationResult NearestRotation(const Eigen::Matrix3d& M, const std::string& source,
                                      const std::string& field);

}  // namespace subflow::vision
