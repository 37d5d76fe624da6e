#include "solver/stereo/photometric_residuals.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>

#include "solver/stereo/stereo_refinement.h"
#include "solver/stereo/view_cache.h"

namespace subflow::solver {
namespace {

// The parameter blocks of the support vertices of a patch at a frame, appended.
void AppendBlocks(RefinementWindow& window, int frame, const std::vector<int>& support,
                  std::vector<double*>* blocks) {
  for (int v : support) blocks->push_back(window.Increment(frame, v));
}

// The bases of `support` at `frame`, read in place (ncc_cost.h: SupportBases).
SupportBases BasesOf(const RefinementWindow& window, int frame, const std::vector<int>& support) {
  return {&window.states.at(frame).basis, &support};
}

// The rows (samples of `face`) usable in every given (frame, camera) view.
std::vector<int> CommonRows(const RefinementWindow& window, int face,
                            const std::vector<std::pair<int, int>>& views) {
  const int first = window.sampling->face_first[face], m = window.sampling->FaceSampleCount(face);
  std::vector<int> rows;
  for (int s = 0; s < m; ++s) {
    bool all = true;
    for (const auto& [frame, k] : views) all = all && window.states.at(frame).usable[k][first + s];
    if (all) rows.push_back(s);
  }
  return rows;
}

PatchView MakeView(RefinementWindow& window, int frame, int camera, int face, int first_block) {
  const int first = window.sampling->face_first[face], m = window.sampling->FaceSampleCount(face);
  PatchView view;
  view.image = &window.images->Gray(frame)[camera];
  view.camera = &(*window.cameras)[camera];
  view.base = {&window.states.at(frame).positions, first, m};
  view.basis = BasesOf(window, frame, window.sampling->support[face]);
  view.first_block = first_block;
  return view;
}

// A view of `face`: (frame, camera) and the index of its frame's first support block in
// the block's parameter list.
struct ViewKey {
  int frame, camera, first_block;
};

// The correlation block of `face` comparing `views` by `pairs`: on the window's view cache
// when it has one (each view sampled once per evaluation point for all blocks), else
// sampling its own views.
PatchCorrelationCost* CorrelationCost(RefinementWindow& window, int face, const std::vector<ViewKey>& views,
                                      std::vector<CorrelationPair> pairs, int block_count) {
  const PatchStencil& stencil = window.sampling->stencil[face];
  const std::vector<int>& support = window.sampling->support[face];
  const double epsilon = window.options->ncc_epsilon;
  PatchCorrelationCost* cost = nullptr;
  if (!window.views) {
    std::vector<PatchView> own;
    for (const ViewKey& key : views) own.push_back(MakeView(window, key.frame, key.camera, face, key.first_block));
    cost = new PatchCorrelationCost(stencil, std::move(own), std::move(pairs), block_count, window.dof, epsilon);
  } else {
    const std::vector<std::vector<int>> rows =
        RowsOfViews(pairs, static_cast<int>(views.size()), static_cast<int>(stencil.rows()));
    std::vector<const SampledView*> sampled;
    std::vector<int> first_blocks;
    for (std::size_t v = 0; v < views.size(); ++v) {
      const ViewKey& key = views[v];
      std::vector<const double*> increments;
      for (int vertex : support) increments.push_back(window.Increment(key.frame, vertex));
      sampled.push_back(window.views->Add(
          key.frame, key.camera, face, stencil, [&] { return MakeView(window, key.frame, key.camera, face, 0); },
          std::move(increments), rows[v]));
      first_blocks.push_back(key.first_block);
    }
    cost = new PatchCorrelationCost(std::move(sampled), std::move(first_blocks), std::move(pairs),
                                    static_cast<int>(support.size()), block_count, window.dof, epsilon);
  }
  if (window.options->solver.reduced_correlation_blocks) cost->UseReducedForm();
  return cost;
}

// The sample of `face` at `frame` on camera k's outline rim, or -1: the patch's samples
// both face the camera and face away (the contour generator crosses it); of those, the one
// nearest the contour generator (smallest |cos| between its normal and its view ray — not
// the one projecting outermost, whose pick would favour the staircase's outward errors)
// lies within `band` pixels inside the outline or outside it; and nothing of the frame's
// current surface covers the image 1 and 2 px beyond it (along the projected normal): the
// rim is the current surface's outline, not one in front of another part (a leg before the
// other leg, a nose before the cheek) or inside a bridge over a hollow, whose outline the
// silhouette does not show.
int RimSample(const RefinementWindow& window, int frame, int face, int k, const SignedDistanceImage& distance,
              double band) {
  const FrameState& state = window.states.at(frame);
  const vision::Camera& camera = (*window.cameras)[k];
  if (state.coverage.empty() || state.coverage[k].empty()) return -1;
  const int first = window.sampling->face_first[face];
  const int m = window.sampling->FaceSampleCount(face);
  const Eigen::Vector3d centre = camera.Center();
  bool facing = false, away = false;
  int rim = -1;
  double smallest = 2.0;
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector3d ray = state.positions.row(first + i).transpose() - centre;
    const double c = state.normals.row(first + i).dot(ray.transpose()) / ray.norm();
    (c < 0 ? facing : away) = true;
    if (std::abs(c) < smallest) smallest = std::abs(c), rim = i;
  }
  if (!facing || !away) return -1;
  const Eigen::Vector3d X = state.positions.row(first + rim).transpose();
  double depth = 0.0, value = 0.0;
  const Eigen::Vector2d pixel = camera.ProjectUndistorted(X, &depth);
  if (depth <= 0 || !SampleScalar(distance.distance, pixel, &value) || value < -band) return -1;
  const double step = 1e-3 * (X - centre).norm();
  const Eigen::Vector2d out = camera.ProjectUndistorted(X + step * state.normals.row(first + rim).transpose()) - pixel;
  if (!(out.norm() > 0)) return -1;
  const cv::Mat& covered = state.coverage[k];
  for (double reach : {1.0, 2.0}) {
    const Eigen::Vector2d q = pixel + reach * out.normalized();
    const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
    if (x >= 0 && y >= 0 && x < covered.cols && y < covered.rows && covered.at<std::uint8_t>(y, x)) return -1;
  }
  return rim;
}

}  // namespace

