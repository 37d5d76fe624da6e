// `subflow reconstruct` of a take longer than --chunk: it runs as the plan of `subflow
// plan --chunk` (docs/cluster.md) in OUT/plan, so its result is the plan's, to the byte;
// the result sits in OUT as every reconstruct's does; a stop (SIGTERM) reaches the task
// that runs, which stops too (no process is left), and --resume runs only what was not
// finished.
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/cli/killed_run.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("chunked_reconstruct");
  return scratch;
}
std::string Quoted(const fs::path& path) { return "'" + path.string() + "'"; }
const std::vector<std::string> kSmall = {"--base-faces", "120", "--levels", "2", "--window", "3", "--iterations", "4"};

// A small deforming blob: 6 gray cameras, 8 frames, 160×120.
const fs::path& Dataset() {
  static const fs::path dataset = test::SynthSmallBlob(Scratch(), 8);
  return dataset;
}

// reconstruct DATASET --out OUT --chunk 5 (8 frames: 2 chunks of 4) and the small options.
std::vector<std::string> ChunkedArguments(const fs::path& out) {
  std::vector<std::string> arguments = {SUBFLOW_BINARY, "reconstruct", Dataset().string(), "--out", out.string(),
                                        "--chunk", "5"};
  arguments.insert(arguments.end(), kSmall.begin(), kSmall.end());
  return arguments;
}

std::string Small() {
  std::string options;
  for (const std::string& option : kSmall) options += " " + option;
  return options;
}

nlohmann::json ReadJson(const fs::path& path) { return nlohmann::json::parse(test::ReadTextFile(path)); }

// Whether a process other than this one has `text` in its command line.
bool AProcessMentions(const std::string& text) {
  for (const auto& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos || name == std::to_string(getpid())) continue;
    std::ifstream file(entry.path() / "cmdline");
    const std::string command_line((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    if (command_line.find(text) != std::string::npos) return true;
  }
  return false;
}

// The result files (meshes, hull, control, obj, base mesh) of `result`: those of `plan`'s result, byte for byte.
void ExpectTheSameResult(const fs::path& result, const fs::path& reference) {
  std::set<std::string> files = test::FilesBelow(result), expected = test::FilesBelow(reference);
  for (std::set<std::string>* set : {&files, &expected})
    for (auto it = set->begin(); it != set->end();)
      it = (*it == "report.json" || *it == "task_stamp.json" || it->rfind("plan/", 0) == 0) ? set->erase(it) : ++it;
  EXPECT_EQ(files, expected);
  ASSERT_GT(files.size(), 8u);
  for (const std::string& file : files)
    EXPECT_EQ(test::ReadTextFile(result / file), test::ReadTextFile(reference / file)) << file;
}

const fs::path& PlanResult() {
  static const fs::path result = [] {
    const fs::path plan = Scratch().FreshPath("plan");
    EXPECT_EQ(test::RunSubflow("plan " + Quoted(Dataset()) + " --out " + Quoted(plan) + " --chunk 4" + Small(),
                               Scratch().path()).exit_code, 0);
    const test::CommandResult run = test::RunSubflow("run-plan " + Quoted(plan), Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return plan / "result";
  }();
  return result;
}

TEST(ChunkedReconstruct, ATakeLongerThanTheChunkRunsAsThePlan) {
  const fs::path out = Scratch().FreshPath("chunked");
  const test::KilledRun run = test::RunAndKill(ChunkedArguments(out), "never printed", 1, SIGINT);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ExpectTheSameResult(out, PlanResult());
  EXPECT_FALSE(fs::exists(out / "plan" / "result"));  // moved into OUT
  const nlohmann::json report = ReadJson(out / "report.json");
  EXPECT_EQ(report["command"], "reconstruct");
  EXPECT_EQ(report["output"], out.string());
  EXPECT_EQ(report["plan"]["chunk"], 5);  // 8 frames, at most 5 a chunk: 2 chunks of 4
  EXPECT_EQ(report["plan"]["chunks"], 2);
  EXPECT_EQ(report["plan"]["tasks"].size(), 11u);  // shape, 2 × (motion, refine, retrack), 3 merges, split
  for (const auto& task : report["plan"]["tasks"]) {
    EXPECT_FALSE(task["skipped"].get<bool>()) << task;
    const std::string id = task["id"];
    if (id != "shape" && id != "split" && id.find("_merge") == std::string::npos) {
      EXPECT_LE(task["frames"][1].get<int>() - task["frames"][0].get<int>(), 4 + 2 * 2) << task;  // chunk + overlaps
    }
    EXPECT_GT(task["max_rss_kib"].get<double>(), 0.0) << task;
  }
  EXPECT_GT(report["timings_seconds"]["refinement"].get<double>(), 0.0);
  EXPECT_EQ(report["flow"].is_null(), false);

  // Not longer than the chunk: one process, no plan.
  const fs::path single = Scratch().FreshPath("single");
  std::vector<std::string> arguments = ChunkedArguments(single);
  arguments[6] = "8";
  ASSERT_EQ(test::RunAndKill(arguments, "never printed", 1, SIGINT).exit_code, 0);
  EXPECT_FALSE(fs::exists(single / "plan"));
  EXPECT_TRUE(fs::is_directory(single / "stages"));
  EXPECT_FALSE(ReadJson(single / "report.json").contains("plan"));
}

TEST(ChunkedReconstruct, AStopReachesTheRunningTaskAndResumeFinishesTheRest) {
  const fs::path out = Scratch().FreshPath("killed");
  const test::KilledRun run = test::RunAndKill(ChunkedArguments(out), "refinement", 1, SIGTERM);
  ASSERT_TRUE(run.signal_sent) << run.err;
  EXPECT_EQ(run.exit_code, 128 + SIGTERM) << run.err;
  EXPECT_NE(run.err.find("subflow reconstruct: interrupted: SIGTERM (finished: task shape, task motion_"),
            std::string::npos)
      << run.err;
  // The task itself stopped cleanly (its own message), not killed by the signal.
  EXPECT_NE(run.err.find("subflow refine: interrupted: SIGTERM"), std::string::npos) << run.err;
  EXPECT_FALSE(AProcessMentions(out.string())) << "a task outlived the stopped reconstruct";
  EXPECT_FALSE(fs::exists(out / "report.json"));
  EXPECT_FALSE(fs::exists(out / "meshes"));
  const nlohmann::json status = ReadJson(out / "plan" / "status" / "refine_0.json");  // the first refine task
  EXPECT_EQ(status["exit_code"], 128 + SIGTERM) << status;

  std::vector<std::string> resume = ChunkedArguments(out);
  resume.push_back("--resume");
  const test::KilledRun resumed = test::RunAndKill(resume, "never printed", 1, SIGINT);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  ExpectTheSameResult(out, PlanResult());
  const nlohmann::json report = ReadJson(out / "report.json");
  for (const auto& task : report["plan"]["tasks"]) {
    const bool before_the_stop = task["id"] == "shape" || task["stage"] == "motion";  // motion chunks and merge
    EXPECT_EQ(task["skipped"].get<bool>(), before_the_stop) << task;
    EXPECT_GT(task["seconds"].get<double>(), 0.0) << task;  // a skipped task: its earlier run's
  }
}

}  // namespace
}  // namespace subflow
