// `subflow export` on a tiny result written in the test (tests/output/tiny_result.h):
// point caches that equal the result's float positions bit for bit, a .glb that the
// Khronos glTF validator passes with 0 errors, Blender 3.4 (headless) playing the OBJ +
// PC2/MDD and the .glb at the result's positions, and refusals that name the file.
// The validator needs node and viewer/node_modules (scripts/install_deps.sh), Blender
// the Debian package `blender`; where one of them is absent the test says so and skips.
#include <cfloat>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "geometry/mesh_io.h"
#include "tests/output/tiny_result.h"
#include "tests/test_support.h"
#include "vision/dataset.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("export_command");
  return scratch;
}
const fs::path& Result() {
  static const fs::path result = [] {
    const fs::path path = Scratch() / "result";
    test::WriteTinyResult(path);
    return path;
  }();
  return result;
}
const fs::path kViewerDirectory = fs::path(SUBFLOW_SOURCE_DIR) / "viewer";

std::string Quote(const fs::path& path) { return "'" + path.string() + "'"; }

// Float positions of frame f as stored in the result's PLY.
geometry::Positions ResultPositions(const fs::path& result, int frame) {
  return geometry::ReadMesh((result / "meshes" / (vision::FrameName(frame) + ".ply")).string()).V;
}

// Reads `count` 32-bit floats at `offset` of `bytes`, little- or big-endian.
std::vector<float> Floats(const std::string& bytes, std::size_t offset, std::size_t count, bool big_endian) {
  std::vector<float> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    unsigned char b[4];
    std::memcpy(b, bytes.data() + offset + 4 * i, 4);
    if (big_endian) std::swap(b[0], b[3]), std::swap(b[1], b[2]);
    std::memcpy(&values[i], b, 4);
  }
  return values;
}
std::int32_t Int(const std::string& bytes, std::size_t offset, bool big_endian) {
  const float value = Floats(bytes, offset, 1, big_endian)[0];
  std::int32_t integer;
  std::memcpy(&integer, &value, 4);
  return integer;
}

// Expects the positions of every frame to follow at `offset`, float for float.
void ExpectFramesAt(const std::string& bytes, std::size_t offset, bool big_endian) {
  for (int f = 0; f < 5; ++f) {
    const geometry::Positions V = ResultPositions(Result(), f);
    const std::vector<float> stored = Floats(bytes, offset + static_cast<std::size_t>(f) * V.size() * 4, V.size(), big_endian);
    for (Eigen::Index k = 0; k < V.size(); ++k)
      ASSERT_EQ(stored[static_cast<std::size_t>(k)], static_cast<float>(V.data()[k])) << "frame " << f << " value " << k;
  }
}

