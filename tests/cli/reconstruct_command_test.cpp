// `subflow reconstruct` end to end on a small synthetic dataset: the OUTPUT.md layout with
// the flow properties, the report, --no-refine, and refusals that leave the user's files
// alone.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "geometry/mesh_io.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;
using test::TemporaryDirectory;

// A small deforming blob: 6 gray cameras, 3 frames, 160×120.
const TemporaryDirectory& Scratch() {
  static const TemporaryDirectory scratch("reconstruct_command");
  return scratch;
}
const fs::path& Dataset() {
  static const fs::path dataset = test::SynthSmallBlob(Scratch());
  return dataset;
}
const std::string kSmall = " --base-faces 120 --levels 2 --window 3 --iterations 4 ";

nlohmann::json ReadReport(const fs::path& out) {
  return nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
}

TEST(ReconstructCommand, WritesTheOutputLayoutWithFlowProperties) {
  const fs::path out = Scratch().FreshPath("full");
  const test::CommandResult run =
      RunSubflow("reconstruct '" + Dataset().string() + "' --out '" + out.string() + "'" + kSmall,
                 Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  Eigen::Index vertices = -1;
  for (const char* frame : {"000000", "000001", "000002"}) {
    geometry::VertexProperties properties;
    const geometry::TriangleMesh mesh =
        geometry::ReadMesh((out / "meshes" / (std::string(frame) + ".ply")).string(), {}, &properties);
    if (vertices < 0) vertices = mesh.V.rows();
    EXPECT_EQ(mesh.V.rows(), vertices) << frame;  // one connectivity for the sequence
    for (const char* name : {"vx", "vy", "vz", "rigid_vx", "nonrigid_vz", "motion_energy", "nonrigid_energy"})
      EXPECT_EQ(properties.values.count(name), 1u) << frame << " " << name;
    EXPECT_TRUE(fs::exists(out / "obj" / (std::string(frame) + ".obj")));
    EXPECT_TRUE(fs::exists(out / "hull" / (std::string(frame) + ".ply")));
    EXPECT_TRUE(fs::exists(out / "control" / frame / "level_2.ply"));
  }
  const nlohmann::json report = ReadReport(out);
  EXPECT_EQ(report["command"], "reconstruct");
  for (const char* stage : {"shape_init", "motion_init", "refinement", "retrack", "total"})
    EXPECT_GT(report["timings_seconds"][stage].get<double>(), 0.0) << stage;
  // The process's peak memory after each stage: it only rises, and no run of subflow (its
  // libraries, the take's images) fits in 10 MB.
  long long peak = 0;
  for (const char* stage : {"shape_init", "motion_init", "refinement", "retrack", "writing"}) {
    const long long after = report["peak_memory_bytes"][stage].get<long long>();
    EXPECT_GE(after, peak) << stage;
    peak = after;
  }
  EXPECT_GT(peak, 10'000'000);
  EXPECT_EQ(report["rigid_motion"].size(), 2u);
  // Each motion pass records the options it ran with: the second one its own hull weight
  // and high-pass (by default the first pass reads the intensities, the retrack the fine
  // structure).
  EXPECT_EQ(report["motion_init"]["options"]["hull_weight"], report["options"]["motion_init"]["hull_weight"]);
  EXPECT_EQ(report["retrack"]["options"]["hull_weight"], report["options"]["retrack_weight"]);
  EXPECT_NE(report["retrack"]["options"]["hull_weight"], report["motion_init"]["options"]["hull_weight"]);
  EXPECT_EQ(report["motion_init"]["options"]["step"]["highpass_sigma"], 0.0);
  EXPECT_EQ(report["retrack"]["options"]["step"]["highpass_sigma"], report["options"]["retrack_highpass"]);
  EXPECT_GT(report["options"]["retrack_highpass"].get<double>(), 0.0);
  ASSERT_EQ(report["refinement"]["frames"].size(), 3u);
  for (const auto& frame : report["refinement"]["frames"]) {
    EXPECT_GT(frame["stereo_pairs"].get<int>(), 0);
    EXPECT_GT(frame["ncc_after"].get<double>(), frame["ncc_before"].get<double>());
  }
  // The result scores against the ground truth.
  const test::CommandResult eval =
      RunSubflow("eval '" + Dataset().string() + "' '" + out.string() + "'", Scratch().path());
  EXPECT_EQ(eval.exit_code, 0) << eval.output();
  EXPECT_NE(eval.out.find("overall"), std::string::npos) << eval.output();
}

TEST(ReconstructCommand, NoRefineStopsAfterMotionInitialization) {
  const fs::path out = Scratch().FreshPath("no_refine");
  const test::CommandResult run = RunSubflow(
      "reconstruct '" + Dataset().string() + "' --out '" + out.string() + "' --no-refine" + kSmall,
      Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const nlohmann::json report = ReadReport(out);
  EXPECT_EQ(report["command"], "reconstruct --no-refine");
  EXPECT_FALSE(report.contains("refinement"));
  EXPECT_FALSE(report.contains("retrack"));
  EXPECT_EQ(report["motion_init"]["frames"].size(), 3u);
  EXPECT_TRUE(fs::exists(out / "meshes" / "000002.ply"));
}

TEST(ReconstructCommand, RefusesToOverwriteAndRejectsBadOptions) {
  const fs::path out = Scratch().Subdirectory("occupied");
  {
    std::ofstream mine(out / "mine.txt");
    mine << "precious";
  }
  const test::CommandResult refused =
      RunSubflow("reconstruct '" + Dataset().string() + "' --out '" + out.string() + "'", Scratch().path());
  EXPECT_EQ(refused.exit_code, 1) << refused.output();
  EXPECT_NE(refused.err.find(out.string()), std::string::npos) << refused.output();
  EXPECT_EQ(test::ReadTextFile(out / "mine.txt"), "precious");
  EXPECT_FALSE(fs::exists(out / "meshes"));

  const test::CommandResult bad = RunSubflow(
      "reconstruct '" + Dataset().string() + "' --out '" + Scratch().FreshPath("bad").string() + "' --window 0",
      Scratch().path());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("window"), std::string::npos) << bad.output();
  const test::CommandResult solver = RunSubflow(
      "reconstruct '" + Dataset().string() + "' --out '" + Scratch().FreshPath("bad2").string() +
          "' --linear-solver magic",
      Scratch().path());
  EXPECT_NE(solver.exit_code, 0);
  EXPECT_NE(solver.err.find("magic"), std::string::npos) << solver.output();
  // --concurrent-halves takes a value: a bad one, or the dataset after it, is a usage error
  // naming the flag (the parser's exit code, not a signal: an exception out of the parser's
  // callback would abort).
  const test::CommandResult halves = RunSubflow(
      "reconstruct '" + Dataset().string() + "' --out '" + Scratch().FreshPath("bad3").string() +
          "' --concurrent-halves sometimes",
      Scratch().path());
  EXPECT_TRUE(halves.exit_code > 0 && halves.exit_code < 128) << halves.output();
  EXPECT_NE(halves.err.find("--concurrent-halves"), std::string::npos) << halves.output();
  const test::CommandResult swallowed = RunSubflow(
      "reconstruct --concurrent-halves '" + Dataset().string() + "' --out '" + Scratch().FreshPath("bad4").string() +
          "'",
      Scratch().path());
  EXPECT_TRUE(swallowed.exit_code > 0 && swallowed.exit_code < 128) << swallowed.output();
  EXPECT_NE(swallowed.err.find("--concurrent-halves"), std::string::npos) << swallowed.output();
}

}  // namespace
}  // namespace subflow
