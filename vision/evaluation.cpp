// The metrics of vision/evaluation.h on meshes in memory.
#include "vision/evaluation.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <optional>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/vertex_normals.h"
#include "vision/evaluation_visibility.h"

namespace subflow::vision {
namespace {

using geometry::ClosestPointTree;
using geometry::Positions;
using geometry::TriangleMesh;

// The p-th percentile (0 < p ≤ 100) by the nearest-rank method: the smallest value with
// at least p % of the values at or below it. Reorders `values`.
double Percentile(std::vector<double>& values, double p) {
  if (values.empty()) return 0.0;
  const std::size_t rank =
      static_cast<std::size_t>(std::ceil(p / 100.0 * static_cast<double>(values.size())));
  const std::size_t index = std::clamp<std::size_t>(rank, 1, values.size()) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(index), values.end());
  return values[index];
}

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

std::vector<double> ToVector(const Eigen::VectorXd& v) { return {v.data(), v.data() + v.size()}; }

// The motion of each result vertex's closest true material point from frame f to f + 1,
// and the unit normal of the true face that point lies on (`truth_face_normals`: of frame f).
Positions TrueMotion(const Positions& result_vertices, const ClosestPointTree& truth_tree,
                     const Positions& truth_face_normals, const TriangleMesh& truth_next,
                     Positions* truth_normals, Positions* closest_points) {
  const std::vector<geometry::SurfacePoint> closest = truth_tree.ClosestPoints(result_vertices);
  Positions motion(result_vertices.rows(), 3);
  truth_normals->resize(result_vertices.rows(), 3);
  closest_points->resize(result_vertices.rows(), 3);
  for (Eigen::Index i = 0; i < result_vertices.rows(); ++i) {
    const Eigen::Vector3d next =
        geometry::FacePoint(truth_next.V, truth_next.F, closest[i].face, closest[i].barycentric);
    motion.row(i) = (next - closest[i].point).transpose();
    truth_normals->row(i) = truth_face_normals.row(closest[i].face);
    closest_points->row(i) = closest[i].point.transpose();
  }
  return motion;
}

void CheckSameTopology(const TriangleMesh& first, const TriangleMesh& mesh, const std::string& source,
                       int frame) {
  const std::string where = source + ": frame " + std::to_string(frame);
  if (mesh.vertex_count() != first.vertex_count())
    ThrowError(where, "vertex count",
               std::to_string(mesh.vertex_count()) + " vertices, expected " +
                   std::to_string(first.vertex_count()) +
                   " as at frame 0 (every frame must have the same vertices in the same order)");
  if (mesh.F.rows() != first.F.rows() || mesh.F != first.F)
    ThrowError(where, "faces", "differ from frame 0 (every frame must have the same faces)");
}

}  // namespace

void EvaluationOptions::Check() const {
  if (!std::isfinite(threshold) || threshold < 0.0)
    ThrowError("eval", "threshold", "expected a finite distance ≥ 0 (0 = 1 % of the true bbox diagonal)");
  if (samples < 100 || samples > 100000000)
    ThrowError("eval", "samples", "expected 100..1e8, got " + std::to_string(samples));
  if (!(accuracy_percentile > 0.0 && accuracy_percentile <= 100.0))
    ThrowError("eval", "accuracy_percentile", "expected a value in (0, 100]");
  if (min_views < 1 || min_views > 1000) ThrowError("eval", "min-views", "expected 1..1000, got " + std::to_string(min_views));
  if (!std::isfinite(visibility_tolerance) || visibility_tolerance < 0.0)
    ThrowError("eval", "visibility-tolerance", "expected a finite distance ≥ 0 (0 = automatic)");
}

