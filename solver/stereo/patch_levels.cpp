#include "solver/stereo/patch_levels.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "geometry/multires_shape.h"

namespace subflow::solver {

PatchLevels::PatchLevels(const geometry::LoopHierarchy& hierarchy, const geometry::Positions& finest_control,
                         const std::vector<vision::Camera>& cameras, double min_patch_area, bool per_patch_levels,
                         double min_detail_patch_area)
    : min_area_(min_patch_area),
      min_detail_area_(min_detail_patch_area > 0.0 ? std::min(min_detail_patch_area, min_patch_area) : min_patch_area),
      per_patch_(per_patch_levels) {
  const geometry::Positions base = geometry::MultiresShape::Analyze(hierarchy, finest_control).base();
  const geometry::Positions corners = hierarchy.LimitPositions(0) * base;
  const geometry::Faces& F = hierarchy.LevelFaces(0);
  base_area_.assign(F.rows(), 0.0);
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d X0 = corners.row(F(f, 0)), X1 = corners.row(F(f, 1)), X2 = corners.row(F(f, 2));
    const Eigen::Vector3d normal = (X1 - X0).cross(X2 - X0);
    for (const vision::Camera& camera : cameras) {
      if (normal.dot(camera.Center() - (X0 + X1 + X2) / 3.0) <= 0.0) continue;
      const Eigen::Vector2d a = camera.ProjectUndistorted(X1) - camera.ProjectUndistorted(X0);
      const Eigen::Vector2d b = camera.ProjectUndistorted(X2) - camera.ProjectUndistorted(X0);
      base_area_[f] = std::max(base_area_[f], 0.5 * std::abs(a.x() * b.y() - a.y() * b.x()));
    }
  }
  std::vector<double> seen;
  for (double area : base_area_)
    if (area > 0.0) seen.push_back(area);
  if (seen.empty()) return;
  std::nth_element(seen.begin(), seen.begin() + seen.size() / 2, seen.end());
  const auto deepest = [&](double area, double floor) {
    int level = 0;
    while (level < hierarchy.finest_level() && area / 4.0 >= floor) area /= 4.0, ++level;
    return level;
  };
  median_level_ = deepest(seen[seen.size() / 2], min_area_);
  finest_level_ =
      per_patch_ ? deepest(*std::max_element(seen.begin(), seen.end()), min_detail_area_) : median_level_;
}

bool PatchLevels::Resolved(int level, int face) const {
  if (level <= median_level_) return true;
  if (!per_patch_ || level > finest_level_) return false;
  return Area(level, face) >= min_area_;
}

bool PatchLevels::ResolvedForDetail(int level, int face) const {
  if (level <= median_level_) return true;
  if (!per_patch_ || level > finest_level_) return false;
  return Area(level, face) >= min_detail_area_;
}

}  // namespace subflow::solver
