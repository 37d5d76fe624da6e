// libFuzzer harness: the dataset layout scan (vision/dataset.h, ../shared/DATASET.md) on a
// fuzzed file tree (fuzz/fuzz_support.h), then the first frame of every camera decoded
// (image, gray, mask, background) when the dataset opens and its images are small.
#include "fuzz/fuzz_support.h"
#include "vision/dataset.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto root = subflow::fuzz::TreeOfInput(data, size);
  subflow::fuzz::RunReader([&] {
    const subflow::vision::Dataset dataset(root.string());
    for (int c = 0; c < dataset.camera_count(); ++c) {
      // Decoding a large image costs the fuzzer time without reaching more of our code.
      if (dataset.camera(c).width() * static_cast<long long>(dataset.camera(c).height()) > 4096) continue;
      subflow::fuzz::RunReader([&] { dataset.Gray(c, 0); });
      if (dataset.has_masks()) subflow::fuzz::RunReader([&] { dataset.Mask(c, 0); });
      if (dataset.has_background()) subflow::fuzz::RunReader([&] { dataset.BackgroundGray(c); });
    }
  });
  return 0;
}
