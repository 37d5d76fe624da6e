// `subflow eval`: scores with known answers — truth against itself, an inflated copy,
// the true shapes without motion — and clear errors on malformed results.
#include "vision/evaluation.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "geometry/closest_point.h"
#include "core/error.h"
#include "geometry/mesh_io.h"
#include "geometry/vertex_normals.h"
#include "vision/camera_rig.h"
#include "vision/dataset.h"
#include "vision/dataset_writer.h"
#include "vision/synthetic_scene.h"
#include "tests/test_support.h"

namespace subflow::vision {
namespace {

namespace fs = std::filesystem;
using geometry::Positions;
using geometry::TriangleMesh;

SyntheticScene Blob(int frames = 3) {
  SyntheticSceneOptions options;
  options.scene = "blob";
  options.frame_count = frames;
  options.subdivisions = 4;  // 2562 vertices: fast, still curved like the real thing
  options.motion = 2.0;
  return MakeSyntheticScene(options);
}

EvaluationOptions SmallOptions() {
  EvaluationOptions options;
  options.samples = 20000;
  return options;
}

EvaluationReport Evaluate(const SyntheticScene& truth, const std::vector<Positions>& result,
                          const std::vector<Positions>* motion = nullptr) {
  return EvaluateSequence(
      truth.frame_count(), [&](int f) { return truth.Mesh(f); },
      [&](int f) {
        EvaluationFrame frame{{result[f], truth.F}, std::nullopt};
        if (motion) frame.motion = (*motion)[f];
        return frame;
      },
      SmallOptions());
}

TEST(Evaluation, GroundTruthAgainstItselfHasZeroError) {
  // Samples lie on the very triangles they are compared with: distances are rounding
  // (< 1e-12 m); every flow vector is the true one.
  const SyntheticScene truth = Blob();
  const EvaluationReport report = Evaluate(truth, truth.frames);
  ASSERT_EQ(report.frames.size(), 3u);
  EXPECT_EQ(report.flow_source, "vertex differences");
  for (const FrameScores& frame : report.frames) {
    EXPECT_LT(frame.surface.accuracy, 1e-12);
    EXPECT_LT(frame.surface.hausdorff, 1e-12);
    EXPECT_LT(frame.surface.chamfer, 1e-12);
    EXPECT_DOUBLE_EQ(frame.surface.completeness, 1.0);
  }
  EXPECT_FALSE(report.frames.back().flow.evaluated);
  ASSERT_TRUE(report.overall.flow.evaluated);
  EXPECT_LT(report.overall.flow.epe_mean, 1e-12);
  EXPECT_GT(report.overall.flow.true_motion_mean, 1e-3);  // the blob does move
}

TEST(Evaluation, AccuracyOfACopyInflatedAlongItsNormalsIsTheInflation) {
  // Each vertex moved by δ = 1 mm along its (area-weighted) normal. Were the surface
  // smooth, every point would lie exactly δ from the truth. On the mesh the offset
  // triangles tilt against the originals by the angle θ between vertex and face normals
  // (a few degrees at 2562 vertices on the blob): distances shrink by about δ(1 − cos θ)
  // ≈ 0.1 % δ, and curvature over one edge changes them by less than that again. So
  // accuracy and Chamfer are δ within 0.5 %, Hausdorff (a maximum, where a vertex's
  // offset is longest relative to the faces) within 1 %. (Measured: 0.9994 δ.)
  const double delta = 1e-3;
  const SyntheticScene truth = Blob();
  std::vector<Positions> inflated;
  for (const Positions& V : truth.frames) inflated.push_back(V + delta * geometry::VertexNormals(V, truth.F));
  const EvaluationReport report = Evaluate(truth, inflated);
  for (const FrameScores& frame : report.frames) {
    EXPECT_NEAR(frame.surface.accuracy, delta, 0.005 * delta);
    EXPECT_NEAR(frame.surface.chamfer, delta, 0.005 * delta);
    EXPECT_NEAR(frame.surface.hausdorff, delta, 0.01 * delta);
  }
  EXPECT_NEAR(report.overall.surface.accuracy, delta, 0.005 * delta);
  std::printf("inflated by %.4g: accuracy %.6g, chamfer %.6g, hausdorff %.6g\n", delta,
              report.overall.surface.accuracy, report.overall.surface.chamfer, report.overall.surface.hausdorff);
  // Completeness: the default threshold (1 % of a 0.2 m box diagonal ≈ 3.5 mm) covers δ.
  EXPECT_GT(report.threshold, 3 * delta);
  EXPECT_DOUBLE_EQ(report.overall.surface.completeness, 1.0);
  // A threshold of δ/2 leaves every true sample uncovered.
  EvaluationOptions tight = SmallOptions();
  tight.threshold = 0.5 * delta;
  const EvaluationReport strict = EvaluateSequence(
      truth.frame_count(), [&](int f) { return truth.Mesh(f); },
      [&](int f) { return EvaluationFrame{{inflated[f], truth.F}, std::nullopt}; }, tight);
  EXPECT_DOUBLE_EQ(strict.overall.surface.completeness, 0.0);
}

TEST(Evaluation, ZeroMotionOnTheTrueShapesHasTheTrueMotionAsError) {
  // Result = the true meshes with vx vy vz = 0. For a true vertex the closest true point
  // is the vertex itself, so the true motion is V(f+1) − V(f) and EPE = |V(f+1) − V(f)|:
  // mean EPE equals the mean true motion (to rounding), relative EPE is 1.
  const SyntheticScene truth = Blob(4);
  const std::vector<Positions> zero(4, Positions::Zero(truth.rest.rows(), 3));
  const EvaluationReport report = Evaluate(truth, truth.frames, &zero);
  EXPECT_EQ(report.flow_source, "vx vy vz");
  double expected_sum = 0.0;
  for (int f = 0; f + 1 < 4; ++f) {
    const double expected = (truth.frames[f + 1] - truth.frames[f]).rowwise().norm().mean();
    expected_sum += expected;
    EXPECT_NEAR(report.frames[f].flow.epe_mean, expected, 1e-12);
    EXPECT_NEAR(report.frames[f].flow.true_motion_mean, expected, 1e-12);
    EXPECT_NEAR(report.frames[f].flow.epe_relative, 1.0, 1e-9);
  }
  EXPECT_NEAR(report.overall.flow.epe_mean, expected_sum / 3.0, 1e-12);
  EXPECT_NEAR(report.overall.flow.epe_relative, 1.0, 1e-9);
}

TEST(Evaluation, FlowIsMeasuredAtTheClosestMaterialPoint) {
  // A result whose vertices are not the true vertices (a finer icosphere of the same
  // analytic blob) carrying the exact analytic flow. The evaluator's true motion comes
  // from the coarse truth, piecewise linear over edges h ≈ 7.8 mm, for waves of
  // |k| ≤ 40 rad/m: interpolation error ≈ (k h)²/8 ≈ 1.2 % of the motion, so the
  // relative EPE must be below 2 % (measured 0.3 %), while zero motion gives exactly 1.
  SyntheticSceneOptions fine_options;
  fine_options.scene = "blob";
  fine_options.frame_count = 2;
  fine_options.subdivisions = 5;
  fine_options.motion = 2.0;
  const SyntheticScene fine = MakeSyntheticScene(fine_options);
  const SyntheticScene coarse = [&] {
    SyntheticSceneOptions o = fine_options;
    o.subdivisions = 4;
    return MakeSyntheticScene(o);
  }();
  // The fine icosphere keeps the coarse vertices first: the coarse truth samples the
  // same analytic surface; fine vertices carry their analytic motion.
  const std::vector<Positions> motion = {fine.frames[1] - fine.frames[0], Positions::Zero(fine.rest.rows(), 3)};
  const EvaluationReport report = EvaluateSequence(
      2, [&](int f) { return coarse.Mesh(f); },
      [&](int f) { return EvaluationFrame{fine.Mesh(f), motion[f]}; }, SmallOptions());
  std::printf("analytic flow at another resolution: relative EPE %.4f (mean EPE %.3g, true %.3g)\n",
              report.overall.flow.epe_relative, report.overall.flow.epe_mean, report.overall.flow.true_motion_mean);
  EXPECT_LT(report.overall.flow.epe_relative, 0.02);
  const std::vector<Positions> still = {Positions::Zero(fine.rest.rows(), 3), Positions::Zero(fine.rest.rows(), 3)};
  const EvaluationReport none = EvaluateSequence(
      2, [&](int f) { return coarse.Mesh(f); },
      [&](int f) { return EvaluationFrame{fine.Mesh(f), still[f]}; }, SmallOptions());
  EXPECT_NEAR(none.overall.flow.epe_relative, 1.0, 1e-9);
}

TEST(Evaluation, FlowErrorSplitsIntoNormalAndTangentialParts) {
  // A flat 5×5 grid in z = 0 moving by (1, 2, 0) mm per frame; the result is the true
  // grid whose vx vy vz err by δ along z (the normal) or along x (in the plane).
  TriangleMesh grid;
  grid.V.resize(25, 3);
  grid.F.resize(32, 3);
  for (int i = 0; i < 25; ++i) grid.V.row(i) << 0.01 * (i % 5), 0.01 * (i / 5), 0.0;
  for (int y = 0, f = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      const int a = 5 * y + x;
      grid.F.row(f++) << a, a + 1, a + 6;
      grid.F.row(f++) << a, a + 6, a + 5;
    }
  const Eigen::RowVector3d step(0.001, 0.002, 0.0);
  const auto truth = [&](int f) { return TriangleMesh{grid.V.rowwise() + f * step, grid.F}; };
  const double delta = 1e-4;
  for (int axis : {2, 0}) {
    Positions motion = Positions::Zero(25, 3).rowwise() + step;
    motion.col(axis).array() += delta;
    const EvaluationReport report =
        EvaluateSequence(2, truth, [&](int f) { return EvaluationFrame{truth(f), motion}; }, SmallOptions());
    const FlowScores& flow = report.overall.flow;
    EXPECT_NEAR(flow.epe_mean, delta, 1e-12);
    EXPECT_NEAR(flow.epe_normal_mean, axis == 2 ? delta : 0.0, 1e-12) << "axis " << axis;
    EXPECT_NEAR(flow.epe_tangential_mean, axis == 2 ? 0.0 : delta, 1e-12) << "axis " << axis;
  }
}

TEST(Evaluation, SurfaceSamplesAreAreaWeightedAndDeterministic) {
  // Two triangles of areas 1 and 3: a quarter of the samples on the first.
  TriangleMesh mesh;
  mesh.V.resize(6, 3);
  mesh.V << 0, 0, 0, 1, 0, 0, 0, 2, 0, 5, 0, 0, 8, 0, 0, 5, 2, 0;
  mesh.F.resize(2, 3);
  mesh.F << 0, 1, 2, 3, 4, 5;
  const Positions samples = SampleSurface(mesh, 4000);
  int first = 0;
  for (Eigen::Index i = 0; i < samples.rows(); ++i) first += samples(i, 0) < 2.0;
  EXPECT_EQ(first, 1000);
  EXPECT_EQ(samples, SampleSurface(mesh, 4000));
  // The samples of triangle 1 fill it evenly: their mean is its centroid (to 1 %).
  EXPECT_NEAR(samples.topRows(1000).col(0).mean(), 1.0 / 3.0, 0.01);
  EXPECT_NEAR(samples.topRows(1000).col(1).mean(), 2.0 / 3.0, 0.01);
}

// Files: DATASET/groundtruth/mesh and RESULT/meshes written with WriteMesh.
struct EvaluationFiles {
  const test::TemporaryDirectory scratch;
  fs::path root, dataset, result;
  explicit EvaluationFiles(const std::string& name) : scratch("eval_test_" + name), root(scratch.path()) {
    dataset = root / "dataset";
    result = root / "result";
    fs::create_directories(dataset / "groundtruth" / "mesh");
    fs::create_directories(result / "meshes");
  }
  void Write(const SyntheticScene& truth, bool with_motion) {
    for (int f = 0; f < truth.frame_count(); ++f) {
      char name[16];
      std::snprintf(name, sizeof(name), "%06d.ply", f);
      geometry::WriteMesh((dataset / "groundtruth" / "mesh" / name).string(), truth.Mesh(f));
      geometry::VertexProperties properties;
      if (with_motion) {
        const Positions motion = f + 1 < truth.frame_count() ? Positions(truth.frames[f + 1] - truth.frames[f])
                                                             : Positions::Zero(truth.rest.rows(), 3);
        properties.names = {"vx", "vy", "vz"};
        for (int k = 0; k < 3; ++k) properties.values[properties.names[k]] = motion.col(k);
      }
      geometry::WriteMesh((result / "meshes" / name).string(), truth.Mesh(f), with_motion ? &properties : nullptr);
    }
  }
};

std::string ErrorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Evaluation, ReadsTheOutputLayoutAndScoresItsOwnGroundTruthAsPerfect) {
  EvaluationFiles files("perfect");
  const SyntheticScene truth = Blob();
  files.Write(truth, true);
  const EvaluationReport report =
      EvaluateReconstruction(files.dataset.string(), files.result.string(), SmallOptions());
  EXPECT_EQ(report.flow_source, "vx vy vz");
  // Float PLY: positions and flow rounded to ~1e-8 m.
  EXPECT_LT(report.overall.surface.hausdorff, 1e-7);
  EXPECT_LT(report.overall.flow.epe_mean, 1e-7);
  EXPECT_NE(report.Table().find("overall"), std::string::npos);
  const nlohmann::json json = nlohmann::json::parse(report.Json());
  EXPECT_EQ(json["frames"].size(), 3u);
  EXPECT_TRUE(json["frames"][2]["flow"].is_null());
  EXPECT_LT(json["overall"]["accuracy"].get<double>(), 1e-7);
}

TEST(Evaluation, MalformedResultsGiveClearErrors) {
  const SyntheticScene truth = Blob();
  {
    EvaluationFiles files("missing_frame");
    files.Write(truth, false);
    fs::remove(files.result / "meshes" / "000001.ply");
    const std::string error = ErrorOf([&] { EvaluateReconstruction(files.dataset, files.result, SmallOptions()); });
    EXPECT_NE(error.find("000001.ply"), std::string::npos) << error;
    EXPECT_NE(error.find("missing"), std::string::npos) << error;
  }
  {
    // A result may cover a contiguous part of the sequence (reconstruct --first-frame /
    // --frames): it is scored on those frames; one that runs past the truth is refused.
    EvaluationFiles files("frame_count");
    files.Write(truth, false);
    fs::remove(files.result / "meshes" / "000000.ply");
    const EvaluationReport part = EvaluateReconstruction(files.dataset, files.result, SmallOptions());
    ASSERT_EQ(part.frames.size(), static_cast<std::size_t>(truth.frame_count() - 1));
    EXPECT_EQ(part.frames.front().frame, 1);
    fs::copy_file(files.result / "meshes" / "000001.ply",
                  files.result / "meshes" / (FrameName(truth.frame_count()) + ".ply"));
    const std::string error = ErrorOf([&] { EvaluateReconstruction(files.dataset, files.result, SmallOptions()); });
    EXPECT_NE(error.find("but the ground truth"), std::string::npos) << error;
    EXPECT_NE(error.find("has " + std::to_string(truth.frame_count()) + " frames"), std::string::npos) << error;
  }
  {
    EvaluationFiles files("vertex_count");
    files.Write(truth, false);
    SyntheticSceneOptions other;
    other.subdivisions = 3;
    geometry::WriteMesh((files.result / "meshes" / "000001.ply").string(), MakeSyntheticScene(other).Mesh(0));
    const std::string error = ErrorOf([&] { EvaluateReconstruction(files.dataset, files.result, SmallOptions()); });
    EXPECT_NE(error.find("frame 1: vertex count"), std::string::npos) << error;
  }
  {
    EvaluationFiles files("no_truth");
    fs::remove_all(files.dataset / "groundtruth");
    const std::string error = ErrorOf([&] { EvaluateReconstruction(files.dataset, files.result, SmallOptions()); });
    EXPECT_NE(error.find("groundtruth/mesh: missing"), std::string::npos) << error;
  }
  EvaluationOptions bad;
  bad.threshold = -1.0;
  EXPECT_NE(ErrorOf([&] { bad.Check(); }).find("threshold"), std::string::npos);
}

TEST(Evaluation, CommandLinePrintsATableAndWritesJson) {
  EvaluationFiles files("cli");
  files.Write(Blob(), false);
  const fs::path json_path = files.root / "scores.json";
  const test::CommandResult run =
      test::RunSubflow("eval '" + files.dataset.string() + "' '" + files.result.string() +
                           "' --samples 5000 --json '" + json_path.string() + "'",
                       files.root);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_NE(run.output().find("overall"), std::string::npos) << run.output();
  std::ifstream json_file(json_path);
  const nlohmann::json json = nlohmann::json::parse(json_file);
  EXPECT_EQ(json["samples"].get<int>(), 5000);
  EXPECT_LT(json["overall"]["chamfer"].get<double>(), 1e-7);
  // A missing result directory: exit status 1 and a one-line error naming it.
  const test::CommandResult bad = test::RunSubflow(
      "eval '" + files.dataset.string() + "' '" + (files.root / "nowhere").string() + "'", files.root);
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output().find("nowhere/meshes: missing"), std::string::npos) << bad.output();
}

