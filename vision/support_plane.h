// Support planes: the floor (or a treadmill, a table top) that an object stands on inside
// the working volume. Photo-consistency finds them as well as the object (a textured floor
// is as consistent as the object's own texture), so they are found and removed before the
// object is taken as what remains.
//
// FindSupportPlane: RANSAC over 3D points (random triples → plane n·X + d = 0, inliers
// |n·X + d| ≤ tolerance, counted on a subsample), the plane with the most inliers refined
// by a least-squares fit to its inliers (smallest eigenvector of their covariance), n
// oriented towards the cameras (the side of the mean camera centre). It is a support plane
// only when
//   - its inliers are at least min_inlier_fraction of the points, and
//   - at least min_above_fraction of the points that are not inliers lie on the cameras'
//     side (n·X + d > tolerance): the object stands ON the plane. A plane through the
//     object (a flat face, its middle) has object points on both sides and is refused.
// RANSAC draws from a fixed seed: the same points give the same plane.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace subflow::vision {

struct SupportPlaneOptions {
  // Distance (world units) within which a point is on the plane; ≤ 0 = automatic, given
  // by the caller (e.g. from the depth resolution).
  double tolerance = 0.0;
  int iterations = 500;
  // Points used to count inliers per hypothesis (a random subsample; all when fewer).
  int sample_points = 20000;
  double min_inlier_fraction = 0.05;
  double min_above_fraction = 0.9;
  unsigned seed = 1;

  void Check() const;  // throws subflow::Error naming the field
};

struct SupportPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, towards the cameras
  double offset = 0;                                  // d of n·X + d = 0
  double tolerance = 0;                               // the inlier distance used
  int inliers = 0, points = 0;
  double above_fraction = 0;  // of the non-inliers, on the cameras' side
  bool found = false;         // passed both tests

  double SignedDistance(const Eigen::Vector3d& X) const { return normal.dot(X) + offset; }
  std::string Describe() const;  // "n = (…), d = …, inliers …/…, above …"
};

// `points`: 3D points (e.g. photo-consistent surface points inside the working volume);
// `viewpoint`: a point on the cameras' side (the mean camera centre); `tolerance` > 0.
SupportPlane FindSupportPlane(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& viewpoint,
                              double tolerance, const SupportPlaneOptions& options = {});

}  // namespace subflow::vision
