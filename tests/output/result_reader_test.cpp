// The result reader accepts the OUTPUT.md layout and refuses everything else with an
// error naming the file: a folder that is no result, a missing frame, frames of other
// vertex counts or faces, a broken report.json.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "core/error.h"
#include "geometry/icosphere.h"
#include "geometry/mesh_io.h"
#include "output/result_reader.h"
#include "tests/output/tiny_result.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("result_reader");
  return scratch;
}

// The message of the subflow::Error that CheckResultFolder throws ("" when none).
std::string CheckError(const fs::path& folder) {
  try {
    output::CheckResultFolder(folder.string());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

fs::path FreshResult(const std::string& name) {
  const fs::path folder = Scratch().FreshPath(name);
  test::WriteTinyResult(folder);
  return folder;
}

TEST(ResultReader, ReadsEveryFrameOfATinyResult) {
  const fs::path folder = FreshResult("good");
  const output::ResultReader reader(folder.string());
  EXPECT_EQ(reader.frame_count(), 5);
  EXPECT_EQ(reader.first_frame(), 0);
  EXPECT_EQ(reader.vertex_count(), 162);
  EXPECT_EQ(reader.face_count(), 320);
  const geometry::TriangleMesh sphere = geometry::MakeIcosphere(2, 0.1);
  const output::ResultFrame frame = reader.ReadFrame(3);
  // Stored as float: equal to the exact positions within float rounding (|x| < 0.2).
  EXPECT_LT((frame.V - test::TinyResultPositions(sphere, 3, {})).cwiseAbs().maxCoeff(), 2e-8);
  EXPECT_EQ(frame.Vectors("v", "x").rows(), 162);
  EXPECT_EQ(CheckError(folder), "");
}

TEST(ResultReader, RefusesAFolderThatIsNoResult) {
  const fs::path folder = Scratch().Subdirectory("not_a_result");
  EXPECT_NE(CheckError(folder).find("not a subflow result folder"), std::string::npos) << CheckError(folder);
  EXPECT_NE(CheckError(folder / "absent").find("no such directory"), std::string::npos);
  // meshes/ without any frame
  fs::create_directories(folder / "meshes");
  std::ofstream(folder / "report.json") << "{}";
  EXPECT_NE(CheckError(folder).find("no frame"), std::string::npos) << CheckError(folder);
}

TEST(ResultReader, NamesTheMissingFrame) {
  const fs::path folder = FreshResult("missing");
  fs::remove(folder / "meshes" / "000002.ply");
  const std::string error = CheckError(folder);
  EXPECT_NE(error.find("000002.ply"), std::string::npos) << error;
  EXPECT_NE(error.find("missing frame"), std::string::npos) << error;
}

TEST(ResultReader, NamesTheFrameWithAnotherVertexCount) {
  const fs::path folder = FreshResult("vertex_count");
  geometry::WriteMesh((folder / "meshes" / "000003.ply").string(), geometry::MakeIcosphere(1, 0.1));
  const std::string error = CheckError(folder);
  EXPECT_NE(error.find("000003.ply"), std::string::npos) << error;
  EXPECT_NE(error.find("42 vertices"), std::string::npos) << error;
}

TEST(ResultReader, NamesTheFrameWithOtherFaces) {
  const fs::path folder = FreshResult("faces");
  geometry::TriangleMesh mesh = geometry::ReadMesh((folder / "meshes" / "000001.ply").string());
  std::swap(mesh.F(0, 0), mesh.F(0, 1));  // same counts, another connectivity
  geometry::WriteMesh((folder / "meshes" / "000001.ply").string(), mesh);
  const std::string error = CheckError(folder);
  EXPECT_NE(error.find("000001.ply: faces"), std::string::npos) << error;
}

TEST(ResultReader, NamesABrokenReportOrFrame) {
  const fs::path folder = FreshResult("broken");
  std::ofstream(folder / "report.json") << "{\"command\": ";
  EXPECT_NE(CheckError(folder).find("report.json: not valid JSON"), std::string::npos) << CheckError(folder);
  std::ofstream(folder / "report.json") << "[1, 2]";
  EXPECT_NE(CheckError(folder).find("expected a JSON object"), std::string::npos) << CheckError(folder);
  std::ofstream(folder / "report.json") << "{}";
  std::ofstream(folder / "meshes" / "000004.ply") << "not a mesh";
  const std::string error = CheckError(folder);
  EXPECT_NE(error.find("000004.ply"), std::string::npos) << error;
  EXPECT_NE(error.find("not a PLY file"), std::string::npos) << error;
}

}  // namespace
}  // namespace subflow