PatchCameras CamerasOfPatch(const RefinementWindow& window, int frame, int face) {
  const StereoRefinementOptions& options = *window.options;
  const std::vector<vision::Camera>& cameras = *window.cameras;
  const FrameState& state = window.states.at(frame);
  const int first = window.sampling->face_first[face], m = window.sampling->FaceSampleCount(face);
  std::vector<std::pair<double, int>> ranked;
  for (int k = 0; k < static_cast<int>(cameras.size()); ++k) {
    const std::vector<std::uint8_t>& visible = state.usable[k];
    int count = 0;
    double cosine = 0.0;
    const Eigen::Vector3d center = cameras[k].Center();
    for (int s = first; s < first + m; ++s) {
      if (!visible[s]) continue;
      ++count;
      const Eigen::Vector3d X = state.positions.row(s).transpose();
      cosine += state.normals.row(s).dot((center - X).normalized());
    }
    if (count >= std::max(options.min_samples, (m + 1) / 2)) ranked.emplace_back(cosine / count, k);
  }
  std::sort(ranked.begin(), ranked.end(), std::greater<>());
  PatchCameras result;
  for (std::size_t i = 0; i < ranked.size() && static_cast<int>(i) < options.max_cameras; ++i) {
    result.cosines.push_back(ranked[i].first);
    result.cameras.push_back(ranked[i].second);
  }
  return result;
}

std::optional<ResidualRecord> AddStereoResidual(RefinementWindow& window, int frame, int face,
                                                const PatchCameras& seen, ceres::LossFunction* loss,
                                                ceres::Problem* problem) {
  const StereoRefinementOptions& options = *window.options;
  const std::vector<int>& support = window.sampling->support[face];
  const int n_seen = static_cast<int>(seen.cameras.size());
  // Each camera's samples are evaluated once, however many pairs use them.
  std::vector<ViewKey> views;
  for (int a = 0; a < n_seen; ++a) views.push_back({frame, seen.cameras[a], 0});
  std::vector<CorrelationPair> pairs;
  for (int a = 0; a < n_seen; ++a)
    for (int b = a + 1; b < n_seen; ++b) {
      std::vector<int> rows = CommonRows(window, face, {{frame, seen.cameras[a]}, {frame, seen.cameras[b]}});
      if (static_cast<int>(rows.size()) < options.min_samples) continue;
      const double weight = std::pow(std::max(0.0, seen.cosines[a]) * std::max(0.0, seen.cosines[b]),
                                     options.angle_weight_power);
      pairs.push_back({a, b, std::move(rows), weight});
    }
  if (pairs.empty()) return std::nullopt;
  std::vector<double*> blocks;
  AppendBlocks(window, frame, support, &blocks);
  PatchCorrelationCost* cost =
      CorrelationCost(window, face, views, std::move(pairs), static_cast<int>(support.size()));
  return ResidualRecord{problem->AddResidualBlock(cost, loss, blocks), frame, cost};
}

