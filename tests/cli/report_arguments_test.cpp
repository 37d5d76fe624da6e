// Every subcommand's report records every flag's value: each subcommand `subflow --help`
// lists is run with every flag its own --help lists set (a value other than the default),
// and its report's "arguments" must hold each value as given (a switch: true). A
// subcommand or a flag that --help lists and the table below does not fails the test, so
// a new one must say how it is run. (report_flags_test.cpp checks, for reconstruct, that
// the values also reach the options each stage records.)
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/sphere_dataset.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("report_arguments_test");
  return scratch;
}

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// The long flags (or, with `commands`, the subcommands) that `subflow ARGUMENTS --help` lists.
std::set<std::string> Listed(const std::string& arguments, bool commands = false) {
  const test::CommandResult help = test::RunSubflow(arguments + " --help", Scratch().path());
  EXPECT_EQ(help.exit_code, 0) << help.output();
  std::set<std::string> names;
  if (commands) {
    const std::string text = help.out.substr(help.out.find("Subcommands:"));
    const std::regex line("\n  ([a-z][a-z-]*) ");
    for (std::sregex_iterator it(text.begin(), text.end(), line), end; it != end; ++it) names.insert((*it)[1].str());
    return names;
  }
  // Option lines only ("  -o,--out TEXT  …"): a description may name another command's flag.
  const std::regex option_line("\n  ((?:-{1,2}[a-zA-Z0-9][a-zA-Z0-9-]*,?)+)");
  const std::regex flag("--[a-z][a-z0-9-]*");
  for (std::sregex_iterator it(help.out.begin(), help.out.end(), option_line), end; it != end; ++it) {
    const std::string names_of_line = (*it)[1].str();
    for (std::sregex_iterator f(names_of_line.begin(), names_of_line.end(), flag); f != end; ++f)
      names.insert(f->str());
  }
  names.erase("--help");
  return names;
}

struct Case {
  std::string arguments;  // the subcommand and its required arguments (--out included)
  std::string report;     // the report it writes, relative to the scratch folder
  std::map<std::string, std::string> flags;  // every other flag: value ("" for a switch)
};

// The folders the cases read: a 3-frame sphere and its reconstruction (stages kept).
struct Inputs {
  fs::path dataset, result, calibration, images;
};

