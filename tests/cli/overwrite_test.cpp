// Every subcommand that writes refuses an existing output unless given --overwrite, and
// then leaves what the user had untouched; with --overwrite it replaces it. The table
// below must list every subcommand of `subflow --help` (a new one fails the test until it
// is classified), so no writing command can slip through.
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "geometry/mesh_io.h"
#include "geometry/mesh_primitives.h"
#include "tests/test_support.h"
#include "vision/synthetic_render.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("overwrite_test");
  return scratch;
}

std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// A sphere seen by 4 cameras at 48×36 pixels, 2 frames: a second to render and to carve.
const fs::path& TinyDataset() {
  static const fs::path directory = [] {
    const fs::path path = Scratch().FreshPath("dataset");
    vision::SynthOptions options;
    options.scene.scene = "sphere";
    options.scene.frame_count = 2;
    options.scene.subdivisions = 3;
    options.rig.camera_count = 4;
    options.colour_cameras = {0};
    options.rig.width = 48;
    options.rig.height = 36;
    vision::WriteSyntheticDataset(path.string(), options);
    return path;
  }();
  return directory;
}

std::string HullOptions() { return " --levels 1 --base-faces 60 --min-cameras 3"; }

// A result of `hull` on the tiny dataset, for eval.
const fs::path& TinyResult() {
  static const fs::path directory = [] {
    const fs::path out = Scratch().FreshPath("result");
    const test::CommandResult run =
        test::RunSubflow("hull " + Quoted(TinyDataset()) + " --out " + Quoted(out) + HullOptions(), Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return out;
  }();
  return directory;
}

// The stage folder `stage` (motion or refine) run on TinyResult (a shape stage folder).
const fs::path& TinyStage(const std::string& stage) {
  static std::map<std::string, fs::path> folders;
  if (!folders.count(stage)) {
    const fs::path from = stage == "motion" ? TinyResult() : TinyStage("motion");
    const fs::path out = Scratch().FreshPath("stage_" + stage);
    const test::CommandResult run = test::RunSubflow(
        stage + " " + Quoted(TinyDataset()) + " --from " + Quoted(from) + " --out " + Quoted(out) +
            (stage == "refine" ? " --iterations 1" : ""),
        Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    folders[stage] = out;
  }
  return folders.at(stage);
}

const fs::path& Tetrahedron() {
  static const fs::path path = [] {
    const fs::path file = Scratch() / "tetrahedron.ply";
    geometry::WriteMesh(file.string(), geometry::Tetrahedron());
    return file;
  }();
  return path;
}

struct WritingCommand {
  bool writes_directory;
  std::function<std::string(const fs::path& out)> arguments;  // without --overwrite
  bool try_overwrite;  // also run with --overwrite (cheap enough here)
};

// Every subcommand: how it names its output, or nullptr for a command that writes no file.
const std::map<std::string, const WritingCommand*>& Commands() {
  static const WritingCommand subdivide{
      false, [](const fs::path& out) { return "subdivide " + Quoted(Tetrahedron()) + " --levels 1 --out " + Quoted(out); },
      true};
  static const WritingCommand eval{
      false,
      [](const fs::path& out) {
        return "eval " + Quoted(TinyDataset()) + " " + Quoted(TinyResult()) + " --samples 500 --json " + Quoted(out);
      },
      true};
  static const WritingCommand synth{
      true, [](const fs::path& out) { return "synth sphere --cameras 2 --width 16 --height 12 --frames 1 --out " + Quoted(out); },
      true};
  static const WritingCommand hull{
      true, [](const fs::path& out) { return "hull " + Quoted(TinyDataset()) + " --out " + Quoted(out) + HullOptions(); },
      true};
  static const WritingCommand shape{
      true, [](const fs::path& out) { return "shape " + Quoted(TinyDataset()) + " --out " + Quoted(out) + HullOptions(); },
      false};
  // The stages after shape, each on the folder of the stage before it.
  const auto stage_command = [](const std::string& stage, const std::string& from) {
    return [stage, from](const fs::path& out) {
      const fs::path input = from == "shape" ? TinyResult() : TinyStage(from);
      return stage + " " + Quoted(TinyDataset()) + " --from " + Quoted(input) + " --out " + Quoted(out) +
             (stage == "refine" ? " --iterations 1" : "");
    };
  };
  static const WritingCommand motion{true, stage_command("motion", "shape"), true};
  static const WritingCommand refine{true, stage_command("refine", "motion"), false};
  static const WritingCommand retrack{true, stage_command("retrack", "refine"), false};
  static const WritingCommand split{true, stage_command("split", "motion"), true};
  static const WritingCommand merge{
      true, [](const fs::path& out) { return "merge " + Quoted(TinyStage("motion")) + " --out " + Quoted(out); },
      true};
  static const WritingCommand plan{
      true, [](const fs::path& out) { return "plan " + Quoted(TinyDataset()) + " --chunk 2 --out " + Quoted(out); },
      true};
  static const WritingCommand reconstruct{
      true, [](const fs::path& out) { return "reconstruct " + Quoted(TinyDataset()) + " --out " + Quoted(out) + HullOptions(); },
      false};
  static const WritingCommand export_glb{
      false, [](const fs::path& out) { return "export " + Quoted(TinyResult()) + " --format glb --out " + Quoted(out); },
      true};
  static const WritingCommand import_qualisys{
      true,
      [](const fs::path& out) {
        const fs::path take = fs::path(SUBFLOW_SHARED_DIR) / "data" / "pose2sim_multiperson";
        return "import qualisys " + Quoted(take / "calibration" / "Calib.qca.txt") + " --videos " +
               Quoted(take / "videos") + " --out " + Quoted(out);
      },
      true};
  static const WritingCommand render{
      true,
      [](const fs::path& out) { return "render " + Quoted(TinyResult()) + " --no-dataset --views 1 --out " + Quoted(out); },
      true};
  static const WritingCommand view{
      false, [](const fs::path& out) { return "view " + Quoted(TinyResult()) + " --no-texture --out " + Quoted(out); },
      true};
  static const std::map<std::string, const WritingCommand*> commands = {
      {"check", nullptr},  // prints its figures (text or --json) on stdout only
      {"subdivide", &subdivide}, {"eval", &eval}, {"synth", &synth}, {"hull", &hull},
      {"shape", &shape}, {"motion", &motion}, {"refine", &refine}, {"retrack", &retrack}, {"split", &split},
      {"merge", &merge}, {"plan", &plan},
      {"run-plan", nullptr},  // writes only the tasks' folders of its plan (each task with --overwrite)
      {"reconstruct", &reconstruct}, {"export", &export_glb}, {"import", &import_qualisys}, {"render", &render},
      {"view", &view}};
  return commands;
}

// The subcommand names listed by `subflow --help`.
std::vector<std::string> ListedSubcommands() {
  const test::CommandResult run = test::RunSubflow("--help", Scratch().path());
  std::istringstream lines(run.out);
  std::vector<std::string> names;
  bool in_list = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("Subcommands:", 0) == 0) {
      in_list = true;
      continue;
    }
    if (in_list && line.size() > 2 && line[0] == ' ' && line[2] != ' ') names.push_back(line.substr(2, line.find(' ', 2) - 2));
  }
  return names;
}

