// `subflow reconstruct` killed with SIGINT / SIGTERM at five points of its work (at the
// start of each stage, and after its last progress line, i.e. while writing): it stops
// with "interrupted: ...", exit code 128 + signal, no report.json, no temporary left, and
// every file it did leave is complete — identical to the same file of an unbroken run
// (stage folders the run finished keep their own report.json: docs/stages.md) — and
// `reconstruct --resume` on what is left gives the unbroken run's result.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "geometry/mesh_io.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::RunSubflow;
using test::TemporaryDirectory;

const TemporaryDirectory& Scratch() {
  static const TemporaryDirectory scratch("interrupt");
  return scratch;
}
const std::vector<std::string> kSmall = {"--base-faces", "120", "--levels", "2", "--window", "3", "--iterations", "4"};

// The small deforming blob of reconstruct_command_test: 6 gray cameras, 3 frames.
const fs::path& Dataset() {
  static const fs::path dataset = [] {
    const fs::path path = Scratch() / "blob";
    const test::CommandResult run =
        RunSubflow("synth blob --out '" + path.string() +
                       "' --cameras 6 --frames 3 --width 160 --height 120 --subdivisions 4 --gray",
                   Scratch().path());
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return path;
  }();
  return dataset;
}

std::vector<std::string> ReconstructArguments(const fs::path& out) {
  std::vector<std::string> arguments = {SUBFLOW_BINARY, "reconstruct", Dataset().string(), "--out", out.string()};
  arguments.insert(arguments.end(), kSmall.begin(), kSmall.end());
  return arguments;
}

struct KilledRun {
  int exit_code = -1;        // −1: did not exit normally (killed by the signal itself)
  bool signal_sent = false;  // false: the run ended before the trigger line
  std::string err;
};

// Runs `arguments`, reading its stderr line by line; sends `signal_number` once the
// `occurrence`-th line containing `trigger` was printed ("" = after the last line whose
// stage is `trigger`... see the callers), then waits for it to end.
KilledRun RunAndKill(const std::vector<std::string>& arguments, const std::string& trigger, int occurrence,
                     int signal_number) {
  int pipe_ends[2];
  EXPECT_EQ(pipe(pipe_ends), 0);
  const pid_t child = fork();
  if (child == 0) {
    dup2(pipe_ends[1], STDERR_FILENO);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDOUT_FILENO);
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    std::vector<char*> argv;
    for (const std::string& argument : arguments) argv.push_back(const_cast<char*>(argument.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(pipe_ends[1]);
  KilledRun run;
  FILE* err = fdopen(pipe_ends[0], "r");
  char line[4096];
  int seen = 0;
  while (std::fgets(line, sizeof line, err)) {
    run.err += line;
    if (!run.signal_sent && std::string(line).find(trigger) != std::string::npos && ++seen == occurrence) {
      kill(child, signal_number);
      run.signal_sent = true;
    }
  }
  std::fclose(err);
  int status = 0;
  waitpid(child, &status, 0);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// Every regular file below `root`, relative.
std::set<std::string> FilesBelow(const fs::path& root) {
  std::set<std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file()) files.insert(fs::relative(entry.path(), root).string());
  return files;
}

// report.json files hold timings: they are compared by presence, not by bytes.
bool IsReport(const std::string& file) { return fs::path(file).filename() == "report.json"; }

const fs::path& UnbrokenRun() {
  static const fs::path out = [] {
    const fs::path path = Scratch().FreshPath("unbroken");
    const KilledRun run = RunAndKill(ReconstructArguments(path), "never printed", 1, SIGINT);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return path;
  }();
  return out;
}

TEST(Interrupt, ReconstructRunIsDeterministic) {
  // The comparison below needs it: two unbroken runs give the same bytes.
  const fs::path again = Scratch().FreshPath("again");
  ASSERT_EQ(RunAndKill(ReconstructArguments(again), "never printed", 1, SIGINT).exit_code, 0);
  ASSERT_EQ(FilesBelow(again), FilesBelow(UnbrokenRun()));
  for (const std::string& file : FilesBelow(again)) {
    if (IsReport(file)) continue;  // holds timings
    EXPECT_EQ(test::ReadTextFile(again / file), test::ReadTextFile(UnbrokenRun() / file)) << file;
  }
}

struct KillPoint {
  std::string trigger;  // a stage name as the progress bar prints it
  int occurrence;       // kill after this many of its lines
  int signal_number;
};

class InterruptedReconstruct : public ::testing::TestWithParam<KillPoint> {};

TEST_P(InterruptedReconstruct, LeavesOnlyCompleteFilesAndNoReport) {
  const KillPoint point = GetParam();
  const std::set<std::string> complete = FilesBelow(UnbrokenRun());
  ASSERT_TRUE(complete.count("report.json"));
  const fs::path out = Scratch().FreshPath("killed_" + std::to_string(point.signal_number) + "_" +
                                           std::to_string(point.occurrence) + "_" + point.trigger.substr(0, 6));
  const KilledRun run = RunAndKill(ReconstructArguments(out), point.trigger, point.occurrence, point.signal_number);
  ASSERT_TRUE(run.signal_sent) << "the run ended before " << point.trigger << " #" << point.occurrence << "\n"
                               << run.err;
  // A run the signal reached before it finished its work stops cleanly; one it reached
  // after (the signal came too late) is complete.
  if (run.exit_code == 0) {
    EXPECT_TRUE(fs::exists(out / "report.json")) << run.err;
    GTEST_SKIP() << "the run completed before the signal was handled (nothing to check beyond that)";
  }
  EXPECT_EQ(run.exit_code, 128 + point.signal_number) << run.err;
  const std::string name = point.signal_number == SIGINT ? "SIGINT" : "SIGTERM";
  EXPECT_NE(run.err.find("subflow reconstruct: interrupted: " + name + " (finished: "), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out / "report.json"));
  if (!fs::exists(out)) return;
  for (const std::string& file : FilesBelow(out)) {
    EXPECT_EQ(file.find(".partial"), std::string::npos) << "temporary left: " << file;
    ASSERT_TRUE(complete.count(file)) << file << " is not a file of the unbroken run";
    if (IsReport(file)) continue;  // a stage folder's: the stage finished (its files are checked here too)
    EXPECT_EQ(test::ReadTextFile(out / file), test::ReadTextFile(UnbrokenRun() / file))
        << file << " differs from the unbroken run's";
    if (fs::path(file).extension() == ".ply") EXPECT_NO_THROW(geometry::ReadMesh((out / file).string()));
  }

  // --resume continues from what the killed run left and gives the unbroken run's result.
  std::vector<std::string> resume = ReconstructArguments(out);
  resume.push_back("--resume");
  const KilledRun resumed = RunAndKill(resume, "never printed", 1, SIGINT);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(FilesBelow(out), complete);
  for (const std::string& file : FilesBelow(out))
    if (!IsReport(file))
      EXPECT_EQ(test::ReadTextFile(out / file), test::ReadTextFile(UnbrokenRun() / file))
          << file << " of the resumed run differs from the unbroken run's";
}

INSTANTIATE_TEST_SUITE_P(
    FivePoints, InterruptedReconstruct,
    ::testing::Values(KillPoint{"visual hull", 1, SIGINT}, KillPoint{"fit subdivision surface", 1, SIGTERM},
                      KillPoint{"motion initialization", 1, SIGINT}, KillPoint{"refinement", 2, SIGTERM},
                      KillPoint{"motion initialization", 6, SIGINT}),
    [](const ::testing::TestParamInfo<KillPoint>& info) { return "point" + std::to_string(info.index); });

}  // namespace
}  // namespace subflow
