// core/atomic_file.h and core/interrupt.h: a file carries its final name only once
// complete, a temporary never survives an error or an interruption, and progress points
// stop the work once a signal arrived.
#include <csignal>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/interrupt.h"
#include "core/progress.h"
#include "tests/test_support.h"

namespace subflow {
namespace {

namespace fs = std::filesystem;

const test::TemporaryDirectory& Scratch() {
  static const test::TemporaryDirectory scratch("atomic_file");
  return scratch;
}

TEST(AtomicFile, TheFinalNameAppearsOnlyAtCommit) {
  const fs::path path = Scratch().FreshPath("a.json");
  AtomicFile file(path.string());
  file.stream() << "{\"complete\": ";
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(fs::exists(Scratch() / ".a.json.partial"));
  file.stream() << "true}\n";
  file.Commit();
  EXPECT_EQ(test::ReadTextFile(path), "{\"complete\": true}\n");
  EXPECT_FALSE(fs::exists(Scratch() / ".a.json.partial"));
}

TEST(AtomicFile, AnUncommittedFileLeavesNothingAndKeepsThePreviousOne) {
  const fs::path path = Scratch().FreshPath("b.ply");
  WriteFileAtomically(path.string(), "the previous, complete file");
  try {
    AtomicFile file(path.string());
    file.stream() << "half a mesh";
    throw Error("the writer failed");
  } catch (const Error&) {
  }
  EXPECT_EQ(test::ReadTextFile(path), "the previous, complete file");
  for (const auto& entry : fs::directory_iterator(Scratch().path()))
    EXPECT_EQ(entry.path().filename().string().find(".partial"), std::string::npos) << entry.path();
}

TEST(AtomicFile, TemporaryNamesAreHiddenAndNotTakenForTheFormat) {
  EXPECT_EQ(AtomicFile::TemporaryPath("out/meshes/000001.ply", AtomicFile::kPartialSuffix),
            "out/meshes/.000001.ply.partial");
  // For writers that choose the container from the extension (cv::VideoWriter).
  EXPECT_EQ(AtomicFile::TemporaryPath("videos/cam01.mp4", AtomicFile::kKeepExtension), "videos/.cam01.partial.mp4");
}

TEST(AtomicFile, CommitWithoutAnyWriteIsAnErrorNamingTheFile) {
  const fs::path path = Scratch().FreshPath("never.mp4");
  AtomicFile file(path.string(), AtomicFile::kKeepExtension);
  try {
    file.Commit();
    ADD_FAILURE() << "a file nobody wrote was committed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(path.string() + ": was not written"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(AtomicFile, UnwritableDirectoryIsAnErrorNamingTheFile) {
  const std::string path = (Scratch() / "no" / "such" / "dir" / "c.png").string();
  AtomicFile file(path);
  try {
    file.stream();
    ADD_FAILURE() << "opened a file in a missing directory";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot open", 0), 0u) << e.what();
  }
}

// A stage that writes one file per step and one file over all steps, as the writers of
// subflow do (meshes/<frame>.ply; a .glb).
void WriteSteps(const fs::path& directory, int steps, int raise_at) {
  ProgressBegin(nullptr, "writing steps", static_cast<std::size_t>(steps));
  AtomicFile all((directory / "all.txt").string());
  for (int i = 0; i < steps; ++i) {
    all.stream() << "step " << i << "\n";
    WriteFileAtomically((directory / (std::to_string(i) + ".txt")).string(), "step " + std::to_string(i) + "\n");
    if (i == raise_at) std::raise(SIGTERM);
    ProgressUpdate(nullptr, static_cast<std::size_t>(i + 1));
  }
  all.Commit();
  ProgressEnd(nullptr);
}

TEST(Interrupt, SignalStopsAtTheNextProgressPointAndRemovesThePartialFile) {
  InstallInterruptHandlers();
  ResetInterruptState();
  const fs::path directory = Scratch().Subdirectory("steps");
  ProgressBegin(nullptr, "reading", 2);
  ProgressEnd(nullptr);
  try {
    WriteSteps(directory, 5, 2);
    ADD_FAILURE() << "SIGTERM did not stop the work";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.signal_number(), SIGTERM);
    EXPECT_EQ(std::string(e.what()), "SIGTERM (finished: reading; stopped in writing steps at 3/5)");
  }
  // Steps 0..2 complete, nothing after; the file over all steps is neither there nor half there.
  EXPECT_EQ(test::ReadTextFile(directory / "2.txt"), "step 2\n");
  EXPECT_FALSE(fs::exists(directory / "3.txt"));
  EXPECT_FALSE(fs::exists(directory / "all.txt"));
  EXPECT_FALSE(fs::exists(directory / ".all.txt.partial"));
  ResetInterruptState();
  InstallInterruptHandlers();  // SA_RESETHAND restored the default action
  WriteSteps(directory, 5, -1);  // without a signal, the same work completes
  EXPECT_EQ(test::ReadTextFile(directory / "all.txt"), "step 0\nstep 1\nstep 2\nstep 3\nstep 4\n");
}

}  // namespace
}  // namespace subflow