Positions SampleSurface(const TriangleMesh& mesh, int count) {
  const Eigen::VectorXd areas = geometry::FaceAreas(mesh.V, mesh.F);
  const double total = areas.sum();
  SUBFLOW_CHECK(count > 0 && total > 0.0, "SampleSurface needs a surface of positive area");
  // R2 sequence (Roberts 2018): the plastic-number Kronecker sequence in the unit square.
  const double alpha1 = 0.7548776662466927, alpha2 = 0.5698402909980532;
  Positions samples(count, 3);
  double cumulative = 0.0;
  long long emitted = 0;
  for (Eigen::Index f = 0; f < mesh.F.rows() && emitted < count; ++f) {
    cumulative += areas[f] / total * count;
    const long long target = std::min<long long>(count, static_cast<long long>(std::floor(cumulative + 1e-9)));
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0));
    const Eigen::Vector3d ab = mesh.V.row(mesh.F(f, 1)).transpose() - a;
    const Eigen::Vector3d ac = mesh.V.row(mesh.F(f, 2)).transpose() - a;
    for (; emitted < target; ++emitted) {
      double r1 = std::fmod(0.5 + alpha1 * static_cast<double>(emitted), 1.0);
      double r2 = std::fmod(0.5 + alpha2 * static_cast<double>(emitted), 1.0);
      if (r1 + r2 > 1.0) {
        r1 = 1.0 - r1;
        r2 = 1.0 - r2;
      }
      samples.row(emitted) = (a + r1 * ab + r2 * ac).transpose();
    }
  }
  // Rounding can leave the last few samples unassigned: put them at face centroids of the
  // largest faces (never happens beyond 1 sample with the 1e-9 guard).
  for (Eigen::Index f = 0; emitted < count; ++emitted, f = (f + 1) % mesh.F.rows()) {
    samples.row(emitted) =
        (mesh.V.row(mesh.F(f, 0)) + mesh.V.row(mesh.F(f, 1)) + mesh.V.row(mesh.F(f, 2))) / 3.0;
  }
  return samples;
}

