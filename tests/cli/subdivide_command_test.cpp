// `subflow subdivide` end to end: the written mesh is LoopHierarchy's refinement (or its
// limit positions), bad input gives a one-line error and exit status 1.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "geometry/loop_hierarchy.h"
#include "geometry/mesh_io.h"
#include "geometry/mesh_primitives.h"
#include "tests/test_support.h"

namespace subflow::geometry {
namespace {

namespace fs = std::filesystem;

class SubdivideCommand : public ::testing::Test {
 protected:
  test::CommandResult Subflow(const std::string& arguments) const {
    return test::RunSubflow(arguments, dir_.path());
  }

  const test::TemporaryDirectory dir_{"subdivide_command"};
};

// PLY stores float coordinates: 1e-6 of unit coordinates covers the rounding to float.
constexpr double kFloatTolerance = 1e-6;

TEST_F(SubdivideCommand, WritesTheRefinedControlMeshAndItsLimitPositions) {
  TriangleMesh base = Octahedron();
  base.V.row(0) *= 1.3;  // not symmetric
  const std::string input = (dir_ / "base.obj").string();
  WriteMesh(input, base);
  const LoopHierarchy hierarchy(base.F, base.vertex_count(), 2);
  const Positions control = hierarchy.Refine(base.V, 0, 2);

  const std::string control_path = (dir_ / "control.ply").string();
  test::CommandResult run = Subflow("subdivide '" + input + "' --levels 2 --out '" + control_path + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("66 vertices, 128 faces"), std::string::npos) << run.out;
  const TriangleMesh written = ReadMesh(control_path);
  ASSERT_EQ(written.vertex_count(), hierarchy.VertexCount(2));
  EXPECT_EQ(written.F, hierarchy.LevelFaces(2));
  EXPECT_LT((written.V - control).cwiseAbs().maxCoeff(), kFloatTolerance);

  const std::string limit_path = (dir_ / "limit.ply").string();
  run = Subflow("subdivide '" + input + "' --levels 2 --limit --out '" + limit_path + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const TriangleMesh limit = ReadMesh(limit_path);
  const Positions expected = hierarchy.LimitPositions(2) * control;
  EXPECT_LT((limit.V - expected).cwiseAbs().maxCoeff(), kFloatTolerance);
  EXPECT_GT((limit.V - control).cwiseAbs().maxCoeff(), 1e-2);  // --limit moved the points
}

TEST_F(SubdivideCommand, BadInputGivesAOneLineErrorAndExitStatusOne) {
  // Two triangles sharing only a vertex: not a manifold.
  const std::string bowtie = (dir_ / "bowtie.obj").string();
  std::ofstream(bowtie) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n";
  test::CommandResult run = Subflow("subdivide '" + bowtie + "' --levels 1 --out '" +
                              (dir_ / "out.ply").string() + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("subflow subdivide: error: " + bowtie), std::string::npos) << run.err;
  EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
  EXPECT_FALSE(fs::exists(dir_ / "out.ply"));

  run = Subflow("subdivide '" + bowtie + "' --levels -1 --out x.ply");
  EXPECT_NE(run.exit_code, 0);
}

TEST_F(SubdivideCommand, HelpDescribesTheOptions) {
  const test::CommandResult run = Subflow("subdivide --help");
  EXPECT_EQ(run.exit_code, 0);
  for (const char* option : {"--levels", "--limit", "--out", "IN"})
    EXPECT_NE(run.out.find(option), std::string::npos) << option;
}

}  // namespace
}  // namespace subflow::geometry
