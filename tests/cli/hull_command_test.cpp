// `subflow hull`: on a tiny synthetic sphere dataset its progress prints each stage's
// final line once.
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/test_support.h"
#include "vision/synthetic_render.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

// This run's scratch directory (removed at exit).
const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("hull_command_test");
  return scratch;
}

// A sphere seen by a ring of 5 cameras at 96×72 pixels, 3 frames (~25³ voxels): seconds.
const fs::path& SphereDataset() {
  static const fs::path directory = [] {
    const fs::path path = Scratch().FreshPath("sphere");
    vision::SynthOptions options;
    options.scene.scene = "sphere";
    options.scene.frame_count = 3;
    options.scene.subdivisions = 4;
    options.rig.camera_count = 5;
    options.rig.width = 96;
    options.rig.height = 72;
    vision::WriteSyntheticDataset(path.string(), options);
    return path;
  }();
  return directory;
}

std::string HullArguments(const fs::path& out) {
  return "hull '" + SphereDataset().string() + "' --out '" + out.string() +
         "' --levels 1 --base-faces 80 --min-cameras 3 --background-threshold 0.07";
}

// Lines of `text` that contain both `a` and `b`.
int CountLines(const std::string& text, const std::string& a, const std::string& b) {
  std::istringstream lines(text);
  int count = 0;
  for (std::string line; std::getline(lines, line);)
    count += line.find(a) != std::string::npos && line.find(b) != std::string::npos;
  return count;
}

TEST(HullCommand, ProgressPrintsEachStagesFinalLineOnce) {
  // stderr is a file here, so the bar prints at 10 % steps; the line "3/3" of a stage is
  // End's, and an Update that reaches the total must not print it as well.
  const fs::path out = Scratch().FreshPath("progress");
  const test::CommandResult run = test::RunSubflow(HullArguments(out), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  EXPECT_EQ(CountLines(run.err, "visual hull", "3/3"), 1) << run.err;
  EXPECT_EQ(CountLines(run.err, "fit subdivision surface", "3/3"), 1) << run.err;
  EXPECT_EQ(CountLines(run.err, "visual hull", "0/3"), 1) << run.err;  // Begin's line
}

}  // namespace
}  // namespace subflow