namespace {

// Selects the values whose flag is set (all of them when `keep` is null).
std::vector<double> Kept(const std::vector<double>& values, const std::vector<std::uint8_t>* keep) {
  if (keep == nullptr) return values;
  std::vector<double> kept;
  for (std::size_t i = 0; i < values.size(); ++i)
    if ((*keep)[i]) kept.push_back(values[i]);
  return kept;
}

double MaxOf(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

// Surface figures of one frame from the distances result → truth and truth → result.
SurfaceScores SummarizeSurface(std::vector<double> to_truth, const std::vector<double>& to_result,
                               double threshold, double percentile) {
  SurfaceScores s;
  s.mean_result_to_truth = Mean(to_truth);
  s.mean_truth_to_result = Mean(to_result);
  s.chamfer = 0.5 * (s.mean_result_to_truth + s.mean_truth_to_result);
  s.hausdorff = std::max(MaxOf(to_truth), MaxOf(to_result));
  if (!to_result.empty())
    s.completeness = static_cast<double>(std::count_if(to_result.begin(), to_result.end(),
                                                       [&](double d) { return d <= threshold; })) /
                     static_cast<double>(to_result.size());
  s.accuracy = Percentile(to_truth, percentile);
  return s;
}

// Per-vertex flow terms of one or more frames, and their summary.
struct FlowTerms {
  std::vector<double> epe, motion, normal, tangential;
  void Append(const FlowTerms& other, const std::vector<std::uint8_t>* keep) {
    for (std::size_t i = 0; i < other.epe.size(); ++i) {
      if (keep && !(*keep)[i]) continue;
      epe.push_back(other.epe[i]);
      motion.push_back(other.motion[i]);
      normal.push_back(other.normal[i]);
      tangential.push_back(other.tangential[i]);
    }
  }
  FlowScores Summary() const {
    FlowScores flow;
    if (epe.empty()) return flow;
    flow.evaluated = true;
    flow.epe_mean = Mean(epe);
    flow.true_motion_mean = Mean(motion);
    flow.epe_relative = flow.true_motion_mean > 0.0 ? flow.epe_mean / flow.true_motion_mean : 0.0;
    flow.epe_normal_mean = Mean(normal);
    flow.epe_tangential_mean = Mean(tangential);
    std::vector<double> copy = epe;
    flow.epe_median = Percentile(copy, 50.0);
    return flow;
  }
};

FlowTerms ComputeFlowTerms(const Positions& recovered, const Positions& true_motion, const Positions& truth_normals) {
  FlowTerms terms;
  for (Eigen::Index i = 0; i < true_motion.rows(); ++i) {
    const Eigen::RowVector3d error = recovered.row(i) - true_motion.row(i);
    const double along_normal = error.dot(truth_normals.row(i));
    terms.epe.push_back(error.norm());
    terms.motion.push_back(true_motion.row(i).norm());
    terms.normal.push_back(std::abs(along_normal));
    terms.tangential.push_back((error - along_normal * truth_normals.row(i)).norm());
  }
  return terms;
}

std::vector<std::uint8_t> Observed(const std::vector<int>& view_counts, int min_views) {
  std::vector<std::uint8_t> observed(view_counts.size());
  for (std::size_t i = 0; i < view_counts.size(); ++i) observed[i] = view_counts[i] >= min_views ? 1 : 0;
  return observed;
}

Positions PointsOf(const std::vector<geometry::SurfacePoint>& points) {
  Positions P(static_cast<Eigen::Index>(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i) P.row(static_cast<Eigen::Index>(i)) = points[i].point.transpose();
  return P;
}

// What is pooled over the frames, for the whole and for the observed surface.
struct Pool {
  std::vector<double> accuracy;
  FlowTerms flow;
  double completeness_sum = 0.0, chamfer_sum = 0.0, hausdorff = 0.0;
  double to_truth_sum = 0.0, to_result_sum = 0.0;
  double observed_fraction_sum = 0.0, footprint_sum = 0.0;
  std::size_t footprint_count = 0;

  void Add(const SurfaceScores& s) {
    completeness_sum += s.completeness;
    chamfer_sum += s.chamfer;
    hausdorff = std::max(hausdorff, s.hausdorff);
    to_truth_sum += s.mean_result_to_truth;
    to_result_sum += s.mean_truth_to_result;
  }
  SurfaceScores Surface(int frame_count, double percentile) {
    SurfaceScores s;
    s.accuracy = Percentile(accuracy, percentile);
    s.completeness = completeness_sum / frame_count;
    s.chamfer = chamfer_sum / frame_count;
    s.hausdorff = hausdorff;
    s.mean_result_to_truth = to_truth_sum / frame_count;
    s.mean_truth_to_result = to_result_sum / frame_count;
    return s;
  }
};

}  // namespace

EvaluationReport EvaluateSequence(int frame_count,
                                  const std::function<TriangleMesh(int)>& load_truth,
                                  const std::function<EvaluationFrame(int)>& load_result,
                                  const EvaluationOptions& options, Progress* progress,
                                  const std::string& truth_source, const std::string& result_source,
                                  const std::vector<Camera>& cameras) {
  options.Check();
  if (frame_count < 1) ThrowError(truth_source, "frames", "expected at least one frame");
  EvaluationReport report;
  report.samples = options.samples;
  report.accuracy_percentile = options.accuracy_percentile;
  report.camera_count = static_cast<int>(cameras.size());
  report.min_views = options.min_views;

  TriangleMesh truth = load_truth(0);
  EvaluationFrame result = load_result(0);
  const TriangleMesh truth_first = truth;
  const TriangleMesh result_first = result.mesh;
  const bool has_motion = result.motion.has_value();
  report.flow_source = !options.score_flow ? "none" : has_motion ? "vx vy vz" : "vertex differences";
  const double diagonal = (truth.V.colwise().maxCoeff() - truth.V.colwise().minCoeff()).norm();
  report.threshold = options.threshold > 0.0 ? options.threshold : 0.01 * diagonal;
  report.visibility_tolerance = options.visibility_tolerance > 0.0 ? options.visibility_tolerance : 0.0025 * diagonal;
  const bool observe = !cameras.empty();
  const double p = options.accuracy_percentile;

  Pool whole, seen;
  ProgressBegin(progress, "eval", static_cast<std::size_t>(frame_count));
  for (int f = 0; f < frame_count; ++f) {
    FrameScores scores;
    scores.frame = f;
    const ClosestPointTree truth_tree(truth, truth_source + ": frame " + std::to_string(f));
    const ClosestPointTree result_tree(result.mesh, result_source + ": frame " + std::to_string(f));
    const Positions result_samples = SampleSurface(result.mesh, options.samples);
    const Positions truth_samples = SampleSurface(truth, options.samples);
    const std::vector<geometry::SurfacePoint> nearest_truth = truth_tree.ClosestPoints(result_samples);
    std::vector<double> to_truth(nearest_truth.size());
    for (std::size_t i = 0; i < nearest_truth.size(); ++i) to_truth[i] = nearest_truth[i].distance;
    const std::vector<double> to_result = ToVector(result_tree.Distances(truth_samples));
    scores.surface = SummarizeSurface(to_truth, to_result, report.threshold, p);
    whole.Add(scores.surface);
    whole.accuracy.insert(whole.accuracy.end(), to_truth.begin(), to_truth.end());

    std::optional<SurfaceVisibility> visibility;
    std::vector<std::uint8_t> result_seen, truth_seen;
    if (observe) {
      visibility.emplace(cameras, truth, report.visibility_tolerance);
      std::vector<double> footprints;
      truth_seen = Observed(visibility->ViewCounts(truth_samples, &footprints), options.min_views);
      result_seen = Observed(visibility->ViewCounts(PointsOf(nearest_truth)), options.min_views);
      const std::vector<double> seen_to_truth = Kept(to_truth, &result_seen);
      ObservedScores& o = scores.observed;
      o.evaluated = true;
      o.surface = SummarizeSurface(seen_to_truth, Kept(to_result, &truth_seen), report.threshold, p);
      const std::vector<double> seen_footprints = Kept(footprints, &truth_seen);
      o.observed_fraction = static_cast<double>(seen_footprints.size()) / static_cast<double>(truth_seen.size());
      o.pixel_footprint = Mean(seen_footprints);
      o.accuracy_px = o.pixel_footprint > 0.0 ? o.surface.accuracy / o.pixel_footprint : 0.0;
      seen.Add(o.surface);
      seen.accuracy.insert(seen.accuracy.end(), seen_to_truth.begin(), seen_to_truth.end());
      seen.observed_fraction_sum += o.observed_fraction;
      for (double footprint : seen_footprints) seen.footprint_sum += footprint;
      seen.footprint_count += seen_footprints.size();
    }

    if (f + 1 < frame_count) {
      TriangleMesh truth_next = load_truth(f + 1);
      EvaluationFrame result_next = load_result(f + 1);
      if (options.score_flow) {
        CheckSameTopology(truth_first, truth_next, truth_source, f + 1);
        CheckSameTopology(result_first, result_next.mesh, result_source, f + 1);
        if (result_next.motion.has_value() != has_motion)
          ThrowError(result_source + ": frame " + std::to_string(f + 1), "vx vy vz",
                     has_motion ? "missing, but present at frame 0" : "present, but missing at frame 0");
        const Positions recovered = has_motion ? *result.motion : Positions(result_next.mesh.V - result.mesh.V);
        SUBFLOW_CHECK(recovered.rows() == result.mesh.V.rows(), "one motion vector per vertex");
        Positions truth_normals, closest_points;
        const Positions true_motion = TrueMotion(result.mesh.V, truth_tree, geometry::FaceNormals(truth.V, truth.F),
                                                 truth_next, &truth_normals, &closest_points);
        const FlowTerms terms = ComputeFlowTerms(recovered, true_motion, truth_normals);
        scores.flow = terms.Summary();
        whole.flow.Append(terms, nullptr);
        if (observe) {
          const std::vector<std::uint8_t> vertex_seen = Observed(visibility->ViewCounts(closest_points), options.min_views);
          FlowTerms seen_terms;
          seen_terms.Append(terms, &vertex_seen);
          scores.observed.flow = seen_terms.Summary();
          seen.flow.Append(seen_terms, nullptr);
        }
      }
      truth = std::move(truth_next);
      result = std::move(result_next);
    }
    report.frames.push_back(scores);
    ProgressUpdate(progress, static_cast<std::size_t>(f + 1));
  }
  ProgressEnd(progress);

  FrameScores& overall = report.overall;
  overall.frame = -1;
  overall.surface = whole.Surface(frame_count, p);
  overall.flow = whole.flow.Summary();
  if (observe) {
    ObservedScores& o = overall.observed;
    o.evaluated = true;
    o.surface = seen.Surface(frame_count, p);
    o.flow = seen.flow.Summary();
    o.observed_fraction = seen.observed_fraction_sum / frame_count;
    o.pixel_footprint = seen.footprint_count > 0 ? seen.footprint_sum / static_cast<double>(seen.footprint_count) : 0.0;
    o.accuracy_px = o.pixel_footprint > 0.0 ? o.surface.accuracy / o.pixel_footprint : 0.0;
  }
  return report;
}

}  // namespace subflow::vision
