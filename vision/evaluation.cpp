// The metrics of vision/evaluation.h on meshes in memory.
#include "vision/evaluation.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/vertex_normals.h"

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

// Distances from the samples of one surface to the other surface (its tree).
std::vector<double> SampleDistances(const TriangleMesh& from, const ClosestPointTree& to, int samples) {
  return ToVector(to.Distances(SampleSurface(from, samples)));
}

// The motion of each result vertex's closest true material point from frame f to f + 1,
// and the unit normal of the true face that point lies on (`truth_face_normals`: of frame f).
Positions TrueMotion(const Positions& result_vertices, const ClosestPointTree& truth_tree,
                     const Positions& truth_face_normals, const TriangleMesh& truth_next,
                     Positions* truth_normals) {
  const std::vector<geometry::SurfacePoint> closest = truth_tree.ClosestPoints(result_vertices);
  Positions motion(result_vertices.rows(), 3);
  truth_normals->resize(result_vertices.rows(), 3);
  for (Eigen::Index i = 0; i < result_vertices.rows(); ++i) {
    const Eigen::Vector3d next =
        geometry::FacePoint(truth_next.V, truth_next.F, closest[i].face, closest[i].barycentric);
    motion.row(i) = (next - closest[i].point).transpose();
    truth_normals->row(i) = truth_face_normals.row(closest[i].face);
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

EvaluationReport EvaluateSequence(int frame_count,
                                  const std::function<TriangleMesh(int)>& load_truth,
                                  const std::function<EvaluationFrame(int)>& load_result,
                                  const EvaluationOptions& options, Progress* progress,
                                  const std::string& truth_source, const std::string& result_source) {
  options.Check();
  if (frame_count < 1) ThrowError(truth_source, "frames", "expected at least one frame");
  EvaluationReport report;
  report.samples = options.samples;
  report.accuracy_percentile = options.accuracy_percentile;

  TriangleMesh truth = load_truth(0);
  EvaluationFrame result = load_result(0);
  const TriangleMesh truth_first = truth;
  const TriangleMesh result_first = result.mesh;
  const bool has_motion = result.motion.has_value();
  report.flow_source = has_motion ? "vx vy vz" : "vertex differences";
  if (options.threshold > 0.0) {
    report.threshold = options.threshold;
  } else {
    report.threshold = 0.01 * (truth.V.colwise().maxCoeff() - truth.V.colwise().minCoeff()).norm();
  }

  std::vector<double> pooled_accuracy, pooled_epe;
  double completeness_sum = 0.0, chamfer_sum = 0.0, hausdorff = 0.0, motion_sum = 0.0;
  double normal_error_sum = 0.0, tangential_error_sum = 0.0;
  ProgressBegin(progress, "eval", static_cast<std::size_t>(frame_count));
  for (int f = 0; f < frame_count; ++f) {
    FrameScores scores;
    scores.frame = f;
    const ClosestPointTree truth_tree(truth, truth_source + ": frame " + std::to_string(f));
    const ClosestPointTree result_tree(result.mesh, result_source + ": frame " + std::to_string(f));
    std::vector<double> to_truth = SampleDistances(result.mesh, truth_tree, options.samples);
    std::vector<double> to_result = SampleDistances(truth, result_tree, options.samples);
    SurfaceScores& s = scores.surface;
    s.mean_result_to_truth = Mean(to_truth);
    s.mean_truth_to_result = Mean(to_result);
    s.chamfer = 0.5 * (s.mean_result_to_truth + s.mean_truth_to_result);
    s.hausdorff = std::max(*std::max_element(to_truth.begin(), to_truth.end()),
                           *std::max_element(to_result.begin(), to_result.end()));
    s.completeness = static_cast<double>(std::count_if(to_result.begin(), to_result.end(),
                                                       [&](double d) { return d <= report.threshold; })) /
                     static_cast<double>(to_result.size());
    pooled_accuracy.insert(pooled_accuracy.end(), to_truth.begin(), to_truth.end());
    s.accuracy = Percentile(to_truth, options.accuracy_percentile);
    completeness_sum += s.completeness;
    chamfer_sum += s.chamfer;
    hausdorff = std::max(hausdorff, s.hausdorff);

    if (f + 1 < frame_count) {
      TriangleMesh truth_next = load_truth(f + 1);
      EvaluationFrame result_next = load_result(f + 1);
      CheckSameTopology(truth_first, truth_next, truth_source, f + 1);
      CheckSameTopology(result_first, result_next.mesh, result_source, f + 1);
      if (result_next.motion.has_value() != has_motion)
        ThrowError(result_source + ": frame " + std::to_string(f + 1), "vx vy vz",
                   has_motion ? "missing, but present at frame 0" : "present, but missing at frame 0");
      const Positions recovered = has_motion ? *result.motion : Positions(result_next.mesh.V - result.mesh.V);
      SUBFLOW_CHECK(recovered.rows() == result.mesh.V.rows(), "one motion vector per vertex");
      Positions truth_normals;
      const Positions true_motion = TrueMotion(result.mesh.V, truth_tree, geometry::FaceNormals(truth.V, truth.F),
                                               truth_next, &truth_normals);
      std::vector<double> epe(static_cast<std::size_t>(true_motion.rows()));
      double frame_motion_sum = 0.0, frame_normal_sum = 0.0, frame_tangential_sum = 0.0;
      for (Eigen::Index i = 0; i < true_motion.rows(); ++i) {
        const Eigen::RowVector3d error = recovered.row(i) - true_motion.row(i);
        const double along_normal = error.dot(truth_normals.row(i));
        epe[i] = error.norm();
        frame_motion_sum += true_motion.row(i).norm();
        frame_normal_sum += std::abs(along_normal);
        frame_tangential_sum += (error - along_normal * truth_normals.row(i)).norm();
      }
      FlowScores& flow = scores.flow;
      flow.evaluated = true;
      flow.epe_mean = Mean(epe);
      flow.epe_normal_mean = frame_normal_sum / static_cast<double>(epe.size());
      flow.epe_tangential_mean = frame_tangential_sum / static_cast<double>(epe.size());
      normal_error_sum += frame_normal_sum;
      tangential_error_sum += frame_tangential_sum;
      flow.true_motion_mean = frame_motion_sum / static_cast<double>(epe.size());
      flow.epe_relative = flow.true_motion_mean > 0.0 ? flow.epe_mean / flow.true_motion_mean : 0.0;
      motion_sum += frame_motion_sum;
      pooled_epe.insert(pooled_epe.end(), epe.begin(), epe.end());
      flow.epe_median = Percentile(epe, 50.0);
      truth = std::move(truth_next);
      result = std::move(result_next);
    }
    report.frames.push_back(scores);
    ProgressUpdate(progress, static_cast<std::size_t>(f + 1));
  }
  ProgressEnd(progress);

  FrameScores& overall = report.overall;
  overall.frame = -1;
  overall.surface.accuracy = Percentile(pooled_accuracy, options.accuracy_percentile);
  overall.surface.completeness = completeness_sum / frame_count;
  overall.surface.chamfer = chamfer_sum / frame_count;
  overall.surface.hausdorff = hausdorff;
  double to_truth_sum = 0.0, to_result_sum = 0.0;
  for (const FrameScores& frame : report.frames) {
    to_truth_sum += frame.surface.mean_result_to_truth;
    to_result_sum += frame.surface.mean_truth_to_result;
  }
  overall.surface.mean_result_to_truth = to_truth_sum / frame_count;
  overall.surface.mean_truth_to_result = to_result_sum / frame_count;
  if (!pooled_epe.empty()) {
    overall.flow.evaluated = true;
    overall.flow.epe_mean = Mean(pooled_epe);
    overall.flow.true_motion_mean = motion_sum / static_cast<double>(pooled_epe.size());
    overall.flow.epe_relative =
        overall.flow.true_motion_mean > 0.0 ? overall.flow.epe_mean / overall.flow.true_motion_mean : 0.0;
    overall.flow.epe_median = Percentile(pooled_epe, 50.0);
    overall.flow.epe_normal_mean = normal_error_sum / static_cast<double>(pooled_epe.size());
    overall.flow.epe_tangential_mean = tangential_error_sum / static_cast<double>(pooled_epe.size());
  }
  return report;
}

}  // namespace subflow::vision
