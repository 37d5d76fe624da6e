// core/atomic_file.h's durability: Commit() flushes the temporary to the disk before the
// rename and the directory after it. This test file replaces fsync() for its own process
// (a definition in the executable comes before libc's) to record which paths are flushed
// and whether the final name existed at that moment, then calls the real fsync.
#include <dlfcn.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "tests/test_support.h"

namespace {

struct Flush {
  std::string path;         // what the descriptor names
  bool final_name_exists;   // whether the watched final path existed when it was flushed
};

std::vector<Flush>* recorded = nullptr;
std::string watched;

}  // namespace

extern "C" int fsync(int fd) {
  static const auto real = reinterpret_cast<int (*)(int)>(dlsym(RTLD_NEXT, "fsync"));
  if (recorded) {
    char target[4096];
    const ssize_t length = readlink(("/proc/self/fd/" + std::to_string(fd)).c_str(), target, sizeof target - 1);
    recorded->push_back({length > 0 ? std::string(target, static_cast<std::size_t>(length)) : std::string(),
                         std::filesystem::exists(watched)});
  }
  return real(fd);
}

namespace subflow {
namespace {

namespace fs = std::filesystem;

TEST(AtomicFileSync, CommitFlushesTheFileBeforeTheRenameAndTheDirectoryAfterIt) {
  const test::TemporaryDirectory scratch("atomic_file_sync");
  const fs::path directory = fs::canonical(scratch.path());
  const fs::path path = directory / "report.json";
  std::vector<Flush> flushes;
  recorded = &flushes;
  watched = path.string();
  WriteFileAtomically(path.string(), "{}\n");
  recorded = nullptr;

  ASSERT_EQ(flushes.size(), 2u);
  EXPECT_EQ(flushes[0].path, (directory / ".report.json.partial").string());
  EXPECT_FALSE(flushes[0].final_name_exists) << "the data must be on the disk before the name";
  EXPECT_EQ(flushes[1].path, directory.string());
  EXPECT_TRUE(flushes[1].final_name_exists) << "the directory is flushed after the rename";
}

TEST(AtomicFileSync, AFileOpenedByALibraryIsFlushedToo) {
  const test::TemporaryDirectory scratch("atomic_file_sync_library");
  const fs::path directory = fs::canonical(scratch.path());
  const fs::path path = directory / "frame.png";
  AtomicFile file(path.string(), AtomicFile::kKeepExtension);
  {
    std::ofstream written(file.temporary(), std::ios::binary);  // as cv::imwrite would
    written << "bytes";
  }
  std::vector<Flush> flushes;
  recorded = &flushes;
  watched = path.string();
  file.Commit();
  recorded = nullptr;

  ASSERT_EQ(flushes.size(), 2u);
  EXPECT_EQ(flushes[0].path, (directory / ".frame.partial.png").string());
  EXPECT_FALSE(flushes[0].final_name_exists);
  EXPECT_EQ(flushes[1].path, directory.string());
  EXPECT_EQ(test::ReadTextFile(path), "bytes");
}

}  // namespace
}  // namespace subflow
