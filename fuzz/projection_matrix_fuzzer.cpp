// libFuzzer harness: the projection-matrix importers (vision/import_projection_matrices.h) on a
// fuzzed folder (fuzz/fuzz_support.h): the matrix-file folder (image sizes from the
// images beside them, or given), and a Middlebury "<name>_par.txt" in it.
#include "fuzz/fuzz_support.h"
#include "vision/import_projection_matrices.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace fs = std::filesystem;
  const auto root = subflow::fuzz::TreeOfInput(data, size);
  subflow::vision::ProjectionMatrixImportOptions given_size;
  given_size.width = 64;
  given_size.height = 48;
  for (const auto& options : {subflow::vision::ProjectionMatrixImportOptions{}, given_size}) {
    subflow::fuzz::RunReader([&] { subflow::vision::ReadProjectionMatrixFolder(root.string(), options); });
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(root, error)) {
      const std::string name = entry.path().filename().string();
      if (name.size() > 8 && name.compare(name.size() - 8, 8, "_par.txt") == 0)
        subflow::fuzz::RunReader(
            [&] { subflow::vision::ReadMiddleburyParameters(entry.path().string(), options); });
    }
  }
  return 0;
}
