#include "solver/motion/normal_flow_constraints.h"

#include <algorithm>
#include <functional>
#include <string>

#include <tbb/parallel_for.h>

#include "core/error.h"

namespace subflow::solver {
namespace {

struct Row {
  int sample, camera;
  Eigen::Vector3d gradient;
  double rhs, photometric;
};

// One row (or none) for (sample, camera).
using RowBuilder = std::function<bool(int sample, int camera, Row* row)>;

// Runs `build` over every visible (sample, camera) in parallel chunks of samples and
// concatenates the rows in sample order.
NormalFlowConstraints CollectRows(int sample_count, const SampleVisibility& visibility,
                                  const RowBuilder& build) {
  constexpr int kChunk = 1024;
  const int chunk_count = (sample_count + kChunk - 1) / kChunk;
  std::vector<std::vector<Row>> chunks(chunk_count);
  tbb::parallel_for(0, chunk_count, [&](int c) {
    for (int s = c * kChunk; s < std::min(sample_count, (c + 1) * kChunk); ++s)
      for (int k = 0; k < visibility.camera_count(); ++k) {
        if (!visibility.visible[k][s]) continue;
        Row row;
        if (build(s, k, &row)) chunks[c].push_back(row);
      }
  });
  std::size_t total = 0;
  for (const auto& chunk : chunks) total += chunk.size();
  NormalFlowConstraints constraints;
  constraints.sample.reserve(total);
  constraints.camera.reserve(total);
  constraints.gradient.resize(static_cast<Eigen::Index>(total), 3);
  constraints.rhs.resize(static_cast<Eigen::Index>(total));
  constraints.photometric.resize(static_cast<Eigen::Index>(total));
  Eigen::Index i = 0;
  for (const auto& chunk : chunks)
    for (const Row& row : chunk) {
      constraints.sample.push_back(row.sample);
      constraints.camera.push_back(row.camera);
      constraints.gradient.row(i) = row.gradient.transpose();
      constraints.rhs(i) = row.rhs;
      constraints.photometric(i) = row.photometric;
      ++i;
    }
  return constraints;
}

void CheckCommon(const std::vector<vision::Camera>& cameras, std::size_t images,
                 const geometry::Positions& sample_positions, const SampleVisibility& visibility) {
  if (images != cameras.size())
    ThrowError("normal flow constraints", "images",
               std::to_string(images) + " per frame for " + std::to_string(cameras.size()) +
                   " cameras");
  if (visibility.camera_count() != static_cast<int>(cameras.size()))
    ThrowError("normal flow constraints", "visibility", "camera count differs");
  for (const auto& camera : visibility.visible)
    if (static_cast<Eigen::Index>(camera.size()) != sample_positions.rows())
      ThrowError("normal flow constraints", "visibility", "sample count differs");
}

// The checks shared by the step form and its photometric differences; returns whether a
// displacement guess is given.
bool CheckStepInputs(const std::vector<vision::Camera>& cameras, const std::vector<SmoothedImage>& before,
                     const std::vector<SmoothedImage>& after, const geometry::Positions& sample_positions,
                     const geometry::Positions& sample_displacement, const SampleVisibility& visibility) {
  CheckCommon(cameras, before.size(), sample_positions, visibility);
  if (after.size() != before.size())
    ThrowError("normal flow constraints", "images", "before and after differ in camera count");
  const bool has_guess = sample_displacement.rows() > 0;
  if (has_guess && sample_displacement.rows() != sample_positions.rows())
    ThrowError("normal flow constraints", "sample displacement",
               std::to_string(sample_displacement.rows()) + " rows for " +
                   std::to_string(sample_positions.rows()) + " samples");
  return has_guess;
}

}  // namespace

Eigen::VectorXd NormalFlowConstraints::Residuals(const geometry::Positions& sample_motion) const {
  Eigen::VectorXd residual(size());
  for (int c = 0; c < size(); ++c)
    residual(c) = gradient.row(c).dot(sample_motion.row(sample[c])) - rhs(c);
  return residual;
}

NormalFlowConstraints BuildStepConstraints(const std::vector<vision::Camera>& cameras,
                                           const std::vector<SmoothedImage>& before,
                                           const std::vector<SmoothedImage>& after,
                                           const geometry::Positions& sample_positions,
                                           const geometry::Positions& sample_displacement,
                                           const SampleVisibility& visibility) {
  const bool has_guess =
      CheckStepInputs(cameras, before, after, sample_positions, sample_displacement, visibility);
  return CollectRows(static_cast<int>(sample_positions.rows()), visibility,
                     [&](int s, int k, Row* row) {
    const vision::Camera& camera = cameras[k];
    const Eigen::Vector3d X = sample_positions.row(s).transpose();
    const Eigen::Vector3d u =
        has_guess ? Eigen::Vector3d(sample_displacement.row(s).transpose()) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d X_after = X + u;
    double depth = 0.0, i_before = 0.0, i_after = 0.0;
    Eigen::Vector2d g_before, g_after;
    if (!SampleImage(before[k], camera.ProjectUndistorted(X), &i_before, &g_before)) return false;
    const Eigen::Vector2d p_after = camera.ProjectUndistorted(X_after, &depth);
    if (!(depth > 0.0) || !SampleImage(after[k], p_after, &i_after, &g_after)) return false;
    const Eigen::Vector2d mean_gradient = 0.5 * (g_before + g_after);
    row->sample = s;
    row->camera = k;
    row->gradient = camera.ProjectionJacobian(X_after).transpose() * mean_gradient;
    row->photometric = i_after - i_before;
    row->rhs = -row->photometric + row->gradient.dot(u);
    return true;
  });
}

Eigen::VectorXd StepPhotometricDifferences(const std::vector<vision::Camera>& cameras,
                                           const std::vector<SmoothedImage>& before,
                                           const std::vector<SmoothedImage>& after,
                                           const geometry::Positions& sample_positions,
                                           const geometry::Positions& sample_displacement,
                                           const SampleVisibility& visibility) {
  const bool has_guess =
      CheckStepInputs(cameras, before, after, sample_positions, sample_displacement, visibility);
  constexpr int kChunk = 1024;
  const int sample_count = static_cast<int>(sample_positions.rows());
  const int chunk_count = (sample_count + kChunk - 1) / kChunk;
  std::vector<std::vector<double>> chunks(chunk_count);
  tbb::parallel_for(0, chunk_count, [&](int c) {
    for (int s = c * kChunk; s < std::min(sample_count, (c + 1) * kChunk); ++s)
      for (int k = 0; k < visibility.camera_count(); ++k) {
        if (!visibility.visible[k][s]) continue;
        const vision::Camera& camera = cameras[k];
        const Eigen::Vector3d X = sample_positions.row(s).transpose();
        const Eigen::Vector3d X_after =
            has_guess ? Eigen::Vector3d(X + sample_displacement.row(s).transpose()) : X;
        double depth = 0.0, i_before = 0.0, i_after = 0.0;
        if (!SampleScalar(before[k].intensity, camera.ProjectUndistorted(X), &i_before)) continue;
        const Eigen::Vector2d p_after = camera.ProjectUndistorted(X_after, &depth);
        if (!(depth > 0.0) || !SampleScalar(after[k].intensity, p_after, &i_after)) continue;
        chunks[c].push_back(i_after - i_before);
      }
  });
  std::size_t total = 0;
  for (const auto& chunk : chunks) total += chunk.size();
  Eigen::VectorXd differences(static_cast<Eigen::Index>(total));
  Eigen::Index i = 0;
  for (const auto& chunk : chunks)
    for (double d : chunk) differences(i++) = d;
  return differences;
}

NormalFlowConstraints BuildFrameConstraints(
    const std::vector<vision::Camera>& cameras,
    const std::vector<SpatioTemporalDerivatives>& derivatives,
    const geometry::Positions& sample_positions, const SampleVisibility& visibility) {
  CheckCommon(cameras, derivatives.size(), sample_positions, visibility);
  return CollectRows(static_cast<int>(sample_positions.rows()), visibility,
                     [&](int s, int k, Row* row) {
    const vision::Camera& camera = cameras[k];
    const Eigen::Vector3d X = sample_positions.row(s).transpose();
    const Eigen::Vector2d p = camera.ProjectUndistorted(X);
    double intensity = 0.0, temporal = 0.0;
    Eigen::Vector2d gradient;
    if (!SampleImage(derivatives[k].spatial, p, &intensity, &gradient)) return false;
    if (!SampleScalar(derivatives[k].temporal, p, &temporal)) return false;
    row->sample = s;
    row->camera = k;
    row->gradient = camera.ProjectionJacobian(X).transpose() * gradient;
    row->rhs = -temporal;
    row->photometric = temporal;
    return true;
  });
}

}  // namespace subflow::solver
