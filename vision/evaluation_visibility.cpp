#include "vision/evaluation_visibility.h"

#include <tbb/parallel_for.h>

namespace subflow::vision {

SurfaceVisibility::SurfaceVisibility(const std::vector<Camera>& cameras, const geometry::TriangleMesh& truth,
                                     double tolerance)
    : cameras_(cameras), zbuffers_(RenderZBuffers(cameras, truth.V, truth.F)), tolerance_(tolerance) {}

std::vector<int> SurfaceVisibility::ViewCounts(const geometry::Positions& points,
                                               std::vector<double>* footprints) const {
  std::vector<int> counts(static_cast<std::size_t>(points.rows()), 0);
  if (footprints) footprints->assign(counts.size(), 0.0);
  tbb::parallel_for(Eigen::Index{0}, points.rows(), [&](Eigen::Index i) {
    const Eigen::Vector3d X = points.row(i).transpose();
    int seen = 0;
    double footprint_sum = 0.0;
    for (std::size_t c = 0; c < cameras_.size(); ++c) {
      if (!zbuffers_[c].IsVisible(X, tolerance_)) continue;
      ++seen;
      const Camera& camera = cameras_[c];
      footprint_sum += camera.ToCamera(X).z() / (0.5 * (camera.K()(0, 0) + camera.K()(1, 1)));
    }
    counts[i] = seen;
    if (footprints && seen > 0) (*footprints)[i] = footprint_sum / seen;
  });
  return counts;
}

}  // namespace subflow::vision