TEST(Overwrite, EverySubcommandIsClassified) {
  const std::vector<std::string> listed = ListedSubcommands();
  ASSERT_GE(listed.size(), 6u);
  for (const std::string& name : listed)
    EXPECT_TRUE(Commands().count(name))
        << "subcommand \"" << name << "\" is not in tests/cli/overwrite_test.cpp's table: add how it names "
        << "its output (it must refuse an existing one without --overwrite), or nullptr if it writes none";
}

TEST(Overwrite, EveryWritingCommandRefusesAnExistingOutputAndLeavesItUntouched) {
  for (const auto& [name, command] : Commands()) {
    if (!command) continue;
    SCOPED_TRACE(name);
    const fs::path out = Scratch().FreshPath("existing_" + name + (command->writes_directory ? "" : ".ply"));
    const fs::path precious = command->writes_directory ? out / "precious.txt" : out;
    if (command->writes_directory) fs::create_directories(out);
    std::ofstream(precious) << "the user's data\n";

    const test::CommandResult refused = test::RunSubflow(command->arguments(out), Scratch().path());
    EXPECT_EQ(refused.exit_code, 1) << refused.output();
    EXPECT_EQ(refused.err.rfind("subflow " + name + ": error: " + out.string(), 0), 0u) << refused.err;
    EXPECT_NE(refused.err.find("--overwrite"), std::string::npos) << refused.err;
    EXPECT_EQ(refused.err.find('\n'), refused.err.size() - 1) << "not one line: " << refused.err;
    EXPECT_EQ(test::ReadTextFile(precious), "the user's data\n");
    if (command->writes_directory) {
      EXPECT_EQ(std::distance(fs::directory_iterator(out), {}), 1);
    }

    if (!command->try_overwrite) continue;
    const test::CommandResult replaced = test::RunSubflow(command->arguments(out) + " --overwrite", Scratch().path());
    EXPECT_EQ(replaced.exit_code, 0) << replaced.output();
    if (!command->writes_directory) {
      EXPECT_NE(test::ReadTextFile(out), "the user's data\n");
    }
  }
}

TEST(Overwrite, OverwritingAResultLeavesNoFileOfThePreviousOne) {
  const fs::path out = Scratch().FreshPath("shorter");
  const std::string hull = "hull " + Quoted(TinyDataset()) + " --out " + Quoted(out) + HullOptions();
  ASSERT_EQ(test::RunSubflow(hull, Scratch().path()).exit_code, 0);
  ASSERT_TRUE(fs::exists(out / "meshes" / "000001.ply"));
  std::ofstream(out / "notes.txt") << "the user's notes\n";
  const test::CommandResult shorter = test::RunSubflow(hull + " --frames 1 --overwrite", Scratch().path());
  ASSERT_EQ(shorter.exit_code, 0) << shorter.output();
  EXPECT_TRUE(fs::exists(out / "meshes" / "000000.ply"));
  EXPECT_FALSE(fs::exists(out / "meshes" / "000001.ply")) << "a frame of the previous result is left";
  EXPECT_FALSE(fs::exists(out / "hull" / "000001.ply")) << "a hull of the previous result is left";
  EXPECT_EQ(test::ReadTextFile(out / "notes.txt"), "the user's notes\n");
}

TEST(Overwrite, AnOutputFileThatIsADirectoryOrInAMissingDirectoryIsRefused) {
  const fs::path directory = Scratch().Subdirectory("a_directory.ply");
  test::CommandResult run = test::RunSubflow(Commands().at("subdivide")->arguments(directory), Scratch().path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("is a directory"), std::string::npos) << run.err;
  run = test::RunSubflow(Commands().at("subdivide")->arguments(Scratch() / "missing" / "out.ply"), Scratch().path());
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("does not exist"), std::string::npos) << run.err;
}

}  // namespace
}  // namespace subflow