TEST(ExportCommand, Pc2HoldsEveryFramesFloatsInBlendersLayout) {
  const fs::path out = Scratch() / "tiny.pc2";
  const test::CommandResult run = RunSubflow("export " + Quote(Result()) + " --format pc2 --out " + Quote(out), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const std::string bytes = test::ReadTextFile(out);
  ASSERT_EQ(bytes.size(), 32u + 5u * 162u * 12u);
  EXPECT_EQ(std::string(bytes.data(), 12), std::string("POINTCACHE2\0", 12));
  EXPECT_EQ(Int(bytes, 12, false), 1);    // version
  EXPECT_EQ(Int(bytes, 16, false), 162);  // vertices
  EXPECT_EQ(Floats(bytes, 20, 2, false), (std::vector<float>{0.0f, 1.0f}));  // start, sampling
  EXPECT_EQ(Int(bytes, 28, false), 5);    // frames
  ExpectFramesAt(bytes, 32, false);
  // The base OBJ beside it: the first frame, same vertex order and faces.
  const geometry::TriangleMesh base = geometry::ReadMesh((Scratch() / "tiny.obj").string());
  const geometry::TriangleMesh first = geometry::ReadMesh((Result() / "meshes" / "000000.ply").string());
  EXPECT_EQ(base.F, first.F);
  EXPECT_EQ(base.V, first.V);  // 17 significant digits: the float values exactly
  EXPECT_TRUE(fs::exists(Scratch() / "tiny.pc2.report.json"));
}

TEST(ExportCommand, MddHoldsBigEndianTimesAndFrames) {
  const fs::path out = Scratch() / "mdd" / "tiny.mdd";
  fs::create_directories(out.parent_path());
  const test::CommandResult run = RunSubflow("export " + Quote(Result()) + " --format mdd --out " + Quote(out), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_NE(run.out.find("25 fps"), std::string::npos) << run.output();  // report.json's dataset.fps
  const std::string bytes = test::ReadTextFile(out);
  ASSERT_EQ(bytes.size(), 8u + 5u * 4u + 5u * 162u * 12u);
  EXPECT_EQ(Int(bytes, 0, true), 5);
  EXPECT_EQ(Int(bytes, 4, true), 162);
  const std::vector<float> times = Floats(bytes, 8, 5, true);
  for (int f = 0; f < 5; ++f) EXPECT_EQ(times[static_cast<std::size_t>(f)], static_cast<float>(f / 25.0));
  ExpectFramesAt(bytes, 28, true);
}

TEST(ExportCommand, ObjAndPlySequencesKeepPositionsFacesAndProperties) {
  for (const char* format : {"obj", "ply"}) {
    const fs::path out = Scratch().FreshPath(std::string("sequence_") + format);
    const test::CommandResult run =
        RunSubflow("export " + Quote(Result()) + " --format " + format + " --out " + Quote(out), Scratch().path());
    ASSERT_EQ(run.exit_code, 0) << run.output();
    for (int f = 0; f < 5; ++f) {
      geometry::VertexProperties properties;
      const geometry::TriangleMesh mesh =
          geometry::ReadMesh((out / (vision::FrameName(f) + "." + format)).string(), {}, &properties);
      const geometry::TriangleMesh stored = geometry::ReadMesh((Result() / "meshes" / (vision::FrameName(f) + ".ply")).string());
      EXPECT_EQ(mesh.V, stored.V) << format << " " << f;  // float values, exactly
      EXPECT_EQ(mesh.F, stored.F) << format << " " << f;
      if (std::string(format) == "ply") {
        EXPECT_EQ(properties.values.count("nonrigid_vx"), 1u);
      }
    }
    EXPECT_TRUE(fs::exists(out / "report.json"));
  }
}

TEST(ExportCommand, RefusesToOverwriteAndNamesBadInput) {
  const fs::path out = Scratch() / "again.glb";
  ASSERT_EQ(RunSubflow("export " + Quote(Result()) + " --format glb --out " + Quote(out), Scratch().path()).exit_code, 0);
  const auto written = fs::last_write_time(out);
  const test::CommandResult again = RunSubflow("export " + Quote(Result()) + " --format glb --out " + Quote(out), Scratch().path());
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find(out.string() + ": exists"), std::string::npos) << again.output();
  EXPECT_EQ(fs::last_write_time(out), written);
  EXPECT_EQ(RunSubflow("export " + Quote(Result()) + " --format glb --overwrite --out " + Quote(out), Scratch().path()).exit_code, 0);

  const test::CommandResult not_result =
      RunSubflow("export " + Quote(Scratch().path()) + " --format glb --out " + Quote(Scratch() / "x.glb"), Scratch().path());
  EXPECT_EQ(not_result.exit_code, 1);
  EXPECT_NE(not_result.err.find("not a subflow result folder"), std::string::npos) << not_result.output();
  EXPECT_FALSE(fs::exists(Scratch() / "x.glb"));
  EXPECT_FALSE(fs::exists(Scratch() / ".x.glb.partial"));

  const test::CommandResult bad_up = RunSubflow(
      "export " + Quote(Result()) + " --format glb --up +w --out " + Quote(Scratch() / "y.glb"), Scratch().path());
  EXPECT_EQ(bad_up.exit_code, 1);
  EXPECT_NE(bad_up.err.find("--up: expected +x, -x, +y, -y, +z or -z"), std::string::npos) << bad_up.output();
  // A frame of another vertex count stops the export before anything is written.
  const fs::path broken = Scratch() / "broken";
  test::WriteTinyResult(broken);
  geometry::WriteMesh((broken / "meshes" / "000003.ply").string(), geometry::MakeIcosphere(1, 0.1));
  const test::CommandResult mixed =
      RunSubflow("export " + Quote(broken) + " --format pc2 --out " + Quote(Scratch() / "z.pc2"), Scratch().path());
  EXPECT_EQ(mixed.exit_code, 1);
  EXPECT_NE(mixed.err.find("000003.ply"), std::string::npos) << mixed.output();
  EXPECT_FALSE(fs::exists(Scratch() / "z.pc2"));
}

// Runs the Khronos validator (viewer/tools/validate_gltf.mjs); the report as JSON.
nlohmann::json Validate(const fs::path& glb) {
  const std::string command = "cd " + Quote(kViewerDirectory) + " && node tools/validate_gltf.mjs " + Quote(glb) +
                              " > " + Quote(glb.string() + ".validation.json");
  std::system(command.c_str());
  return nlohmann::json::parse(test::ReadTextFile(glb.string() + ".validation.json"));
}

bool ValidatorAvailable(std::string* why) {
  if (std::system("node --version > /dev/null 2>&1") != 0) return *why = "node is not installed", false;
  if (!fs::exists(kViewerDirectory / "node_modules" / "gltf-validator"))
    return *why = kViewerDirectory.string() + "/node_modules/gltf-validator is absent (run scripts/install_deps.sh)", false;
  return true;
}

TEST(ExportCommand, GlbPassesTheKhronosValidator) {
  std::string why;
  if (!ValidatorAvailable(&why)) GTEST_SKIP() << "cannot run the glTF validator: " << why;
  const fs::path sparse_result = Scratch() / "static_half";
  test::TinyResultOptions options;
  options.static_half = true;
  test::WriteTinyResult(sparse_result, options);
  struct Case { fs::path result; std::string flags, name; int sparse_targets; };
  for (const Case& c : {Case{Result(), "", "plain", 0}, Case{Result(), "--color flow", "coloured", 0},
                        Case{Result(), "--color nonrigid --no-normals --up -y", "nonrigid", 0},
                        Case{sparse_result, "--color flow", "sparse", 4}}) {
    const fs::path out = Scratch() / (c.name + ".glb");
    const test::CommandResult run =
        RunSubflow("export " + Quote(c.result) + " --format glb " + c.flags + " --out " + Quote(out), Scratch().path());
    ASSERT_EQ(run.exit_code, 0) << run.output();
    const nlohmann::json report = Validate(out);
    EXPECT_EQ(report["issues"]["numErrors"], 0) << c.name << ": " << report["issues"].dump(1);
    EXPECT_EQ(report["issues"]["numWarnings"], 0) << c.name << ": " << report["issues"].dump(1);
    EXPECT_EQ(report["info"]["animationCount"], 1) << c.name;
    EXPECT_EQ(report["info"]["totalVertexCount"], 162) << c.name;
    const nlohmann::json export_report = nlohmann::json::parse(test::ReadTextFile(out.string() + ".report.json"));
    EXPECT_EQ(export_report["details"]["morph_targets"], 4) << c.name;
    EXPECT_EQ(export_report["details"]["sparse_targets"], c.sparse_targets) << c.name;
  }
}

// Evaluated world positions Blender reports at `frames` (tests/data/blender_evaluated_positions.py).
nlohmann::json BlenderPositions(const std::string& mode, const std::vector<fs::path>& files, const std::string& name) {
  const fs::path out = Scratch() / (name + ".blender.json");
  std::string command = "blender -b --factory-startup --python " +
                        Quote(fs::path(SUBFLOW_TEST_DATA_DIR) / "blender_evaluated_positions.py") + " -- " + mode +
                        " 25 0,2,4 " + Quote(out);
  for (const fs::path& file : files) command += " " + Quote(file);
  command += " > " + Quote(Scratch() / (name + ".blender.log")) + " 2>&1";
  const int status = std::system(command.c_str());
  EXPECT_EQ(status, 0) << test::ReadTextFile(Scratch() / (name + ".blender.log"));
  return fs::exists(out) ? nlohmann::json::parse(test::ReadTextFile(out)) : nlohmann::json();
}

// Blender's positions at frames 0, 2, 4 equal the result's to `ulps` float roundings of
// the largest coordinate (0 = bit for bit).
void ExpectBlenderMatches(const fs::path& result, const nlohmann::json& blender, double ulps, const std::string& name) {
  ASSERT_TRUE(blender.contains("frames")) << name;
  for (int frame : {0, 2, 4}) {
    const geometry::Positions V = ResultPositions(result, frame);
    const nlohmann::json& seen = blender["frames"][std::to_string(frame)];
    ASSERT_EQ(seen.size(), static_cast<std::size_t>(V.rows())) << name << " frame " << frame;
    const double tolerance = ulps * FLT_EPSILON * V.cwiseAbs().maxCoeff();
    double error = 0.0;
    for (Eigen::Index v = 0; v < V.rows(); ++v)
      for (int k = 0; k < 3; ++k) error = std::max(error, std::abs(seen[v][k].get<double>() - V(v, k)));
    EXPECT_LE(error, tolerance) << name << " frame " << frame;
  }
}

TEST(ExportCommand, BlenderPlaysPointCachesAndGlbAtTheResultsPositions) {
  if (std::system("blender --version > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "Blender is not installed (Debian package blender; scripts/install_deps.sh installs it)";
  const fs::path directory = Scratch().Subdirectory("blender");
  for (const char* format : {"pc2", "mdd", "glb"}) {
    const fs::path out = directory / (std::string("tiny.") + format);
    const test::CommandResult run = RunSubflow("export " + Quote(Result()) + " --format " + format + " --out " +
                                                   Quote(out) + (std::string(format) == "mdd" ? "" : " --overwrite"),
                                               Scratch().path());
    ASSERT_EQ(run.exit_code, 0) << run.output();
    if (std::string(format) == "pc2") fs::rename(directory / "tiny.obj", directory / "pc2_base.obj");
  }
  // Point caches: exactly the float positions (Blender reads them as float).
  ExpectBlenderMatches(Result(), BlenderPositions("pc2", {directory / "pc2_base.obj", directory / "tiny.pc2"}, "pc2"), 0, "pc2");
  ExpectBlenderMatches(Result(), BlenderPositions("mdd", {directory / "tiny.obj", directory / "tiny.mdd"}, "mdd"), 0, "mdd");
  // glb: base + morph delta in float, then the importer's Y-up → Z-up turn: ≤ 2 roundings.
  ExpectBlenderMatches(Result(), BlenderPositions("glb", {directory / "tiny.glb"}, "glb"), 2, "glb");
  // Sparse morph targets (half of the vertices never move) read the same way.
  const fs::path sparse_result = directory / "static_half";
  test::TinyResultOptions options;
  options.static_half = true;
  test::WriteTinyResult(sparse_result, options);
  ASSERT_EQ(RunSubflow("export " + Quote(sparse_result) + " --format glb --out " + Quote(directory / "sparse.glb"),
                       Scratch().path()).exit_code, 0);
  ExpectBlenderMatches(sparse_result, BlenderPositions("glb", {directory / "sparse.glb"}, "sparse"), 2, "sparse glb");
}

}  // namespace
}  // namespace subflow
