// libFuzzer harness: the COLMAP text model importer (vision/import_colmap.h) on a fuzzed
// folder with cameras.txt and images.txt (fuzz/fuzz_support.h), both naming rules.
#include "fuzz/fuzz_support.h"
#include "vision/import_colmap.h"

SUBFLOW_FUZZ_QUIET_INITIALIZE()

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto root = subflow::fuzz::TreeOfInput(data, size);
  using Options = subflow::vision::ColmapImportOptions;
  for (Options::NameFrom rule : {Options::NameFrom::kFileStem, Options::NameFrom::kParentFolder}) {
    Options options;
    options.name_from = rule;
    subflow::fuzz::RunReader([&] { subflow::vision::ReadColmapTextModel(root.string(), options); });
  }
  return 0;
}
