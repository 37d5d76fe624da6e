#include "solver/shape/base_resolution.h"

#include <algorithm>
#include <cmath>

#include <spdlog/spdlog.h>

#include "solver/shape/shape_init.h"
#include "vision/working_scale.h"

namespace subflow::solver {

namespace {

constexpr int kMaxLevels = 6;  // ShapeInitOptions::Check's bound

// The largest L ≤ levels with faces · 4^L ≤ max_finest_faces (at least 0).
int WithinFaceBudget(int levels, int faces, long long max_finest_faces) {
  while (levels > 0 && static_cast<long long>(faces) << (2 * levels) > max_finest_faces) --levels;
  return levels;
}

}  // namespace

double MedianProjectedEdge(const std::vector<vision::Camera>& cameras, const geometry::Positions& V,
                           const geometry::Faces& F) {
  std::vector<double> medians;
  for (const vision::Camera& camera : cameras) {
    double median = 0;
    vision::SurfaceScale(camera, V, F, 0.0, &median);
    if (median > 0) medians.push_back(median);
  }
  if (medians.empty()) return 0;
  std::nth_element(medians.begin(), medians.begin() + medians.size() / 2, medians.end());
  return medians[medians.size() / 2];
}

int LevelsForEdge(double edge_pixels, double target_pixels, int max_levels) {
  if (!(edge_pixels > 0) || !(target_pixels > 0)) return 0;
  const int levels = static_cast<int>(std::floor(std::log2(edge_pixels / target_pixels)));
  return std::clamp(levels, 0, max_levels);
}

BaseResolution ChooseBaseResolution(const geometry::TriangleMesh& hull, const std::vector<vision::Camera>& cameras,
                                    double voxel_size, const ShapeInitOptions& options, const std::string& source) {
  BaseResolution result;
  geometry::SimplifyOptions simplify = options.simplify;
  const bool bounded = options.base_distance_voxels > 0;
  simplify.max_distance = bounded ? options.base_distance_voxels * voxel_size : 0.0;
  result.base = geometry::SimplifyMesh(hull, simplify, &result.simplify, source);
  const double edge = MedianProjectedEdge(cameras, result.base.V, result.base.F);
  if (bounded) {
    result.bound_face_count = result.base.face_count();
    result.bound_edge_pixels = edge;
  }
  if (options.levels >= 0) {
    result.levels = options.levels;
  } else {
    result.levels = WithinFaceBudget(LevelsForEdge(edge, options.finest_edge_pixels, kMaxLevels),
                                     result.base.face_count(), options.max_finest_faces);
    if (bounded) {
      // Raise T0's faces so that its typical edges project to t · 2^L (the collapses stop
      // earlier; the bound still holds).
      const double ratio = edge / (options.finest_edge_pixels * std::ldexp(1.0, result.levels));
      const double budget = static_cast<double>(options.max_finest_faces) / std::ldexp(1.0, 2 * result.levels);
      const double wanted =
          std::min({result.base.face_count() * ratio * ratio, static_cast<double>(simplify.max_face_count), budget});
      if (wanted > result.base.face_count() * 1.05) {
        simplify.min_face_count = static_cast<int>(std::lround(wanted));
        result.base = geometry::SimplifyMesh(hull, simplify, &result.simplify, source);
        result.levels = WithinFaceBudget(result.levels, result.base.face_count(), options.max_finest_faces);
      }
    }
  }
  result.base_edge_pixels = MedianProjectedEdge(cameras, result.base.V, result.base.F);
  result.finest_edge_pixels = result.base_edge_pixels / std::ldexp(1.0, result.levels);
  if (options.levels < 0 && result.finest_edge_pixels > 2 * options.finest_edge_pixels)
    spdlog::info("base mesh T0: the finest edges project to {:.1f} px, not {:.1f}: the face budget ({} finest faces, "
                 "--max-finest-faces) bounds the levels' cost",
                 result.finest_edge_pixels, options.finest_edge_pixels, options.max_finest_faces);
  spdlog::info("base mesh T0: {} faces{} (edges {:.1f} px), {} levels (finest edges {:.2f} px){}",
               result.base.face_count(),
               bounded ? fmt::format(" within {:.3g} of the hull ({} faces by the bound alone, edges {:.1f} px)",
                                     simplify.max_distance, result.bound_face_count, result.bound_edge_pixels)
                       : std::string(" by count"),
               result.base_edge_pixels, result.levels, result.finest_edge_pixels,
               result.simplify.bound_kept ? "" : "; the face cap overrode the distance bound");
  return result;
}

}  // namespace subflow::solver