int AddTemporalResiduals(RefinementWindow& window, int frame, int face, const PatchCameras& seen,
                         ceres::LossFunction* loss, ceres::Problem* problem) {
  const StereoRefinementOptions& options = *window.options;
  if (options.temporal_weight <= 0) return 0;
  const std::vector<int>& support = window.sampling->support[face];
  const int support_size = static_cast<int>(support.size());
  std::vector<std::pair<int, int>> steps;
  if (frame + 1 <= window.SpanLast()) steps.emplace_back(frame, frame + 1);
  if (frame == window.first && frame > window.span_first) steps.emplace_back(frame - 1, frame);
  int added = 0;
  for (const auto& [ta, tb] : steps) {
    std::vector<ViewKey> views;
    std::vector<CorrelationPair> pairs;
    for (std::size_t a = 0; a < seen.cameras.size(); ++a) {
      const int i = seen.cameras[a];
      std::vector<int> rows = CommonRows(window, face, {{ta, i}, {tb, i}});
      if (static_cast<int>(rows.size()) < options.min_samples) continue;
      const double weight = options.temporal_weight *
                            std::pow(std::max(0.0, seen.cosines[a]), 2.0 * options.angle_weight_power);
      const int index = static_cast<int>(views.size());
      views.push_back({ta, i, 0});
      views.push_back({tb, i, support_size});
      pairs.push_back({index, index + 1, std::move(rows), weight});
    }
    if (pairs.empty()) continue;
    std::vector<double*> blocks;
    AppendBlocks(window, ta, support, &blocks);
    AppendBlocks(window, tb, support, &blocks);
    problem->AddResidualBlock(CorrelationCost(window, face, views, std::move(pairs), 2 * support_size), loss,
                              blocks);
    ++added;
  }
  return added;
}

void AddSilhouetteResiduals(RefinementWindow& window, int frame, int face, ceres::Problem* problem,
                            std::vector<ResidualRecord>* records) {
  const StereoRefinementOptions& options = *window.options;
  if (options.silhouette_weight <= 0 || window.level < options.silhouette_from_level) return;
  const std::vector<vision::Camera>& cameras = *window.cameras;
  const auto& distances = window.images->Silhouettes(frame);
  const std::vector<int>& support = window.sampling->support[face];
  const PatchStencil& stencil = window.sampling->stencil[face];
  const int m = window.sampling->FaceSampleCount(face);
  const int first = window.sampling->face_first[face];
  const Eigen::Vector3i corners = window.hierarchy->LevelFaces(window.level).row(face).transpose();
  const bool held_elsewhere = window.dof == 3 && options.tangential_only_at_outlines;  // HoldToNormals reads sliding
  const auto add = [&](int k, int i, bool one_sided) {
    std::vector<double*> blocks;
    AppendBlocks(window, frame, support, &blocks);
    auto* cost = new SilhouetteCost(distances[k].get(), &cameras[k],
                                    window.states.at(frame).positions.row(first + i).transpose(),
                                    stencil.row(i).transpose(), BasesOf(window, frame, support), window.dof,
                                    options.silhouette_weight, one_sided);
    records->push_back({problem->AddResidualBlock(cost, nullptr, blocks), frame, nullptr});
    if (held_elsewhere && window.images->TightOutline(k))  // these corners may slide
      for (int c = 0; c < 3; ++c) window.sliding.insert(window.Increment(frame, corners(c)));
  };
  const Eigen::Vector3d X = window.states.at(frame).positions.row(first + m / 2).transpose();
  for (int k = 0; k < static_cast<int>(cameras.size()); ++k) {
    if (!distances[k]) continue;
    if (options.rim_band > 0 && window.images->TightOutline(k)) {
      const int rim = RimSample(window, frame, face, k, *distances[k], options.rim_band);
      if (rim >= 0) {
        add(k, rim, false);
        continue;
      }
    }
    double depth = 0.0;
    const Eigen::Vector2d p = cameras[k].ProjectUndistorted(X, &depth);
    double distance = 0.0;
    if (depth <= 0 || !SampleScalar(distances[k]->distance, p, &distance)) continue;
    // Inside by more than half a pixel: the one-sided term is inactive. About a quarter of
    // a convex surface projects within 2 px of its outline in a camera, so a wider band
    // would cost many blocks for nothing.
    if (distance < -0.5) continue;
    add(k, m / 2, true);
  }
}

}  // namespace subflow::solver
