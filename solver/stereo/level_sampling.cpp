#include "solver/stereo/level_sampling.h"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "solver/observation/surface_sampling.h"
#include "solver/stereo/stereo_refinement.h"

namespace subflow::solver {

using geometry::LoopHierarchy;
using geometry::Positions;

LevelSampling SampleLevel(const LoopHierarchy& hierarchy, int level, const Positions& level_control,
                          const std::vector<vision::Camera>& cameras,
                          const StereoRefinementOptions& options, const std::vector<char>* active_faces) {
  SurfaceSamplingOptions sampling;
  sampling.samples_per_pixel = options.samples_per_pixel;
  sampling.max_density = options.max_density;
  std::vector<int> density = FaceSampleDensities(hierarchy, level, level_control, cameras, sampling);
  LevelSampling result;
  const int faces = hierarchy.FaceCount(level);
  for (int f = 0; f < faces; ++f) {
    result.face_first.push_back(static_cast<int>(result.samples.size()));
    if (active_faces == nullptr || (*active_faces)[f])
      AppendFaceSamplePattern(f, std::max(density[f], options.min_density), &result.samples);
  }
  result.face_first.push_back(static_cast<int>(result.samples.size()));

  const geometry::LoopLimitEvaluator level_evaluator(hierarchy.Topology(level));
  const geometry::SparseMatrix L = level_evaluator.LimitMatrix(result.samples);
  result.support.resize(faces);
  result.stencil.resize(faces);
  tbb::parallel_for(0, faces, [&](int f) {
    std::vector<int>& support = result.support[f];
    for (int s = result.face_first[f]; s < result.face_first[f + 1]; ++s)
      for (geometry::SparseMatrix::InnerIterator it(L, s); it; ++it) support.push_back(static_cast<int>(it.col()));
    std::sort(support.begin(), support.end());
    support.erase(std::unique(support.begin(), support.end()), support.end());
    PatchStencil& stencil = result.stencil[f];
    stencil.setZero(result.FaceSampleCount(f), static_cast<Eigen::Index>(support.size()));
    for (int s = result.face_first[f]; s < result.face_first[f + 1]; ++s)
      for (geometry::SparseMatrix::InnerIterator it(L, s); it; ++it) {
        const auto j = std::lower_bound(support.begin(), support.end(), static_cast<int>(it.col())) -
                       support.begin();
        stencil(s - result.face_first[f], j) += it.value();
      }
  });

  // The same points as faces and barycentrics of the finest level (nested faces: child k
  // of face f is 4f + k), where the current surface is evaluated.
  const int finest = hierarchy.finest_level();
  std::vector<geometry::FaceSample> mapped(result.samples.size());
  for (std::size_t s = 0; s < result.samples.size(); ++s) {
    geometry::FaceSample sample = result.samples[s];
    Eigen::Vector3d u(1.0 - sample.u - sample.v, sample.u, sample.v);
    for (int l = level; l < finest; ++l) {
      Eigen::Vector3d w;
      sample.face = LoopHierarchy::ChildFace(sample.face, LoopHierarchy::ParentToChildBarycentric(u, &w));
      u = w;
    }
    sample.u = u(1);
    sample.v = u(2);
    mapped[s] = sample;
  }
  const geometry::LoopLimitEvaluator finest_evaluator(hierarchy.Topology(finest));
  result.finest_limit = finest_evaluator.LimitMatrix(mapped, &result.finest_du, &result.finest_dv);
  return result;
}

}  // namespace subflow::solver
