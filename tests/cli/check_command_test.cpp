// `subflow check` end to end: exit status, one-line errors, JSON output.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

class CheckCommand : public ::testing::Test {
 protected:
  test::CommandResult Subflow(const std::string& arguments) const {
    return test::RunSubflow(arguments, dir_.path());
  }

  const test::TemporaryDirectory dir_{"check_command"};
};

const std::string kBlobMesh =
    std::string(SUBFLOW_SHARED_DIR) + "/data/blob/groundtruth/mesh/000000.ply";

TEST_F(CheckCommand, ValidMeshExitsZeroAndPrintsItsFigures) {
  const test::CommandResult run = Subflow("check '" + kBlobMesh + "'");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("10242 vertices, 20480 faces"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("genus 0"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("verdict: valid"), std::string::npos) << run.out;
  EXPECT_TRUE(run.err.empty()) << run.err;
}

TEST_F(CheckCommand, JsonOutputParsesAndSkippingIntersectionsIsHonoured) {
  const test::CommandResult run = Subflow("check --json --no-self-intersections '" + kBlobMesh + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json json = nlohmann::json::parse(run.out);
  EXPECT_EQ(json["valid"], true);
  EXPECT_EQ(json["counts"]["faces"], 20480);
  EXPECT_EQ(json["topology"]["closed"], true);
  EXPECT_EQ(json["self_intersections"]["cgal"]["ran"], false);
  EXPECT_EQ(json["self_intersections"]["tetgen"]["ran"], false);
}

TEST_F(CheckCommand, InvalidOrUnreadableMeshExitsOneWithAOneLineError) {
  // Two triangles sharing only vertex 0 (a bowtie): readable, but not a manifold.
  const fs::path bowtie = dir_ / "bowtie.obj";
  std::ofstream(bowtie) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv -1 0 0\nv -1 -1 0\nf 1 2 3\nf 1 4 5\n";
  const test::CommandResult invalid = Subflow("check '" + bowtie.string() + "'");
  EXPECT_EQ(invalid.exit_code, 1);
  EXPECT_EQ(invalid.err.rfind("subflow check: error: " + bowtie.string() + ": invalid mesh:", 0),
            0u)
      << invalid.err;
  EXPECT_NE(invalid.err.find("bowtie"), std::string::npos) << invalid.err;
  EXPECT_EQ(invalid.err.find('\n'), invalid.err.size() - 1) << "not one line: " << invalid.err;

  const fs::path segment = dir_ / "segment.obj";
  std::ofstream(segment) << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2\n";
  const test::CommandResult unreadable = Subflow("check '" + segment.string() + "'");
  EXPECT_EQ(unreadable.exit_code, 1);
  EXPECT_NE(unreadable.err.find(segment.string() + ": line 5 (face 0): has 2 vertices"),
            std::string::npos)
      << unreadable.err;
  EXPECT_TRUE(unreadable.out.empty()) << unreadable.out;

  const test::CommandResult missing = Subflow("check '" + (dir_ / "missing.ply").string() + "'");
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.err.find("no such file"), std::string::npos) << missing.err;
}

TEST_F(CheckCommand, HelpDescribesTheVerdict) {
  const test::CommandResult run = Subflow("check --help");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_NE(run.out.find("--no-self-intersections"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("Exit status"), std::string::npos) << run.out;
}

}  // namespace
}  // namespace subflow
