#include "solver/stereo_refinement.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <thread>
#include <utility>

#include <ceres/ceres.h>
#include <spdlog/spdlog.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/stopwatch.h"
#include "geometry/limit_evaluation.h"
#include "geometry/local_frames.h"
#include "geometry/multires_shape.h"
#include "solver/ncc_cost.h"
#include "solver/surface_sampling.h"

namespace subflow::solver {
namespace {

using geometry::LoopHierarchy;
using geometry::Positions;
ceres::LinearSolverType ParseLinearSolver(const std::string& name) {
  if (name == "sparse_normal_cholesky") return ceres::SPARSE_NORMAL_CHOLESKY;
  if (name == "cgnr") return ceres::CGNR;
  if (name == "iterative_schur") return ceres::ITERATIVE_SCHUR;
  if (name == "sparse_schur") return ceres::SPARSE_SCHUR;
  if (name == "dense_qr") return ceres::DENSE_QR;
  ThrowError("stereo refinement", "linear_solver",
             "'" + name + "' is not one of sparse_normal_cholesky, cgnr, iterative_schur, "
                          "sparse_schur, dense_qr");
}

// r = Σ_b A_b e_b + r0: membrane and damping of the increments, temporal second
// differences of the trajectories (r0: those of the current ones).
class LinearResidualCost final : public ceres::CostFunction {
 public:
  explicit LinearResidualCost(std::vector<Eigen::MatrixXd> blocks, Eigen::VectorXd offset = {})
      : blocks_(std::move(blocks)), offset_(std::move(offset)) {
    set_num_residuals(static_cast<int>(blocks_.front().rows()));
    if (offset_.size() == 0) offset_ = Eigen::VectorXd::Zero(num_residuals());
    SUBFLOW_CHECK(offset_.size() == num_residuals(), "offset does not match the residuals");
    for (const Eigen::MatrixXd& A : blocks_)
      mutable_parameter_block_sizes()->push_back(static_cast<int>(A.cols()));
  }
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int rows = num_residuals();
    Eigen::Map<Eigen::VectorXd> r(residuals, rows);
    r = offset_;
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      const Eigen::MatrixXd& A = blocks_[b];
      r += A * Eigen::Map<const Eigen::VectorXd>(parameters[b], A.cols());
      if (jacobians && jacobians[b])
        Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
            jacobians[b], rows, A.cols()) = A;
    }
    return true;
  }

 private:
  std::vector<Eigen::MatrixXd> blocks_;
  Eigen::VectorXd offset_;
};

// The samples of one level: a pattern inside every face of level ℓ, their level-ℓ limit
// stencils grouped per face (the Jacobian of the samples w.r.t. level-ℓ control points)
// and the limit matrix of the same points on the finest level (their current positions).
struct LevelSampling {
  std::vector<geometry::FaceSample> samples;      // on level-ℓ faces
  std::vector<int> face_first;                    // #F + 1 offsets
  geometry::SparseMatrix finest_limit, finest_du, finest_dv;
  std::vector<std::vector<int>> support;          // per face: level-ℓ vertices
  std::vector<PatchStencil> stencil;              // per face: m × #support

  int FaceSampleCount(int face) const { return face_first[face + 1] - face_first[face]; }
};

