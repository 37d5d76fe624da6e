// report.json records the value of every command-line flag: `subflow reconstruct` is run
// once with every flag its --help lists set to a value other than its default, and each
// value is looked for where the report records it. A flag that --help lists and this
// table does not fails the test, so a new flag must say where its value is recorded.
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/sphere_dataset.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("report_flags_test");
  return scratch;
}

// tests/cli/sphere_dataset.h, written once per run.
const fs::path& SphereDataset() {
  static const fs::path directory = test::WriteSphereDataset(Scratch() / "sphere");
  return directory;
}

// The flags --help of `command` lists (long names).
std::set<std::string> HelpFlags(const std::string& command) {
  const test::CommandResult help = test::RunSubflow(command + " --help", Scratch().path());
  EXPECT_EQ(help.exit_code, 0) << help.output();
  std::set<std::string> flags;
  const std::regex flag("(^|[ ,])(--[a-z][a-z0-9-]*)");
  for (std::sregex_iterator it(help.out.begin(), help.out.end(), flag), end; it != end; ++it)
    flags.insert((*it)[2].str());
  flags.erase("--help");
  return flags;
}

struct Recorded {
  std::string value;           // on the command line ("" for a flag without value)
  std::string pointer;         // JSON pointer into report.json
  nlohmann::json expected;     // what must be there
};

// Each flag of `reconstruct` with a non-default value. Refinement and re-tracking are
// switched off (fast), their options are recorded all the same.
std::map<std::string, Recorded> ReconstructFlags() {
  return {
      {"--overwrite", {"", "/overwrite", true}},
      {"--resume", {"", "/resume", true}},
      {"--chunk", {"50", "/arguments/--chunk", "50"}},  // longer than the take: one process
      {"--no-refine", {"", "/options/refine", false}},
      {"--no-retrack", {"", "/options/retrack", false}},
      {"--retrack-weight", {"0.3", "/options/retrack_weight", 0.3}},
      {"--retrack-highpass", {"1.3", "/options/retrack_highpass", 1.3}},
      {"--no-retrack-register", {"", "/options/retrack_register", false}},
      {"--evidence", {"background", "/options/shape_init/silhouettes/source", "background"}},
      {"--levels", {"1", "/options/shape_init/levels", 1}},
      {"--base-faces", {"60", "/options/shape_init/simplify/target_face_count", 60}},
      // --base-faces selects the count mode: the distance bound given too is set to 0.
      {"--base-distance", {"1.5", "/options/shape_init/base_distance_voxels", 0.0}},
      {"--finest-edge-pixels", {"1.5", "/options/shape_init/finest_edge_pixels", 1.5}},
      {"--max-finest-faces", {"20000", "/options/shape_init/max_finest_faces", 20000}},
      {"--reference-frame", {"2", "/options/shape_init/reference_frame", 2}},
      {"--first-frame", {"1", "/options/shape_init/first_frame", 1}},
      {"--frames", {"2", "/options/shape_init/frame_count", 2}},
      {"--resolution", {"28", "/options/shape_init/carving/resolution", 28}},
      {"--min-cameras", {"3", "/options/shape_init/carving/min_cameras", 3}},
      {"--max-misses", {"1", "/options/shape_init/carving/max_misses", 1}},
      {"--evidence-threshold", {"0.2", "/options/shape_init/carving/evidence_threshold", 0.2}},
      {"--footprint-margin", {"1.5", "/options/shape_init/carving/footprint_margin", 1.5}},
      {"--lambda", {"0.002", "/options/shape_init/silhouettes/motion_lambda", 0.002}},
      {"--motion-window", {"1", "/options/shape_init/silhouettes/motion_window", 1}},
      {"--motion-threshold", {"0.3", "/options/shape_init/silhouettes/motion_threshold", 0.3}},
      {"--background-threshold", {"0.07", "/options/shape_init/silhouettes/background_threshold", 0.07}},
      {"--background-noise-factor", {"4.5", "/options/shape_init/silhouettes/background_noise_factor", 4.5}},
      {"--no-shadow-test", {"", "/options/shape_init/silhouettes/background_shadow_test", false}},
      {"--concavities", {"", "/options/shape_init/concavities/enabled", true}},
      {"--motion-smoothness", {"0.004", "/options/motion_init/step/solver/smoothness", 0.004}},
      {"--motion-highpass", {"1.2", "/options/motion_init/step/highpass_sigma", 1.2}},
      {"--hull-weight", {"0.4", "/options/motion_init/hull_weight", 0.4}},
      {"--no-velocity-guess", {"", "/options/motion_init/guess_previous_step", false}},
      {"--slide-at-outlines", {"", "/options/refinement/tangential_only_at_outlines", true}},
      {"--refine-from", {"1", "/options/refinement/coarsest_level", 1}},
      {"--refine-to", {"1", "/options/refinement/finest_level", 1}},
      {"--window", {"4", "/options/refinement/window", 4}},
      {"--window-overlap", {"1", "/options/refinement/window_overlap", 1}},
      {"--rounds", {"2", "/options/refinement/rounds", 2}},
      {"--concurrent-halves", {"on", "/options/refinement/concurrent_halves", "on"}},
      {"--iterations", {"3", "/options/refinement/solver/max_iterations", 3}},
      {"--function-tolerance", {"0.01", "/options/refinement/solver/function_tolerance", 0.01}},
      {"--linear-solver", {"DENSE_QR", "/options/refinement/solver/linear_solver", "dense_qr"}},
      {"--threads", {"1", "/options/refinement/solver/threads", 1}},
      {"--iterative-from-unknowns", {"100", "/options/refinement/solver/iterative_from_unknowns", 100}},
      {"--iterative-solver", {"DENSE_QR", "/options/refinement/solver/iterative_solver", "dense_qr"}},
      {"--samples-per-pixel", {"0.5", "/options/refinement/samples_per_pixel", 0.5}},
      {"--max-cameras", {"4", "/options/refinement/max_cameras", 4}},
      {"--temporal-weight", {"0.5", "/options/refinement/temporal_weight", 0.5}},
      {"--silhouette-weight", {"0.1", "/options/refinement/silhouette_weight", 0.1}},
      {"--silhouette-from-level", {"2", "/options/refinement/silhouette_from_level", 2}},
      {"--rim-band", {"1.5", "/options/refinement/rim_band", 1.5}},
      {"--membrane-weight", {"0.2", "/options/refinement/membrane_weight", 0.2}},
      {"--temporal-smoothness", {"0.2", "/options/refinement/temporal_smoothness", 0.2}},
      {"--slide-coherence", {"2.5", "/options/refinement/slide_coherence", 2.5}},
  };
}

