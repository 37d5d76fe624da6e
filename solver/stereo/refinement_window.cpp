#include "solver/stereo/refinement_window.h"

#include <Eigen/Geometry>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/local_frames.h"
#include "geometry/mean_edge_length.h"
#include "solver/stereo/stereo_refinement.h"

namespace subflow::solver {

using geometry::LoopHierarchy;
using geometry::Positions;


FrameImageCache::FrameImageCache(const vision::ImageSequence& images, double sigma)
    : images_(images), sigma_(sigma) {}

const std::vector<SmoothedImage>& FrameImageCache::Gray(int frame) {
  auto it = gray_cache_.find(frame);
  if (it != gray_cache_.end()) return it->second;
  const int cameras = images_.camera_count();
  std::vector<SmoothedImage> smoothed(cameras);
  tbb::parallel_for(0, cameras, [&](int k) { smoothed[k] = SmoothImage(GrayFloat(images_.gray(k, frame)), sigma_); });
  return gray_cache_.emplace(frame, std::move(smoothed)).first->second;
}

const std::vector<std::unique_ptr<SignedDistanceImage>>& FrameImageCache::Silhouettes(int frame) {
  auto it = silhouette_cache_.find(frame);
  if (it != silhouette_cache_.end()) return it->second;
  const int cameras = images_.camera_count();
  std::vector<std::unique_ptr<SignedDistanceImage>> distances(cameras);
  if (images_.silhouette) {
    tbb::parallel_for(0, cameras, [&](int k) {
      const cv::Mat mask = images_.silhouette(k, frame);
      if (!mask.empty()) distances[k] = std::make_unique<SignedDistanceImage>(ComputeSignedDistance(mask));
    });
  }
  return silhouette_cache_.emplace(frame, std::move(distances)).first->second;
}

const FrameVisibility* FrameImageCache::Visibility(int frame, const Positions& control) const {
  const auto it = visibility_cache_.find(frame);
  if (it == visibility_cache_.end() || it->second.first.rows() != control.rows() || it->second.first != control)
    return nullptr;
  return &it->second.second;
}

void FrameImageCache::KeepVisibility(int frame, const Positions& control, FrameVisibility visible) {
  visibility_cache_[frame] = {control, std::move(visible)};
}

void FrameImageCache::Release(int first_kept, int last_kept) {
  const auto release = [first_kept, last_kept](auto& cache) {
    for (auto it = cache.begin(); it != cache.end();)
      it = it->first < first_kept || it->first > last_kept ? cache.erase(it) : ++it;
  };
  release(gray_cache_);
  release(silhouette_cache_);
  release(visibility_cache_);
}

RefinementLevel PrepareLevel(const LoopHierarchy& hierarchy, const std::vector<vision::Camera>& cameras,
                             const StereoRefinementOptions& options, const geometry::Trajectory& trajectory,
                             int level, std::vector<char> active_faces) {
  RefinementLevel prepared;
  prepared.level = level;
  prepared.dof = level >= options.normal_only_from_level ? 1 : 3;
  const int reference = static_cast<int>(trajectory.size()) / 2;
  const Positions reference_level = trajectory[reference].Synthesize(hierarchy, level);
  prepared.h = geometry::MeanEdgeLength(hierarchy.Topology(level), reference_level);
  prepared.sampling = SampleLevel(hierarchy, level, reference_level, cameras, options, &active_faces);
  prepared.visibility = std::make_unique<VisibilityTester>(hierarchy, hierarchy.finest_level(), options.visibility);
  prepared.active_faces = std::move(active_faces);
  const geometry::Faces& F = hierarchy.LevelFaces(level);
  prepared.active_vertices.assign(hierarchy.VertexCount(level), 0);
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    if (prepared.active_faces[f])
      for (int k = 0; k < 3; ++k) prepared.active_vertices[F(f, k)] = 1;
  return prepared;
}

RefinementWindow OpenWindow(const RefinementLevel& level, const LoopHierarchy& hierarchy,
                            const std::vector<vision::Camera>& cameras, const StereoRefinementOptions& options,
                            const geometry::Trajectory& trajectory, const std::vector<Positions>& control,
                            FrameImageCache* images, int first, int last, int span_first, int span_last) {
  RefinementWindow window;
  window.options = &options;
  window.cameras = &cameras;
  window.hierarchy = &hierarchy;
  window.trajectory = &trajectory;
  window.sampling = &level.sampling;
  window.images = images;
  window.level = level.level;
  window.dof = level.dof;
  window.first = first;
  window.last = last;
  window.frame_count = static_cast<int>(control.size());
  window.span_first = span_first < 0 ? 0 : span_first;
  window.span_last = span_last;
  if (window.span_first > first || window.SpanLast() < last || window.SpanLast() >= window.frame_count)
    ThrowError("stereo refinement", "window",
               "frames " + std::to_string(first) + "–" + std::to_string(last) + " outside their span " +
                   std::to_string(window.span_first) + "–" + std::to_string(window.SpanLast()));
  window.h = level.h;
  window.active_faces = level.active_faces;
  window.active_vertices = level.active_vertices;
  const int c0 = std::max(window.span_first, first - 1), c1 = std::min(window.SpanLast(), last + 1);
  const bool rim = options.rim_band > 0 && options.silhouette_weight > 0 &&
                   level.level >= options.silhouette_from_level;
  for (int f = c0; f <= c1; ++f) {
    const auto& silhouettes = images->Silhouettes(f);
    std::vector<char> coverage_of(cameras.size(), 0);
    for (std::size_t k = 0; rim && k < cameras.size(); ++k)
      coverage_of[k] = silhouettes[k] && images->TightOutline(static_cast<int>(k));
    const FrameVisibility* known = images->Visibility(f, control[f]);
    FrameVisibility decided;
    window.states.emplace(f, MakeFrameState(hierarchy, level.level, level.dof, trajectory[f], control[f],
                                            level.sampling, *level.visibility, cameras, silhouettes, coverage_of,
                                            options.outline_margin, known, known ? nullptr : &decided));
    if (!known) images->KeepVisibility(f, control[f], std::move(decided));
  }
  return window;
}

FrameState MakeFrameState(const LoopHierarchy& hierarchy, int level, int dof,
                          const geometry::MultiresShape& shape, const Positions& finest_control,
                          const LevelSampling& sampling, const VisibilityTester& tester,
                          const std::vector<vision::Camera>& cameras,
                          const std::vector<std::unique_ptr<SignedDistanceImage>>& silhouettes,
                          const std::vector<char>& coverage_of, double outline_margin,
                          const FrameVisibility* known, FrameVisibility* decided) {
  FrameState state;
  std::vector<geometry::LocalFrames> frames;
  state.level_control = shape.Synthesize(hierarchy, level, &frames);
  const int vertices = hierarchy.VertexCount(level);
  state.basis.resize(vertices);
  if (level == 0) {
    const Positions normals = geometry::LimitNormals(hierarchy, 0, state.level_control);
    // Normal first, then two tangents (dof 3), so that holding a vertex to its normal keeps
    // its first increment.
    for (int v = 0; v < vertices; ++v) {
      const Eigen::Vector3d n = normals.row(v).transpose();
      state.basis[v].setZero();
      state.basis[v].col(0) = n;
      if (dof == 3) {
        state.basis[v].col(1) = n.unitOrthogonal();
        state.basis[v].col(2) = n.cross(state.basis[v].col(1));
      }
    }
  } else {
    const geometry::LocalFrames& F = frames.at(level - 1);
    for (int v = 0; v < vertices; ++v) {
      state.basis[v].col(0) = F.normal.row(v).transpose();
      state.basis[v].col(1) = F.r.row(v).transpose();
      state.basis[v].col(2) = F.q.row(v).transpose();
    }
  }
  state.positions = sampling.finest_limit * finest_control;
  const Positions du = sampling.finest_du * finest_control;
  const Positions dv = sampling.finest_dv * finest_control;
  state.normals.resize(state.positions.rows(), 3);
  for (Eigen::Index s = 0; s < du.rows(); ++s)
    state.normals.row(s) = du.row(s).cross(dv.row(s)).normalized();
  if (known) {
    state.usable = known->visible;
    state.coverage = known->coverage;
  } else {
    SampleVisibility computed = tester.Compute(cameras, finest_control, state.positions, state.normals, &coverage_of);
    state.usable = std::move(computed.visible);
    state.coverage = std::move(computed.coverage);
    if (decided) *decided = {state.usable, state.coverage};
  }
  tbb::parallel_for(0, static_cast<int>(cameras.size()), [&](int k) {
    if (!silhouettes[k]) return;
    for (Eigen::Index s = 0; s < state.positions.rows(); ++s) {
      if (!state.usable[k][s]) continue;
      double distance = 0.0;
      const Eigen::Vector2d p = cameras[k].ProjectUndistorted(state.positions.row(s).transpose());
      if (!SampleScalar(silhouettes[k]->distance, p, &distance) || distance > -outline_margin)
        state.usable[k][s] = 0;
    }
  });
  state.increments.assign(static_cast<std::size_t>(vertices) * dof, 0.0);
  return state;
}

}  // namespace subflow::solver
