// core/memory.h: the peak resident size that report.json records, and the freed heap
// memory given back between the stages of `reconstruct`.
#include "core/memory.h"

#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

// Clang says whether AddressSanitizer is on by __has_feature, GCC by __SANITIZE_ADDRESS__.
#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define SUBFLOW_HAS_ADDRESS_SANITIZER 1
#endif
#endif
#ifndef SUBFLOW_HAS_ADDRESS_SANITIZER
#define SUBFLOW_HAS_ADDRESS_SANITIZER 0
#endif

namespace subflow {
namespace {

// The resident size now (bytes), from /proc/self/statm; −1 where there is none.
long long ResidentBytes() {
  std::FILE* statm = std::fopen("/proc/self/statm", "r");
  if (!statm) return -1;
  long long pages = 0, resident = 0;
  const int read = std::fscanf(statm, "%lld %lld", &pages, &resident);
  std::fclose(statm);
  return read == 2 ? resident * sysconf(_SC_PAGESIZE) : -1;
}

TEST(Memory, FreedHeapBlocksAreGivenBackAndThePeakRemembersThem) {
#if !defined(__GLIBC__)
  GTEST_SKIP() << "ReleaseFreeMemory gives memory back with glibc's malloc_trim only";
#endif
#if defined(__SANITIZE_ADDRESS__) || SUBFLOW_HAS_ADDRESS_SANITIZER
  GTEST_SKIP() << "under AddressSanitizer malloc is the sanitizer's (freed blocks are quarantined), not glibc's, "
                  "so neither mallopt nor malloc_trim applies";
#endif
  if (ResidentBytes() < 0) GTEST_SKIP() << "no /proc/self/statm to read the resident size from";
  KeepFreedMemoryForReuse();  // as subflow's main sets it: freed blocks up to 256 MB stay
  constexpr std::size_t kBlock = 4 << 20, kBlocks = 64;  // 256 MB in blocks of 4 MB
  std::vector<std::unique_ptr<char[]>> blocks;
  for (std::size_t b = 0; b < kBlocks; ++b) {
    blocks.emplace_back(new char[kBlock]);
    std::memset(blocks.back().get(), 1, kBlock);  // resident
  }
  const long long holding = ResidentBytes();
  const long long peak_holding = PeakResidentBytes();
  blocks.clear();
  const long long freed = ResidentBytes();
  ReleaseFreeMemory();
  const long long released = ResidentBytes();
  std::printf("resident: %.0f MB holding the blocks, %.0f MB freed, %.0f MB after ReleaseFreeMemory\n",
              holding / 1e6, freed / 1e6, released / 1e6);
  EXPECT_GT(freed, holding - (64 << 20)) << "the freed blocks should still be resident before the release";
  EXPECT_LT(released, freed - (192 << 20)) << "most of the 256 MB should be given back";
  EXPECT_GT(peak_holding, 256 << 20);
  EXPECT_GE(PeakResidentBytes(), peak_holding) << "the peak is kept after the memory is given back";
}

}  // namespace
}  // namespace subflow