LevelSampling SampleLevel(const LoopHierarchy& hierarchy, int level, const Positions& level_control,
                          const std::vector<vision::Camera>& cameras,
                          const StereoRefinementOptions& options) {
  SurfaceSamplingOptions sampling;
  sampling.samples_per_pixel = options.samples_per_pixel;
  sampling.max_density = options.max_density;
  std::vector<int> density = FaceSampleDensities(hierarchy, level, level_control, cameras, sampling);
  LevelSampling result;
  const int faces = hierarchy.FaceCount(level);
  for (int f = 0; f < faces; ++f) {
    result.face_first.push_back(static_cast<int>(result.samples.size()));
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

// The frame ranges [w0, w1] of the windows over `frames` frames: `window` frames each
// (fewer at the end), consecutive ones sharing min(overlap, window − 1) frames.
std::vector<std::pair<int, int>> Windows(int frames, int window, int overlap) {
  std::vector<std::pair<int, int>> windows;
  const int step = window - std::min(overlap, window - 1);
  for (int w0 = 0;; w0 += step) {
    const int w1 = std::min(frames - 1, w0 + window - 1);
    windows.emplace_back(w0, w1);
    if (w1 == frames - 1) break;
  }
  return windows;
}

double MeanEdgeLength(const geometry::Faces& F, const Positions& V) {
  double sum = 0.0;
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    for (int k = 0; k < 3; ++k) sum += (V.row(F(f, k)) - V.row(F(f, (k + 1) % 3))).norm();
  return sum / (3.0 * static_cast<double>(F.rows()));
}

// Images of the frames a window needs, smoothed once; released when no longer needed.
class FrameImages {
 public:
  FrameImages(const RefinementImageLoader& gray, const RefinementImageLoader& silhouettes,
              int cameras, double sigma)
      : gray_(gray), silhouettes_(silhouettes), cameras_(cameras), sigma_(sigma) {}

  const std::vector<SmoothedImage>& Gray(int frame) {
    auto it = gray_cache_.find(frame);
    if (it != gray_cache_.end()) return it->second;
    std::vector<SmoothedImage> images(cameras_);
    tbb::parallel_for(0, cameras_, [&](int k) { images[k] = SmoothImage(GrayFloat(gray_(k, frame)), sigma_); });
    return gray_cache_.emplace(frame, std::move(images)).first->second;
  }
  // Per camera: the signed distance to the silhouette's outline, or null.
  const std::vector<std::unique_ptr<SignedDistanceImage>>& Silhouettes(int frame) {
    auto it = silhouette_cache_.find(frame);
    if (it != silhouette_cache_.end()) return it->second;
    std::vector<std::unique_ptr<SignedDistanceImage>> distances(cameras_);
    if (silhouettes_) {
      tbb::parallel_for(0, cameras_, [&](int k) {
        const cv::Mat mask = silhouettes_(k, frame);
        if (!mask.empty()) distances[k] = std::make_unique<SignedDistanceImage>(ComputeSignedDistance(mask));
      });
    }
    return silhouette_cache_.emplace(frame, std::move(distances)).first->second;
  }
  void Release(int first_kept) {
    for (auto* cache : {&gray_cache_})
      for (auto it = cache->begin(); it != cache->end();) it = it->first < first_kept ? cache->erase(it) : ++it;
    for (auto it = silhouette_cache_.begin(); it != silhouette_cache_.end();)
      it = it->first < first_kept ? silhouette_cache_.erase(it) : ++it;
  }

 private:
  const RefinementImageLoader& gray_;
  const RefinementImageLoader& silhouettes_;
  int cameras_;
  double sigma_;
  std::map<int, std::vector<SmoothedImage>> gray_cache_;
  std::map<int, std::vector<std::unique_ptr<SignedDistanceImage>>> silhouette_cache_;
};

// Everything the residuals of one frame need at level ℓ: the parameter bases, the
// current sample positions and normals, their visibility, the level-ℓ control points.
struct FrameState {
  Positions level_control;              // c(ℓ), #V(ℓ)×3
  std::vector<Eigen::Matrix3d> basis;   // per level-ℓ vertex: columns (n, r, q) or I
  Positions positions, normals;         // per sample (finest limit surface)
  // usable[k][s]: visible in camera k (z-buffer, view angle) and, where camera k has a
  // silhouette, at least `outline_margin` pixels inside it: the smoothed intensity of a
  // sample near the outline mixes in the background, which biases the correlation
  // towards shrinking the surface away from the outline.
  std::vector<std::vector<std::uint8_t>> usable;
  std::vector<double> increments;       // e: #V(ℓ) × dof, the unknowns (zero at the start)
};

FrameState MakeFrameState(const LoopHierarchy& hierarchy, int level, int dof,
                          const geometry::MultiresShape& shape, const Positions& finest_control,
                          const LevelSampling& sampling, const VisibilityTester& tester,
                          const std::vector<vision::Camera>& cameras,
                          const std::vector<std::unique_ptr<SignedDistanceImage>>& silhouettes,
                          double outline_margin) {
  FrameState state;
  std::vector<geometry::LocalFrames> frames;
  state.level_control = shape.Synthesize(hierarchy, level, &frames);
  const int vertices = hierarchy.VertexCount(level);
  state.basis.resize(vertices);
  if (level == 0) {
    const Positions normals = geometry::LimitNormals(hierarchy, 0, state.level_control);
    for (int v = 0; v < vertices; ++v) {
      if (dof == 3) {
        state.basis[v].setIdentity();
      } else {
        state.basis[v].setZero();
        state.basis[v].col(0) = normals.row(v).transpose();
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
  state.usable = tester.Compute(cameras, finest_control, state.positions, state.normals).visible;
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

// Bounds of a normal-only increment e so that c + n e stays in the box.
std::pair<double, double> SlabRange(const Eigen::Vector3d& p, const Eigen::Vector3d& n,
                                    const vision::Bounds& bounds) {
  double lo = -std::numeric_limits<double>::infinity(), hi = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (std::abs(n(a)) < 1e-12) continue;
    double t0 = (bounds.min(a) - p(a)) / n(a), t1 = (bounds.max(a) - p(a)) / n(a);
    if (t0 > t1) std::swap(t0, t1);
    lo = std::max(lo, t0);
    hi = std::min(hi, t1);
  }
  return {std::min(lo, 0.0), std::max(hi, 0.0)};  // a point already outside may stay put
}

struct PatchCameras {
  std::vector<int> cameras;     // best-facing first
  std::vector<double> cosines;  // mean cos θ over the visible samples
};

PatchCameras CamerasOfPatch(const LevelSampling& sampling, int face, const FrameState& state,
                            const std::vector<vision::Camera>& cameras,
                            const StereoRefinementOptions& options) {
  const int first = sampling.face_first[face], m = sampling.FaceSampleCount(face);
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

struct ResidualRecord {
  ceres::ResidualBlockId id;
  int frame;
  const PatchCorrelationCost* correlation;  // null: a silhouette block
};

class LevelRefiner {
 public:
  LevelRefiner(const std::vector<vision::Camera>& cameras, const LoopHierarchy& hierarchy,
               const vision::Bounds& bounds, const StereoRefinementOptions& options,
               FrameImages& images, geometry::Trajectory& trajectory,
               std::vector<Positions>& control, RefinementResult& result)
      : cameras_(cameras), hierarchy_(hierarchy), bounds_(bounds), options_(options),
        images_(images), trajectory_(trajectory), control_(control), result_(result) {}

  // Refines level ℓ over all frames; `active_faces` (level ℓ) on input, and on output
  // the vertices of ℓ that moved by more than the adaptive threshold.
  void Run(int level, const std::vector<char>& active_faces, std::vector<char>* moved_vertices,
           Progress* progress, std::size_t* progress_done);

 private:
  void SolveWindow(int level, int dof, int w0, int w1, const LevelSampling& sampling,
                   const VisibilityTester& tester, const std::vector<char>& active_faces,
                   double h, RefinementLevelReport* report, std::vector<double>* moved);

  const std::vector<vision::Camera>& cameras_;
  const LoopHierarchy& hierarchy_;
  const vision::Bounds& bounds_;
  const StereoRefinementOptions& options_;
  FrameImages& images_;
  geometry::Trajectory& trajectory_;
  std::vector<Positions>& control_;
  RefinementResult& result_;
};

void LevelRefiner::Run(int level, const std::vector<char>& active_faces,
                       std::vector<char>* moved_vertices, Progress* progress,
                       std::size_t* progress_done) {
  const Stopwatch start;
  const int frames = static_cast<int>(control_.size());
  const int dof = level >= options_.normal_only_from_level ? 1 : 3;
  const int reference = frames / 2;
  const Positions reference_level = trajectory_[reference].Synthesize(hierarchy_, level);
  const double h = MeanEdgeLength(hierarchy_.LevelFaces(level), reference_level);
  const LevelSampling sampling = SampleLevel(hierarchy_, level, reference_level, cameras_, options_);
  const VisibilityTester tester(hierarchy_, hierarchy_.finest_level(), options_.visibility);

  RefinementLevelReport report;
  report.level = level;
  report.dof = dof;
  report.patches = hierarchy_.FaceCount(level);
  report.active_patches = static_cast<int>(std::count(active_faces.begin(), active_faces.end(), 1));
  report.active_fraction = static_cast<double>(report.active_patches) / report.patches;
  std::vector<double> moved(hierarchy_.VertexCount(level), 0.0);
  const auto windows = Windows(frames, options_.window, options_.window_overlap);
  report.windows = static_cast<int>(windows.size());
  for (int round = 0; round < options_.rounds; ++round) {
    report.parameters = 0;
    report.residual_blocks = 0;
    for (std::size_t w = 0; w < windows.size(); ++w) {
      const auto [w0, w1] = windows[w];
      SolveWindow(level, dof, w0, w1, sampling, tester, active_faces, h, &report, &moved);
      // The next window needs its frames and its context frame before them.
      if (w + 1 < windows.size()) images_.Release(windows[w + 1].first - 1);
      ProgressUpdate(progress, ++*progress_done);
    }
  }
  double moved_sum = 0.0;
  moved_vertices->assign(moved.size(), 0);
  for (std::size_t v = 0; v < moved.size(); ++v) {
    moved_sum += moved[v];
    (*moved_vertices)[v] = moved[v] > options_.adaptive_threshold * h ? 1 : 0;
  }
  report.mean_increment = moved_sum / static_cast<double>(moved.size());
  report.seconds = start.Seconds();
  spdlog::info("refinement level {}: {} of {} patches, dof {}, {} unknowns, {} residual blocks, "
               "{} iterations, mean max |increment| {:.3g}, {:.1f} s ({:.1f} s in Ceres)",
               level, report.active_patches, report.patches, dof, report.parameters,
               report.residual_blocks, report.iterations, report.mean_increment, report.seconds,
               report.solver_seconds);
  result_.levels.push_back(report);
}

void LevelRefiner::SolveWindow(int level, int dof, int w0, int w1, const LevelSampling& sampling,
                               const VisibilityTester& tester, const std::vector<char>& active_faces,
                               double h, RefinementLevelReport* report, std::vector<double>* moved) {
  const int frames = static_cast<int>(control_.size());
  const int c0 = std::max(0, w0 - 1), c1 = std::min(frames - 1, w1 + 1);
  std::map<int, FrameState> states;
  for (int f = c0; f <= c1; ++f)
    states.emplace(f, MakeFrameState(hierarchy_, level, dof, trajectory_[f], control_[f], sampling,
                                     tester, cameras_, images_.Silhouettes(f),
                                     options_.outline_margin));

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  std::unique_ptr<ceres::LossFunction> ncc_loss;
  if (options_.ncc_loss_scale > 0) ncc_loss = std::make_unique<ceres::CauchyLoss>(options_.ncc_loss_scale);

  auto blocks_of = [&](int frame, const std::vector<int>& support, std::vector<double*>* blocks) {
    double* e = states.at(frame).increments.data();
    for (int v : support) blocks->push_back(e + static_cast<std::ptrdiff_t>(v) * dof);
  };
  auto bases_of = [&](int frame, const std::vector<int>& support) {
    std::vector<Eigen::Matrix3d> basis;
    basis.reserve(support.size());
    for (int v : support) basis.push_back(states.at(frame).basis[v]);
    return basis;
  };

  std::vector<ResidualRecord> stereo, silhouette;
  const int faces = hierarchy_.FaceCount(level);
  for (int t = w0; t <= w1; ++t) {
    const FrameState& state = states.at(t);
    const auto& distances = images_.Silhouettes(t);
    for (int f = 0; f < faces; ++f) {
      if (!active_faces[f]) continue;
      const std::vector<int>& support = sampling.support[f];
      const PatchStencil& stencil = sampling.stencil[f];
      const int first = sampling.face_first[f], m = sampling.FaceSampleCount(f);
      const PatchCameras seen = CamerasOfPatch(sampling, f, state, cameras_, options_);

      // The rows of the samples visible in the given views.
      auto common_rows = [&](const std::vector<std::pair<int, int>>& views) {
        std::vector<int> rows;
        for (int s = 0; s < m; ++s) {
          bool all = true;
          for (const auto& [frame, k] : views) all = all && states.at(frame).usable[k][first + s];
          if (all) rows.push_back(s);
        }
        return rows;
      };
      auto make_view = [&](int frame, int k, int first_block) {
        PatchView view;
        view.image = &images_.Gray(frame)[k];
        view.camera = &cameras_[k];
        for (int s = 0; s < m; ++s) view.base.push_back(states.at(frame).positions.row(first + s).transpose());
        view.basis = bases_of(frame, support);
        view.first_block = first_block;
        return view;
      };
      // Stereo: every pair of the best-facing cameras at frame t, in one block per patch
      // (each camera's samples are evaluated once).
      const int n_seen = static_cast<int>(seen.cameras.size());
      const int support_size = static_cast<int>(support.size());
      {
        std::vector<PatchView> views;
        for (int a = 0; a < n_seen; ++a) views.push_back(make_view(t, seen.cameras[a], 0));
        std::vector<CorrelationPair> pairs;
        for (int a = 0; a < n_seen; ++a)
          for (int b = a + 1; b < n_seen; ++b) {
            std::vector<int> rows = common_rows({{t, seen.cameras[a]}, {t, seen.cameras[b]}});
            if (static_cast<int>(rows.size()) < options_.min_samples) continue;
            const double weight = std::pow(std::max(0.0, seen.cosines[a]) * std::max(0.0, seen.cosines[b]),
                                           options_.angle_weight_power);
            pairs.push_back({a, b, std::move(rows), weight});
          }
        if (!pairs.empty()) {
          std::vector<double*> blocks;
          blocks_of(t, support, &blocks);
          auto* cost = new PatchCorrelationCost(stencil, std::move(views), std::move(pairs), support_size,
                                                dof, options_.ncc_epsilon);
          stereo.push_back({problem.AddResidualBlock(cost, ncc_loss.get(), blocks), t, cost});
        }
      }
      // Temporal self-correlation of each of those cameras: (t, t + 1), and (t − 1, t) at
      // the window's start; one block per patch and step.
      if (options_.temporal_weight > 0) {
        std::vector<std::pair<int, int>> steps;
        if (t + 1 < frames) steps.emplace_back(t, t + 1);
        if (t == w0 && t > 0) steps.emplace_back(t - 1, t);
        for (const auto& [ta, tb] : steps) {
          std::vector<PatchView> views;
          std::vector<CorrelationPair> pairs;
          for (int a = 0; a < n_seen; ++a) {
            const int i = seen.cameras[a];
            std::vector<int> rows = common_rows({{ta, i}, {tb, i}});
            if (static_cast<int>(rows.size()) < options_.min_samples) continue;
            const double weight = options_.temporal_weight *
                                  std::pow(std::max(0.0, seen.cosines[a]), 2.0 * options_.angle_weight_power);
            const int index = static_cast<int>(views.size());
            views.push_back(make_view(ta, i, 0));
            views.push_back(make_view(tb, i, support_size));
            pairs.push_back({index, index + 1, std::move(rows), weight});
          }
          if (pairs.empty()) continue;
          std::vector<double*> blocks;
          blocks_of(ta, support, &blocks);
          blocks_of(tb, support, &blocks);
          problem.AddResidualBlock(new PatchCorrelationCost(stencil, std::move(views), std::move(pairs),
                                                            2 * support_size, dof, options_.ncc_epsilon),
                                   ncc_loss.get(), blocks);
        }
      }
      // Silhouette (one-sided): the patch's middle sample must project inside every
      // silhouette. A two-sided "rim on the outline" term would be biased outwards: a
      // sample near, but not on, the contour generator projects inside the outline.
      if (options_.silhouette_weight > 0) {
        const int s = first + m / 2;
        const Eigen::Vector3d X = state.positions.row(s).transpose();
        for (int k = 0; k < static_cast<int>(cameras_.size()); ++k) {
          if (!distances[k]) continue;
          double depth = 0.0;
          const Eigen::Vector2d p = cameras_[k].ProjectUndistorted(X, &depth);
          double distance = 0.0;
          if (depth <= 0 || !SampleScalar(distances[k]->distance, p, &distance)) continue;
          // Inside (by more than half a pixel): the one-sided term is inactive. About a
          // quarter of a convex surface projects within 2 px of its outline in a camera, so
          // a wider band would cost many blocks for nothing.
          if (distance < -0.5) continue;
          std::vector<double*> blocks;
          blocks_of(t, support, &blocks);
          auto* cost = new SilhouetteCost(distances[k].get(), &cameras_[k], X,
                                          stencil.row(m / 2).transpose(), bases_of(t, support), dof,
                                          options_.silhouette_weight, true);
          const auto id = problem.AddResidualBlock(cost, nullptr, blocks);
          silhouette.push_back({id, t, nullptr});
        }
      }
    }
  }

  // Regularization of the increments, per active vertex of the window's frames.
  const geometry::MeshTopology& topology = hierarchy_.Topology(level);
  const int vertices = hierarchy_.VertexCount(level);
  std::vector<char> active_vertex(vertices, 0);
  const geometry::Faces& F = hierarchy_.LevelFaces(level);
  for (int f = 0; f < faces; ++f)
    if (active_faces[f])
      for (int k = 0; k < 3; ++k) active_vertex[F(f, k)] = 1;
  const double inverse_h = 1.0 / h;
  for (int t = w0; t <= w1; ++t) {
    double* e = states.at(t).increments.data();
    for (int v = 0; v < vertices; ++v) {
      if (!active_vertex[v]) continue;
      auto B = [&](int frame, int u) { return Eigen::MatrixXd(states.at(frame).basis[u].leftCols(dof)); };
      if (options_.membrane_weight > 0 && topology.Ring(v).size() > 0) {
        const double w = options_.membrane_weight * inverse_h;
        std::vector<Eigen::MatrixXd> A{w * B(t, v)};
        std::vector<double*> blocks{e + static_cast<std::ptrdiff_t>(v) * dof};
        const double share = w / topology.Ring(v).size();
        for (int u : topology.Ring(v)) {
          A.push_back(-share * B(t, u));
          blocks.push_back(e + static_cast<std::ptrdiff_t>(u) * dof);
        }
        problem.AddResidualBlock(new LinearResidualCost(std::move(A)), nullptr, blocks);
      }
      if (options_.temporal_smoothness > 0 && t > 0 && t + 1 < frames) {
        // Second difference over time: above level 0, of the detail in its local frame
        // (n, r, q), which a rigid motion leaves unchanged, so only non-rigid
        // acceleration is penalized (neighbouring frames outside the window count with
        // their current values). At level 0, of the increments only: the base control
        // points' world trajectories accelerate with the rigid motion itself (a rotating
        // or swinging object), which a smoothness term would fight. Measured with 2-frame
        // overlaps: on synth rigid, the world-trajectory term gave accuracy P90 0.94 mm
        // against 0.80 mm with this one (end-point error 0.101 against 0.107 mm); on blob
        // frames 0–11 it gave 0.540 against 0.510 mm (end-point error 0.053 against 0.058).
        const double w = options_.temporal_smoothness * inverse_h;
        std::vector<Eigen::MatrixXd> A;
        Eigen::VectorXd offset;
        if (level == 0) {
          A = {w * B(t - 1, v), -2.0 * w * B(t, v), w * B(t + 1, v)};
        } else {
          const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(dof, dof);
          A = {w * I, -2.0 * w * I, w * I};
          const auto detail = [&](int frame) {
            return trajectory_[frame].Detail(level).row(v).leftCols(dof).transpose();
          };
          offset = w * (detail(t - 1) - 2.0 * detail(t) + detail(t + 1));
        }
        std::vector<double*> blocks;
        for (int frame : {t - 1, t, t + 1})
          blocks.push_back(states.at(frame).increments.data() + static_cast<std::ptrdiff_t>(v) * dof);
        problem.AddResidualBlock(new LinearResidualCost(std::move(A), std::move(offset)), nullptr, blocks);
      }
      if (options_.damping > 0) {
        std::vector<Eigen::MatrixXd> A{Eigen::MatrixXd::Identity(dof, dof) * (options_.damping * inverse_h)};
        problem.AddResidualBlock(new LinearResidualCost(std::move(A)), nullptr,
                                 {e + static_cast<std::ptrdiff_t>(v) * dof});
      }
    }
  }

  // Constant context frames and inactive vertices; bounds on the free increments.
  for (auto& [frame, state] : states) {
    for (int v = 0; v < vertices; ++v) {
      double* block = state.increments.data() + static_cast<std::ptrdiff_t>(v) * dof;
      if (!problem.HasParameterBlock(block)) continue;
      if (frame < w0 || frame > w1 || !active_vertex[v]) {
        problem.SetParameterBlockConstant(block);
        continue;
      }
      const double limit = options_.max_step * h;
      double lo = -limit, hi = limit;
      if (dof == 1) {
        const auto [slab_lo, slab_hi] =
            SlabRange(state.level_control.row(v).transpose(), state.basis[v].col(0), bounds_);
        lo = std::max(lo, slab_lo);
        hi = std::min(hi, slab_hi);
      }
      for (int d = 0; d < dof; ++d) {
        problem.SetParameterLowerBound(block, d, dof == 1 ? lo : -limit);
        problem.SetParameterUpperBound(block, d, dof == 1 ? hi : limit);
      }
      ++report->parameters;
    }
  }
  report->parameters *= dof;
  report->residual_blocks += problem.NumResidualBlocks();

  auto evaluate = [&](const std::vector<ResidualRecord>& records, bool ncc,
                      std::vector<double>* sum, std::vector<int>* count) {
    sum->assign(frames, 0.0);
    count->assign(frames, 0);
    Eigen::VectorXd r;
    for (const ResidualRecord& record : records) {
      double cost = 0.0;
      r.resize(problem.GetCostFunctionForResidualBlock(record.id)->num_residuals());
      problem.EvaluateResidualBlock(record.id, false, &cost, r.data(), nullptr);
      if (ncc) {  // per pair: NCC ≈ 1 − ‖r_pair‖² / (2 W) (exact for ε = 0)
        int offset = 0;
        for (const CorrelationPair& pair : record.correlation->pairs()) {
          const int n = static_cast<int>(pair.rows.size());
          if (pair.weight > 0) {
            (*sum)[record.frame] += 1.0 - r.segment(offset, n).squaredNorm() / (2.0 * pair.weight);
            ++(*count)[record.frame];
          }
          offset += n;
        }
        continue;
      }
      (*sum)[record.frame] += std::pow(std::max(0.0, r(0)) / options_.silhouette_weight, 2);
      ++(*count)[record.frame];
    }
  };
  std::vector<double> ncc_before, silhouette_before, ncc_after, silhouette_after;
  std::vector<int> ncc_count, silhouette_count;
  evaluate(stereo, true, &ncc_before, &ncc_count);
  evaluate(silhouette, false, &silhouette_before, &silhouette_count);

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ParseLinearSolver(options_.linear_solver);
  solver_options.max_num_iterations = options_.max_iterations;
  solver_options.num_threads = options_.threads > 0 ? options_.threads
                                                    : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  solver_options.minimizer_progress_to_stdout = false;
  solver_options.logging_type = ceres::SILENT;
  solver_options.function_tolerance = 1e-4;
  ceres::Solver::Summary summary;
  if (problem.NumParameterBlocks() > 0 && problem.NumResidualBlocks() > 0) {
    const Stopwatch solve_start;
    ceres::Solve(solver_options, &problem, &summary);
    report->solver_seconds += solve_start.Seconds();
    report->iterations += static_cast<int>(summary.iterations.size());
    spdlog::debug("refinement level {} frames {}–{}: {}; jacobians {:.2f} s, residuals {:.2f} s, "
                  "linear solver {:.2f} s", level, w0, w1, summary.BriefReport(),
                  summary.jacobian_evaluation_time_in_seconds, summary.residual_evaluation_time_in_seconds,
                  summary.linear_solver_time_in_seconds);
  }
  evaluate(stereo, true, &ncc_after, &ncc_count);
  evaluate(silhouette, false, &silhouette_after, &silhouette_count);

  // Apply the increments: details (or base control points) of the window's frames, then
  // re-synthesize their finest control points.
  const int finest = hierarchy_.finest_level();
  for (int t = w0; t <= w1; ++t) {
    FrameState& state = states.at(t);
    geometry::MultiresShape& shape = trajectory_[t];
    Positions& target = level == 0 ? shape.base() : shape.Detail(level);
    for (int v = 0; v < vertices; ++v) {
      const double* e = state.increments.data() + static_cast<std::ptrdiff_t>(v) * dof;
      Eigen::Vector3d world = Eigen::Vector3d::Zero();
      for (int d = 0; d < dof; ++d) world += e[d] * state.basis[v].col(d);
      (*moved)[v] = std::max((*moved)[v], world.norm());
      if (level == 0) {
        target.row(v) += world.transpose();
      } else {
        for (int d = 0; d < dof; ++d) target(v, d) += e[d];  // local (n, r, q) components
      }
    }
    control_[t] = shape.Synthesize(hierarchy_, finest);

    RefinementFrameReport& frame_report = result_.frames[t];
    if (frame_report.stereo_pairs == 0 && ncc_count[t] > 0) {  // first time this frame is refined
      frame_report.ncc_before = ncc_before[t] / ncc_count[t];
      frame_report.silhouette_rms_before =
          silhouette_count[t] ? std::sqrt(silhouette_before[t] / silhouette_count[t]) : 0.0;
    }
    if (ncc_count[t] > 0) {
      frame_report.stereo_pairs = ncc_count[t];
      frame_report.ncc_after = ncc_after[t] / ncc_count[t];
      frame_report.silhouette_rms_after =
          silhouette_count[t] ? std::sqrt(silhouette_after[t] / silhouette_count[t]) : 0.0;
    }
  }
}

// The finest level whose faces' median largest projected area (over the cameras facing
// them) is at least `min_area` pixels²; level 0 when none is. Areas shrink 4× per level.
int AutomaticFinestLevel(const LoopHierarchy& hierarchy, const Positions& finest_control,
                         const std::vector<vision::Camera>& cameras, double min_area) {
  const Positions base = geometry::MultiresShape::Analyze(hierarchy, finest_control).base();
  const Positions corners = hierarchy.LimitPositions(0) * base;
  const geometry::Faces& F = hierarchy.LevelFaces(0);
  std::vector<double> areas;
  for (Eigen::Index f = 0; f < F.rows(); ++f) {
    const Eigen::Vector3d X0 = corners.row(F(f, 0)), X1 = corners.row(F(f, 1)), X2 = corners.row(F(f, 2));
    const Eigen::Vector3d normal = (X1 - X0).cross(X2 - X0);
    double largest = 0.0;
    for (const vision::Camera& camera : cameras) {
      if (normal.dot(camera.Center() - (X0 + X1 + X2) / 3.0) <= 0.0) continue;
      const Eigen::Vector2d a = camera.ProjectUndistorted(X1) - camera.ProjectUndistorted(X0);
      const Eigen::Vector2d b = camera.ProjectUndistorted(X2) - camera.ProjectUndistorted(X0);
      largest = std::max(largest, 0.5 * std::abs(a.x() * b.y() - a.y() * b.x()));
    }
    if (largest > 0.0) areas.push_back(largest);
  }
  if (areas.empty()) return 0;
  std::nth_element(areas.begin(), areas.begin() + areas.size() / 2, areas.end());
  double area = areas[areas.size() / 2];
  int level = 0;
  while (level < hierarchy.finest_level() && area / 4.0 >= min_area) {
    area /= 4.0;
    ++level;
  }
  return level;
}

}  // namespace

void StereoRefinementOptions::Check() const {
  auto require = [](bool ok, const char* field, const char* expected) {
    if (!ok) ThrowError("stereo refinement options", field, expected);
  };
  require(coarsest_level >= 0, "coarsest_level", "must be ≥ 0");
  require(normal_only_from_level >= 0, "normal_only_from_level", "must be ≥ 0");
  require(window >= 1, "window", "must be ≥ 1");
  require(window_overlap >= 0, "window_overlap", "must be ≥ 0");
  require(rounds >= 1, "rounds", "must be ≥ 1");
  require(max_iterations >= 1, "max_iterations", "must be ≥ 1");
  require(threads >= 0, "threads", "must be ≥ 0");
  require(samples_per_pixel > 0, "samples_per_pixel", "must be > 0");
  require(min_density >= 1 && max_density >= min_density, "min_density/max_density",
          "must satisfy 1 ≤ min_density ≤ max_density");
  require(max_cameras >= 2, "max_cameras", "must be ≥ 2 (a stereo pair)");
  require(min_samples >= 3, "min_samples", "must be ≥ 3");
  require(image_sigma >= 0, "image_sigma", "must be ≥ 0");
  require(ncc_epsilon >= 0, "ncc_epsilon", "must be ≥ 0");
  require(ncc_loss_scale >= 0, "ncc_loss_scale", "must be ≥ 0");
  require(temporal_weight >= 0 && silhouette_weight >= 0 && membrane_weight >= 0 &&
              temporal_smoothness >= 0 && damping >= 0,
          "weights", "must be ≥ 0");
  require(min_patch_area > 0, "min_patch_area", "must be > 0 (pixels²)");
  require(angle_weight_power >= 0, "angle_weight_power", "must be ≥ 0");
  require(outline_margin >= 0, "outline_margin", "must be ≥ 0 (pixels)");
  require(max_step > 0, "max_step", "must be > 0");
  require(adaptive_threshold >= 0, "adaptive_threshold", "must be ≥ 0");
  ParseLinearSolver(linear_solver);
  visibility.Check();
}

RefinementResult RefineStereo(const std::vector<vision::Camera>& cameras,
                              const RefinementImageLoader& gray,
                              const RefinementImageLoader& silhouettes,
                              const LoopHierarchy& hierarchy, const std::vector<Positions>& control,
                              const vision::Bounds& bounds, const StereoRefinementOptions& options,
                              Progress* progress) {
  const Stopwatch start;
  options.Check();
  if (cameras.size() < 2) ThrowError("stereo refinement", "cameras", "needs at least 2 cameras");
  if (control.empty()) ThrowError("stereo refinement", "control", "needs at least one frame");
  for (std::size_t f = 0; f < control.size(); ++f)
    if (control[f].rows() != hierarchy.VertexCount(hierarchy.finest_level()) || !control[f].allFinite())
      ThrowError("stereo refinement", "control[" + std::to_string(f) + "]",
                 "must have #V(finest) = " + std::to_string(hierarchy.VertexCount(hierarchy.finest_level())) +
                     " finite rows");
  const int finest_refined =
      options.finest_level >= 0
          ? options.finest_level
          : AutomaticFinestLevel(hierarchy, control[control.size() / 2], cameras, options.min_patch_area);
  if (finest_refined > hierarchy.finest_level() || options.coarsest_level > finest_refined)
    ThrowError("stereo refinement options", "coarsest_level/finest_level",
               "must satisfy coarsest ≤ finest ≤ " + std::to_string(hierarchy.finest_level()));

  RefinementResult result;
  result.control = control;
  result.linear_solver = options.linear_solver;
  result.frames.resize(control.size());
  for (std::size_t f = 0; f < control.size(); ++f) result.frames[f].frame = static_cast<int>(f);
  geometry::Trajectory trajectory = geometry::AnalyzeTrajectory(hierarchy, control);
  FrameImages images(gray, silhouettes, static_cast<int>(cameras.size()), options.image_sigma);

  const int frames = static_cast<int>(control.size());
  const std::size_t windows = Windows(frames, options.window, options.window_overlap).size();
  ProgressBegin(progress, "refinement",
                static_cast<std::size_t>(finest_refined - options.coarsest_level + 1) * options.rounds * windows);
  std::size_t done = 0;
  LevelRefiner refiner(cameras, hierarchy, bounds, options, images, trajectory, result.control, result);
  std::vector<char> active(hierarchy.FaceCount(options.coarsest_level), 1);
  for (int level = options.coarsest_level; level <= finest_refined; ++level) {
    std::vector<char> moved;
    refiner.Run(level, active, &moved, progress, &done);
    if (level == finest_refined) break;
    // Adaptivity: a child face is refined when its parent was and one of the parent's
    // corners moved by more than the threshold at this level.
    const geometry::Faces& F = hierarchy.LevelFaces(level);
    std::vector<char> next(hierarchy.FaceCount(level + 1), 0);
    for (int f = 0; f < hierarchy.FaceCount(level); ++f) {
      const bool refine = active[f] && (moved[F(f, 0)] || moved[F(f, 1)] || moved[F(f, 2)]);
      for (int k = 0; k < 4; ++k) next[LoopHierarchy::ChildFace(f, k)] = refine ? 1 : 0;
    }
    active = std::move(next);
  }
  ProgressEnd(progress);
  result.seconds = start.Seconds();
  return result;
}

}  // namespace subflow::solver