TEST(ReportFlags, EveryReconstructFlagsValueIsRecorded) {
  const std::map<std::string, Recorded> table = ReconstructFlags();
  for (const std::string& flag : HelpFlags("reconstruct")) {
    if (flag != "--out") {  // given below, recorded as "output"
      EXPECT_EQ(table.count(flag), 1u) << flag << " is listed by --help but the test does not say where it is recorded";
    }
  }

  const fs::path out = Scratch().Subdirectory("reconstruct");
  std::string arguments = "reconstruct '" + SphereDataset().string() + "' --out '" + out.string() + "'";
  for (const auto& [flag, recorded] : table) arguments += " " + flag + (recorded.value.empty() ? "" : " " + recorded.value);
  const test::CommandResult run = test::RunSubflow(arguments, Scratch().path());
  ASSERT_EQ(run.exit_code, 0) << arguments << "\n" << run.output();
  const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(out / "report.json"));
  EXPECT_EQ(report.at("output"), out.string());
  EXPECT_EQ(report.at("dataset").at("directory"), SphereDataset().string());
  for (const auto& [flag, recorded] : table) {
    const nlohmann::json::json_pointer pointer(recorded.pointer);
    ASSERT_TRUE(report.contains(pointer)) << flag << ": no " << recorded.pointer;
    EXPECT_EQ(report.at(pointer), recorded.expected) << flag << " at " << recorded.pointer;
  }
  // The values used: the frames asked for, the base mesh of about the faces asked for.
  EXPECT_EQ(report.at("shape_init").at("frames").size(), 2u);
  EXPECT_EQ(report.at("shape_init").at("reference_frame"), 2);
  EXPECT_EQ(report.at("motion_init").at("options").at("hull_weight"), 0.4);
}

}  // namespace
}  // namespace subflow