TEST(Evaluation, CommandLineScoresTheObservedSurfaceAndHulls) {
  // With the dataset's cameras (a ring of 4 around the blob), the JSON has the observed
  // figures with the requested --min-views; --hull scores RESULT/hull/ without flow.
  EvaluationFiles files("observed");
  const SyntheticScene truth = Blob(2);
  files.Write(truth, true);
  CameraRigOptions rig;
  rig.camera_count = 4;
  WriteCamerasJson((files.dataset / "cameras.json").string(), MakeCameraRig(rig), std::nullopt, std::nullopt,
                   std::nullopt);
  fs::create_directories(files.result / "hull");
  for (int f = 0; f < 2; ++f)
    geometry::WriteMesh((files.result / "hull" / (FrameName(f) + ".ply")).string(), Blob(1).Mesh(0));
  const fs::path json_path = files.root / "observed.json", hull_json = files.root / "hull.json";
  const test::CommandResult run = test::RunSubflow("eval '" + files.dataset.string() + "' '" + files.result.string() +
                                                       "' --samples 5000 --min-views 3 --json '" + json_path.string() + "'",
                                                   files.root);
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_NE(run.output().find("observed surface: seen by >= 3 of 4 cameras"), std::string::npos) << run.output();
  std::ifstream json_file(json_path);
  const nlohmann::json json = nlohmann::json::parse(json_file);
  EXPECT_EQ(json["min_views"].get<int>(), 3);
  EXPECT_EQ(json["camera_count"].get<int>(), 4);
  const nlohmann::json& observed = json["overall"]["observed"];
  // Four cameras at 10° elevation: three of them see a band around the blob, not its poles.
  EXPECT_GT(observed["observed_fraction"].get<double>(), 0.05);
  EXPECT_LT(observed["observed_fraction"].get<double>(), 0.95);
  EXPECT_GT(observed["pixel_footprint"].get<double>(), 0.0);
  EXPECT_LT(observed["accuracy"].get<double>(), 1e-7);
  const test::CommandResult hull = test::RunSubflow("eval '" + files.dataset.string() + "' '" + files.result.string() +
                                                        "' --samples 5000 --hull --json '" + hull_json.string() + "'",
                                                    files.root);
  ASSERT_EQ(hull.exit_code, 0) << hull.output();
  std::ifstream hull_file(hull_json);
  const nlohmann::json hull_scores = nlohmann::json::parse(hull_file);
  EXPECT_EQ(hull_scores["surfaces"].get<std::string>(), "hull");
  EXPECT_TRUE(hull_scores["overall"]["flow"].is_null());
  EXPECT_GT(hull_scores["overall"]["observed"]["accuracy"].get<double>(), 1e-4);  // frame 1's truth moved
}

}  // namespace
}  // namespace subflow::vision
