// Shared by the libFuzzer harnesses (fuzz/<reader>_fuzzer.cpp, one per reader).
//
// A harness feeds the fuzzer's bytes to one reader and lets only subflow::Error through:
// a reader that crashes, trips ASan/UBSan, throws anything else (std::bad_alloc,
// std::out_of_range, nlohmann's exceptions...), runs out of the memory limit or hangs is a
// finding. Readers of files or directories get them on tmpfs (/dev/shm when present).
//
// Directory readers (the dataset layout, the calibration importers) take a file tree
// written as blocks, as `head` prints several files:
//
//   ==> cameras.json <==
//   {"format": ...}
//   ==> images/cam0/000000.png <==
//   <bytes of the PNG>
//   ==> masks/ <==
//
// A block's content runs from the line after its marker to the next marker line (the
// newline before a marker belongs to the marker). A path ending in '/' is a directory.
// Paths are relative, of at most kMaxDepth components of at most kMaxName characters,
// without "." or ".." components; other blocks are skipped. Adding a harness for a new
// directory reader is one file: WriteFileTree, then call the reader in RunReader.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>
#include <algorithm>

#include <spdlog/spdlog.h>

#include "core/error.h"

namespace subflow::fuzz {

namespace fs = std::filesystem;

inline constexpr int kMaxDepth = 6;
inline constexpr std::size_t kMaxName = 64;
inline constexpr int kMaxFiles = 64;

// Calls `read`; swallows subflow::Error (the readers' way to refuse input), lets every
// other exception escape (libFuzzer reports it as a crash).
template <class Read>
void RunReader(Read read) {
  try {
    read();
  } catch (const subflow::Error&) {
  }
}

// Silences the readers' warnings (call from LLVMFuzzerInitialize).
inline void QuietLogs() { spdlog::set_level(spdlog::level::off); }

// A per-process scratch directory on tmpfs, emptied by each call.
inline fs::path FreshScratch() {
  static const fs::path root =
      (fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path()) /
      ("subflow_fuzz_" + std::to_string(::getpid()));
  std::error_code ignored;
  fs::remove_all(root, ignored);
  fs::create_directories(root);
  return root;
}

inline void WriteFile(const fs::path& path, std::string_view content) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(content.data(), static_cast<std::streamsize>(content.size()));
}

// `relative` as a safe path below `root`, or empty when it is not acceptable.
inline fs::path SafePath(const fs::path& root, std::string_view relative) {
  fs::path path = root;
  int depth = 0;
  std::size_t start = 0;
  while (start < relative.size()) {
    std::size_t end = relative.find('/', start);
    if (end == std::string_view::npos) end = relative.size();
    const std::string_view name = relative.substr(start, end - start);
    if (name.empty() || name == "." || name == ".." || name.size() > kMaxName ||
        name.find('\0') != std::string_view::npos || ++depth > kMaxDepth)
      return {};
    path /= std::string(name);
    start = end + 1;
  }
  return depth == 0 ? fs::path() : path;
}

// Writes the file tree described by `data` (see the file comment) below `root`.
inline void WriteFileTree(const std::uint8_t* data, std::size_t size, const fs::path& root) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  static constexpr std::string_view kOpen = "==> ", kClose = " <==";
  struct Block {
    std::string_view name;
    std::size_t marker = 0, body = 0;  // start of the marker line, of the content
  };
  std::vector<Block> blocks;
  for (std::size_t line = 0; line < text.size();) {
    std::size_t end = text.find('\n', line);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view content = text.substr(line, end - line);
    if (content.size() >= kOpen.size() + kClose.size() && content.substr(0, kOpen.size()) == kOpen &&
        content.substr(content.size() - kClose.size()) == kClose)
      blocks.push_back({content.substr(kOpen.size(), content.size() - kOpen.size() - kClose.size()),
                        line, std::min(end + 1, text.size())});
    line = end + 1;
  }
  int files = 0;
  for (std::size_t b = 0; b < blocks.size() && files < kMaxFiles; ++b) {
    const Block& block = blocks[b];
    // Up to the newline before the next marker, or to the end.
    const std::size_t end = b + 1 < blocks.size() ? std::max(block.body, blocks[b + 1].marker - 1) : text.size();
    const bool directory = !block.name.empty() && block.name.back() == '/';
    const fs::path path =
        SafePath(root, directory ? block.name.substr(0, block.name.size() - 1) : block.name);
    if (path.empty()) continue;
    ++files;
    std::error_code error;
    if (directory) {
      fs::create_directories(path, error);
      continue;
    }
    fs::create_directories(path.parent_path(), error);
    if (!error && !fs::is_directory(path, error)) WriteFile(path, text.substr(block.body, end - block.body));
  }
}

// A fresh scratch directory holding the file tree of the fuzzer's input.
inline fs::path TreeOfInput(const std::uint8_t* data, std::size_t size) {
  const fs::path root = FreshScratch();
  WriteFileTree(data, size, root);
  return root;
}

}  // namespace subflow::fuzz

// Every harness's LLVMFuzzerInitialize: the readers' warnings silenced.
#define SUBFLOW_FUZZ_QUIET_INITIALIZE()                  \
  extern "C" int LLVMFuzzerInitialize(int*, char***) { \
    subflow::fuzz::QuietLogs();                        \
    return 0;                                          \
  }
