// libFuzzer harness: every calibration importer behind `subflow import` (vision/
// read_calibration.h, CalibrationFormats(): COLMAP text/binary, matrices, Middlebury,
// Qualisys, TOML, EasyMocap, Panoptic, and any format added there) on a fuzzed file tree
// (fuzz/fuzz_support.h): each format reads the folder itself and each file in it.
#include "fuzz/fuzz_support.h"
#include "vision/read_calibration.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const auto root = subflow::fuzz::TreeOfInput(data, size);
  std::vector<std::string> sources{root.string()};
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(root, error))
    if (entry.is_regular_file(error)) sources.push_back(entry.path().string());
  for (const auto& format : subflow::vision::CalibrationFormats())  // {name, description}
    for (const std::string& source : sources)
      subflow::fuzz::RunReader([&] { subflow::vision::ReadCalibration(format.first, source); });
  return 0;
}
