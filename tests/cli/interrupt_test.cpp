// `subflow reconstruct` killed with SIGINT / SIGTERM at five points of its work (at the
// start of each stage, and after its last progress line: rigid split or writing): it stops
// with "interrupted: ...", exit code 128 + signal, no report.json, no temporary left, and
// every file it did leave is complete — identical to the same file of an unbroken run.
#include <csignal>
#include <cstdio>
#include <iterator>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "geometry/mesh_io.h"
#include "tests/cli/killed_run.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;
using test::FilesBelow;
using test::KilledRun;
using test::RunAndKill;
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
