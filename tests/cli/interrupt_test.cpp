// `subflow reconstruct` killed with SIGINT / SIGTERM at five points of its work (at the
// start of each stage, and after its last progress line: rigid split or writing): it stops
// with "interrupted: ...", exit code 128 + signal, no report.json, no temporary left, and
// every file it did leave is complete — identical to the same file of an unbroken run.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <iterator>
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
using test::TemporaryDirectory;

const TemporaryDirectory& Scratch() {
  static const TemporaryDirectory scratch("interrupt");
  return scratch;
}
const std::vector<std::string> kSmall = {"--base-faces", "120", "--levels", "2", "--window", "3", "--iterations", "4"};

const fs::path& Dataset() {
  static const fs::path dataset = test::SynthSmallBlob(Scratch());
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
// `occurrence`-th line containing `trigger` was printed, then waits for it to end.
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

struct KillPoint {
  std::string trigger;  // a stage name as the progress bar prints it
  int occurrence;       // kill after this many of its lines
  int signal_number;
  bool may_complete = false;  // the work may end before the signal is handled
};

// report.json files hold timings: they are compared by presence, not by bytes (a stage
// folder the killed run finished keeps its own: docs/stages.md).
bool IsReport(const std::string& file) { return fs::path(file).filename() == "report.json"; }

// Checks one killed run against the unbroken one, then that `reconstruct --resume` on what
// it left gives the unbroken run's files; returns how many files the killed run left.
int CheckKilledRun(const KillPoint& point, const fs::path& unbroken, const fs::path& out) {
  const std::set<std::string> complete = FilesBelow(unbroken);
  const KilledRun run = RunAndKill(ReconstructArguments(out), point.trigger, point.occurrence, point.signal_number);
  EXPECT_TRUE(run.signal_sent) << "the run ended before " << point.trigger << " #" << point.occurrence << "\n"
                               << run.err;
  if (point.may_complete && run.exit_code == 0) {  // complete: then it is the unbroken run
    EXPECT_EQ(FilesBelow(out), complete);
    std::printf("the run completed before the signal was handled\n");
    return -1;
  }
  EXPECT_EQ(run.exit_code, 128 + point.signal_number) << run.err;
  const std::string name = point.signal_number == SIGINT ? "SIGINT" : "SIGTERM";
  EXPECT_NE(run.err.find("subflow reconstruct: interrupted: " + name + " (finished: "), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(out / "report.json"));
  if (!fs::exists(out)) return 0;
  const std::set<std::string> left = FilesBelow(out);
  for (const std::string& file : left) {
    EXPECT_EQ(file.find(".partial"), std::string::npos) << "temporary left: " << file;
    if (!complete.count(file)) {
      ADD_FAILURE() << file << " is not a file of the unbroken run";
      continue;
    }
    if (IsReport(file)) continue;
    EXPECT_EQ(test::ReadTextFile(out / file), test::ReadTextFile(unbroken / file))
        << file << " differs from the unbroken run's";
    if (fs::path(file).extension() == ".ply") {
      EXPECT_NO_THROW(geometry::ReadMesh((out / file).string())) << file;
    }
  }
  std::vector<std::string> resume = ReconstructArguments(out);
  resume.push_back("--resume");
  const KilledRun resumed = RunAndKill(resume, "never printed", 1, SIGINT);
  EXPECT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(FilesBelow(out), complete);
  for (const std::string& file : FilesBelow(out)) {
    if (!IsReport(file)) {
      EXPECT_EQ(test::ReadTextFile(out / file), test::ReadTextFile(unbroken / file))
          << file << " of the resumed run differs from the unbroken run's";
    }
  }
  return static_cast<int>(left.size());
}

TEST(Interrupt, KilledReconstructLeavesOnlyCompleteFilesAndNoReport) {
  const fs::path unbroken = Scratch().FreshPath("unbroken");
  ASSERT_EQ(RunAndKill(ReconstructArguments(unbroken), "never printed", 1, SIGINT).exit_code, 0);
  ASSERT_TRUE(fs::exists(unbroken / "report.json"));
  // The comparison needs it: a second unbroken run gives the same bytes.
  const fs::path again = Scratch().FreshPath("again");
  ASSERT_EQ(RunAndKill(ReconstructArguments(again), "never printed", 1, SIGINT).exit_code, 0);
  ASSERT_EQ(FilesBelow(again), FilesBelow(unbroken));
  for (const std::string& file : FilesBelow(again)) {
    if (IsReport(file)) continue;  // holds timings
    ASSERT_EQ(test::ReadTextFile(again / file), test::ReadTextFile(unbroken / file)) << file;
  }

  // At the start of each stage, and after the retrack's last line (while the rigid split
  // runs or the files are being written: then complete meshes may be left, no report).
  const KillPoint points[] = {{"visual hull", 1, SIGINT},
                              {"fit subdivision surface", 1, SIGTERM},
                              {"motion initialization", 2, SIGINT},
                              {"refinement", 2, SIGTERM},
                              {"motion initialization", 6, SIGINT, true}};
  for (std::size_t p = 0; p < std::size(points); ++p) {
    SCOPED_TRACE("kill point " + std::to_string(p) + ": " + points[p].trigger + " #" +
                 std::to_string(points[p].occurrence));
    const int left = CheckKilledRun(points[p], unbroken, Scratch().FreshPath("killed_" + std::to_string(p)));
    std::printf("kill point %zu: %d complete files left\n", p, left);
  }
}

}  // namespace
}  // namespace subflow