const Inputs& MadeInputs() {
  static const Inputs inputs = [] {
    Inputs made;
    made.dataset = test::WriteSphereDataset(Scratch() / "sphere");
    made.result = Scratch() / "result";
    const test::CommandResult run = test::RunSubflow(
        "reconstruct " + Quoted(made.dataset) + " --out " + Quoted(made.result) + " --no-refine --no-retrack",
        Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    // A Middlebury calibration of two of its cameras, with their first images.
    made.calibration = Scratch() / "scene_par.txt";
    made.images = Scratch().Subdirectory("middlebury_images");
    std::ofstream par(made.calibration);
    par << "2\n";
    for (const char* name : {"img0", "img1"}) {
      fs::copy_file(made.dataset / "images" / (std::string(name) == "img0" ? "cam00" : "cam01") / "000000.png",
                    made.images / (std::string(name) + ".png"));
      par << name << ".png 100 0 48 0 100 36 0 0 1 1 0 0 0 1 0 0 0 1 0 0 " << (name[3] == '0' ? 2 : 3) << "\n";
    }
    return made;
  }();
  return inputs;
}

// An output path in the scratch folder, quoted (the commands run in the test's folder).
std::string Out(const std::string& name) { return Quoted(Scratch() / name); }

std::map<std::string, Case> Cases(const Inputs& in) {
  const std::string dataset = Quoted(in.dataset), result = Quoted(in.result);
  const std::string shape = Quoted(in.result / "stages" / "shape"), motion = Quoted(in.result / "stages" / "motion");
  return {
      {"synth", {"synth sphere --out " + Out("o_synth"), "o_synth/report.json",
                 {{"--overwrite", ""}, {"--rig", "dome"}, {"--cameras", "4"}, {"--width", "64"}, {"--height", "48"},
                  {"--frames", "2"}, {"--subdivisions", "3"}, {"--seed", "7"}, {"--noise", "0.013"},
                  {"--focal", "123"}, {"--distance", "0.77"}, {"--distortion", "-0.11,0.02,0,0,0"},
                  {"--motion", "0.37"}, {"--environment", "room"}, {"--distractors", "walker"}, {"--shadows", ""},
                  {"--supersample", "2"}, {"--video", "mp4"}, {"--gray", ""}, {"--start-frame", "1"},
                  {"--voxel", "0.0037"}, {"--color-cameras", "2"}, {"--color-every", "3"}, {"--no-masks", ""},
                  {"--no-background", ""}, {"--background", "texture"}}}},
      {"subdivide", {"subdivide " + Quoted(in.result / "base_mesh.ply") + " --out " + Out("o_sub.ply"), "o_sub.ply.report.json",
                     {{"--levels", "2"}, {"--limit", ""}, {"--overwrite", ""}}}},
      {"eval", {"eval " + dataset + " " + result + " --json " + Out("o_eval.json"), "o_eval.json",
                {{"--overwrite", ""}, {"--threshold", "0.0031"}, {"--samples", "1234"}, {"--min-views", "3"},
                 {"--visibility-tolerance", "0.0017"}, {"--hull", ""}, {"--error-maps", Out("o_eval_maps")}}}},
      {"export", {"export " + result + " --format glb --out " + Out("o_export.glb"), "o_export.glb.report.json",
                  {{"--overwrite", ""}, {"--dataset", dataset}, {"--fps", "17"}, {"--color", "flow"}, {"--up", "-y"},
                   {"--no-normals", ""}, {"--no-sparse", ""}}}},
      {"render", {"render " + result + " --out " + Out("o_render"), "o_render/report.json",
                  {{"--overwrite", ""}, {"--dataset", dataset}, {"--fps", "13"}, {"--frames", "2"}, {"--views", "2"},
                   {"--elevation", "23"}, {"--view-width", "64"}, {"--view-height", "48"}, {"--turntable-frame", "1"},
                   {"--no-overlays", ""}, {"--no-textured", ""}, {"--no-dataset", ""}, {"--mp4", ""}}}},
      {"view", {"view " + result + " --out " + Out("o_view.html"), "o_view.html.report.json",
                {{"--overwrite", ""}, {"--dataset", dataset}, {"--fps", "19"}, {"--stride", "2"},
                 {"--max-megabytes", "7"}, {"--no-texture", ""}}}},
      {"shape", {"shape " + dataset + " --out " + Out("o_shape"), "o_shape/report.json",
                 {{"--overwrite", ""}, {"--evidence", "background"}, {"--levels", "1"}, {"--base-faces", "60"}, {"--base-distance", "1.5"}, {"--finest-edge-pixels", "1.5"}, {"--max-finest-faces", "20000"},
                  {"--reference-frame", "1"}, {"--first-frame", "0"}, {"--frames", "2"}, {"--resolution", "28"},
                  {"--min-cameras", "3"}, {"--max-misses", "1"}, {"--evidence-threshold", "0.21"},
                  {"--footprint-margin", "1.7"}, {"--lambda", "0.0021"}, {"--motion-window", "1"},
                  {"--motion-threshold", "0.31"}, {"--background-threshold", "0.071"}, {"--background-noise-factor", "5"},
                  {"--no-shadow-test", ""}, {"--concavities", ""}, {"--options", ""}}}},
      {"motion", {"motion " + dataset + " --from " + shape + " --out " + Out("o_motion"), "o_motion/report.json",
                  {{"--overwrite", ""}, {"--frames", "0:2"}, {"--hull-weight", "0.41"},
                   {"--motion-smoothness", "0.0041"}, {"--no-velocity-guess", ""}, {"--motion-highpass", "1.2"}, {"--seed", ""}, {"--options", ""}}}},
      {"split", {"split " + dataset + " --from " + motion + " --out " + Out("o_split"), "o_split/report.json",
                 {{"--overwrite", ""}}}},
      {"merge", {"merge " + motion + " --out " + Out("o_merge"), "o_merge/report.json", {{"--overwrite", ""}}}},
      {"plan", {"plan " + dataset + " --out " + Out("o_plan"), "o_plan/plan.json",
                {{"--overwrite", ""}, {"--chunk", "2"}, {"--overlap", "1"}, {"--memory", "3000"}, {"--slurm", ""},
                 {"--retrack-weight", "0.31"}, {"--retrack-highpass", "1.3"}, {"--hull-weight", "0.41"}, {"--no-refine", ""}, {"--no-retrack", ""}, {"--no-retrack-register", ""},
                 {"--evidence", "background"}, {"--levels", "1"}, {"--base-faces", "60"}, {"--base-distance", "1.5"}, {"--finest-edge-pixels", "1.5"}, {"--max-finest-faces", "20000"}, {"--reference-frame", "1"},
                 {"--first-frame", "0"}, {"--frames", "3"}, {"--resolution", "28"}, {"--min-cameras", "3"},
                 {"--max-misses", "1"}, {"--evidence-threshold", "0.21"}, {"--footprint-margin", "1.7"},
                 {"--lambda", "0.0021"}, {"--motion-window", "1"}, {"--motion-threshold", "0.31"},
                 {"--background-threshold", "0.071"}, {"--background-noise-factor", "5"}, {"--no-shadow-test", ""},
                 {"--concavities", ""},
                 {"--motion-smoothness", "0.0041"}, {"--no-velocity-guess", ""}, {"--motion-highpass", "1.2"}, {"--refine-from", "1"},
                 {"--refine-to", "1"}, {"--window", "4"}, {"--window-overlap", "1"}, {"--rounds", "2"},
                 {"--concurrent-halves", "on"},
                 {"--iterations", "3"}, {"--linear-solver", "DENSE_QR"}, {"--threads", "1"},
                 {"--iterative-from-unknowns", "100"}, {"--iterative-solver", "DENSE_QR"},
                 {"--samples-per-pixel", "0.5"}, {"--max-cameras", "4"}, {"--temporal-weight", "0.5"},
                 {"--silhouette-weight", "0.1"}, {"--silhouette-from-level", "1"}, {"--slide-at-outlines", ""}, {"--rim-band", "1.5"}, {"--membrane-weight", "0.2"}, {"--temporal-smoothness", "0.2"}, {"--slide-coherence", "2.5"},
                 {"--function-tolerance", "0.004"}}}},
      {"import", {"import middlebury " + Quoted(in.calibration) + " --images " + Quoted(in.images) + " --out " + Out("o_import"),
                  "o_import/report.json",
                  {{"--overwrite", ""}, {"--units", "mm"}, {"--floor", "none"}, {"--link", "copy"},
                   {"--frames", "1"}}}},
  };
}

// Flags a case leaves out, with the reason: they need inputs of another kind, or exclude
// a flag the case sets. Each is still checked to be recorded (null or its default).
const std::map<std::string, std::set<std::string>> kNotSet = {
    {"synth", {"--gray"}},               // excludes --color-cameras
    {"shape", {"--options"}},            // every option from a file instead of the flags
    {"motion", {"--seed", "--options"}},  // an earlier range's folder; a file of options
    {"render", {"--no-dataset",        // excludes --dataset
                "--colour-by", "--colour-range"}},  // need an eval --error-maps folder (render_command_test)
    {"import", {"--videos", "--images", "--bounds", "--binning", "--colmap-names", "--min-camera-fraction",
                "--name-pattern", "--preview", "--qualisys-raw-distortion", "--skip-unmatched"}},
    {"plan", {}},
};

// Subcommands that write no report, with the reason.
const std::map<std::string, std::string> kNoReport = {
    {"check", "prints its verdict; writes nothing"},
    {"run-plan", "runs the plan's tasks, each a subflow command that writes its own report"},
    {"hull", "the shape command under another name (case shape)"},
    {"refine", "the stage commands share one report head (case shape, motion); refine needs a refinement run"},
    {"retrack", "as refine"},
    {"reconstruct", "report_flags_test.cpp"},
};

TEST(ReportArguments, EverySubcommandRecordsEveryFlagAsGiven) {
  const Inputs& inputs = MadeInputs();
  const std::map<std::string, Case> cases = Cases(inputs);
  for (const std::string& command : Listed("", true))
    EXPECT_TRUE(cases.count(command) || kNoReport.count(command))
        << "subflow " << command << " is listed by --help, but the test does not run it";
  for (const auto& [command, item] : cases) {
    SCOPED_TRACE(command);
    std::set<std::string> not_set = kNotSet.count(command) ? kNotSet.at(command) : std::set<std::string>();
    std::string arguments = item.arguments;
    for (const auto& [flag, value] : item.flags)
      if (!not_set.count(flag) && !(value.empty() && (flag == "--options" || flag == "--seed")))
        arguments += " " + flag + (value.empty() ? "" : " " + value);
    for (const std::string& flag : Listed(command))
      EXPECT_TRUE(item.flags.count(flag) || not_set.count(flag) || item.arguments.find(flag + " ") != std::string::npos)
          << flag << " is listed by --help but the test does not set it";
    const test::CommandResult run = test::RunSubflow(arguments, Scratch().path());
    ASSERT_EQ(run.exit_code, 0) << arguments << "\n" << run.output();
    const nlohmann::json report = nlohmann::json::parse(test::ReadTextFile(Scratch() / item.report));
    ASSERT_TRUE(report.contains("arguments")) << item.report;
    const nlohmann::json& recorded = report.at("arguments");
    for (const std::string& flag : Listed(command)) {
      ASSERT_TRUE(recorded.contains(flag)) << flag << " not in " << item.report << "'s arguments";
      if (!item.flags.count(flag) || not_set.count(flag)) continue;
      const std::string& value = item.flags.at(flag);
      if (value.empty() && flag != "--options" && flag != "--seed") {
        EXPECT_EQ(recorded.at(flag), true) << flag;
      } else if (!value.empty()) {
        std::string unquoted = value;
        if (unquoted.size() > 1 && unquoted.front() == '\'') unquoted = unquoted.substr(1, unquoted.size() - 2);
        const nlohmann::json& got = recorded.at(flag);
        const std::string text = got.is_string() ? got.get<std::string>() : got.dump();
        EXPECT_TRUE(text == unquoted || (got.is_array() && text.find(unquoted.substr(0, unquoted.find(','))) != std::string::npos))
            << flag << ": recorded " << got.dump() << ", given " << unquoted;
      }
    }
  }
}

}  // namespace
}  // namespace subflow
