// `subflow hull`: on a tiny synthetic sphere dataset it writes the OUTPUT.md layout and a
// report.json that records every silhouette and carving option it ran with (and the
// values chosen automatically), and its progress prints each stage's final line once.
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "output/options_json.h"
#include "tests/cli/sphere_dataset.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

// This run's scratch directory (removed at exit).
const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("hull_command_test");
  return scratch;
}

// tests/cli/sphere_dataset.h, written once per run.
const fs::path& SphereDataset() {
  static const fs::path directory = test::WriteSphereDataset(Scratch() / "sphere");
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

TEST(HullCommand, ReportRecordsEverySilhouetteAndCarvingOptionAndTheValuesUsed) {
  const fs::path out = Scratch().FreshPath("report");
  const test::CommandResult run = test::RunSubflow(HullArguments(out), Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  ASSERT_TRUE(fs::exists(out / "meshes" / "000002.ply"));
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  const nlohmann::json& options = report.at("options").at("shape_init");

  // Every field of SilhouetteOptions and VoxelCarvingOptions (vision/silhouettes.h,
  // vision/voxel_carving.h), with the values given on the command line.
  const nlohmann::json& silhouettes = options.at("silhouettes");
  for (const char* field :
       {"source", "background_blur_sigma", "background_threshold", "background_method",
        "background_open_radius", "background_min_threshold", "background_contour_fraction",
        "motion_sigma", "motion_lambda",
        "motion_window", "motion_threshold", "motion_method", "motion_min_threshold",
        "close_radius", "fill_holes", "min_region_pixels", "min_object_pixels"})
    EXPECT_TRUE(silhouettes.contains(field)) << "silhouettes." << field;
  EXPECT_EQ(silhouettes.size(), nlohmann::json(vision::SilhouetteOptions{}).size()) << silhouettes.dump();
  EXPECT_EQ(silhouettes.at("background_threshold").get<double>(), 0.07);
  EXPECT_EQ(silhouettes.at("background_method").get<std::string>(), "triangle");
  EXPECT_EQ(silhouettes.at("motion_method").get<std::string>(), "otsu");
  const nlohmann::json& carving = options.at("carving");
  for (const char* field :
       {"resolution", "pixels_per_voxel", "max_auto_resolution", "min_cameras", "max_misses",
        "evidence_threshold", "footprint_margin", "closing_radius", "opening_radius",
        "connectivity", "min_component_fraction", "fill_cavities", "compute_silhouette_iou",
        "threads"})
    EXPECT_TRUE(carving.contains(field)) << "carving." << field;
  EXPECT_EQ(carving.size(), nlohmann::json(vision::VoxelCarvingOptions{}).size()) << carving.dump();
  EXPECT_EQ(carving.at("min_cameras").get<int>(), 3);
  EXPECT_EQ(carving.at("max_misses").get<int>(), -1);  // automatic, as given
  EXPECT_EQ(carving.at("footprint_margin").get<double>(), 0.5);
  EXPECT_EQ(carving.at("evidence_threshold").get<double>(), 0.1);

  // Per frame, the values the automatic options took: masks everywhere → max_misses 0,
  // threshold 0.5 per camera.
  const nlohmann::json& frames = report.at("shape_init").at("frames");
  ASSERT_EQ(frames.size(), 3u);
  for (const nlohmann::json& frame : frames) {
    EXPECT_EQ(frame.at("max_misses").get<int>(), 0);
    EXPECT_EQ(frame.at("hull_from_frame").get<int>(), frame.at("frame").get<int>());
    EXPECT_GT(frame.at("voxel_resolution").get<int>(), 8);
    EXPECT_GE(frame.at("carved_voxels").get<long>(), frame.at("occupied_voxels").get<long>() / 2);
    EXPECT_EQ(frame.at("border_voxels").size(), 6u);
    ASSERT_EQ(frame.at("cameras").size(), 5u);
    for (const nlohmann::json& camera : frame.at("cameras")) {
      EXPECT_EQ(camera.at("source").get<std::string>(), "mask");
      EXPECT_EQ(camera.at("threshold").get<double>(), 0.5);
    }
  }
}

// The carving options given on the command line reach the carving and report.json.
TEST(HullCommand, CarvingFlagsAreUsedAndRecorded) {
  const fs::path out = Scratch().FreshPath("flags");
  const test::CommandResult run = test::RunSubflow(
      HullArguments(out) + " --frames 1 --max-misses 1 --evidence-threshold 0.25 --footprint-margin 1.5"
                           " --motion-window 1 --evidence background",
      Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << run.output();
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  const nlohmann::json& options = report.at("options").at("shape_init");
  EXPECT_EQ(options.at("carving").at("max_misses").get<int>(), 1);
  EXPECT_EQ(options.at("carving").at("evidence_threshold").get<double>(), 0.25);
  EXPECT_EQ(options.at("carving").at("footprint_margin").get<double>(), 1.5);
  EXPECT_EQ(options.at("silhouettes").at("motion_window").get<int>(), 1);
  const nlohmann::json& frame = report.at("shape_init").at("frames").at(0);
  EXPECT_EQ(frame.at("max_misses").get<int>(), 1);  // the value used
  EXPECT_EQ(frame.at("cameras").at(0).at("source").get<std::string>(), "background");
  EXPECT_EQ(frame.at("cameras").at(0).at("threshold").get<double>(), 0.07);
}

// Bad values of the carving flags: a one-line error naming the flag and the range, exit ≠ 0.
TEST(HullCommand, BadCarvingFlagValuesAreRejectedNamingTheFlag) {
  for (const std::string flag : {"--max-misses -2", "--min-cameras 0", "--evidence-threshold 0",
                                 "--evidence-threshold 1.5", "--footprint-margin -1", "--motion-window -1",
                                 "--lambda 0", "--max-misses two"}) {
    const fs::path out = Scratch().FreshPath("bad");
    const test::CommandResult run = test::RunSubflow(HullArguments(out) + " " + flag, Scratch().path());
    EXPECT_NE(run.exit_code, 0) << flag;
    const std::string name = flag.substr(0, flag.find(' '));
    EXPECT_NE(run.err.find(name), std::string::npos) << flag << ": " << run.err;
    EXPECT_FALSE(fs::exists(out / "report.json")) << flag;
  }
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
