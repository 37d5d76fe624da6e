// libFuzzer harness: cameras.json (vision/dataset.h ReadCamerasJson), from a file.
#include "fuzz/fuzz_support.h"
#include "vision/dataset.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto path = subflow::fuzz::FreshScratch() / "cameras.json";
  subflow::fuzz::WriteFile(path, {reinterpret_cast<const char*>(data), size});
  subflow::fuzz::RunReader([&] {
    subflow::vision::DatasetInfo info;
    subflow::vision::ReadCamerasJson(path.string(), &info);
  });
  return 0;
}
