#include "vision/rotation.h"

#include <cmath>
#include <sstream>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "core/error.h"

namespace subflow::vision {
namespace {

// max |MᵀM − I| of a rotation computed in double precision: a few units of 2⁻⁵².
constexpr double kExactRotationTolerance = 1e-14;

}  // namespace

NearestRotationResult NearestRotation(const Eigen::Matrix3d& M, const std::string& source,
                                      const std::string& field) {
  auto describe = [&](const Eigen::Vector3d& singular_values) {
    std::ostringstream out;
    out.precision(9);
    out << "det = " << M.determinant() << ", singular values " << singular_values.transpose()
        << " for [";
    for (int r = 0; r < 3; ++r)
      out << (r ? ", [" : "[") << M(r, 0) << ", " << M(r, 1) << ", " << M(r, 2) << "]";
    return out.str() + "]";
  };
  if (!M.allFinite()) ThrowError(source, field, "expected a rotation with finite values");
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sigma = svd.singularValues();
  if (M.determinant() < 0)
    ThrowError(source, field,
               "expected a rotation, got a mirrored matrix (det < 0, a reflection): " + describe(sigma));
  if ((sigma.array() - 1).abs().maxCoeff() > kRotationScaleTolerance) {
    std::ostringstream tolerance;
    tolerance << kRotationScaleTolerance;
    ThrowError(source, field,
               "expected a rotation (singular values 1 to " + tolerance.str() +
                   "), got a scaled or sheared matrix: " + describe(sigma));
  }
  NearestRotationResult result;
  // A rotation exact to rounding stays as given (bit for bit, so files round-trip).
  if ((M.transpose() * M - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= kExactRotationTolerance) {
    result.rotation = M;
    return result;
  }
  result.rotation = svd.matrixU() * svd.matrixV().transpose();
  result.correction = (M - result.rotation).cwiseAbs().maxCoeff();
  return result;
}

}  // namespace subflow::vision
